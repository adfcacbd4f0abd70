//! `cancosim regress --html DIR` end to end: a regression with every kind
//! of cell (pass, waived, diverged, failed) on the golden model and on the
//! deviant fixture (`tb/fixtures/cosim_deviant.v`, tx stuck recessive,
//! built as an external core), the page rendered by headless Chromium
//! (`--dump-dom`, and a screenshot) and checked: per-core counts, the
//! divergence in words, its SVG waveform, the frame, and links to files
//! that exist. Without Chromium the test says so and checks the page's
//! text alone.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The fixture alone in a fixed directory (the build cache is keyed on its path).
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

/// Chromium's DOM of `page` after loading it, and a screenshot's size; None without Chromium.
fn chromium(page: &Path, scratch: &Path) -> Option<(String, u64)> {
    let bin = ["chromium", "chromium-browser"].into_iter().find(|b| Command::new(b).arg("--version").output().is_ok_and(|o| o.status.success()))?;
    let args = |profile: &str| {
        vec![
            "--headless".to_string(),
            "--no-sandbox".into(),
            "--disable-gpu".into(),
            "--disable-background-networking".into(),
            "--disable-component-update".into(),
            "--disable-sync".into(),
            "--no-first-run".into(),
            format!("--user-data-dir={}", scratch.join(profile).display()),
        ]
    };
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let dom = Command::new(bin).args(args("dom")).arg("--dump-dom").arg(&url).output().unwrap();
    assert!(dom.status.success(), "chromium --dump-dom: {}", String::from_utf8_lossy(&dom.stderr));
    let png = scratch.join("page.png");
    let _ = std::fs::remove_file(&png);
    let shot = Command::new(bin).args(args("shot")).arg(format!("--screenshot={}", png.display())).arg("--window-size=1100,1400").arg(&url).output().unwrap();
    assert!(shot.status.success(), "chromium --screenshot: {}", String::from_utf8_lossy(&shot.stderr));
    Some((String::from_utf8(dom.stdout).unwrap(), std::fs::metadata(&png).map(|m| m.len()).unwrap_or(0)))
}

/// The `<tr data-core="NAME">` row's numbers: pass, waived, diverged, failed, error, skipped.
fn per_core(dom: &str, core: &str) -> Vec<u32> {
    let row = &dom[dom.find(&format!("<tr data-core=\"{core}\">")).unwrap_or_else(|| panic!("no row for {core}"))..];
    let row = &row[..row.find("</tr>").unwrap()];
    row.split("<td class=").skip(1).map(|c| c[c.find('>').unwrap() + 1..c.find("</td>").unwrap()].parse().unwrap()).collect()
}

#[test]
fn the_html_report_renders_every_verdict_with_waveform_and_links() {
    let scratch = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("html-report");
    let _ = std::fs::remove_dir_all(&scratch);
    std::fs::create_dir_all(&scratch).unwrap();
    let out_dir = scratch.join("report");
    let here = root().join("crates/cli/tests/html");
    let out = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .args(["regress", "--dut", "model", "--top", "cosim_deviant", "--profile", "tb/fixtures/at-ack.toml", "--html"])
        .arg(&out_dir)
        .arg(here.join("regression.list"))
        .arg("--external")
        .arg(format!("deviant={}", deviant_core().display()))
        .arg("--waivers")
        .arg(here.join("deviant-waivers.toml"))
        .current_dir(root())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "a failing regression: {stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let page = out_dir.join("index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    // Self-contained: nothing fetched.
    assert!(!html.contains("<script") && !html.contains("http://") && !html.contains("https://") && !html.contains("<link"), "{html}");

    let (dom, png) = match chromium(&page, &scratch) {
        Some(x) => x,
        None => {
            eprintln!("SKIPPED the Chromium part: no `chromium` on PATH (Debian: apt-get install chromium); checking the page text only");
            (html.clone(), 0)
        }
    };
    if png > 0 {
        assert!(png > 20_000, "a screenshot of a whole page, not a blank one: {png} bytes");
    }
    // Per core: pass, waived, diverged, failed, error, skipped, expected failure.
    assert_eq!(per_core(&dom, "model"), [2, 0, 0, 1, 0, 0, 0], "{dom}");
    assert_eq!(per_core(&dom, "deviant"), [0, 1, 1, 1, 0, 0, 0], "{dom}");
    assert!(dom.contains("<b>FAIL</b>"), "{dom}");
    // The known deviations waived per core, in words (the model hits none).
    let hit = dom.split("<table class=\"waivers-hit\" data-core=\"deviant\">").nth(1).and_then(|t| t.split("</table>").next()).unwrap_or_else(|| panic!("no waivers-hit table for deviant\n{dom}"));
    assert!(hit.contains("echo-registers") && hit.contains("the echo fixture's registers are plain memory"), "{hit}");
    assert!(!dom.contains("data-core=\"model\"><tr><th>waiver"), "the model hits no waiver\n{dom}");
    // The diverged cell links to its section, which has the divergence,
    // the diagnosis, a waveform with four traces and the marker, and the frame.
    assert!(dom.contains("href=\"#f-tx-deviant-deviant\""), "{dom}");
    let sec = &dom[dom.find("<section id=\"f-tx-deviant-deviant\"").expect("a section for the divergence")..];
    let sec = &sec[..sec.find("</section>").unwrap()];
    assert!(sec.contains("tx-bit at bit 13") && sec.contains("frame 1, BaseId") && sec.contains("model 0, DUT 1"), "{sec}");
    assert!(sec.contains("DutDeviatesFromModel"), "{sec}");
    let svg = &sec[sec.find("<svg").expect("an SVG waveform")..sec.find("</svg>").unwrap()];
    assert_eq!(svg.matches("<polyline").count(), 4, "{svg}");
    for row in ["bus", "DUT tx", "model tx", "DUT rx"] {
        assert!(svg.contains(&format!("data-row=\"{row}\"")), "{row}: {svg}");
    }
    assert!(svg.contains("class=\"marker\"") && svg.contains("BaseId"), "{svg}");
    assert!(sec.contains("<b>Frame:</b>"), "{sec}");
    // Links to files that exist; the candump log reads back.
    for (label, ext) in [("VCD", "vcd"), ("GTKWave view", "gtkw"), ("candump log", "log"), ("run record", "json")] {
        let href = format!("runs/tx-deviant.deviant.{ext}");
        assert!(sec.contains(&format!("<a href=\"{href}\">{label}</a>")), "{label}: {sec}");
        assert!(out_dir.join(&href).exists(), "{href}");
    }
    let log = std::fs::read_to_string(out_dir.join("runs/tx-deviant.deviant.log")).unwrap();
    cosim::candump::parse_log(&log, "tx-deviant.deviant.log").unwrap();
    let record: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("runs/tx-deviant.deviant.json")).unwrap()).unwrap();
    assert_eq!(record["divergence"]["bit"], 13);
    // The failed expectation: its section says so, without a waveform.
    let sec = &dom[dom.find("<section id=\"f-expect-wrong-model\"").expect("a section for the failure")..];
    let sec = &sec[..sec.find("</section>").unwrap()];
    assert!(sec.contains("No divergence from the golden model") && !sec.contains("<svg"), "{sec}");
    // Passing cells have no section.
    assert!(!dom.contains("id=\"f-reg-only-deviant\""), "{dom}");
}
