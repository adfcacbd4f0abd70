//! candump -l lines: each frame kind written as can-utils writes it, read
//! back equal, bad lines refused with file:line, and the error frames of a
//! state sequence as the Linux driver raises them.

use can_proto::CanFrame;
use cosim::candump::{BusLog, LogEntry, LogKind, err, line, parse_frame, parse_log, write_log};
use diagnose::EventKind;

fn frame(id: can_proto::Id, rtr: bool, dlc: u8, data: &[u8]) -> LogKind {
    LogKind::Frame(CanFrame::with_dlc(id, rtr, dlc, data).unwrap())
}

fn std(id: u16) -> can_proto::Id {
    CanFrame::std_id(id).unwrap()
}

fn ext(id: u32) -> can_proto::Id {
    CanFrame::ext_id(id).unwrap()
}

#[test]
fn each_frame_kind_is_written_as_candump_writes_it() {
    let cases = [
        (frame(std(0x123), false, 3, &[0xA5, 0x55, 0x20]), "123#A55520"),
        (frame(std(0x7FF), false, 0, &[]), "7FF#"),
        (frame(std(0x001), false, 8, &[1, 2, 3, 4, 5, 6, 7, 8]), "001#0102030405060708"),
        (frame(ext(0x1ABC_DEF0), false, 2, &[0xFF, 0x00]), "1ABCDEF0#FF00"),
        (frame(ext(0x5), false, 0, &[]), "00000005#"),
        (frame(std(0x321), true, 0, &[]), "321#R"),
        (frame(std(0x321), true, 4, &[]), "321#R4"),
        (frame(ext(0x18DA_F110), true, 8, &[]), "18DAF110#R8"),
        (frame(std(0x10), false, 0xF, &[9; 8]), "010#0909090909090909_F"),
        (LogKind::Error { id: err::FLAG | err::PROT | err::BUSERROR | err::CNT, data: [0, 0, 0x81, 0x03, 0, 0, 0x08, 0] }, "20000288#0000810300000800"),
    ];
    for (i, (kind, want)) in cases.iter().enumerate() {
        let e = LogEntry { t_ps: 1_234_567_891_000_000 + i as u64, kind: kind.clone() };
        assert_eq!(line(&e, "can0"), format!("(0000001234.567891) can0 {want}"));
        // And back: the same frame.
        assert_eq!(&parse_frame(want).unwrap(), kind, "{want}");
    }
}

#[test]
fn a_log_reads_back_equal_with_its_timestamps() {
    let entries: Vec<LogEntry> = [
        frame(std(0x0F), false, 1, &[0x0F]),
        frame(ext(0x1234567), true, 2, &[]),
        LogKind::Error { id: err::FLAG | err::BUSOFF | err::CNT, data: [0, 0, 0, 0, 0, 0, 0xFF, 0] },
        frame(std(0x7E8), false, 8, &[0xDE, 0xAD, 0xBE, 0xEF, 0, 1, 2, 3]),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, kind)| LogEntry { t_ps: 17_000_000 * i as u64 + 3_000_000, kind })
    .collect();
    let text = write_log(&entries, "vcan1");
    assert_eq!(text.lines().count(), 4);
    let back = parse_log(&text, "x.log").unwrap();
    for (e, r) in entries.iter().zip(&back) {
        assert_eq!(r.kind, e.kind);
        assert_eq!(r.t_us, e.t_ps / 1_000_000);
        assert_eq!(r.iface, "vcan1");
    }
    // Lines as other tools write them: candump -x direction, nanoseconds, blank lines.
    let other = "(1700000000.5) can0 123#11 R\n\n(1700000000.123456789) can1 00000123#R T\n";
    let r = parse_log(other, "o.log").unwrap();
    assert_eq!(r.len(), 2);
    assert_eq!(r[0].t_us, 1_700_000_000_500_000);
    assert_eq!(r[1].t_us, 1_700_000_000_123_456);
    assert_eq!(r[1].line, 3);
    assert_eq!(r[1].kind, frame(ext(0x123), true, 0, &[]));
}

#[test]
fn bad_lines_are_refused_with_file_and_line() {
    let cases = [
        ("(1.000000) can0 12#00", "an ID is 3 hex digits"),
        ("(1.000000) can0 800#00", "standard ID above 0x7FF"),
        ("(1.000000) can0 123#0011223344556677889900", "at most 8"),
        ("(1.000000) can0 123#0G", "not a hex byte"),
        ("(1.000000) can0 123#001", "odd number"),
        ("(1.000000) can0 123##1001122", "CAN FD"),
        ("1.000000 can0 123#00", "timestamp"),
        ("(1.000000) can0", "expected `(seconds.micros) iface ID#DATA`"),
        ("(1.000000) can0 123#R9", "remote frame's DLC"),
        ("(1.000000) can0 20000080#0000", "8 data bytes"),
        ("(1.000000) can0 123#0011_9", "raw DLC needs 8 data bytes"),
    ];
    for (l, want) in cases {
        let text = format!("(0.000001) can0 001#\n{l}\n");
        let e = parse_log(&text, "cap.log").expect_err(l).to_string();
        assert!(e.starts_with("cap.log:2: "), "{l}: {e}");
        assert!(e.contains(want), "{l}: {e}");
    }
}

#[test]
fn state_changes_are_logged_once_each_as_the_kernel_reports_them() {
    let mut log = BusLog::new();
    let bit_err = EventKind::BusError { kind: can_engine::ErrorKind::Bit, ecc: 0x03, field: can_proto::Field::Sof };
    log.event(1_000_000, &bit_err, Some((8, 0)));
    // Warning reached (SR.ES), reported once even when repeated.
    log.event(2_000_000, &EventKind::ErrorWarning(true), Some((96, 0)));
    log.event(2_000_000, &EventKind::ErrorWarning(true), Some((96, 0)));
    log.event(3_000_000, &EventKind::FaultState(can_engine::FaultState::ErrorPassive), Some((10, 128)));
    log.event(4_000_000, &EventKind::FaultState(can_engine::FaultState::BusOff), Some((256, 0)));
    log.event(5_000_000, &EventKind::FaultState(can_engine::FaultState::ErrorActive), Some((0, 0)));
    log.event(5_000_000, &EventKind::ErrorWarning(false), Some((0, 0)));
    log.event(6_000_000, &EventKind::ArbitrationLost { alc: 0x2A }, Some((0, 0)));
    // Not reported by the driver: nothing.
    log.event(7_000_000, &EventKind::TxComplete, Some((0, 0)));
    let text = write_log(log.entries(), "can0");
    let want = [
        "(0000000000.000001) can0 20000288#0000810300000800",
        "(0000000000.000002) can0 20000204#0008000000006000",
        "(0000000000.000003) can0 20000204#0010000000000A80",
        "(0000000000.000004) can0 20000240#000000000000FF00",
        "(0000000000.000005) can0 20000204#0040000000000000",
        "(0000000000.000006) can0 20000202#0A00000000000000",
    ];
    assert_eq!(text.lines().collect::<Vec<_>>(), want);
}
