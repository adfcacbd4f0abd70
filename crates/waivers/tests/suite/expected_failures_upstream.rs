//! The shipped upstream file's `[[expected-failure]]` entries stay tied to
//! what they judge: each names an existing scenario (a renamed scenario
//! would leave its entry matching nothing, and the run would fail without
//! saying why), its id appears in docs/opencores-deviations.md, and every
//! deviation row it names (`D29`, `D21/D8a`, ...) is a row of that doc.

use std::collections::BTreeSet;
use std::path::Path;
use waivers::WaiverSet;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// The name of every scenario file under `tb/` (its `name`, else its file
/// stem; fixtures included, profiles and waiver files not).
fn scenario_names(dir: &Path, out: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            // profiles and waiver files are not scenarios (a profile has a `name` too)
            if !path.ends_with("profiles") && !path.ends_with("waivers") {
                scenario_names(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).unwrap();
            if let Ok(value) = text.parse::<toml::Table>() {
                // a scenario without `name` is named by its file stem
                match value.get("name").and_then(|n| n.as_str()) {
                    Some(name) => out.insert(name.to_string()),
                    None => out.insert(path.file_stem().unwrap().to_string_lossy().to_string()),
                };
            }
        }
    }
}

/// The deviation rows a doc table defines: cells like `| D29 |` or `| D10d (BasicCAN) |`.
fn doc_rows(doc: &str) -> BTreeSet<String> {
    doc.lines()
        .filter_map(|l| l.strip_prefix("| D"))
        .filter_map(|rest| {
            let row: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric()).collect();
            (!row.is_empty()).then(|| format!("D{row}"))
        })
        .collect()
}

fn problems(set: &WaiverSet, doc: &str, scenarios: &BTreeSet<String>) -> Vec<String> {
    let rows = doc_rows(doc);
    let mut out = Vec::new();
    for e in set.expected_failures() {
        if !scenarios.contains(&e.scenario) {
            out.push(format!("{}: no scenario named `{}` under tb/", e.id, e.scenario));
        }
        if !doc.contains(&format!("`{}`", e.id)) {
            out.push(format!("{}: id not named in docs/opencores-deviations.md", e.id));
        }
        for d in e.deviation.split('/').map(str::trim) {
            if !rows.contains(d) {
                out.push(format!("{}: deviation `{d}` is not a row of docs/opencores-deviations.md", e.id));
            }
        }
    }
    out
}

#[test]
fn every_shipped_expected_failure_names_a_scenario_its_doc_id_and_documented_rows() {
    let set = WaiverSet::load(root().join("tb/waivers/opencores-upstream.toml")).unwrap();
    let doc = std::fs::read_to_string(root().join("docs/opencores-deviations.md")).unwrap();
    let mut scenarios = BTreeSet::new();
    scenario_names(&root().join("tb"), &mut scenarios);
    assert!(set.expected_failures().len() >= 20, "the shipped entries were loaded");
    assert!(scenarios.len() >= 190, "the scenarios under tb/ were found: {}", scenarios.len());
    for row in ["D1", "D8a", "D10b", "D10f", "D21", "D29"] {
        assert!(doc_rows(&doc).contains(row), "{row} is read as a row of the doc");
    }
    let found = problems(&set, &doc, &scenarios);
    assert!(found.is_empty(), "{}", found.join("\n"));
}

#[test]
fn a_renamed_scenario_an_undocumented_id_or_an_unknown_row_is_reported() {
    let set = WaiverSet::load(root().join("tb/waivers/opencores-upstream.toml")).unwrap();
    let doc = std::fs::read_to_string(root().join("docs/opencores-deviations.md")).unwrap();
    let mut scenarios = BTreeSet::new();
    scenario_names(&root().join("tb"), &mut scenarios);
    let id = "coverage-peli-captures-no-bus-integration-and-ali-cleared-by-reset-mode";
    let scenario = "PeliCAN captures read in reset mode: ECC, ALC, ALI, and TXERR above 127";
    // The scenario renamed: its entries (Wishbone/Avalon and pio-edge) name nothing.
    let mut renamed = scenarios.clone();
    assert!(renamed.remove(scenario));
    let found = problems(&set, &doc, &renamed);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(found.iter().all(|p| p.contains("no scenario named")), "{found:?}");
    // The id left out of the doc.
    let undocumented = doc.replace(&format!("`{id}`"), "`(removed)`");
    let found = problems(&set, &undocumented, &scenarios);
    assert_eq!(found, vec![format!("{id}: id not named in docs/opencores-deviations.md")]);
    // The row D29 taken out of the doc's tables: each of its three entries
    // (Wishbone/Avalon, pio-edge, the 8051 bus) reports it.
    let no_row = doc.replace("| D29 |", "| (D29) |");
    let found = problems(&set, &no_row, &scenarios);
    assert_eq!(found.len(), 3, "{found:?}");
    assert!(found.iter().all(|p| p.contains("deviation `D29` is not a row")), "{found:?}");
}
