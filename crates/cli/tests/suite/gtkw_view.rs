//! The GTKWave view written next to a VCD (`cancosim cosim --vcd`): groups,
//! text traces, the marker on the first divergence and the view around it.
//! The save file is checked against the VCD and the run record; then
//! GTKWave opens it under Xvfb, as a person would, and the screenshot must
//! show the primary marker (GTKWave draws it only when it is in view),
//! which the same VCD opened without the save file does not. Without
//! gtkwave, xvfb-run, xwd and xwdtopnm the screenshot part says so and skips.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The deviant fixture alone, in the directory the HTML test uses (one build).
fn deviant_core() -> PathBuf {
    let core = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("html-report-core");
    std::fs::create_dir_all(&core).unwrap();
    let src = std::fs::read(root().join("tb/fixtures/cosim_deviant.v")).unwrap();
    if std::fs::read(core.join("cosim_deviant.v")).ok().as_deref() != Some(&src[..]) {
        // Written whole or not at all: the HTML and GTKWave tests share it
        // and may run at once.
        let tmp = core.join(format!("cosim_deviant.v.{:?}", std::thread::current().id()));
        std::fs::write(&tmp, src).unwrap();
        std::fs::rename(&tmp, core.join("cosim_deviant.v")).unwrap();
    }
    core
}

fn have(tool: &str) -> bool {
    Command::new("sh").args(["-c", &format!("command -v {tool}")]).output().is_ok_and(|o| o.status.success())
}

/// A screenshot (PPM) of GTKWave opening `file` on a 1400x800 Xvfb screen.
fn screenshot(file: &Path, ppm: &Path) -> Vec<u8> {
    let script = format!(
        "gtkwave '{}' >/dev/null 2>&1 & pid=$!; sleep 5; xwd -root -silent | xwdtopnm > '{}' 2>/dev/null; kill $pid",
        file.display(),
        ppm.display()
    );
    let out = Command::new("timeout").args(["60", "xvfb-run", "-a", "-s", "-screen 0 1400x800x24", "sh", "-c", &script]).output().unwrap();
    assert!(out.status.success(), "xvfb-run gtkwave: {}", String::from_utf8_lossy(&out.stderr));
    std::fs::read(ppm).unwrap()
}

/// Columns of a binary PPM (P6) whose pixels from `top` to `bottom` are all `rgb`.
fn full_columns(ppm: &[u8], rgb: [u8; 3], top: usize, bottom: usize) -> Vec<usize> {
    // Header: P6, width height, maxval, one whitespace byte, then pixels.
    let mut fields = Vec::new();
    let mut i = 0;
    while fields.len() < 4 {
        while ppm[i].is_ascii_whitespace() {
            i += 1;
        }
        let s = i;
        while !ppm[i].is_ascii_whitespace() {
            i += 1;
        }
        fields.push(std::str::from_utf8(&ppm[s..i]).unwrap().to_string());
    }
    assert_eq!(fields[0], "P6");
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let px = &ppm[i + 1..];
    // 8 or 16 bits a sample (xwdtopnm may write 16): compare the high byte.
    let b = if fields[3].parse::<u32>().unwrap() > 255 { 2 } else { 1 };
    assert_eq!(px.len(), w * h * 3 * b);
    let at = |x: usize, y: usize| [0, 1, 2].map(|c| px[((y * w + x) * 3 + c) * b]);
    (0..w).filter(|&x| (top..bottom.min(h)).all(|y| at(x, y) == rgb)).collect()
}

#[test]
fn the_gtkwave_view_marks_and_shows_the_first_divergence() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gtkw-view");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let here = root().join("crates/cli/tests/html");
    let out = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .arg("cosim")
        .arg(here.join("tx-deviant.toml"))
        .arg("--external")
        .arg(deviant_core())
        .args(["--top", "cosim_deviant", "--profile", "tb/fixtures/at-ack.toml", "--waivers"])
        .arg(here.join("deviant-waivers.toml"))
        .arg("--vcd")
        .arg(dir.join("run.vcd"))
        .arg("--record")
        .arg(dir.join("run.json"))
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "the fixture diverges: {}", String::from_utf8_lossy(&out.stdout));
    let record: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
    let t = record["divergence"]["time_ps"].as_u64().expect("a divergence");
    assert_eq!(record["divergence"]["kind"], "TxBit");

    // The save file: the VCD, the marker on the divergence, the view on it,
    // five groups of signals that the VCD declares.
    let gtkw = std::fs::read_to_string(dir.join("run.gtkw")).expect("a .gtkw next to the VCD");
    assert!(gtkw.contains(&format!("[dumpfile] \"{}\"", dir.join("run.vcd").display())), "{gtkw}");
    let star = gtkw.lines().find(|l| l.starts_with('*')).unwrap();
    assert_eq!(star.split(' ').nth(1), Some(t.to_string().as_str()), "{star}");
    let start: u64 = gtkw.lines().find_map(|l| l.strip_prefix("[timestart] ")).unwrap().parse().unwrap();
    assert!(start < t, "the view starts before the divergence: {start} vs {t}");
    assert_eq!(gtkw.matches("@800200").count(), 5);
    assert_eq!(gtkw.matches("@1000200").count(), 5);
    let vcd = std::fs::read_to_string(dir.join("run.vcd")).unwrap();
    let header = &vcd[..vcd.find("$enddefinitions").unwrap()];
    for sig in gtkw.lines().filter_map(|l| l.strip_prefix("cosim.")) {
        let name = sig.split('[').next().unwrap();
        assert!(header.contains(&format!(" {name} $end")), "{name} is not in the VCD");
    }
    assert!(gtkw.contains("@2028\ncosim.field") && gtkw.contains("@2028\ncosim.model_field"), "fields as text traces: {gtkw}");

    let tools = ["gtkwave", "xvfb-run", "xwd", "xwdtopnm", "timeout"];
    if let Some(missing) = tools.iter().find(|t| !have(t)) {
        eprintln!("SKIPPED the GTKWave screenshot: `{missing}` not found (Debian: apt-get install gtkwave xvfb x11-apps netpbm)");
        return;
    }
    // GTKWave's primary marker: a full-height column of (255, 128, 128) in
    // the wave pane (rows 140..780 of a 1400x800 screen).
    const MARKER: [u8; 3] = [255, 128, 128];
    let with = screenshot(&dir.join("run.gtkw"), &dir.join("with.ppm"));
    let cols = full_columns(&with, MARKER, 140, 780);
    assert!(!cols.is_empty() && cols.iter().all(|&x| x > 480), "marker columns {cols:?}");
    let without = screenshot(&dir.join("run.vcd"), &dir.join("without.ppm"));
    assert!(full_columns(&without, MARKER, 140, 780).is_empty(), "no marker without the save file");
}
