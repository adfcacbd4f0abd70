//! The bin model and what a run's record marks in it.

use can_proto::CanFrame;
use diagnose::{CanMode, EngineEvent, EventKind, HostOp, RunRecord, Side, WriteOutcome};
use funcov::{BusFrame, Coverage};

fn frame(ext: bool, remote: bool, dlc: u8) -> CanFrame {
    let id = if ext { CanFrame::ext_id(0x1ABC_DE01) } else { CanFrame::std_id(0x123) }.unwrap();
    let data: Vec<u8> = if remote { vec![] } else { vec![0x55; dlc.min(8) as usize] };
    CanFrame::with_dlc(id, remote, dlc, &data).unwrap()
}

#[test]
fn an_eff_remote_frame_marks_its_bin_and_the_others_stay_holes() {
    let mut c = Coverage::new();
    c.observe(&RunRecord::new("t", "model"), &[BusFrame { t_ps: 10, frame: frame(true, true, 3) }]);
    assert_eq!(c.hits("frame kinds", "EFF remote DLC 3"), Some(1));
    assert_eq!(c.hits("frame kinds", "SFF data DLC 0"), Some(0));
    assert!(c.holes().any(|b| b.name == "SFF data DLC 0"));
    assert!(!c.holes().any(|b| b.name == "EFF remote DLC 3"));
    let table = c.to_table();
    let holes_line = table.lines().find(|l| l.starts_with("holes in frame kinds")).expect("a holes line for frame kinds");
    assert!(holes_line.contains("SFF data DLC 0") && !holes_line.contains("EFF remote DLC 3"), "{holes_line}");
    assert!(holes_line.contains("(39)"), "39 of 40 frame-kind bins are holes: {holes_line}");
    // DLC 9..15 share the >8 bin.
    c.observe(&RunRecord::new("t", "model"), &[BusFrame { t_ps: 10, frame: frame(false, false, 12) }]);
    assert_eq!(c.hits("frame kinds", "SFF data DLC >8"), Some(1));
}

#[test]
fn holes_come_first_in_the_table() {
    let mut c = Coverage::new();
    let mut r = RunRecord::new("t", "model");
    r.events.push(EngineEvent::new(5, Side::Model, EventKind::ArbitrationLost { alc: 0 }));
    c.observe(&r, &[]);
    let table = c.to_table();
    let rows: Vec<&str> = table.lines().skip(1).take_while(|l| !l.starts_with("total")).collect();
    let pct = |l: &str| l.trim_end_matches('%').rsplit(' ').next().unwrap().parse::<f64>().unwrap();
    assert!(rows.windows(2).all(|w| pct(w[0]) <= pct(w[1])), "sorted by cover, lowest first:\n{table}");
    assert_eq!(c.hits("arbitration loss", "first base ID bit (ID.28, ALC 0)"), Some(1));
}

#[test]
fn errors_count_by_kind_and_field_and_an_impossible_pair_is_unlisted() {
    use can_engine::ErrorKind;
    use can_proto::Field;
    let mut r = RunRecord::new("t", "model");
    r.events.push(EngineEvent::new(1, Side::Model, EventKind::BusError { kind: ErrorKind::Stuff, ecc: 0, field: Field::Data }));
    // The DUT's own events are not the reference's: not counted.
    r.events.push(EngineEvent::new(1, Side::Dut, EventKind::BusError { kind: ErrorKind::Ack, ecc: 0, field: Field::AckSlot }));
    // A stuff error in the EOF cannot happen (not a stuffed field).
    r.events.push(EngineEvent::new(2, Side::Model, EventKind::BusError { kind: ErrorKind::Stuff, ecc: 0, field: Field::Eof }));
    let mut c = Coverage::new();
    c.observe(&r, &[]);
    assert_eq!(c.hits("error kinds x field", "stuff error in data field"), Some(1));
    assert_eq!(c.hits("error kinds x field", "ACK error in ACK slot"), Some(0));
    let un: Vec<_> = c.unlisted().collect();
    assert_eq!(un.len(), 1, "{un:?}");
    assert!(c.to_table().contains("seen outside the bin model (1)"));
}

#[test]
fn fault_confinement_transitions_and_the_warning_limit_from_the_counters() {
    use can_engine::FaultState;
    let mut r = RunRecord::new("t", "model");
    let ev = |bit, k, tec| EngineEvent { rec: Some(0), ..EngineEvent::new(bit, Side::Model, k).tec(tec) };
    r.events.push(ev(1, EventKind::TxAborted, 96));
    r.events.push(ev(2, EventKind::FaultState(FaultState::ErrorPassive), 128));
    r.events.push(ev(3, EventKind::FaultState(FaultState::BusOff), 256));
    r.events.push(ev(4, EventKind::FaultState(FaultState::ErrorActive), 0));
    let mut c = Coverage::new();
    c.observe(&r, &[]);
    for b in ["error warning limit reached", "error warning limit left", "error active -> error passive", "error passive -> bus-off"] {
        assert_eq!(c.hits("fault confinement", b), Some(1), "{b}");
    }
    assert!(c.bins.iter().any(|b| b.name.starts_with("bus-off -> error active (recovery") && b.hits == 1));
    assert_eq!(c.hits("fault confinement", "error passive -> error active"), Some(0));
}

#[test]
fn register_bits_count_per_view_mode_and_value_and_ignored_writes_do_not() {
    let w = |addr, data, reset, outcome| HostOp { addr, data, mode: CanMode::PeliCan, reset_mode: reset, outcome: Some(outcome), ..HostOp::write(addr, data) };
    let mut r = RunRecord::new("t", "model");
    r.host_ops.push(w(16, 0x80, true, WriteOutcome::Applied)); // ACR0 = 0x80 in reset mode
    r.host_ops.push(w(16, 0x01, false, WriteOutcome::IgnoredNotInResetMode));
    let mut c = Coverage::new();
    c.observe(&r, &[]);
    let g = "registers PeliCAN reset write";
    assert_eq!(c.hits(g, "ACR0 bit 7=1"), Some(1));
    assert_eq!(c.hits(g, "ACR0 bit 0=0"), Some(1));
    assert_eq!(c.hits(g, "ACR0 bit 0=1"), Some(0), "the ignored write sets nothing");
    assert_eq!(c.hits(g, "ACR0 bit 7=0"), Some(0));
    // The holes fold per register and value.
    let holes = c.holes_in(g);
    assert!(holes.contains(&"ACR0 =1 bits 6-0".to_string()), "{holes:?}");
    assert!(holes.contains(&"ACR0 =0 bit 7".to_string()), "{holes:?}");
}

#[test]
fn an_interrupt_read_set_then_clear_is_raised_and_cleared() {
    let rd = |data| HostOp { mode: CanMode::PeliCan, ..HostOp::read(3, data) };
    let mut r = RunRecord::new("t", "model");
    r.host_ops.push(rd(0x02)); // TI
    r.host_ops.push(rd(0x00));
    let mut c = Coverage::new();
    c.observe(&r, &[]);
    assert_eq!(c.hits("interrupts PeliCAN", "TI raised"), Some(1));
    assert_eq!(c.hits("interrupts PeliCAN", "TI cleared"), Some(1));
    assert_eq!(c.hits("interrupts PeliCAN", "RI raised"), Some(0));
}

#[test]
fn the_filter_verdict_follows_the_configured_single_filter() {
    let w = |addr, data| HostOp { mode: CanMode::PeliCan, reset_mode: true, time_ps: 1, outcome: Some(WriteOutcome::Applied), ..HostOp::write(addr, data) };
    let mut r = RunRecord::new("t", "model");
    r.host_ops.push(w(0, 0x09)); // MOD: RM, AFM (single filter)
    for (a, d) in [(16, 0x24), (17, 0x60), (18, 0), (19, 0), (20, 0), (21, 0x1F), (22, 0xFF), (23, 0xFF)] {
        r.host_ops.push(w(a, d)); // accepts SFF ID 0x123 exactly
    }
    let f1 = frame(false, false, 1); // ID 0x123: accepted
    let f2 = CanFrame::with_dlc(CanFrame::std_id(0x124).unwrap(), false, 0, &[]).unwrap(); // rejected
    for (bit, f) in [(10, f1), (20, f2)] {
        r.events.push(EngineEvent::new(bit, Side::Model, EventKind::Received { id: f.raw_id(), dlc: f.dlc_raw(), own: false }));
    }
    let mut c = Coverage::new();
    c.observe(&r, &[BusFrame { t_ps: 100, frame: f1 }, BusFrame { t_ps: 200, frame: f2 }]);
    assert_eq!(c.hits("acceptance filter", "PeliCAN single SFF accepted"), Some(1));
    assert_eq!(c.hits("acceptance filter", "PeliCAN single SFF rejected"), Some(1));
    assert_eq!(c.hits("acceptance filter", "PeliCAN dual SFF accepted"), Some(0));
}

#[test]
fn merging_adds_hits_and_keeps_unlisted_bins() {
    let mut a = Coverage::new();
    a.hit("frame kinds", "SFF data DLC 1");
    let mut b = Coverage::new();
    b.hit("frame kinds", "SFF data DLC 1");
    b.hit("x", "y");
    a.merge(&b);
    assert_eq!(a.hits("frame kinds", "SFF data DLC 1"), Some(2));
    assert_eq!(a.unlisted().count(), 1);
    assert_eq!(a.totals().hit, 1);
    // JSON round trip: the bins survive, the index is rebuilt on merge.
    let back: Coverage = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
    let mut m = Coverage::new();
    m.merge(&back);
    assert_eq!(m.hits("frame kinds", "SFF data DLC 1"), Some(2));
}

#[test]
fn reads_count_the_golden_models_value_not_the_duts() {
    // The DUT read IR = 0x02 (TI), the model 0x01 (RI): coverage is the model's.
    let op = HostOp { mode: CanMode::PeliCan, model_data: Some(0x01), ..HostOp::read(3, 0x02) };
    let mut r = RunRecord::new("t", "rtl");
    r.host_ops.push(op);
    let mut c = Coverage::new();
    c.observe(&r, &[]);
    assert_eq!(c.hits("interrupts PeliCAN", "RI raised"), Some(1));
    assert_eq!(c.hits("interrupts PeliCAN", "TI raised"), Some(0));
    assert_eq!(c.hits("registers PeliCAN operating read", "IR bit 0=1"), Some(1));
    assert_eq!(c.hits("registers PeliCAN operating read", "IR bit 1=1"), Some(0));
}

/// Every unreachable entry names a bin of the model (a typo or a changed
/// register map would otherwise mark nothing, silently).
#[test]
fn every_unreachable_entry_names_a_bin() {
    assert_eq!(Coverage::unmatched_unreachable_entries(), Vec::<String>::new());
}

/// An unreachable bin is no hole and not in the totals; the table prints it
/// with its reason; a run that hits one anyway is printed as a contradiction.
#[test]
fn unreachable_bins_are_printed_with_their_reason_not_counted() {
    let mut c = Coverage::new();
    let un: Vec<_> = c.unreachable().collect();
    assert!(!un.is_empty());
    assert!(un.iter().all(|b| b.unreachable.as_deref().is_some_and(|r| r.len() > 20)), "each has a reason");
    let rm0 = un.iter().find(|b| b.group == "registers PeliCAN reset read" && b.name == "MOD bit 0=0").expect("MOD.RM = 0 in reset mode is unreachable");
    assert!(rm0.unreachable.as_deref().unwrap().contains("is the mode"));
    let n_un = un.len();
    assert!(!c.holes().any(|b| b.unreachable.is_some()));
    let all = c.bins.iter().filter(|b| !b.unlisted).count();
    assert_eq!(c.totals().total, all - n_un);
    let table = c.to_table();
    assert!(table.contains(&format!("unreachable, not counted ({n_un} bins):")), "{table}");
    assert!(
        table.lines().any(|l| l.contains("registers PeliCAN reset read (") && l.contains("MOD =0 bit 0") && l.contains("is the mode")),
        "the bin with its reason: {table}"
    );
    assert!(!table.contains("HIT ALTHOUGH"), "{table}");
    // A reachable bin still counts as a hole: MOD.RM read 1 in reset mode.
    assert!(c.holes().any(|b| b.group == "registers PeliCAN reset read" && b.name == "MOD bit 0=1"));
    c.hit("registers PeliCAN reset read", "MOD bit 0=0");
    assert_eq!(c.totals().hit, 0, "an unreachable hit is not counted as coverage");
    assert!(c.to_table().contains("HIT ALTHOUGH MARKED UNREACHABLE (1"), "{}", c.to_table());
}

/// The SJA1000 reports the error and the overload delimiter with one ECC
/// segment (10111): the engine's field tells a form error in the overload
/// delimiter from one in the error delimiter.
#[test]
fn a_form_error_in_the_overload_delimiter_has_its_own_bin() {
    use can_engine::ErrorKind;
    use can_proto::Field;
    let mut r = RunRecord::new("t", "model");
    // Reported at the first bit of the error flag: the bit before is where it was.
    for (bit, field) in [(9, Field::OverloadDelimiter), (10, Field::ActiveErrorFlag), (19, Field::ErrorDelimiter), (20, Field::ActiveErrorFlag)] {
        r.bus_bits.push(diagnose::BusBit { bit, bus: true, dut_tx: true, model_tx: true, dut_rx: true, field: Some(field), frame: Some(1) });
    }
    r.events.push(EngineEvent::new(10, Side::Model, EventKind::BusError { kind: ErrorKind::Form, ecc: 0x77, field: Field::ActiveErrorFlag }));
    r.events.push(EngineEvent::new(20, Side::Model, EventKind::BusError { kind: ErrorKind::Form, ecc: 0x77, field: Field::ActiveErrorFlag }));
    let mut c = Coverage::new();
    c.observe(&r, &[]);
    assert_eq!(c.hits("error kinds x field", "form error in overload delimiter"), Some(1));
    assert_eq!(c.hits("error kinds x field", "form error in error delimiter"), Some(1));
}
