//! `cancosim regress --html DIR`: one self-contained page (inline CSS and
//! SVG, no script, nothing fetched) with the per-core table and, for every
//! cell that did not pass, its diagnosis, the first divergence with a small
//! waveform of the bits around it (SVG drawn here), the frame decoded, and
//! links to the run's VCD, GTKWave save file, candump log and run record,
//! written next to the page under `runs/`.
//!
//! The failing cells are run again for their files (runs are
//! deterministic): with every bus bit kept, a VCD, and the bus log.

use crate::regress::{Cell, RegressOptions, RegressReport, Status};
use crate::run::{DutSpec, RunOptions, RunOutcome, run};
use crate::Scenario;
use can_proto::decode::{DecodeEvent, Decoder};
use can_proto::FrameTrait;
use diagnose::BusBit;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A cell that did not pass, run again for its files.
pub struct Detail {
    /// Scenario name.
    pub scenario: String,
    /// DUT name.
    pub dut: String,
    /// The second run.
    pub outcome: RunOutcome,
    /// (label, link relative to the page) of each file written.
    pub links: Vec<(String, String)>,
}

/// A file-name-safe form of `s`.
fn slug(s: &str) -> String {
    s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

/// Runs every failed, diverged or error cell of `report` again with its
/// files in `dir/runs/` (VCD, `.gtkw`, candump log, run record). Cells of
/// scenarios or DUTs not in `scenarios`/`duts` (unloadable files) get no
/// detail run.
pub fn rerun_failures(report: &RegressReport, scenarios: &[Scenario], duts: &[DutSpec], opts: &RegressOptions, dir: &Path) -> std::io::Result<Vec<Detail>> {
    let runs = dir.join("runs");
    std::fs::create_dir_all(&runs)?;
    let mut out = Vec::new();
    for c in report.cells.iter().filter(|c| !c.status.ok()) {
        let (Some(s), Some(d)) = (scenarios.iter().find(|s| s.name == c.scenario), duts.iter().find(|d| d.name == c.dut)) else {
            continue;
        };
        let base = format!("{}.{}", slug(&c.scenario), slug(&c.dut));
        let vcd = runs.join(format!("{base}.vcd"));
        // Every bus bit kept, so the waveform can show the bits around the
        // first divergence wherever the run stopped.
        let mut s = s.clone();
        s.keep_bits = 0;
        // `..Default::default()` on purpose: options added later (a
        // profile) keep their defaults here.
        #[allow(clippy::needless_update)]
        let o = RunOptions {
            dut: Some(d.clone()),
            vcd: Some(vcd.clone()),
            max_bits: opts.max_bits,
            waivers: opts.waivers.clone(),
            dut_revision: opts.dut_revision.clone(),
            // A run an expected-failure entry named was judged in collect mode.
            collect: if c.xfail.is_some() { waivers::CollectMode::Collect } else { opts.collect },
            host: opts.host,
            ..Default::default()
        };
        let outcome = run(&s, &o);
        let mut links = Vec::new();
        if vcd.exists() {
            links.push(("VCD".to_string(), format!("runs/{base}.vcd")));
            let gtkw = runs.join(format!("{base}.gtkw"));
            if gtkw.exists() {
                links.push(("GTKWave view".to_string(), format!("runs/{base}.gtkw")));
            }
        }
        std::fs::write(runs.join(format!("{base}.log")), cosim::candump::write_log(&outcome.bus_log, "can0"))?;
        links.push(("candump log".to_string(), format!("runs/{base}.log")));
        let json = serde_json::to_string_pretty(&outcome.record).map_err(std::io::Error::other)?;
        std::fs::write(runs.join(format!("{base}.json")), json)?;
        links.push(("run record".to_string(), format!("runs/{base}.json")));
        out.push(Detail { scenario: c.scenario.clone(), dut: c.dut.clone(), outcome, links });
    }
    Ok(out)
}

/// Escapes text for HTML element content and attribute values.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

/// Class and text of a cell in the table.
fn verdict(c: &Cell) -> (&'static str, String) {
    match &c.status {
        Status::Pass if !c.waived.is_empty() => ("waived", format!("waived ({})", c.waived.len())),
        Status::Pass => ("pass", "pass".into()),
        Status::Diverged(w) => ("diverged", format!("diverged: {w}")),
        Status::Failed(_) => ("failed", format!("failed ({})", c.category)),
        Status::Error(_) => ("error", "error".into()),
        Status::Skipped(_) => ("skipped", "skipped".into()),
        Status::ExpectedFailure { id, deviation } => ("xfail", format!("expected failure ({deviation}: {id})")),
        Status::UnexpectedPass { id } => ("failed", format!("UNEXPECTED PASS ({id})")),
        Status::WrongFailure { id, .. } => ("failed", format!("failed, not as {id}")),
    }
}

fn anchor(scenario: &str, dut: &str) -> String {
    format!("f-{}-{}", slug(scenario), slug(dut))
}

const CSS: &str = "body{font-family:sans-serif;margin:1.5em;color:#222}table{border-collapse:collapse;margin:.5em 0 1.5em}\
td,th{border:1px solid #bbb;padding:3px 8px;text-align:left;font-size:14px}th{background:#eee}\
.pass{background:#d9f2d9}.waived{background:#fff3c4}.diverged{background:#f8c9c9}.failed{background:#f4a6a6}\
.error{background:#e0b0e8}.xfail{background:#dde4f7}.skipped{background:#e6e6e6}pre{background:#f6f6f6;padding:8px;white-space:pre-wrap;font-size:13px}\
section{border-top:2px solid #999;margin-top:1.5em}svg text{font-family:monospace}";

/// The whole page.
pub fn render(report: &RegressReport, details: &[Detail], title: &str) -> String {
    let mut h = String::new();
    let _ = write!(h, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{CSS}</style></head><body>\n", esc(title));
    let _ = writeln!(h, "<h1>{}</h1>", esc(title));
    let not_ok = report.cells.iter().filter(|c| !c.status.ok()).count();
    let _ = writeln!(
        h,
        "<p id=\"verdict\">{} cell(s) run, {} not passed: <b>{}</b></p>",
        report.cells.len(),
        not_ok,
        if report.passed() { "PASS" } else { "FAIL" }
    );
    // Per core: how many of each verdict.
    h.push_str("<h2>Per core</h2>\n<table id=\"per-core\"><tr><th>core</th><th>pass</th><th>waived</th><th>diverged</th><th>failed</th><th>error</th><th>skipped</th><th>expected failure</th></tr>\n");
    for d in &report.duts {
        let cells: Vec<&Cell> = report.cells.iter().filter(|c| &c.dut == d).collect();
        let n = |k: &str| cells.iter().filter(|c| verdict(c).0 == k).count();
        let _ = writeln!(
            h,
            "<tr data-core=\"{0}\"><td>{0}</td><td class=\"pass\">{1}</td><td class=\"waived\">{2}</td><td class=\"diverged\">{3}</td><td class=\"failed\">{4}</td><td class=\"error\">{5}</td><td class=\"skipped\">{6}</td><td class=\"xfail\">{7}</td></tr>",
            esc(d),
            n("pass"),
            n("waived"),
            n("diverged"),
            n("failed"),
            n("error"),
            n("skipped"),
            n("xfail")
        );
    }
    h.push_str("</table>\n");
    // Per core: the known deviations its waivers let through, in words.
    for d in &report.duts {
        let used = report.waivers_hit(d);
        if used.is_empty() {
            continue;
        }
        let _ = writeln!(h, "<h3>Known deviations waived on {}</h3>\n<table class=\"waivers-hit\" data-core=\"{0}\"><tr><th>waiver</th><th>hits</th><th>scenarios</th><th>deviation</th><th>clause</th></tr>", esc(d));
        for u in &used {
            let x = &u.deviation;
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                esc(&x.waiver_id),
                x.hits,
                esc(&u.scenarios.join(", ")),
                esc(&x.summary),
                esc(x.clause.as_deref().unwrap_or(""))
            );
        }
        h.push_str("</table>\n");
    }
    let stale = report.stale_warnings();
    if !stale.is_empty() {
        h.push_str("<ul id=\"stale-waivers\">");
        for (_, w) in &stale {
            let _ = write!(h, "<li>{}</li>", esc(w));
        }
        h.push_str("</ul>\n");
    }
    h.push_str("<h2>Scenarios</h2>\n<table id=\"cells\"><tr><th>scenario</th>");
    for d in &report.duts {
        let _ = write!(h, "<th>{}</th>", esc(d));
    }
    h.push_str("</tr>\n");
    for s in &report.scenarios {
        let _ = write!(h, "<tr><td>{}</td>", esc(s));
        for d in &report.duts {
            match report.cells.iter().find(|c| &c.scenario == s && &c.dut == d) {
                None => h.push_str("<td>-</td>"),
                Some(c) => {
                    let (class, text) = verdict(c);
                    if c.status.ok() {
                        let _ = write!(h, "<td class=\"{class}\">{}</td>", esc(&text));
                    } else {
                        let _ = write!(h, "<td class=\"{class}\"><a href=\"#{}\">{}</a></td>", anchor(s, d), esc(&text));
                    }
                }
            }
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    // Runs an [[expected-failure]] entry named: the entry, its verdict, and
    // for a failure that is not the recorded one, the lines that differ.
    let named: Vec<&Cell> = report.cells.iter().filter(|c| c.xfail.is_some()).collect();
    if !named.is_empty() {
        h.push_str("<h2>Expected failures</h2>\n<table id=\"expected-failures\"><tr><th>scenario</th><th>core</th><th>entry</th><th>deviation</th><th>clause</th><th>verdict</th><th>reason</th></tr>\n");
        for c in &named {
            let r = c.xfail.as_ref().expect("filtered");
            let (class, text) = verdict(c);
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{} ({})</td><td>{}</td><td>{}</td><td class=\"{class}\">{}</td><td>{}</td></tr>",
                esc(&c.scenario),
                esc(&c.dut),
                esc(&r.entry.id),
                esc(&r.entry.location()),
                esc(&r.entry.deviation),
                esc(&r.entry.clause),
                esc(&text),
                esc(&r.entry.reason)
            );
        }
        h.push_str("</table>\n");
    }
    for c in report.cells.iter().filter(|c| !c.status.ok()) {
        let (class, text) = verdict(c);
        let _ = writeln!(h, "<section id=\"{}\" class=\"detail\"><h2>{} on {} <span class=\"{class}\">{}</span></h2>", anchor(&c.scenario, &c.dut), esc(&c.scenario), esc(&c.dut), esc(&text));
        let detail = details.iter().find(|x| x.scenario == c.scenario && x.dut == c.dut);
        if let Some(x) = detail {
            h.push_str("<p class=\"links\">");
            for (i, (label, href)) in x.links.iter().enumerate() {
                let _ = write!(h, "{}<a href=\"{}\">{}</a>", if i > 0 { " · " } else { "" }, esc(href), esc(label));
            }
            h.push_str("</p>\n");
        }
        h.push_str("<h3>Diagnosis</h3>\n");
        let _ = writeln!(h, "<pre class=\"diagnosis\">{}</pre>", esc(&c.report));
        if let Some(x) = detail {
            divergence_html(&mut h, &x.outcome);
        }
        h.push_str("</section>\n");
    }
    h.push_str("</body></html>\n");
    h
}

/// The first divergence: words, waveform, frame.
fn divergence_html(h: &mut String, o: &RunOutcome) {
    let Some(d) = &o.record.divergence else {
        h.push_str("<p>No divergence from the golden model: the outcome differs from the scenario's [expect].</p>\n");
        return;
    };
    let _ = writeln!(h, "<h3>First divergence</h3>\n<p class=\"divergence\">{}</p>", esc(&waivers::describe(d)));
    let bits = &o.record.bus_bits;
    // At a sample point: its bit; between (a register read): the bit before.
    let pos = match d.bit {
        Some(b) => bits.iter().rposition(|x| x.bit <= b),
        None => None,
    };
    let Some(pos) = pos else {
        h.push_str("<p>No bus bits around it (not at a bit of the bus).</p>\n");
        return;
    };
    h.push_str(&waveform_svg(bits, pos));
    h.push_str(&frame_html(bits, pos));
}

/// A waveform row: its name and the level it draws.
type Row = (&'static str, fn(&BusBit) -> bool);

/// An SVG of the bits around `bits[pos]`: bus, DUT tx, model tx, DUT rx,
/// the field of each bit, the divergence marked.
pub fn waveform_svg(bits: &[BusBit], pos: usize) -> String {
    const BEFORE: usize = 12;
    const AFTER: usize = 8;
    const W: usize = 24;
    const ROW: usize = 34;
    const LEFT: usize = 80;
    const TOP: usize = 40;
    let from = pos.saturating_sub(BEFORE);
    let to = (pos + AFTER + 1).min(bits.len());
    let win = &bits[from..to];
    let rows: [Row; 4] =
        [("bus", |b| b.bus), ("DUT tx", |b| b.dut_tx), ("model tx", |b| b.model_tx), ("DUT rx", |b| b.dut_rx)];
    let width = LEFT + win.len() * W + 10;
    let height = TOP + rows.len() * ROW + 10;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg class=\"wave\" width=\"{width}\" height=\"{height}\" viewBox=\"0 0 {width} {height}\" role=\"img\" aria-label=\"bits {} to {} around the divergence\">",
        win.first().map_or(0, |b| b.bit),
        win.last().map_or(0, |b| b.bit)
    );
    // The divergent bit.
    let mx = LEFT + (pos - from) * W;
    let _ = writeln!(s, "<rect class=\"marker\" x=\"{mx}\" y=\"{}\" width=\"{W}\" height=\"{}\" fill=\"#f55\" fill-opacity=\"0.25\" stroke=\"#d00\"/>", TOP - 14, rows.len() * ROW + 14);
    // Bit numbers every 4 bits, field names where a field starts.
    let mut last_field = None;
    for (i, b) in win.iter().enumerate() {
        let x = LEFT + i * W;
        if b.bit % 4 == 0 {
            let _ = writeln!(s, "<text x=\"{}\" y=\"12\" font-size=\"10\" fill=\"#555\">{}</text>", x + 2, b.bit);
        }
        if b.field != last_field {
            last_field = b.field;
            let name = b.field.map(|f| format!("{f:?}")).unwrap_or_default();
            let _ = writeln!(s, "<line x1=\"{x}\" y1=\"16\" x2=\"{x}\" y2=\"{}\" stroke=\"#ccc\"/><text x=\"{}\" y=\"{}\" font-size=\"10\" fill=\"#225\">{}</text>", height - 6, x + 2, TOP - 16, esc(&name));
        }
    }
    for (r, (name, level)) in rows.iter().enumerate() {
        let y_hi = TOP + r * ROW + 4;
        let y_lo = y_hi + ROW - 12;
        let _ = writeln!(s, "<text x=\"4\" y=\"{}\" font-size=\"12\">{name}</text>", y_lo - 4);
        let mut pts = Vec::new();
        for (i, b) in win.iter().enumerate() {
            let y = if level(b) { y_hi } else { y_lo };
            pts.push(format!("{},{y}", LEFT + i * W));
            pts.push(format!("{},{y}", LEFT + (i + 1) * W));
        }
        let _ = writeln!(s, "<polyline class=\"trace\" data-row=\"{name}\" fill=\"none\" stroke=\"#036\" stroke-width=\"2\" points=\"{}\"/>", pts.join(" "));
    }
    s.push_str("</svg>\n");
    s
}

/// The frame the divergence is in, decoded from the bus bits (all of them
/// from the start of the run, as the detail run keeps them).
fn frame_html(bits: &[BusBit], pos: usize) -> String {
    let mut dec = Decoder::new();
    let mut sof = None;
    let mut found = None;
    for (i, b) in bits.iter().enumerate() {
        for e in dec.push(b.bus) {
            match e {
                DecodeEvent::FieldStart { field: can_proto::Field::Sof, bit } if i <= pos => sof = Some(bit),
                DecodeEvent::Frame(f) if Some(f.start_bit) == sof && i >= pos => {
                    found = Some(Ok(f));
                }
                DecodeEvent::Error { error, field, bit } if sof.is_some() && i >= pos && found.is_none() => {
                    found = Some(Err(format!("not completed: {error} in {field} at bus bit {bit}")));
                }
                _ => {}
            }
        }
        if found.is_some() {
            break;
        }
    }
    let text = match found {
        Some(Ok(f)) => {
            let fr = f.frame;
            let data: Vec<String> = fr.data().iter().map(|b| format!("{b:02X}")).collect();
            format!(
                "ID 0x{:X}{}{} DLC {} data [{}]{} (candump: {})",
                fr.raw_id(),
                if fr.is_extended() { " (extended)" } else { "" },
                if fr.is_remote_frame() { " remote" } else { "" },
                fr.dlc_raw(),
                data.join(" "),
                if f.ack { ", acknowledged" } else { ", not acknowledged" },
                cosim::candump::frame_text(&cosim::candump::LogKind::Frame(fr))
            )
        }
        Some(Err(e)) => format!("frame {e}"),
        None if sof.is_some() => "frame not completed before the run stopped".into(),
        None => "no frame on the bus before the divergence".into(),
    };
    format!("<p class=\"frame\"><b>Frame:</b> {}</p>\n", esc(&text))
}

/// Writes `dir/index.html` (and the detail files); returns the page's path.
pub fn write_report(dir: &Path, report: &RegressReport, scenarios: &[Scenario], duts: &[DutSpec], opts: &RegressOptions) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    let details = rerun_failures(report, scenarios, duts, opts, dir)?;
    let page = dir.join("index.html");
    std::fs::write(&page, render(report, &details, "cancosim regression"))?;
    Ok(page)
}
