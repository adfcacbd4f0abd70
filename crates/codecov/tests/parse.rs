//! Verilator's coverage .dat: parsing, per-source counting, summary.

use codecov::{Kind, parse_dat, summarize};

fn pt(file: &str, line: u32, col: u32, page: &str, o: &str, h: &str, n: u64) -> String {
    format!("C '\x01f\x02{file}\x01l\x02{line}\x01n\x02{col}\x01page\x02{page}\x01o\x02{o}\x01h\x02{h}' {n}\n")
}

#[test]
fn points_are_read_by_kind_and_counted_once_per_source_over_instances() {
    let mut t = String::from("# SystemC::Coverage-3\n");
    t += &pt("a.v", 10, 3, "v_line/m", "block", "TOP.u1", 5);
    t += &pt("a.v", 12, 3, "v_branch/m", "if", "TOP.u1", 0);
    t += &pt("a.v", 12, 4, "v_branch/m", "else", "TOP.u1", 7);
    // The same if-arm in a second instance: hit there, so hit.
    t += &pt("a.v", 12, 3, "v_branch/m", "if", "TOP.u2", 2);
    t += &pt("a.v", 3, 9, "v_toggle/m", "x[0]", "TOP.u1", 0);
    t += &pt("b.v", 3, 9, "v_toggle/n", "y", "TOP.v", 1);
    let pts = parse_dat(&t, "t.dat").unwrap();
    assert_eq!(pts.len(), 6);
    assert_eq!(pts[1].kind, Kind::Branch);
    assert_eq!(pts[4].comment, "x[0]");
    let s = summarize(&pts);
    assert_eq!(s.len(), 3, "a.v, b.v, total");
    let a = &s[0];
    assert_eq!(a.file, "a.v");
    assert_eq!((a.line.hit, a.line.total), (1, 1));
    assert_eq!((a.branch.hit, a.branch.total), (2, 2), "the if-arm counts once, hit in u2");
    assert_eq!((a.toggle.hit, a.toggle.total), (0, 1));
    let total = &s[2];
    assert_eq!((total.toggle.hit, total.toggle.total), (1, 2));
    assert!((total.toggle.percent() - 50.0).abs() < 1e-9);
}

#[test]
fn a_line_that_is_not_a_point_is_a_clear_error() {
    let e = parse_dat("# SystemC::Coverage-3\nC 'broken 12\n", "x.dat").unwrap_err().to_string();
    assert!(e.starts_with("x.dat:2: not a Verilator coverage point"), "{e}");
}

#[test]
fn nothing_to_merge_is_an_error_not_an_empty_report() {
    let e = codecov::report(&[], std::path::Path::new("/nonexistent")).unwrap_err().to_string();
    assert!(e.contains("no coverage .dat files"), "{e}");
}
