//! The per-module formal check from reset on chosen lines of a saved
//! mutation list (ids = line numbers from 1, as `cancosim mutate --list`
//! numbers them), without the simulation campaign:
//!
//! cargo run --release -p mutate --example prove_list -- DIR TOP FILES(comma) LIST WORK SECONDS ID...
//!
//! FILES in the order of the mutants' build (cancosim's RTL_FILES for rtl/).
use mutate::{CoreSources, FormalOptions, Mutation};
use std::path::PathBuf;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 7 {
        eprintln!("usage: prove_list DIR TOP FILES LIST WORK SECONDS ID...");
        std::process::exit(2);
    }
    let src = CoreSources { dir: PathBuf::from(&a[0]), top: a[1].clone(), files: a[2].split(',').map(PathBuf::from).collect(), ..Default::default() };
    let lines: Vec<String> = std::fs::read_to_string(&a[3]).expect("the list").lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#')).map(String::from).collect();
    let opts = FormalOptions { steps: 30, induction: 0, timeout_s: a[5].parse().expect("seconds") };
    for id in &a[6..] {
        let id: u32 = id.parse().expect("an id");
        let m = Mutation::parse(id, &lines[id as usize - 1]).expect("a mutation line");
        match mutate::reset_proof::check_in_module(&src, &m, &opts, &PathBuf::from(&a[4])) {
            Ok(Ok(c)) => println!("{id}\t{}\t{}\t{:.1} s\t{}", m.location(), c.module, c.seconds, c.verdict.describe()),
            Ok(Err(why)) => println!("{id}\t{}\tnot per module: {why:?}", m.location()),
            Err(e) => println!("{id}\t{}\terror: {}", m.location(), e.to_string().lines().last().unwrap_or("")),
        }
    }
}
