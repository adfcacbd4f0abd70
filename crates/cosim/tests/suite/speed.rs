//! Co-simulation speed against a raw C++ Verilator loop of the same top,
//! measured in one run.

use std::time::Instant;

use cosim::perf::{bundled_sources, cpp_baseline};
use cosim::{Dut, DutChoice, HostBfm, HostPort, Kernel, TbConfig, Testbench, VerilatedDut};

const HOST_HZ: u64 = 50_000_000;
const CAN_HZ: u64 = 24_000_000;

fn bridge_only(top: &str, cycles: u64) -> f64 {
    bridge_loop(
        VerilatedDut::bundled(top, HostPort::Wishbone, false).unwrap(),
        cycles,
    )
}

fn bridge_loop(mut dut: VerilatedDut, cycles: u64) -> f64 {
    let mut k = Kernel::new(HOST_HZ, CAN_HZ).unwrap();
    dut.set_reset(true);
    let t0 = Instant::now();
    let mut host_rises = 0;
    while k.can().cycles() < cycles {
        let t = k.advance();
        if t.host_rise {
            host_rises += 1;
            if host_rises == 4 {
                dut.set_reset(false);
            }
        }
        dut.eval(k.host().level(), k.can().level());
    }
    cycles as f64 / t0.elapsed().as_secs_f64()
}

fn testbench(top: &str, cycles: u64) -> f64 {
    let mut tb = Testbench::new(TbConfig {
        dut: DutChoice::Bundled(top.into()),
        host: HostBfm::Wishbone,
        ..TbConfig::default()
    })
    .unwrap();
    let t0 = Instant::now();
    tb.run_can_cycles(cycles).unwrap();
    cycles as f64 / t0.elapsed().as_secs_f64()
}

#[test]
#[ignore = "speed figures (builds a C++ harness, ~1 min); run with cargo test -p cosim --release --test suite speed:: -- --ignored --nocapture"]
fn cosim_speed_against_a_raw_cpp_loop() {
    let cycles = 2_000_000;
    for top in ["can_top", "cosim_echo"] {
        let cpp = cpp_baseline(&bundled_sources(top), cycles, HOST_HZ, CAN_HZ)
            .unwrap_or_else(|e| panic!("{e}"));
        let bridge = bridge_only(top, cycles);
        let tb = testbench(top, cycles);
        let cpp_rate = cpp.cycles_per_s();
        println!(
            "{top}: C++ loop {:.2} M CAN cycles/s; Rust kernel + bridge {:.2} M/s ({:.2}x); full test bench (BFM, monitor, bit clock, decoder, record) {:.2} M/s ({:.2}x)",
            cpp_rate / 1e6,
            bridge / 1e6,
            bridge / cpp_rate,
            tb / 1e6,
            tb / cpp_rate
        );
        assert_eq!(cpp.cycles, cycles);
        assert!(
            bridge / cpp_rate > 0.3,
            "the bridge should not cost more than 3x: {:.2}",
            bridge / cpp_rate
        );
        if top == "can_top" {
            // The run-time path: the same RTL built as a shared library and
            // loaded with libloading.
            let lib = cosim::build_external(&bundled_sources(top))
                .unwrap_or_else(|e| panic!("{e}"));
            let dl = bridge_loop(
                VerilatedDut::new(lib.instantiate(false), HostPort::Wishbone).unwrap(),
                cycles,
            );
            println!(
                "{top}: run-time shared library (-fPIC -fno-semantic-interposition -Wl,-Bsymbolic) {:.2} M/s ({:.2}x)",
                dl / 1e6,
                dl / cpp_rate
            );
            assert!(dl / cpp_rate > 0.2);
        }
    }
}
