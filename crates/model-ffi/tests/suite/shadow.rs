//! The shadow against a second golden model standing in for the DUT: the
//! same stimulus agrees; a DUT that differs in one register bit, in its tx,
//! or a bench whose rx does not follow tx is diagnosed.

use std::ffi::{CStr, CString};

use sja1000::Sja1000;
use sja1000_model::*;

/// PeliCAN self-test set-up, then a self-reception request: (addr, data).
const SELF_TEST: &[(u8, u8)] = &[
    (0, 0x01),  // MOD: reset mode
    (31, 0x80), // CDR: PeliCAN
    (0, 0x05),  // MOD: reset + self-test
    (6, 0x41),  // BTR0
    (7, 0x25),  // BTR1
    (16, 0xFF),
    (17, 0xFF),
    (18, 0xFF),
    (19, 0xFF), // ACR0..3
    (20, 0xFF),
    (21, 0xFF),
    (22, 0xFF),
    (23, 0xFF), // AMR0..3
    (0, 0x04),  // MOD: operating, self-test
    (16, 0x01), // TX frame info: standard, DLC 1
    (17, 0x24),
    (18, 0x60), // ID 0x123
    (19, 0x5A), // data
    (1, 0x10),  // CMR: self reception request
];

/// Runs `n` CAN clocks of `shadow` and a model `dut` with tx looped to rx
/// (unless `rx_tied`); `dut_tx` may distort the DUT's tx.
fn run(
    shadow: &mut Shadow,
    dut: &mut Sja1000,
    n: u64,
    rx_tied: bool,
    dut_tx: impl Fn(bool, u64) -> bool,
) {
    let mut tx = true;
    for _ in 0..n {
        let rx = rx_tied || tx;
        let t = dut.clock(rx);
        tx = dut_tx(t, shadow.bits());
        let pins = DutPins {
            tx: Some(tx),
            irq_n: Some(!dut.irq()),
            bus_on: Some(!dut.bus_off()),
        };
        shadow.clock(rx, Some(pins));
        if shadow.failed() {
            return;
        }
    }
}

fn set_up(shadow: &mut Shadow, dut: &mut Sja1000) {
    for &(a, d) in SELF_TEST {
        shadow.request(true, a, d);
        dut.write(a, d);
    }
}

#[test]
fn the_same_core_agrees_through_a_self_test_frame() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    run(&mut shadow, &mut dut, 150 * 40, false, |t, _| t);
    let sr = dut.read(2);
    shadow.compare_read(2, sr);
    assert_eq!(sr & 0x08, 0x08, "the frame completed (SR.TCS)");
    run(&mut shadow, &mut dut, 100, false, |t, _| t);
    assert!(!shadow.finish(), "{:?}", shadow.diagnosis());
    assert!(
        shadow.compared_bits() > 40,
        "tx compared at each sample point: {}",
        shadow.compared_bits()
    );
    assert_eq!(shadow.compared_reads(), 1);
}

#[test]
fn a_wrong_register_bit_is_diagnosed_with_the_register_and_values() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    // BTR0 read back with one bit flipped (a planted register-file bug).
    let v = dut.read(6) ^ 0x01;
    let _ = shadow.compare_read(6, v);
    let d = shadow.diagnosis().expect("a divergence");
    assert!(d.contains("BTR0"), "{d}");
    assert!(d.contains("0x40") && d.contains("0x41"), "{d}");
}

#[test]
fn an_sr_read_within_the_status_tolerance_passes_and_one_beyond_it_fails() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    for &(a, d) in &SELF_TEST[..SELF_TEST.len() - 1] {
        shadow.request(true, a, d);
        dut.write(a, d);
    }
    // SR as the model had it before the request (transmit buffer free, no
    // transmission): a DUT whose status lags a few clocks reads that.
    run(&mut shadow, &mut dut, 4, false, |t, _| t);
    let early = shadow.peek(2);
    shadow.request(true, 1, 0x10);
    dut.write(1, 0x10);
    run(&mut shadow, &mut dut, 30, false, |t, _| t);
    assert_ne!(shadow.peek(2), early, "SR moved within the 30 clocks");
    shadow.compare_read(2, early);
    run(&mut shadow, &mut dut, 60, false, |t, _| t);
    assert!(!shadow.failed(), "{:?}", shadow.diagnosis());
    // A value the model never held: judged when the look-ahead closes.
    shadow.compare_read(2, 0x80 | shadow.peek(2));
    run(&mut shadow, &mut dut, 60, false, |t, _| t);
    let d = shadow
        .diagnosis()
        .expect("an SR value the model never held");
    assert!(d.contains("SR"), "{d}");
}

#[test]
fn a_tx_stuck_recessive_is_a_tx_divergence_at_the_start_of_frame() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    run(&mut shadow, &mut dut, 150 * 40, false, |_, _| true);
    let d = shadow.diagnosis().expect("tx differs");
    assert!(d.contains("tx"), "{d}");
}

#[test]
fn rx_tied_recessive_leaves_the_frame_pending_and_names_the_wiring() {
    let mut shadow = Shadow::new("rtl", 24e6).unwrap();
    // The thesis's BasicCAN set-up; the DUT is the model itself (so the
    // comparison agrees), the wiring is what fails.
    let steps: &[(u8, u8)] = &[
        (0, 0x01),
        (31, 0x00),
        (4, 0xFF),
        (5, 0xFF),
        (6, 0x41),
        (7, 0x25),
        (8, 0xDB),
        (0, 0x00),
        (10, 0xA5),
        (11, 0x21),
        (12, 0x51),
        (1, 0x01),
    ];
    for &(a, d) in steps {
        shadow.request(true, a, d);
        for _ in 0..4 {
            shadow.clock(true, None);
        }
    }
    for _ in 0..(3000 * 10) {
        shadow.clock(true, None);
    }
    assert!(!shadow.failed());
    assert!(shadow.finish());
    let d = shadow.diagnosis().unwrap();
    assert!(
        d.contains("RxNotFollowingTx") || d.contains("rx_i is tied"),
        "{d}"
    );
    assert!(d.contains("tied to 1"), "{d}");
}

#[test]
fn the_candump_log_holds_the_self_test_frame_and_reads_back() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    run(&mut shadow, &mut dut, 150 * 40, false, |t, _| t);
    let log = shadow.candump_log("can0");
    let lines = cosim::candump::parse_log(&log, "run.log").expect("the log parses");
    let frames: Vec<String> = lines
        .iter()
        .map(|l| cosim::candump::frame_text(&l.kind))
        .collect();
    assert_eq!(frames, ["123#5A"], "{log}");
}

#[test]
fn the_candump_log_reports_the_bus_errors_of_a_tied_rx_with_the_counters() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    // Normal mode: rx tied recessive, so every attempt ends in a bit error.
    for &(a, d) in &[(0, 0x01), (0, 0x00), (1, 0x01)] {
        shadow.request(true, a, d);
        dut.write(a, d);
    }
    run(&mut shadow, &mut dut, 2 * 40 * 40, true, |t, _| t);
    let log = shadow.candump_log("can0");
    let lines = cosim::candump::parse_log(&log, "run.log").expect("the log parses");
    let errors: Vec<String> = lines
        .iter()
        .map(|l| cosim::candump::frame_text(&l.kind))
        .filter(|t| t.starts_with("2000"))
        .collect();
    // CAN_ERR_PROT | CAN_ERR_BUSERROR | CAN_ERR_CNT, bit error while
    // transmitting (PROT_BIT | PROT_TX), TXERR 8 after the first attempt.
    assert!(!errors.is_empty(), "{log}");
    assert!(errors[0].starts_with("20000288#000081"), "{log}");
    assert_eq!(&errors[0][errors[0].len() - 4..], "0800", "{log}");
}

#[test]
fn the_c_abi_refuses_bad_input_with_a_message() {
    // SAFETY: handles come from sja1000_model_new and are freed once; strings are NUL-terminated.
    unsafe {
        let p = CString::new("no-such-profile").unwrap();
        let m = sja1000_model_new(p.as_ptr(), 24e6);
        assert!(m.is_null());
        let e = (CStr::from_ptr(sja1000_model_last_error()))
            .to_str()
            .unwrap()
            .to_string();
        assert!(e.contains("no-such-profile"), "{e}");
        let m = sja1000_model_new(std::ptr::null(), -1.0);
        assert!(m.is_null());
        let e = (CStr::from_ptr(sja1000_model_last_error()))
            .to_str()
            .unwrap()
            .to_string();
        assert!(e.contains("positive"), "{e}");
        // A NULL handle is answered, never dereferenced.
        assert_eq!(sja1000_model_read(std::ptr::null_mut(), 0), -1);
        assert_eq!(sja1000_model_failed(std::ptr::null_mut()), 1);
        sja1000_model_free(std::ptr::null_mut());
    }
}

#[test]
fn the_c_abi_compares_a_read_and_hands_out_the_diagnosis() {
    // SAFETY: handles come from sja1000_model_new and are freed once; strings are NUL-terminated.
    unsafe {
        let m = sja1000_model_new(std::ptr::null(), 24e6);
        assert!(!m.is_null());
        // rtl profile: a write lands at the 4th CAN edge, a read at the 3rd.
        for (w, a, d) in [(1, 0, 0x01), (1, 6, 0x41), (0, 6, 0)] {
            sja1000_model_request(m, w, a, d);
            for _ in 0..4 {
                sja1000_model_clock_compare(m, 1, -1, -1, -1);
            }
        }
        assert_eq!(sja1000_model_compare_read(m, 6, 0x41), 0x41);
        assert_eq!(sja1000_model_failed(m), 0);
        let text = (CStr::from_ptr(sja1000_model_diagnosis(m)))
            .to_str()
            .unwrap()
            .to_string();
        assert_eq!(text, "");
        sja1000_model_request(m, 0, 6, 0);
        for _ in 0..3 {
            sja1000_model_clock(m, 1);
        }
        assert_eq!(sja1000_model_compare_read(m, 6, 0x43), 0x41);
        assert_eq!(sja1000_model_failed(m), 1);
        let text = (CStr::from_ptr(sja1000_model_diagnosis(m)))
            .to_str()
            .unwrap()
            .to_string();
        assert!(text.contains("BTR0") && text.contains("rtl"), "{text}");
        sja1000_model_free(m);
    }
}

#[test]
fn an_avalon_access_is_taken_at_the_edges_the_profile_declares_for_avalon() {
    // A profile whose Avalon timing differs from its Wishbone timing.
    let mut p = cosim::Profile::rtl();
    p.wishbone = cosim::AccessTiming::CanEdges {
        read: 3,
        write: 4,
        command: 4,
    };
    p.avalon = cosim::AccessTiming::CanEdges {
        read: 1,
        write: 7,
        command: 7,
    };
    let mut shadow = Shadow::with_profile(&p, 24e6).unwrap();
    shadow.set_host_bus(diagnose::HostBus::Avalon);
    assert_eq!(shadow.host_bus(), diagnose::HostBus::Avalon);
    // Reset mode, then CDR = PeliCAN through Avalon: written at the 7th edge.
    shadow.write(0, 0x01);
    shadow.request(true, 31, 0x80);
    for _ in 0..6 {
        shadow.clock(true, None);
    }
    assert_eq!(shadow.peek(31) & 0x80, 0, "taken before its 7th CAN edge");
    shadow.clock(true, None);
    assert_eq!(shadow.peek(31) & 0x80, 0x80, "taken at its 7th CAN edge");
    let r = shadow.record();
    assert_eq!(r.host_bus, diagnose::HostBus::Avalon);
    assert!(
        r.host_ops
            .iter()
            .all(|o| o.bfm == diagnose::HostBus::Avalon),
        "{:?}",
        r.host_ops
    );
    // Wishbone again: its own 4 edges.
    shadow.set_host_bus(diagnose::HostBus::Wishbone);
    shadow.request(true, 31, 0x00);
    for _ in 0..3 {
        shadow.clock(true, None);
    }
    assert_eq!(shadow.peek(31) & 0x80, 0x80);
    shadow.clock(true, None);
    assert_eq!(shadow.peek(31) & 0x80, 0);
}

/// CAN clocks until a write of CDR = PeliCAN through `bus` reaches the model.
fn edges_to_take_a_write(shadow: &mut Shadow, bus: diagnose::HostBus) -> u32 {
    shadow.set_host_bus(bus);
    shadow.write(0, 0x01);
    shadow.write(31, 0x00);
    shadow.request(true, 31, 0x80);
    for n in 1..=16 {
        shadow.clock(true, None);
        if shadow.peek(31) & 0x80 != 0 {
            return n;
        }
    }
    panic!("the write through {bus:?} never reached the model");
}

#[test]
fn axi4_lite_and_apb_accesses_take_their_profile_timing_or_else_wishbone_s() {
    let mut p = cosim::Profile::rtl();
    p.wishbone = cosim::AccessTiming::CanEdges {
        read: 3,
        write: 4,
        command: 4,
    };
    p.axi4lite = Some(cosim::AccessTiming::CanEdges {
        read: 2,
        write: 6,
        command: 6,
    });
    p.apb = Some(cosim::AccessTiming::CanEdges {
        read: 1,
        write: 9,
        command: 9,
    });
    let mut shadow = Shadow::with_profile(&p, 24e6).unwrap();
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Axi4Lite),
        6
    );
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Apb),
        9
    );
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Wishbone),
        4
    );
    let r = shadow.record();
    assert!(
        r.host_ops
            .iter()
            .any(|o| o.bfm == diagnose::HostBus::Axi4Lite)
            && r.host_ops.iter().any(|o| o.bfm == diagnose::HostBus::Apb),
        "{:?}",
        r.host_ops
    );
    // Without [access.axi4-lite] / [access.apb]: the Wishbone timing.
    p.axi4lite = None;
    p.apb = None;
    let mut shadow = Shadow::with_profile(&p, 24e6).unwrap();
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Axi4Lite),
        4
    );
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Apb),
        4
    );
}

#[test]
fn register_port_and_motorola_accesses_take_their_profile_timing_or_their_fallback() {
    let mut p = cosim::Profile::rtl();
    p.wishbone = cosim::AccessTiming::CanEdges {
        read: 3,
        write: 4,
        command: 4,
    };
    p.i8051 = Some(cosim::AccessTiming::CanEdges {
        read: 8,
        write: 9,
        command: 9,
    });
    p.regport.timing = None;
    p.motorola.timing = None;
    // Without [access.regport] / [access.motorola]: Wishbone's and the 8051 bus's.
    let mut shadow = Shadow::with_profile(&p, 24e6).unwrap();
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Regport),
        4
    );
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Motorola),
        9
    );
    p.regport.timing = Some(cosim::AccessTiming::CanEdges {
        read: 2,
        write: 5,
        command: 5,
    });
    p.motorola.timing = Some(cosim::AccessTiming::CanEdges {
        read: 2,
        write: 3,
        command: 3,
    });
    let mut shadow = Shadow::with_profile(&p, 24e6).unwrap();
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Regport),
        5
    );
    assert_eq!(
        edges_to_take_a_write(&mut shadow, diagnose::HostBus::Motorola),
        3
    );
    assert_eq!(shadow.record().host_bus, diagnose::HostBus::Motorola);
}

#[test]
fn the_c_abi_sets_the_host_bus_by_name_and_refuses_an_unknown_one() {
    // SAFETY: the handle comes from sja1000_model_new and is freed once; strings are NUL-terminated.
    unsafe {
        let m = sja1000_model_new(std::ptr::null(), 24e6);
        assert!(!m.is_null());
        for name in [
            "axi4-lite",
            "APB",
            "avalon",
            "regport",
            "Motorola",
            "wishbone",
        ] {
            let n = CString::new(name).unwrap();
            assert_eq!(sja1000_model_set_host_bus(m, n.as_ptr()), 0, "{name}");
        }
        let n = CString::new("ahb").unwrap();
        assert_eq!(sja1000_model_set_host_bus(m, n.as_ptr()), -1);
        let e = (CStr::from_ptr(sja1000_model_last_error()))
            .to_str()
            .unwrap()
            .to_string();
        assert!(e.contains("\"ahb\"") && e.contains("axi4-lite"), "{e}");
        assert_eq!(sja1000_model_set_host_bus(m, std::ptr::null()), -1);
        sja1000_model_free(m);
    }
}

/// The time at which `var` of the marker VCD first takes `value`.
fn first_change(path: &std::path::Path, var: &str, value: &str) -> Option<u64> {
    let mut p = vcd::Parser::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let h = p.parse_header().unwrap();
    let id = match h.find_var(&[sja1000_model::markers::SCOPE, var]).unwrap() {
        v => v.code,
    };
    let mut t = 0;
    for cmd in p {
        match cmd.unwrap() {
            vcd::Command::Timestamp(x) => {
                assert!(x > t || x == 0, "time goes back: #{x} after #{t}");
                t = x
            }
            vcd::Command::ChangeScalar(i, v) if i == id && v.to_string() == value => {
                return Some(t);
            }
            vcd::Command::ChangeString(i, v) if i == id && v.contains(value) => return Some(t),
            _ => {}
        }
    }
    None
}

#[test]
fn a_divergence_is_a_marker_at_its_time_on_the_bench_s_time_line() {
    const T0: u64 = 3_001_000; // the bench's time of the first CAN clock
    const P: u64 = 41_666; // its CAN clock period
    let mut shadow = Shadow::immediate(24e6).unwrap();
    shadow.set_time_ps(T0);
    shadow.set_period_ps(P);
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    run(&mut shadow, &mut dut, 150 * 40, false, |t, _| t);
    let sr = dut.read(2);
    assert_eq!(shadow.compare_read(2, sr), sr);
    // 6000 clocks later; then a CDR read that says PeliCAN is off.
    let at = T0 + (150 * 40 - 1) * P;
    assert_eq!(shadow.now(), at);
    shadow.compare_read(31, 0x00);
    assert!(shadow.failed());
    assert_eq!(shadow.record().divergence.unwrap().time_ps, at);
    let dir = tempfile::tempdir().unwrap();
    let vcd_path = dir.path().join("sb.vcd");
    sja1000_model::markers::write_vcd(&shadow, &vcd_path).unwrap();
    assert_eq!(first_change(&vcd_path, "divergence", "1"), Some(at));
    assert_eq!(
        first_change(&vcd_path, "divergence_kind", "RegisterRead:CDR"),
        Some(at)
    );
    // The set-up's writes were taken at the first clock's instant (before it),
    // the self-test frame completed on the DUT's rx, the model received it.
    // (Address 0 is BasicCAN's CR until CDR selects PeliCAN.)
    assert_eq!(
        first_change(&vcd_path, "host_access", "W:CR=0x01+W:CDR=0x80"),
        Some(T0)
    );
    let frame = first_change(&vcd_path, "bus_frame", "123#5A").expect("the frame on the bus");
    let received = first_change(&vcd_path, "model_event", "Received:0x123").expect("received");
    assert!(
        T0 < frame && frame < at && T0 < received && received < at,
        "{frame} {received}"
    );
    assert!(first_change(&vcd_path, "model_event", "TxComplete").is_some());
    // The save file's primary marker is the divergence.
    let gtkw = sja1000_model::markers::save_file(&shadow, &vcd_path);
    let marker_line = gtkw.lines().find(|l| l.starts_with('*')).unwrap();
    assert_eq!(
        marker_line.split(' ').nth(1),
        Some(at.to_string().as_str()),
        "{gtkw}"
    );
    assert!(gtkw.contains("sja1000_scoreboard.divergence\n"), "{gtkw}");
}

#[test]
fn without_a_divergence_the_marker_file_has_none_and_no_marker() {
    let mut shadow = Shadow::immediate(24e6).unwrap();
    let mut dut = Sja1000::new();
    set_up(&mut shadow, &mut dut);
    run(&mut shadow, &mut dut, 150 * 40, false, |t, _| t);
    assert!(!shadow.finish());
    let dir = tempfile::tempdir().unwrap();
    let vcd_path = dir.path().join("sb.vcd");
    sja1000_model::markers::write_vcd(&shadow, &vcd_path).unwrap();
    assert_eq!(first_change(&vcd_path, "divergence", "1"), None);
    assert!(first_change(&vcd_path, "bus_frame", "123#5A").is_some());
    let gtkw = sja1000_model::markers::save_file(&shadow, &vcd_path);
    let marker_line = gtkw.lines().find(|l| l.starts_with('*')).unwrap();
    assert_eq!(marker_line.split(' ').nth(1), Some("-1"), "{gtkw}");
}
