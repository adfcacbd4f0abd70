//! `cancosim`: the command line of the verification kit.
fn main() {
    eprintln!("cancosim: not built yet");
    std::process::exit(2);
}
