//! The waiver file (matching, errors), the report renderings and the
//! suggestions.

use can_proto::Field;
use diagnose::{Divergence, DivergenceKind};
use quick_xml::Reader;
use quick_xml::events::Event;
use waivers::{CollectMode, DutInfo, Resync, Session, Verdict, WaiverError, WaiverReport, WaiverSet, suggest};

fn tx_div(bit: u64, field: Field) -> Divergence {
    Divergence {
        kind: DivergenceKind::TxBit,
        bit: Some(bit),
        field: Some(field),
        expected: 1,
        seen: 0,
        context: "flag".into(),
        ..Divergence::default()
    }
}

fn read_div(reg: &str, expected: u32, seen: u32) -> Divergence {
    Divergence {
        kind: DivergenceKind::RegisterRead,
        bit: Some(5),
        register: Some(reg.into()),
        expected,
        seen,
        ..Divergence::default()
    }
}

const GENERIC: &str = r#"
[[waiver]]
id = "flag"
kind = "tx-bit"
dut = ["*opencores-can*", "rtl-r?"]
revisions = ["r3..r7", "v2.1.."]
explanation = "an accepted deviation, for the tests"
resync = ["skip-bits 2"]
"#;

#[test]
fn dut_globs_and_revision_ranges() {
    let mut set = WaiverSet::parse(GENERIC, "g.toml").unwrap();
    let d = tx_div(10, Field::Crc);
    let cases = [
        (DutInfo::new("/x/opencores-can").revision("r3"), true),
        (DutInfo::new("/x/opencores-can").revision("r7"), true),
        (DutInfo::new("/x/opencores-can").revision("r8"), false),
        (DutInfo::new("/x/opencores-can").revision("r2"), false),
        (DutInfo::new("/x/opencores-can"), false), // revision unknown
        (DutInfo::new("opencores-can-fork").revision("v2.1.4"), true),
        (DutInfo::new("opencores-can-fork").revision("v2.0"), false),
        (DutInfo::new("rtl-rb").revision("r4"), true),
        (DutInfo::new("rtl-rbb").revision("r4"), false),
        (DutInfo::new("rtl").revision("r4"), false),
        (DutInfo::new("model").revision("r4"), false),
    ];
    for (dut, want) in cases {
        let got = set.check(&d, &dut);
        assert_eq!(matches!(got, Verdict::Waived { .. }), want, "{dut:?}: {got:?}");
        if want {
            assert_eq!(got, Verdict::Waived { waiver_id: "flag".into(), resync: vec![Resync::SkipBits(2)] });
        }
    }
    // No revisions key: any revision, even unknown.
    let mut any = WaiverSet::parse(&GENERIC.replace("revisions = [\"r3..r7\", \"v2.1..\"]\n", ""), "a.toml").unwrap();
    assert!(matches!(any.check(&d, &DutInfo::new("/x/opencores-can")), Verdict::Waived { .. }));
    // Kind must match.
    assert_eq!(set.check(&read_div("SR", 0, 0x40), &DutInfo::new("/x/opencores-can").revision("r5")), Verdict::Failure);
}

#[test]
fn register_bounds_bits_values_and_adopted_values() {
    let src = r#"
[[waiver]]
id = "es-late"
kind = "register-read"
register = "sr"
bits = [6]
dut = ["*"]
explanation = "ES is set a little late by this core"
resync = ["none"]

[[waiver]]
id = "btr0-bit7"
kind = "register-read"
register = "address 4"
address = 4
expected = [0xFF]
seen = [0x7F, 0x7E]
dut = ["*"]
explanation = "bit 7 of address 4 is not implemented"
resync = ["adopt-dut-register"]

[[waiver]]
id = "txerr"
kind = "register-read"
register = "TXERR"
seen = [136]
dut = ["*"]
explanation = "the TEC ends at 136 on this core"
resync = ["adopt-dut-tec", "adopt-dut-rec"]
"#;
    let mut set = WaiverSet::parse(src, "r.toml").unwrap();
    let dut = DutInfo::new("any");
    assert_eq!(
        set.check(&read_div("SR", 0x0C, 0x4C), &dut),
        Verdict::Waived { waiver_id: "es-late".into(), resync: vec![] }
    );
    assert_eq!(set.check(&read_div("SR", 0x0C, 0xCC), &dut), Verdict::Failure, "BS differs too");
    assert_eq!(
        set.check(&read_div("address 4", 0xFF, 0x7F), &dut),
        Verdict::Waived { waiver_id: "btr0-bit7".into(), resync: vec![Resync::AdoptRegister { addr: 4, value: 0x7F }] }
    );
    assert_eq!(set.check(&read_div("address 4", 0xFF, 0x3F), &dut), Verdict::Failure, "0x3F not allowed");
    assert_eq!(set.check(&read_div("address 4", 0xFE, 0x7F), &dut), Verdict::Failure, "model value not allowed");
    assert_eq!(
        set.check(&read_div("TXERR", 128, 136), &dut),
        Verdict::Waived {
            waiver_id: "txerr".into(),
            resync: vec![Resync::AdoptTec(Some(136)), Resync::AdoptRec(None)]
        }
    );
    assert_eq!(set.check(&read_div("TXERR", 128, 144), &dut), Verdict::Failure);
    assert_eq!(set.hits("es-late"), Some(1));
    assert_eq!(set.hits("btr0-bit7"), Some(1));
    let notes = set.near_misses(&read_div("address 4", 0xFF, 0x3F), &dut, &Default::default());
    assert_eq!(notes.len(), 1, "only the waiver for that register: {notes:?}");
    assert!(
        notes[0].contains("btr0-bit7") && notes[0].contains("r.toml:12") && notes[0].contains("not in the allowed"),
        "{notes:?}"
    );
}

#[test]
fn fields_frames_context_and_max_hits_bound_a_tx_waiver() {
    let src = r#"
[[waiver]]
id = "f"
kind = "tx-bit"
fields = ["ActiveErrorFlag"]
frames = "2..3"
context = "flag"
max-hits = 2
dut = ["d"]
explanation = "bounded on purpose for the test"
resync = ["none"]
"#;
    let mut set = WaiverSet::parse(src, "f.toml").unwrap();
    let dut = DutInfo::new("d");
    let at = |frame: u32, field: Field| Divergence { frame: Some(frame), ..tx_div(frame as u64 * 100, field) };
    assert_eq!(set.check(&at(2, Field::Crc), &dut), Verdict::Failure, "field");
    assert_eq!(set.check(&at(1, Field::ActiveErrorFlag), &dut), Verdict::Failure, "frame");
    assert_eq!(
        set.check(&Divergence { context: "x".into(), ..at(2, Field::ActiveErrorFlag) }, &dut),
        Verdict::Failure,
        "context"
    );
    assert!(matches!(set.check(&at(2, Field::ActiveErrorFlag), &dut), Verdict::Waived { .. }));
    assert!(matches!(set.check(&at(3, Field::ActiveErrorFlag), &dut), Verdict::Waived { .. }));
    assert_eq!(set.check(&at(3, Field::ActiveErrorFlag), &dut), Verdict::Failure, "max-hits");
}

fn err(src: &str) -> (usize, String, String) {
    match WaiverSet::parse(src, "bad.toml") {
        Err(WaiverError::Invalid { file, line, key, message }) => {
            assert_eq!(file, "bad.toml");
            let e = WaiverSet::parse(src, "bad.toml").unwrap_err().to_string();
            assert!(e.starts_with(&format!("bad.toml:{line}: {key}: ")), "{e}");
            (line, key, message)
        }
        other => panic!("expected an error for\n{src}\ngot {other:?}"),
    }
}

#[test]
fn malformed_files_name_file_line_and_key() {
    let base = GENERIC.trim_start();
    // Unknown key.
    let (line, key, msg) = err(&base.replace("resync =", "colour = \"red\"\nresync ="));
    assert_eq!((line, key.as_str()), (7, "colour"), "{msg}");
    // Bad values, each on its own line.
    let (line, key, msg) = err(&base.replace("\"r3..r7\"", "\"r7..r3\""));
    assert_eq!((line, key.as_str()), (5, "revisions"), "{msg}");
    assert!(msg.contains("empty"), "{msg}");
    let (line, key, msg) = err(&base.replace("skip-bits 2", "skip 2"));
    assert_eq!((line, key.as_str()), (7, "resync"), "{msg}");
    let (line, key, _) = err(&base.replace("tx-bit", "tx-bits"));
    assert_eq!((line, key.as_str()), (3, "kind"));
    let (line, key, _) = err(&base.replace("rtl-r?", "rtl-[r"));
    assert_eq!((line, key.as_str()), (4, "dut"));
    // Missing key.
    let (_, key, _) = err(&base.replace("explanation = \"an accepted deviation, for the tests\"\n", ""));
    assert_eq!(key, "explanation");
    // Checks across keys.
    let (line, key, _) =
        err(&base.replace("explanation = \"an accepted deviation, for the tests\"", "explanation = \"TODO\""));
    assert_eq!((line, key.as_str()), (6, "explanation"));
    let (line, key, _) = err(&base.replace("kind = \"tx-bit\"", "kind = \"tx-bit\"\nregister = \"SR\""));
    assert_eq!((line, key.as_str()), (4, "register"));
    let (line, key, _) = err(&base.replace("skip-bits 2", "adopt-dut-register"));
    assert_eq!((line, key.as_str()), (7, "resync"));
    let (line, key, _) = err(&format!("{base}\n{base}"));
    assert_eq!((line, key.as_str()), (10, "id"), "duplicate id at the second entry");
    let (_, key, _) = err("[[waivers]]\nid = \"x\"\n");
    assert_eq!(key, "waivers");
    // Syntax error.
    let (line, _, _) = err(&base.replace("id = \"flag\"", "id = flag"));
    assert_eq!(line, 2);
    // A bad value inside an array written over several lines.
    let (line, key, _) =
        err(&base
            .replace("dut = [\"*opencores-can*\", \"rtl-r?\"]", "dut = [\n  \"*opencores-can*\",\n  \"rtl-[r\",\n]"));
    assert_eq!((line, key.as_str()), (4, "dut"), "toml points at the array, on the key's line");
    // Unreadable file.
    assert!(matches!(WaiverSet::load("/nonexistent/w.toml"), Err(WaiverError::Io { .. })));
}

#[test]
fn the_shipped_file_loads_from_disk_and_names_the_upstream_deviation() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    let set = WaiverSet::load(path).unwrap();
    let w = set.get("rx-stored-at-last-eof-bit").unwrap();
    assert!(w.explanation.contains("EOF") && w.clause.as_deref().is_some_and(|c| c.contains("§5")), "{w:?}");
    assert!(w.applies_to(&DutInfo::new("opencores-can (/work/cores/can)")));
    // Dropped as stale (the model now counts TEC 136 like the core).
    assert!(set.get("tec-after-error-passive").is_none() && set.get("tec-136-read-back").is_none());
    assert!(!w.applies_to(&DutInfo::new("rtl")), "our own core is not waived");
    assert!(!w.applies_to(&DutInfo::new("model")));
}

fn sample_report() -> WaiverReport {
    let mut s = Session::new(
        WaiverSet::parse(GENERIC, "g.toml").unwrap(),
        DutInfo::new("/x/opencores-can").revision("r4"),
        CollectMode::Collect,
    );
    s.divergence(tx_div(7, Field::ActiveErrorFlag));
    s.divergence(read_div("IR", 0x01, 0x00));
    s.divergence(Divergence { context: "a <b> & \"c\"".into(), ..read_div("SR", 0x0C, 0x4C) });
    let (mut r, _) = s.finish();
    r.stale.push(waivers::Stale { waiver_id: "never".into(), location: "h.toml:2".into() });
    r
}

#[test]
fn report_counts_text_and_json() {
    let r = sample_report();
    let c = r.counts();
    assert_eq!((c.waived, c.failures, c.stale), (1, 2, 1));
    assert!(!r.passed());
    let t = r.to_text();
    assert!(t.contains("3 divergence(s): 2 failure(s), 1 waived; 1 stale waiver(s)"), "{t}");
    assert!(t.contains("FAIL   register-read IR at bit 5"), "{t}");
    assert!(t.contains("WAIVED [flag] tx-bit at bit 7"), "{t}");
    assert!(t.ends_with("result: FAIL\n"), "{t}");
    let back: WaiverReport = serde_json::from_str(&r.to_json()).unwrap();
    assert_eq!(back, r);
    let v: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
    assert_eq!(v["waived"][0]["waiver_id"], "flag");
    let counts = (v["counts"]["failures"].as_u64(), v["counts"]["waived"].as_u64(), v["passed"].as_bool());
    assert_eq!(counts, (Some(2), Some(1), Some(false)));
    assert!(v["warnings"][0].as_str().unwrap().contains("stale waiver `never`"));
    assert_eq!(v["failures"][1]["register"], "SR");
}

#[test]
fn junit_keeps_waived_apart_from_failures_and_parses_back() {
    let r = sample_report();
    let xml = r.to_junit("de2-loopback");
    let mut reader = Reader::from_str(&xml);
    let (mut failures, mut skipped, mut cases, mut suite_attrs, mut skip_msgs, mut err_text) =
        (0, 0, 0, None, vec![], String::new());
    let mut in_err = false;
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) | Event::Empty(e) => {
                let attr = |k: &str| e.try_get_attribute(k).unwrap().map(|a| a.unescape_value().unwrap().into_owned());
                match e.name().as_ref() {
                    b"testsuite" => suite_attrs = Some((attr("tests"), attr("failures"), attr("skipped"))),
                    b"testcase" => cases += 1,
                    b"failure" => {
                        failures += 1;
                        assert!(attr("message").unwrap().starts_with("register-read"), "{xml}");
                    }
                    b"skipped" => {
                        skipped += 1;
                        skip_msgs.push(attr("message").unwrap());
                    }
                    b"system-err" => in_err = true,
                    _ => {}
                }
            }
            Event::Text(t) if in_err => err_text.push_str(&t.xml_content().unwrap()),
            Event::End(e) if e.name().as_ref() == b"system-err" => in_err = false,
            Event::Eof => break,
            _ => {}
        }
    }
    assert_eq!((cases, failures, skipped), (3, 2, 1), "{xml}");
    assert_eq!(suite_attrs, Some((Some("3".into()), Some("2".into()), Some("1".into()))));
    assert_eq!(skip_msgs, ["waived by flag"]);
    assert!(err_text.contains("stale waiver `never`"), "{xml}");
    assert!(xml.contains("a &lt;b&gt; &amp;"), "context escaped: {xml}");
    // And through quick-junit's own reader: the same suite, cases and counts.
    let back = quick_junit::Report::deserialize_from_str(&xml).unwrap();
    let suite = &back.test_suites[0];
    assert_eq!((suite.name.as_str(), suite.test_cases.len(), suite.failures, suite.skipped), ("de2-loopback", 3, 2, 1));
    assert!(matches!(&suite.test_cases[2].status, quick_junit::TestCaseStatus::Skipped { message: Some(m), .. } if m.as_str() == "waived by flag"));
}

#[test]
fn suggestions_are_candidates_that_need_an_explanation() {
    let dut = DutInfo::new("/x/opencores-can").revision("r5");
    let divs = vec![
        tx_div(100, Field::PassiveErrorFlag),
        tx_div(101, Field::PassiveErrorFlag),
        read_div("TXERR", 128, 136),
        read_div("SR", 0x0C, 0x4C),
        read_div("address 4", 0xFF, 0x7F),
    ];
    let text = suggest(&divs, &dut);
    assert!(text.contains("NOT applied"), "{text}");
    // Not usable as is: the TODO explanation is rejected.
    let e = WaiverSet::parse(&text, "s.toml").unwrap_err();
    assert!(matches!(&e, WaiverError::Invalid { key, .. } if key == "explanation"), "{e}");
    // After an engineer writes why, every suggested entry covers its divergences.
    let edited = text.replace("TODO: why is this deviation accepted?", "Accepted after review:");
    let mut set = WaiverSet::parse(&edited, "s.toml").unwrap();
    assert_eq!(set.waivers().len(), 4, "{edited}");
    let mut resyncs = vec![];
    for d in &divs {
        match set.check(d, &dut) {
            Verdict::Waived { resync, .. } => resyncs.push(resync),
            Verdict::Failure => panic!("suggestion does not cover {d:?}:\n{edited}"),
        }
    }
    assert_eq!(resyncs[0], [Resync::SkipBits(2)], "the two consecutive bits");
    assert_eq!(resyncs[2], [Resync::AdoptTec(Some(136))]);
    assert_eq!(resyncs[4], [Resync::AdoptRegister { addr: 4, value: 0x7F }]);
    assert!(set.stale().is_empty());
    // Bounded by what was seen: another SR bit is not covered.
    assert_eq!(set.check(&read_div("SR", 0x0C, 0x8C), &dut), Verdict::Failure);
    assert_eq!(
        set.check(&read_div("SR", 0x0C, 0x4C), &DutInfo::new("/x/opencores-can").revision("r6")),
        Verdict::Failure
    );
}

#[test]
fn an_unobserved_tec_is_assumed_only_from_a_single_measured_value() {
    // The pair (dropped from the shipped file as stale), kept as data.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/tec-pair.toml");
    let mut set = WaiverSet::load(path).unwrap();
    let dut = DutInfo::new("/cores/opencores-can");
    // The comparator sees pins only: the measured 136 is what gets adopted.
    assert_eq!(
        set.check(&tx_div(900, Field::PassiveErrorFlag), &dut),
        Verdict::Waived {
            waiver_id: "tec-after-error-passive".into(),
            resync: vec![Resync::SkipBits(1), Resync::AdoptTec(Some(136))]
        }
    );
    // Observed, the bound is checked.
    let obs = waivers::Observed { dut_tec: Some(144), ..Default::default() };
    assert_eq!(set.check_observed(&tx_div(5000, Field::PassiveErrorFlag), &dut, &obs), Verdict::Failure);
    // Several allowed values and nothing observed: no match, said so.
    let src = std::fs::read_to_string(path).unwrap().replacen("dut-tec = [136]", "dut-tec = [136, 144]", 1);
    let mut set = WaiverSet::parse(&src, "two.toml").unwrap();
    let d = tx_div(900, Field::PassiveErrorFlag);
    assert_eq!(set.check(&d, &dut), Verdict::Failure);
    let notes = set.near_misses(&d, &dut, &Default::default());
    assert!(notes.iter().any(|n| n.contains("did not observe the DUT's TEC")), "{notes:?}");
}

#[test]
fn suggestions_keep_ids_unique_and_skip_an_unreadable_revision() {
    let dut = DutInfo::new("core").revision("nightly");
    let divs = vec![read_div("SR", 0x0C, 0x4C), read_div("sr", 0x0C, 0x4C)];
    let text = suggest(&divs, &dut).replace("TODO: why is this deviation accepted?", "Accepted after review:");
    let set = WaiverSet::parse(&text, "s.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
    let ids: Vec<&str> = set.waivers().iter().map(|w| w.id.as_str()).collect();
    assert_eq!(ids, ["register-read-sr", "register-read-sr-2"]);
    assert!(!text.contains("revisions"), "{text}");
}

#[test]
fn several_files_load_into_one_set_and_ids_stay_unique() {
    let dir = std::env::temp_dir().join(format!("waivers-load-all-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (a, b) = (dir.join("a.toml"), dir.join("b.toml"));
    std::fs::write(&a, GENERIC).unwrap();
    std::fs::write(&b, GENERIC.replace("id = \"flag\"", "id = \"other\"")).unwrap();
    let set = WaiverSet::load_all(&[&a, &b]).unwrap();
    assert_eq!(set.waivers().len(), 2);
    assert_eq!(set.get("other").unwrap().file, b.display().to_string());
    let e = WaiverSet::load_all(&[&a, &a]).unwrap_err().to_string();
    assert!(e.contains("already defined at") && e.contains(":3: id:"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every entry of the shipped upstream file is bounded by a count or by a
/// bound that follows the run whatever the host's pace (after an abort,
/// until a read, at most N bits per episode, at most so late, only after
/// a lost message, only for a frame format),
/// names its row in docs/opencores-deviations.md (or is one of the two
/// original TEC entries), is for the upstream core only, and the row exists in the doc.
#[test]
fn every_shipped_upstream_waiver_is_bounded_documented_and_for_upstream_only() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let set = WaiverSet::load(format!("{root}/tb/waivers/opencores-upstream.toml")).unwrap();
    let doc = std::fs::read_to_string(format!("{root}/docs/opencores-deviations.md")).unwrap();
    assert!(set.waivers().len() >= 15, "one entry per deviation");
    for w in set.waivers() {
        assert!(
            w.max_hits.is_some() || w.after_abort || w.until_read.is_some() || w.late_bits.is_some() || w.late_by.is_some() || w.after_lost.is_some() || w.model_rx_extended.is_some(),
            "{}: every waiver has max-hits or a bound that follows the run",
            w.id
        );
        assert!(doc.contains(&format!("`{}`", w.id)), "{} is listed in docs/opencores-deviations.md", w.id);
        let row = w.explanation.split_whitespace().next().unwrap_or("");
        assert!(
            (row.starts_with('D') && row.trim_end_matches(['.', ' ']).len() <= 4) || w.id.starts_with("tec-"),
            "{}: the explanation starts with its row (D1..): {row}",
            w.id
        );
        assert!(w.applies_to(&DutInfo::new("opencores-can (/cores/can/rtl/verilog)")), "{}", w.id);
        for other in ["rtl", "model", "/cores/rtl"] {
            assert!(!w.applies_to(&DutInfo::new(other)), "{} must not apply to {other}", w.id);
        }
        if !w.id.starts_with("tec-") {
            assert!(!w.applies_to(&DutInfo::new("opencores-can-fork (/x)")), "{}: the profile's name only", w.id);
        }
    }
}

/// The bus-off and self-reception waivers take only their
/// pattern, and only as often as measured.
#[test]
fn bus_off_and_self_reception_waivers_catch_the_rest() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    let mut set = WaiverSet::load(path).unwrap();
    let dut = DutInfo::new("opencores-can (/cores/can)");
    let by = |v: &Verdict| match v {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id.clone()),
        _ => None,
    };
    // D10e: BS with TS, no RS, TBS 0, once.
    let d10e = "bus-off-sr-before-reset-mode".to_string();
    assert_eq!(by(&set.check(&read_div("SR", 0xF4, 0xE0), &dut)), Some(d10e.clone()));
    assert_eq!(by(&set.check(&read_div("SR", 0xF4, 0xE0), &dut)), None, "max-hits 1");
    let mut set = WaiverSet::load(path).unwrap();
    assert_ne!(by(&set.check(&read_div("SR", 0x74, 0x60), &dut)), Some(d10e.clone()), "not bus-off");
    assert_ne!(by(&set.check(&read_div("SR", 0xF4, 0xE8), &dut)), Some(d10e), "TCS differs too");
    // D10f: IR.EI only, in operating mode.
    let d10f = "ei-when-es-clears-during-bus-off-recovery".to_string();
    let operating = waivers::Observed { model_mod: Some(0x00), ..Default::default() };
    let reset = waivers::Observed { model_mod: Some(0x01), ..Default::default() };
    assert_ne!(by(&set.check_observed(&read_div("IR", 0x00, 0x04), &dut, &reset)), Some(d10f.clone()));
    assert_ne!(by(&set.check_observed(&read_div("IR", 0x00, 0x06), &dut, &operating)), Some(d10f.clone()), "TI too");
    assert_eq!(by(&set.check_observed(&read_div("IR", 0x00, 0x04), &dut, &operating)), Some(d10f));
    // D1 with self reception: RBS late with TS = 1, RS = 0 on both.
    let d1s = "rbs-late-at-eof-self-reception".to_string();
    let eof = |e, s| Divergence { field: Some(can_proto::Field::Eof), ..read_div("SR", e, s) };
    assert_ne!(by(&set.check(&eof(0x2D, 0x28), &dut)), Some(d1s.clone()), "TBS differs too");
    assert_ne!(by(&set.check(&eof(0x0D, 0x0C), &dut)), Some(d1s.clone()), "not transmitting");
    assert_ne!(by(&set.check(&read_div("SR", 0x2D, 0x2C), &dut)), Some(d1s.clone()), "not in EOF");
    assert_eq!(by(&set.check(&eof(0x2D, 0x2C), &dut)), Some(d1s));
    assert!(!set.get("rbs-late-at-eof-self-reception").unwrap().applies_to(&DutInfo::new("rtl")));
    // D10d in BasicCAN: RS without TS at bus-off, twice at most; RS with TS,
    // RS while on the bus, or another bit too are still failures.
    let mut set = WaiverSet::load(path).unwrap();
    let d10b = "basic-rs-without-ts-at-bus-off".to_string();
    assert_ne!(by(&set.check(&read_div("SR", 0xC4, 0xF4), &dut)), Some(d10b.clone()), "TS too");
    assert_ne!(by(&set.check(&read_div("SR", 0x44, 0x54), &dut)), Some(d10b.clone()), "not bus-off");
    assert_ne!(by(&set.check(&read_div("SR", 0xC4, 0xD5), &dut)), Some(d10b.clone()), "RBS too");
    assert_eq!(by(&set.check(&read_div("SR", 0xC4, 0xD4), &dut)), Some(d10b.clone()));
    assert_eq!(by(&set.check(&read_div("SR", 0xC4, 0xD4), &dut)), Some(d10b.clone()));
    assert_ne!(by(&set.check(&read_div("SR", 0xC4, 0xD4), &dut)), Some(d10b), "max-hits 2");
}

/// The two irq pin waivers (D8d in pelican-fifo-overrun, D10f in
/// pelican-bus-off-recovery) each take only their own frame, bus idle and
/// measured count; the RBS-for-a-lost-entry read waiver only RBS with DOS clear.
#[test]
fn irq_pin_waivers_take_only_their_own_scenario() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    let dut = DutInfo::new("opencores-can (/cores/can)");
    let by = |v: &Verdict| match v {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id.clone()),
        _ => None,
    };
    let pin = |frame: u32, field: Field| Divergence {
        kind: DivergenceKind::Irq,
        bit: Some(1406),
        frame: Some(frame),
        field: Some(field),
        expected: 1,
        seen: 0,
        ..Divergence::default()
    };
    // The comparator's clock (24 MHz, 40 clocks a bit), which `until-read`
    // needs; the model lost a message (D8d's `after = "data-overrun"`).
    let clock = waivers::Observed { model_lost_messages: Some(1), ..waivers::Observed::timed(0, 40 * 41_667, 41_667) };
    let operating = waivers::Observed { model_mod: Some(0x00), ..clock };
    let reset = waivers::Observed { model_mod: Some(0x01), ..clock };
    let d8 = "doi-irq-at-release-not-at-loss".to_string();
    let d10 = "ei-irq-when-es-clears-during-bus-off-recovery".to_string();
    let mut set = WaiverSet::load(path).unwrap();
    // D8d only after a lost message.
    let no_loss = waivers::Observed { model_lost_messages: Some(0), ..operating };
    assert_ne!(by(&set.check_observed(&pin(8, Field::BusIdle), &dut, &no_loss)), Some(d8.clone()), "no message lost");
    // Each takes its own frame and not the other's.
    assert_eq!(by(&set.check_observed(&pin(8, Field::BusIdle), &dut, &operating)), Some(d8.clone()));
    assert_eq!(by(&set.check_observed(&pin(16, Field::BusIdle), &dut, &operating)), Some(d10.clone()));
    // Another frame, another field, or (D10f) reset mode: still failures.
    for (frame, field, obs) in [
        (7, Field::BusIdle, &operating),
        (9, Field::BusIdle, &operating),
        (8, Field::Intermission, &operating),
        (16, Field::Eof, &operating),
        (15, Field::BusIdle, &operating),
        (16, Field::BusIdle, &reset),
    ] {
        let v = set.check_observed(&pin(frame, field), &dut, obs);
        assert!(by(&v) != Some(d8.clone()) && by(&v) != Some(d10.clone()), "frame {frame} {field:?}: {v:?}");
    }
    // Bounded by the host's next read of IR (until-read), one episode each:
    // the same difference reported again, however often, is waived until a
    // report whose run began after that read; a second difference is not.
    let again = waivers::Observed { pin_continues: Some(true), ..operating };
    let new = waivers::Observed { pin_continues: Some(false), ..operating };
    let at = |frame: u32, t_ps: u64| Divergence { time_ps: t_ps, ..pin(frame, Field::BusIdle) };
    let mut set = WaiverSet::load(path).unwrap();
    for (frame, id) in [(8, &d8), (16, &d10)] {
        let t0 = 1_000_000_000 * frame as u64;
        assert_eq!(by(&set.check_observed(&at(frame, t0), &dut, &new)), Some(id.clone()));
        for k in 1..400 {
            assert_eq!(by(&set.check_observed(&at(frame, t0 + k * 2_000_000), &dut, &again)), Some(id.clone()), "{id} report {k}");
        }
        set.host_read("IR", t0 + 400 * 2_000_000 - 1);
        assert_eq!(by(&set.check_observed(&at(frame, t0 + 400 * 2_000_000), &dut, &again)), None, "{id}: the pin outlasted the IR read");
        assert_eq!(by(&set.check_observed(&at(frame, t0 + 500 * 2_000_000), &dut, &new)), None, "{id}: max-hits 1 episode");
    }
    // RBS for the lost entry: RBS only, bus idle, TBS = TCS = 1 on both
    // (DOS either way: before and after CDO), twice.
    // (after = "data-overrun": the model lost a message; tests/after_overrun.rs without.)
    let rbs = "rbs-for-lost-message-entry".to_string();
    let mut set = WaiverSet::load(path).unwrap();
    let lost = waivers::Observed { model_lost_messages: Some(1), ..Default::default() };
    assert_ne!(by(&set.check_observed(&read_div("SR", 0x0C, 0x1D), &dut, &lost)), Some(rbs.clone()), "RS too");
    assert_ne!(by(&set.check_observed(&read_div("SR", 0x1C, 0x1D), &dut, &lost)), Some(rbs.clone()), "while receiving");
    assert_ne!(by(&set.check_observed(&read_div("SR", 0x00, 0x01), &dut, &lost)), Some(rbs.clone()), "a transmission pending");
    assert_ne!(by(&set.check_observed(&read_div("SR", 0x0D, 0x0C), &dut, &lost)), Some(rbs.clone()), "the other way round");
    assert_eq!(by(&set.check_observed(&read_div("SR", 0x0E, 0x0F), &dut, &lost)), Some(rbs.clone()), "DOS set, before CDO");
    assert_eq!(by(&set.check_observed(&read_div("SR", 0x0C, 0x0D), &dut, &lost)), Some(rbs.clone()));
    assert_ne!(by(&set.check_observed(&read_div("SR", 0x0C, 0x0D), &dut, &lost)), Some(rbs), "max-hits 2");
}

/// D5 on IR (no WUI) and D12 (abort in an error frame:
/// TBS, TCS and TI at the start of the attempt still sent) take only their
/// own bits, modes, frames and counts.
#[test]
fn wake_up_and_abort_retransmission_waivers_catch_the_rest() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    let dut = DutInfo::new("opencores-can (/cores/can)");
    let by = |v: &Verdict| match v {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id.clone()),
        _ => None,
    };
    let operating = waivers::Observed { model_mod: Some(0x00), ..Default::default() };
    let reset = waivers::Observed { model_mod: Some(0x01), ..Default::default() };
    // D5 on IR: WUI only, twice.
    let wui = "no-wake-up-interrupt".to_string();
    let mut set = WaiverSet::load(path).unwrap();
    assert_ne!(by(&set.check(&read_div("IR", 0x11, 0x00), &dut)), Some(wui.clone()), "RI too");
    assert_ne!(by(&set.check(&read_div("IR", 0x01, 0x11), &dut)), Some(wui.clone()), "the other way round");
    assert_eq!(by(&set.check(&read_div("IR", 0x11, 0x01), &dut)), Some(wui.clone()));
    assert_eq!(by(&set.check(&read_div("IR", 0x10, 0x00), &dut)), Some(wui.clone()));
    assert_eq!(by(&set.check(&read_div("IR", 0x10, 0x00), &dut)), Some(wui.clone()), "three refused sleep requests");
    assert_ne!(by(&set.check(&read_div("IR", 0x10, 0x00), &dut)), Some(wui), "max-hits 3");
    // D12 on SR: TBS and TCS together, only while transmitting on both.
    let tbs = "tbs-released-at-retransmission-after-abort".to_string();
    let mut set = WaiverSet::load(path).unwrap();
    assert_ne!(by(&set.check(&read_div("SR", 0x00, 0x0C), &dut)), Some(tbs.clone()), "not transmitting");
    assert_ne!(by(&set.check(&read_div("SR", 0x20, 0x24), &dut)), Some(tbs.clone()), "TBS alone");
    assert_ne!(by(&set.check(&read_div("SR", 0x60, 0x6C), &dut)), Some(tbs.clone()), "error status");
    assert_ne!(by(&set.check(&read_div("SR", 0x20, 0x2D), &dut)), Some(tbs.clone()), "RBS too");
    for _ in 0..4 {
        assert_eq!(by(&set.check(&read_div("SR", 0x20, 0x2C), &dut)), Some(tbs.clone()));
    }
    assert_ne!(by(&set.check(&read_div("SR", 0x20, 0x2C), &dut)), Some(tbs), "max-hits 4");
    // D12 on IR: TI only, operating mode, once.
    let ti = "ti-at-retransmission-after-abort".to_string();
    let mut set = WaiverSet::load(path).unwrap();
    assert_ne!(by(&set.check_observed(&read_div("IR", 0x00, 0x02), &dut, &reset)), Some(ti.clone()), "reset mode");
    assert_ne!(by(&set.check_observed(&read_div("IR", 0x00, 0x82), &dut, &operating)), Some(ti.clone()), "BEI too");
    assert_eq!(by(&set.check_observed(&read_div("IR", 0x00, 0x02), &dut, &operating)), Some(ti.clone()));
    assert_ne!(by(&set.check_observed(&read_div("IR", 0x00, 0x02), &dut, &operating)), Some(ti), "max-hits 1");
    // D12 on the pin: the last attempt's header only (its SOF is stamped
    // frame 3 when the pin window is short), operating mode, one episode
    // until the host's next read of IR.
    let pin = |frame: u32, field: Field, t_ps: u64| Divergence {
        kind: DivergenceKind::Irq,
        time_ps: t_ps,
        bit: Some(374),
        frame: Some(frame),
        field: Some(field),
        expected: 1,
        seen: 0,
        ..Divergence::default()
    };
    let clock = waivers::Observed::timed(0, 40 * 41_667, 41_667);
    let new = waivers::Observed { model_mod: Some(0x00), pin_continues: Some(false), ..clock };
    let again = waivers::Observed { model_mod: Some(0x00), pin_continues: Some(true), ..clock };
    let reset = waivers::Observed { model_mod: Some(0x01), pin_continues: Some(false), ..clock };
    let irq = "ti-irq-at-retransmission-after-abort".to_string();
    let mut set = WaiverSet::load(path).unwrap();
    for (frame, field, obs) in [(2, Field::BaseId, &new), (4, Field::Data, &new), (4, Field::Eof, &new), (4, Field::BaseId, &reset)] {
        assert_ne!(by(&set.check_observed(&pin(frame, field, 0), &dut, obs)), Some(irq.clone()), "frame {frame} {field:?}");
    }
    let t0 = 1_000_000_000;
    assert_eq!(by(&set.check_observed(&pin(3, Field::Sof, t0), &dut, &new)), Some(irq.clone()));
    for k in 1..40 {
        assert_eq!(by(&set.check_observed(&pin(4, Field::ExtId, t0 + k * 2_000_000), &dut, &again)), Some(irq.clone()), "report {k}");
    }
    set.host_read("IR", t0 + 40 * 2_000_000 - 1);
    assert_ne!(by(&set.check_observed(&pin(4, Field::ExtId, t0 + 40 * 2_000_000), &dut, &again)), Some(irq.clone()), "the pin outlasted the IR read");
    assert_ne!(by(&set.check_observed(&pin(4, Field::ExtId, t0 + 50 * 2_000_000), &dut, &new)), Some(irq), "max-hits 1 episode");
}

/// D10b's BEI part (conformance tx-8.5.11): BEI cleared by bus-off is
/// waived only in the bus-off read (EI set in both), once.
#[test]
fn bei_cleared_by_bus_off_takes_only_the_bus_off_read() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    let dut = DutInfo::new("opencores-can (/cores/can)");
    let by = |v: &Verdict| match v {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id.clone()),
        _ => None,
    };
    let mut set = WaiverSet::load(path).unwrap();
    assert_eq!(by(&set.check(&read_div("IR", 0x80, 0x00), &dut)), None, "BEI without EI is not the bus-off read");
    assert_eq!(by(&set.check(&read_div("IR", 0x84, 0x00), &dut)), None, "EI lost too: more than BEI");
    assert_eq!(by(&set.check(&read_div("IR", 0x84, 0x04), &dut)), Some("bei-cleared-by-bus-off".into()));
    assert_eq!(by(&set.check(&read_div("IR", 0x84, 0x04), &dut)), None, "max-hits 1");
}
