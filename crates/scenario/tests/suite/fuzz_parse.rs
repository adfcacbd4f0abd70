//! The scenario parser never panics or hangs, whatever the
//! input: random text; shipped files with lines dropped, duplicated or
//! bytes changed; shipped files with values replaced by out-of-range,
//! wrongly typed or absurd ones and keys misspelt; and valid-looking
//! scenarios generated from scratch with random values in every table.
//! Every rejection is a `ScenarioError::At` with a line inside the file, a
//! key and a message; every case ends within its time bound.
//!
//! CI runs a few thousand cases; `fuzz_parse_large` (ignored) runs
//! `FUZZ_CASES` (default 100 000) per strategy:
//! `cargo test -p scenario --test suite fuzz_parse:: -- --ignored --nocapture`.

#[path = "../../../can-proto/tests/support/time_bound.rs"]
mod time_bound;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use scenario::{Scenario, ScenarioError};
use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

const CASE_BOUND: Duration = Duration::from_secs(2);

fn shipped_texts() -> &'static [String] {
    static T: OnceLock<Vec<String>> = OnceLock::new();
    T.get_or_init(|| {
        let tb = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb");
        let mut v: Vec<String> = std::fs::read_dir(&tb)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect();
        v.sort();
        assert!(v.len() >= 7);
        v
    })
}

/// Parses `text`; panics (a fuzz failure) on anything but a success or a
/// well-formed `At` error, or on a case over its time bound.
fn check(text: &str) -> Result<(), String> {
    time_bound::within(CASE_BOUND, || format!("{text:?}"), || {
        match Scenario::parse(text, "fuzz.toml") {
            Ok(s) => {
                // A parsed scenario is usable: its header and timing do not panic.
                let _ = s.header();
                let _ = s.dut_timing();
                Ok(())
            }
            Err(e @ ScenarioError::At { .. }) => {
                let ScenarioError::At { ref file, line, col, ref key, ref message } = e else { unreachable!() };
                let lines = text.lines().count().max(1) + 1;
                let msg = e.to_string();
                if !(line >= 1 && line <= lines) {
                    return Err(format!("line {line} outside 1..={lines}: {msg}"));
                }
                if col == 0 || message.is_empty() || key.is_empty() || file != "fuzz.toml" {
                    return Err(format!("malformed error: {msg}"));
                }
                if !msg.starts_with("fuzz.toml:") {
                    return Err(format!("error text: {msg}"));
                }
                Ok(())
            }
            Err(e) => Err(format!("unexpected error kind: {e}")),
        }
    })
}

/// Values worth trying in place of any value.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<i64>().prop_map(|v| v.to_string()),
        prop::sample::select(vec![
            "-1", "0", "1", "8", "9", "15", "16", "31", "32", "127", "128", "255", "256", "0x7FF", "0x800",
            "0x1FFFFFFF", "0x20000000", "9223372036854775807", "-9223372036854775808", "0.0", "-0.0", "1e308",
            "-1e308", "nan", "inf", "-inf", "0.000001", "true", "false", "\"\"", "\"peli\"", "\"basic\"",
            "\"rtl\"", "\"model\"", "\"external\"", "\"avalon\"", "\"pio\"", "\"wishbone\"", "\"bus\"",
            "\"tied-dominant\"", "\"stuck-dominant\"", "\"glitch\"", "\"flip\"", "\"BTR0\"", "\"TXDATA+9\"",
            "\"IER\"", "\"SR\"", "\"CR\"", "\"nope\"", "[]", "[1,2,3,4,5,6,7,8,9]", "[256]", "[-1]",
            "{}", "{ id = 0x800 }", "{ id = 1, dlc = 16 }", "{ id = 1, data = [1], dlc = 0, raw_dlc = true }",
            "\"RxNotFollowingTx\"", "\"Crc\"", "1979-05-27T07:32:00Z",
        ])
        .prop_map(str::to_string),
        "\"\\PC{0,12}\"",
    ]
}

/// Shipped files with `key = value` values replaced and keys misspelt.
fn mutated_values() -> impl Strategy<Value = String> {
    (0..64usize, prop::collection::vec((any::<prop::sample::Index>(), value(), 0u8..6), 1..6)).prop_map(|(file, edits)| {
        let texts = shipped_texts();
        let mut lines: Vec<String> = texts[file % texts.len()].lines().map(str::to_string).collect();
        let assigns: Vec<usize> = (0..lines.len()).filter(|&i| lines[i].contains(" = ")).collect();
        if assigns.is_empty() {
            return lines.join("\n");
        }
        for (pick, v, how) in edits {
            let i = assigns[pick.index(assigns.len())];
            let (k, _) = lines[i].split_once(" = ").unwrap();
            let k = k.to_string();
            lines[i] = match how {
                // a typo in the key: swap two letters or add one
                0 if k.len() > 2 => {
                    let mut c: Vec<char> = k.chars().collect();
                    let j = c.len() / 2;
                    c.swap(j - 1, j);
                    format!("{} = {v}", c.into_iter().collect::<String>())
                }
                1 => format!("{k}x = {v}"),
                // the key twice
                2 => format!("{k} = {v}\n{k} = {v}"),
                _ => format!("{k} = {v}"),
            };
        }
        lines.join("\n")
    })
}

/// Mostly one of `valid`, now and then one of `invalid`.
fn pick(valid: &[&'static str], invalid: &[&'static str]) -> BoxedStrategy<String> {
    prop_oneof![
        12 => prop::sample::select(valid.to_vec()).prop_map(str::to_string),
        1 => prop::sample::select(invalid.to_vec()).prop_map(str::to_string),
        1 => value(),
    ]
    .boxed()
}

/// A number: mostly in `range`, now and then anything.
fn num_in(range: std::ops::Range<i64>) -> BoxedStrategy<String> {
    prop_oneof![30 => range.prop_map(|v| v.to_string()), 1 => value()].boxed()
}

/// A valid-looking scenario built from scratch: every table, every key,
/// values mostly plausible, one in a few dozen absurd, so that both the
/// early and the late checks are reached.
fn generated() -> impl Strategy<Value = String> {
    let byte = || num_in(0..256);
    let step = prop_oneof![
        (pick(&["\"CR\"", "\"CMR\"", "\"CDR\"", "\"ACR\"", "\"AMR\"", "\"OCR\"", "\"TXDATA+1\"", "4", "31"], &["\"IER\"", "\"MOD\"", "40", "200", "\"BTR0\""]), byte())
            .prop_map(|(r, v)| format!("write = {r}\nvalue = {v}\n")),
        (pick(&["\"SR\"", "\"IR\"", "\"CR\"", "2", "31"], &["\"ECC\"", "127", "128", "255"]), byte(), byte())
            .prop_map(|(r, e, m)| format!("read = {r}\nexpect = {e}\nmask = {m}\n")),
        (num_in(0..500), num_in(1..500)).prop_map(|(w, t)| format!("wait_bits = {w}\ntimeout_bits = {t}\n")),
        (byte(), num_in(1..500)).prop_map(|(s, t)| format!("wait_sr_set = {s}\ntimeout_bits = {t}\n")),
        Just("wait_irq = true\ntimeout_bits = 100\n".to_string()),
        (num_in(0..0x800), prop::bool::weighted(0.2), prop::bool::weighted(0.2), prop::collection::vec(byte(), 0..9), prop::option::weighted(0.2, num_in(0..16)), prop::bool::weighted(0.1))
            .prop_map(|(id, ext, rtr, data, dlc, raw)| format!(
                "load_tx = {{ id = {id}, extended = {ext}, rtr = {rtr}, data = [{}]{}, raw_dlc = {raw} }}\n",
                data.join(", "),
                dlc.map(|d| format!(", dlc = {d}")).unwrap_or_default()
            )),
    ];
    let node = (
        pick(&["0x41", "0x43", "0x03", "0x01"], &["0", "256"]),
        pick(&["0x25", "0x1C", "0xBB", "0x2F"], &["0x12", "0"]),
        pick(&["basic", "peli"], &["x"]),
        prop::collection::vec(byte(), 0..2),
        prop::collection::vec(byte(), 0..2),
        num_in(0..0x800),
        num_in(0..2000),
        prop::option::weighted(0.2, pick(&["24.0", "16.0"], &["0.0", "nan"])),
        0..1000u32,
    )
        .prop_map(|(b0, b1, mode, acr, amr, id, at, mhz, k)| format!(
            "[[node]]\nname = \"n{k}\"\nbtr0 = {b0}\nbtr1 = {b1}\nmode = \"{mode}\"\nacr = [{}]\namr = [{}]\nsend = [ {{ id = {id}, data = [1, 2], at_bit = {at} }} ]\n{}",
            acr.join(", "),
            amr.join(", "),
            mhz.map(|m| format!("can_mhz = {m}\n")).unwrap_or_default()
        ));
    let fault = (
        pick(&["stuck-dominant", "stuck-recessive", "flip", "glitch"], &["melt"]),
        num_in(0..3000),
        num_in(0..8),
        num_in(0..100),
        num_in(1..50),
        pick(&["bus", "dut-rx"], &["nobody"]),
    )
        .prop_map(|(k, a, f, b, d, t)| {
            // at_bit, or frame + bit_in_frame (giving both is an error the parser must name)
            let when = match a.parse::<i64>().map(|v| v % 3) {
                Ok(0) => format!("at_bit = {a}"),
                Ok(1) => format!("frame = {f}\nbit_in_frame = {b}"),
                _ => format!("at_bit = {a}\nframe = {f}\nbit_in_frame = {b}"),
            };
            format!("[[fault]]\nkind = \"{k}\"\n{when}\nduration_bits = {d}\ntarget = \"{t}\"\n")
        });
    (
        pick(&["50.0", "100.0", "12.5"], &["0.0", "-1.0", "1e9"]),
        pick(&["24.0", "16.0", "8.0"], &["0.0", "nan", "inf"]),
        prop::option::weighted(0.3, pick(&["125000", "250000", "500000"], &["2000000", "0", "-1"])),
        pick(&["wishbone", "avalon", "pio"], &["nope"]),
        pick(&["bus", "tied-recessive", "tied-dominant"], &["air"]),
        pick(&["model", "rtl"], &["ghost"]),
        prop::collection::vec(step, 0..8),
        prop::collection::vec(node, 0..3),
        prop::collection::vec(fault, 0..2),
        (num_in(0..300), pick(&["\"RxNotFollowingTx\"", "\"Pass\"", "\"NoAcknowledge\""], &["\"Broken\"", "3"])),
    )
        .prop_map(|(host, can, rate, bfm, rx, dut, steps, nodes, faults, (tec, cat))| {
            let mut s = format!("purpose = \"fuzz\"\nverifies = [\"x\"]\n[clocks]\nhost_mhz = {host}\ncan_mhz = {can}\n");
            if let Some(r) = rate {
                s += &format!("bit_rate = {r}\n");
            }
            s += &format!("[host]\nbfm = \"{bfm}\"\ntimeout_cycles = 100\n[dut]\nkind = \"{dut}\"\n[wiring]\nrx = \"{rx}\"\ntx_to_bus = true\n[run]\nmax_bits = 1000\n");
            for st in steps {
                s += "[[step]]\n";
                s += &st;
            }
            for n in nodes {
                s += &n;
            }
            for f in faults {
                s += &f;
            }
            s += &format!("[expect]\ncategory = {cat}\ntec = {tec}\n");
            s
        })
}

/// Line-level mutations of shipped files (drop, duplicate, insert a char,
/// widen a hex number).
fn mutated_lines() -> impl Strategy<Value = String> {
    (0usize..64, prop::collection::vec((0u8..4, any::<u16>(), any::<char>()), 1..6)).prop_map(|(file, ops)| {
        let texts = shipped_texts();
        let mut lines: Vec<String> = texts[file % texts.len()].lines().map(str::to_string).collect();
        for (op, pos, c) in ops {
            if lines.is_empty() {
                break;
            }
            let i = pos as usize % lines.len();
            match op {
                0 => {
                    lines.remove(i);
                }
                1 => {
                    let l = lines[i].clone();
                    lines.insert(i, l);
                }
                2 => {
                    let mut chars: Vec<char> = lines[i].chars().collect();
                    let j = pos as usize % (chars.len() + 1);
                    chars.insert(j, c);
                    lines[i] = chars.into_iter().collect();
                }
                _ => {
                    // change a number: the classic out-of-range edit
                    lines[i] = lines[i].replace("0x", "0x1FF");
                }
            }
        }
        lines.join("\n")
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    #[test]
    fn random_text_never_panics(s in "\\PC{0,200}") {
        check(&s).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn mutated_shipped_files_never_panic(text in mutated_lines()) {
        check(&text).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn shipped_files_with_mutated_values_never_panic(text in mutated_values()) {
        check(&text).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn generated_scenarios_never_panic(text in generated()) {
        check(&text).map_err(TestCaseError::fail)?;
    }
}

/// The generator is not vacuous: some generated scenarios are accepted and
/// some rejected (else the fuzz would only test the first check).
#[test]
fn generated_scenarios_reach_both_outcomes() {
    let mut runner = TestRunner::deterministic();
    let (mut ok, mut bad) = (0, 0);
    for _ in 0..400 {
        let t = proptest::strategy::ValueTree::current(&generated().new_tree(&mut runner).unwrap());
        match Scenario::parse(&t, "g.toml") {
            Ok(_) => ok += 1,
            Err(_) => bad += 1,
        }
    }
    eprintln!("generated: accepted {ok}, rejected {bad}");
    assert!(ok >= 20 && bad >= 20, "accepted {ok}, rejected {bad}");
}

#[test]
#[ignore = "large fuzz run (minutes); run with FUZZ_CASES=N cargo test -p scenario --test suite fuzz_parse::fuzz_parse_large -- --ignored --nocapture"]
fn fuzz_parse_large() {
    let cases = time_bound::large_cases(100_000);
    let mut failures = Vec::new();
    let strategies: Vec<(&str, BoxedStrategy<String>)> = vec![
        ("random text", "\\PC{0,200}".boxed()),
        ("mutated lines", mutated_lines().boxed()),
        ("mutated values", mutated_values().boxed()),
        ("generated scenarios", generated().boxed()),
    ];
    for (name, strat) in strategies {
        let mut runner = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
        let accepted = std::sync::atomic::AtomicU64::new(0);
        let t = Instant::now();
        let r = runner.run(&strat, |text| {
            check(&text).map_err(TestCaseError::fail)?;
            if Scenario::parse(&text, "fuzz.toml").is_ok() {
                accepted.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
            Ok(())
        });
        println!(
            "fuzz scenario parser / {name}: {cases} cases ({} accepted) in {:.1} s: {}",
            accepted.into_inner(),
            t.elapsed().as_secs_f64(),
            match &r {
                Ok(()) => "no failure".to_string(),
                Err(e) => format!("FAILED: {e}"),
            }
        );
        if let Err(e) = r {
            failures.push(format!("{name}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
