//! The regression runner: parallel runs, JUnit XML parsed back, the DUT x
//! scenario table, shards, exit code.

use diagnose::Category;
use quick_xml::Reader;
use quick_xml::events::Event;
use scenario::regress::{Status, parse_shard};
use scenario::{DutSpec, RegressOptions, Scenario, load_list, regress};
use std::path::PathBuf;

fn shipped() -> Vec<Scenario> {
    load_list(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb/regression.list")).unwrap()
}

fn two_models() -> Vec<DutSpec> {
    vec![DutSpec::model(), DutSpec { name: "model-b".into(), ..DutSpec::model() }]
}

/// (testcases, failures, errors) counted from the XML elements themselves.
fn parse_junit(xml: &str) -> (usize, usize, usize, Vec<(String, String)>) {
    let mut r = Reader::from_str(xml);
    let (mut cases, mut fails, mut errs) = (0, 0, 0);
    let mut names = Vec::new();
    loop {
        match r.read_event().expect("well-formed JUnit XML") {
            Event::Start(e) | Event::Empty(e) => match e.name().as_ref() {
                b"testcase" => {
                    cases += 1;
                    let get = |k: &[u8]| {
                        e.attributes().flatten().find(|a| a.key.as_ref() == k).map(|a| String::from_utf8_lossy(&a.value).into_owned()).unwrap()
                    };
                    names.push((get(b"classname"), get(b"name")));
                }
                b"failure" => fails += 1,
                b"error" => errs += 1,
                _ => {}
            },
            Event::Eof => break,
            _ => {}
        }
    }
    (cases, fails, errs, names)
}

#[test]
fn all_shipped_scenarios_on_two_duts_pass_with_table_and_junit() {
    let s = shipped();
    let rep = regress(&s, &two_models(), &RegressOptions { jobs: 2, ..Default::default() });
    let table = rep.to_table();
    eprintln!("{table}");
    assert_eq!(rep.cells.len(), s.len() * 2);
    assert!(rep.passed(), "{table}");
    assert_eq!(rep.exit_code(), 0);
    assert!(table.lines().next().unwrap().contains("model-b"));
    assert!(table.contains("de2-thesis") && table.contains("pass (RxNotFollowingTx)"), "{table}");
    let (cases, fails, errs, names) = parse_junit(&rep.to_junit());
    assert_eq!((cases, fails, errs), (s.len() * 2, 0, 0));
    assert!(names.contains(&("model-b".to_string(), "parking-10-nodes".to_string())));
}

#[test]
fn failures_show_in_table_junit_and_exit_code() {
    let mut s = shipped();
    s.truncate(2);
    s[1].expect.category = Some(Category::Pass); // loopback-no-ack is not a pass
    let rep = regress(&s, &[DutSpec::model()], &RegressOptions::default());
    assert!(!rep.passed());
    assert_eq!(rep.exit_code(), 1);
    let c = rep.cells.iter().find(|c| c.scenario == "de2-loopback-no-ack").unwrap();
    assert!(matches!(&c.status, Status::Failed(m) if m.contains("expected Pass, diagnosed NoAcknowledge")), "{:?}", c.status);
    assert!(rep.to_table().contains("FAIL (NoAcknowledge)"));
    let (cases, fails, errs, _) = parse_junit(&rep.to_junit());
    assert_eq!((cases, fails, errs), (2, 1, 0));
}

#[test]
fn a_dut_that_cannot_be_built_is_an_error_cell() {
    let s = vec![shipped().remove(0)];
    let rep = regress(&s, &[DutSpec::external("ghost", "/nonexistent", "can_top")], &RegressOptions::default());
    assert!(matches!(rep.cells[0].status, Status::Error(_)), "{:?}", rep.cells[0].status);
    assert!(rep.to_table().contains("error ("));
    let (_, fails, errs, _) = parse_junit(&rep.to_junit());
    assert_eq!((fails, errs), (0, 1));
}

#[test]
fn shards_partition_the_pairs() {
    let s = shipped();
    let duts = two_models();
    let mut seen = Vec::new();
    for k in 1..=3 {
        let rep = regress(&s, &duts, &RegressOptions { shard: Some((k, 3)), jobs: 1, ..Default::default() });
        for c in &rep.cells {
            seen.push((c.scenario.clone(), c.dut.clone()));
        }
        // cells outside the shard show as "-"
        assert!(rep.to_table().contains(" - ") || rep.to_table().contains("| -"));
    }
    seen.sort();
    let before = seen.len();
    seen.dedup();
    assert_eq!(before, seen.len(), "no pair twice");
    assert_eq!(seen.len(), s.len() * duts.len(), "every pair once");
}

#[test]
fn shard_syntax() {
    assert_eq!(parse_shard("2/4"), Ok((2, 4)));
    assert!(parse_shard("0/4").is_err());
    assert!(parse_shard("5/4").is_err());
    assert!(parse_shard("x").is_err());
}

#[test]
fn table_for_rtl_and_model() {
    // The PIO scenarios need the RTL rebuilt with a level ack (see the
    // ignored full table below); the others run on the bundled RTL.
    let s: Vec<Scenario> = shipped().into_iter().filter(|s| s.host != scenario::HostBfm::Pio).collect();
    assert!(s.len() >= 3);
    let rep = regress(&s, &[DutSpec::rtl(), DutSpec::model()], &RegressOptions { jobs: 2, ..Default::default() });
    let table = rep.to_table();
    eprintln!("{table}");
    assert_eq!(rep.cells.len(), s.len() * 2);
    assert!(rep.passed(), "{table}");
    let row = table.lines().find(|l| l.starts_with("de2-avalon-begintransfer ")).expect("a row per scenario");
    let cols: Vec<&str> = row.split('|').map(str::trim).collect();
    assert_eq!(cols, ["de2-avalon-begintransfer", "pass (HostBusViolation)", "pass (HostBusViolation)"], "{table}");
}

#[test]
fn full_table_for_rtl_and_model() {
    let s = shipped();
    let rep = regress(&s, &[DutSpec::rtl(), DutSpec::model()], &RegressOptions { jobs: 2, ..Default::default() });
    let table = rep.to_table();
    eprintln!("{table}");
    eprintln!("{}", rep.to_junit());
    assert_eq!(rep.cells.len(), s.len() * 2);
    assert!(rep.cells.iter().filter(|c| c.dut == "model").all(|c| c.status == Status::Pass), "{table}");
}
