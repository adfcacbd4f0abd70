//! The Verilator bridge on the bundled fixtures, driven port by port.

use cosim::{BridgeError, ExternalCore, Model};

fn edge(m: &mut Model, clk: cosim::Port) {
    m.set(clk, 1);
    m.eval();
    m.set(clk, 0);
    m.eval();
}

#[test]
fn echo_fixture_registers_and_tx_through_raw_ports() {
    let mut m = cosim::bundled("cosim_echo", false).unwrap();
    let p = |n: &str| m.port(n, None, "can_top").unwrap();
    let (clk, rst, cyc, stb, we, adr, dat_i, dat_o, ack, tx) = (
        p("wb_clk_i"),
        p("wb_rst_i"),
        p("wb_cyc_i"),
        p("wb_stb_i"),
        p("wb_we_i"),
        p("wb_adr_i"),
        p("wb_dat_i"),
        p("wb_dat_o"),
        p("wb_ack_o"),
        p("tx_o"),
    );
    m.set(rst, 1);
    edge(&mut m, clk);
    m.set(rst, 0);
    edge(&mut m, clk);
    assert_eq!(m.get(tx), 1, "tx recessive after reset");
    // Write 0x00 to register 0: tx goes dominant.
    m.set(cyc, 1);
    m.set(stb, 1);
    m.set(we, 1);
    m.set(adr, 0);
    m.set(dat_i, 0);
    edge(&mut m, clk);
    assert_eq!(m.get(ack), 1);
    m.set(cyc, 0);
    m.set(stb, 0);
    edge(&mut m, clk);
    assert_eq!(m.get(tx), 0, "tx follows register 0 bit 0");
    // Write 0xA5 to register 5 and read it back.
    for (w, d) in [(1, 0xA5), (0, 0)] {
        m.set(cyc, 1);
        m.set(stb, 1);
        m.set(we, w);
        m.set(adr, 5);
        m.set(dat_i, d);
        edge(&mut m, clk);
        assert_eq!(m.get(ack), 1);
        m.set(cyc, 0);
        m.set(stb, 0);
        edge(&mut m, clk);
    }
    assert_eq!(m.get(dat_o), 0xA5);
    // Values are masked to the port width.
    m.set(adr, 0x1ff);
    assert_eq!(m.get(adr), 0xff);
}

#[test]
fn unknown_top_and_missing_port_are_clear_errors() {
    let e = cosim::bundled("no_such_top", false).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("no_such_top") && msg.contains("cosim_echo"),
        "{msg}"
    );
    let m = cosim::bundled("cosim_noack", false).unwrap();
    let e = m.port("avalon_address", None, "Avalon").unwrap_err();
    assert!(matches!(e, BridgeError::MissingPort { .. }));
    assert!(
        e.to_string().contains("wb_clk_i"),
        "lists the ports it has: {e}"
    );
    let e = m.port("wb_adr_i", Some(16), "can_top").unwrap_err();
    assert!(e.to_string().contains("8 bits wide"), "{e}");
}

#[test]
fn two_instances_are_independent() {
    let mut a = cosim::bundled("cosim_echo", false).unwrap();
    let b = cosim::bundled("cosim_echo", false).unwrap();
    let pa = a.port("wb_adr_i", None, "").unwrap();
    let pb = b.port("wb_adr_i", None, "").unwrap();
    a.set(pa, 7);
    assert_eq!(a.get(pa), 7);
    assert_eq!(b.get(pb), 0);
}

#[test]
#[should_panic(expected = "another model")]
fn a_port_of_one_model_cannot_be_used_on_another() {
    let a = cosim::bundled("cosim_echo", false).unwrap();
    let mut b = cosim::bundled("cosim_echo", false).unwrap();
    let pa = a.port("wb_adr_i", None, "").unwrap();
    b.set(pa, 1);
}

#[test]
fn verilator_error_in_an_external_core_is_one_paragraph_not_a_panic() {
    let dir = std::env::temp_dir().join(format!("cosim-broken-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("broken.v"),
        "module broken(input a, output b);\n  assign b = a +;\nendmodule\n",
    )
    .unwrap();
    let core = ExternalCore {
        dir: dir.clone(),
        top: "broken".into(),
        ..Default::default()
    };
    let e = cosim::build_external(&core).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, BridgeError::Verilate { .. }), "{msg}");
    assert!(
        msg.contains("broken.v") && msg.contains("syntax error"),
        "carries Verilator's message: {msg}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn models_run_on_their_own_threads_from_one_build() {
    // A compiled core is shareable; each thread makes its own instance
    // (Verilator models are not Send).
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<cosim::CompiledCore>();
    let handles: Vec<_> = (0..2u8)
        .map(|k| {
            std::thread::spawn(move || {
                let mut m = cosim::bundled("cosim_echo", false).unwrap();
                let adr = m.port("wb_adr_i", None, "").unwrap();
                m.set(adr, 10 + k as u64);
                m.eval();
                m.get(adr)
            })
        })
        .collect();
    let got: Vec<u64> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    assert_eq!(got, vec![10, 11]);
}

/// Two threads build one external core at once into an empty cache (regress
/// workers do): both load a working model, and the cache holds one
/// entry and no work directory.
#[test]
fn two_threads_build_one_external_core_at_once_on_an_empty_cache() {
    let scratch = tempfile::tempdir().unwrap();
    let (src, cache) = (scratch.path().join("src"), scratch.path().join("cache"));
    std::fs::create_dir_all(&src).unwrap();
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures/cosim_echo.v");
    std::fs::copy(fixture, src.join("cosim_echo.v")).unwrap();
    let core = ExternalCore { dir: src, top: "cosim_echo".into(), ..Default::default() };
    let built: Vec<_> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..2).map(|_| s.spawn(|| core.build_in(&cache))).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for b in built {
        let c = b.unwrap_or_else(|e| panic!("a concurrent build failed: {e}"));
        let m = c.instantiate(false);
        assert!(m.port("wb_adr_i", None, "").is_ok(), "a working model from {}", c.path.display());
    }
    let entries: Vec<_> = std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(entries.len(), 1, "one entry, no work directory left: {entries:?}");
}
