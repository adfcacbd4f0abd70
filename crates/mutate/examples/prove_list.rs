//! The per-module formal check from reset on chosen lines of a saved
//! mutation list (ids = line numbers from 1, as `cancosim mutate --list`
//! numbers them), without the simulation campaign; a mutant it does not
//! prove is checked again in a widened scope (widen.rs), as `cancosim
//! mutate` does:
//!
//! cargo run --release -p mutate --example prove_list -- DIR TOP FILES(comma) LIST WORK SECONDS [--scope I1,I2] [--widened-only] ID...
//!
//! FILES in the order of the mutants' build (cancosim's RTL_FILES for rtl/).
//! `--scope u_bsp,u_btl`: the widened scope (the mutated instance first)
//! instead of the kit's choice; `--widened-only`: skip the per-module check.
use mutate::widen::{self, Scope};
use mutate::{CoreSources, FormalOptions, FormalVerdict, Mutation};
use std::path::PathBuf;

fn main() {
    let mut a: Vec<String> = std::env::args().skip(1).collect();
    let mut scope = None;
    if let Some(i) = a.iter().position(|x| x == "--scope") {
        let list: Vec<String> = a.get(i + 1).expect("--scope I1,I2").split(',').map(String::from).collect();
        scope = Some(Scope { mutated: list[0].clone(), with: list[1..].to_vec() });
        a.drain(i..i + 2);
    }
    let widened_only = a.iter().any(|x| x == "--widened-only");
    a.retain(|x| x != "--widened-only");
    if a.len() < 7 {
        eprintln!("usage: prove_list DIR TOP FILES LIST WORK SECONDS [--scope I1,I2] [--widened-only] ID...");
        std::process::exit(2);
    }
    let src = CoreSources { dir: PathBuf::from(&a[0]), top: a[1].clone(), files: a[2].split(',').map(PathBuf::from).collect(), ..Default::default() };
    let lines: Vec<String> = std::fs::read_to_string(&a[3]).expect("the list").lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#')).map(String::from).collect();
    let opts = FormalOptions { steps: 30, induction: 0, timeout_s: a[5].parse().expect("seconds") };
    let work = PathBuf::from(&a[4]);
    for id in &a[6..] {
        let id: u32 = id.parse().expect("an id");
        let m = Mutation::parse(id, &lines[id as usize - 1]).expect("a mutation line");
        if !widened_only {
            match mutate::reset_proof::check_in_module(&src, &m, &opts, &work) {
                Ok(Ok(c)) => {
                    println!("{id}\t{}\t{}\t{:.1} s\t{}", m.location(), c.module, c.seconds, c.verdict.describe());
                    if matches!(c.verdict, FormalVerdict::Equivalent { .. }) {
                        continue;
                    }
                }
                Ok(Err(why)) => println!("{id}\t{}\tnot per module: {why:?}", m.location()),
                Err(e) => println!("{id}\t{}\terror: {}", m.location(), e.to_string().lines().last().unwrap_or("")),
            }
        }
        match widen::check_widened(&src, &m, scope.as_ref(), &opts, &work) {
            Ok(cs) if cs.is_empty() => println!("{id}\t{}\tno widened scope (a cell of the top, or no sibling driver)", m.location()),
            Ok(cs) => {
                for c in cs {
                    println!("{id}\t{}\t{}\t{:.1} s\t{}", m.location(), c.label, c.seconds, c.verdict.describe());
                }
            }
            Err(e) => println!("{id}\t{}\twidened: error: {}", m.location(), e.to_string().lines().last().unwrap_or("")),
        }
    }
}
