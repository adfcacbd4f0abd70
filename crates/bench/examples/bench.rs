//! The full bench by command, until the CLI exposes it:
//! `cargo run --release -p bench --example bench -- [--smoke] [--json] [--frames N]`.

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut opts = bench::BenchOptions {
        smoke: args.iter().any(|a| a == "--smoke"),
        ..Default::default()
    };
    if let Some(i) = args.iter().position(|a| a == "--frames") {
        opts.frames = args
            .get(i + 1)
            .and_then(|v| v.parse().ok())
            .unwrap_or(opts.frames);
    }
    match bench::run(&opts) {
        Ok(r) => {
            if args.iter().any(|a| a == "--json") {
                println!("{}", r.to_json());
            } else {
                print!("{}", r.to_table());
            }
            if let Err(e) = r.check() {
                eprintln!("{e}");
                std::process::exit(2);
            }
        }
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    }
}
