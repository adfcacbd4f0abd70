//! The generated device-tree node compiled by dtc, the compiler the kernel
//! build uses: in a minimal tree, to a blob and back, and the properties
//! the sja1000 platform driver reads come out with the values of the
//! register settings. Skipped, with a message, where dtc is not installed
//! (Debian: device-tree-compiler; scripts/setup.sh installs it).

use regmap::generate::{dt_node, DtOptions, Spacing};
use std::process::Command;

fn dtc_present() -> bool {
    Command::new("dtc").arg("--version").output().is_ok_and(|o| o.status.success())
}

/// Compiles `node` under a bus with one address and one size cell, and
/// decompiles the blob: the tree as dtc understood it.
fn through_dtc(node: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("can.dts");
    let blob = tmp.path().join("can.dtb");
    let tree = format!(
        "/dts-v1/;\n/ {{\n\t#address-cells = <1>;\n\t#size-cells = <1>;\n\tintc: interrupt-controller {{\n\t\tinterrupt-controller;\n\t\t#interrupt-cells = <3>;\n\t}};\n\tsoc {{\n\t\t#address-cells = <1>;\n\t\t#size-cells = <1>;\n\t\tranges;\n{node}\t}};\n}};\n"
    );
    std::fs::write(&src, tree).unwrap();
    let out = Command::new("dtc").args(["-W", "no-unit_address_vs_reg", "-I", "dts", "-O", "dtb", "-o"]).arg(&blob).arg(&src).output().unwrap();
    assert!(out.status.success(), "dtc refused the node:\n{node}\n{}", String::from_utf8_lossy(&out.stderr));
    let back = Command::new("dtc").args(["-I", "dtb", "-O", "dts"]).arg(&blob).output().unwrap();
    assert!(back.status.success(), "{}", String::from_utf8_lossy(&back.stderr));
    String::from_utf8(back.stdout).unwrap()
}

#[test]
fn dtc_compiles_the_node_with_the_register_settings_values() {
    if !dtc_present() {
        eprintln!("skipped: dtc not installed (Debian package device-tree-compiler; scripts/setup.sh installs it)");
        return;
    }
    // Our DE2 settings at a byte stride: OCR 0xDA, CDR 0xC8 (CLKOUT off, CBP).
    let de2 = DtOptions {
        base: 0xff20_0000,
        interrupts: vec![0, 40, 4],
        interrupt_parent: Some("intc".into()),
        btr: Some((0x00, 0x1C)),
        ..Default::default()
    };
    let t = through_dtc(&dt_node(&de2).unwrap());
    assert!(t.contains("can@ff200000 {"), "{t}");
    assert!(t.contains("compatible = \"nxp,sja1000\";"), "{t}");
    assert!(t.contains("reg = <0xff200000 0x80>;"), "{t}");
    assert!(t.contains("reg-io-width = <0x01>;"), "{t}");
    assert!(t.contains("interrupts = <0x00 0x28 0x04>;"), "{t}");
    assert!(t.contains("nxp,external-clock-frequency = <0x16e3600>;"), "24 MHz: {t}");
    assert!(t.contains("nxp,tx-output-mode = <0x02>;"), "{t}");
    assert!(t.contains("nxp,tx-output-config = <0x36>;"), "{t}");
    assert!(!t.contains("clock-out-frequency") && !t.contains("no-comparator-bypass"), "{t}");
    // A 4-byte stride, CLKOUT at fosc/4, comparator not bypassed.
    let axi = DtOptions { spacing: Spacing::Word, cdr: 0x81, ocr: 0x1A, ..Default::default() };
    let t = through_dtc(&dt_node(&axi).unwrap());
    assert!(t.contains("can@0 {") && t.contains("reg = <0x00 0x200>;") && t.contains("reg-io-width = <0x04>;"), "{t}");
    assert!(t.contains("nxp,clock-out-frequency = <0x5b8d80>;"), "6 MHz: {t}");
    assert!(t.contains("nxp,no-comparator-bypass;"), "{t}");
    assert!(t.contains("nxp,tx-output-config = <0x06>;"), "OCR 0x1A: TX0 push-pull: {t}");
}
