//! The file-format pages of the reference: each format's JSON schema (from
//! its serde structs, `schemars`; doc comments are the descriptions) turned
//! into one Markdown table per TOML table, with every key's type, default
//! and meaning, and a complete example that the tests load.

use std::fmt::Write as _;

use serde_json::Value;

/// One generated page.
pub struct Page {
    /// Path under the reference directory.
    pub file: &'static str,
    /// Its text.
    pub markdown: String,
}

/// A short scenario for the reference (tested to load).
pub const SCENARIO_EXAMPLE: &str = r#"name = "tx-acked"
purpose = "The DUT sends one frame that a model node acknowledges"
verifies = ["datasheet 6.4.3: CMR.0 TR starts a transmission"]
sequence = ["set bit timing in reset mode", "load and send a frame", "wait for the transmit interrupt"]

[clocks]
host_mhz = 50.0
can_mhz = 24.0
bit_rate = 125000

[[step]]
write = "CR"
value = 0x01          # reset mode
[[step]]
write = "BTR0"
value = 0x45
[[step]]
write = "BTR1"
value = 0x2F
[[step]]
write = "CR"
value = 0x02          # leave reset mode, transmit interrupt enabled
[[step]]
load_tx = { id = 0x123, data = [0xDE, 0xAD] }
[[step]]
write = "CMR"
value = 0x01          # transmission request
[[step]]
wait_irq = true
timeout_bits = 2000
[[step]]
read = "SR"
expect = 0x08         # TCS: transmission complete
mask = 0x08

[[node]]
name = "acker"
btr0 = 0x45
btr1 = 0x2F

[expect]
received = { acker = 1 }
"#;

/// The three format pages.
pub fn pages() -> Vec<Page> {
    vec![
        Page {
            file: "scenario-format.md",
            markdown: page(
                "Scenario file format (`tb/*.toml`)",
                "A scenario is one TOML file: what it verifies, the clocks, host and DUT, the host program \
                 (`[[step]]`), golden-model nodes, faults and the expected outcome. Play one with \
                 `cancosim run FILE`; list several in a regression list for `cancosim regress`.",
                scenario::file_schema(),
                SCENARIO_EXAMPLE,
            ),
        },
        Page {
            file: "profile-format.md",
            markdown: page(
                "Core profile format (`tb/profiles/*.toml`, `--profile`)",
                "A profile declares the implementation freedoms the SJA1000 datasheet and CAN 2.0B leave open \
                 for one core (when a host access takes effect, where its bit timing starts, tolerances, port \
                 names), so the reference never guesses them. `--profile NAME` finds `tb/profiles/NAME.toml`; \
                 `--profile FILE` reads a file.\n\n\
                 **Extends and families.** A profile may `extends` another (by name or path) and write only the \
                 keys that differ: nested tables merge key by key, other values replace the parent's. Its \
                 family is its own name and its ancestors' names. Waiver and expected-failure `dut` globs match \
                 the DUT under any member of the family (an external core is named `\"<profile> (<dir>)\"`), so \
                 a fork of the opencores core whose profile extends `opencores-can` gets the opencores waivers, \
                 and the report says `waiver X applied via family member opencores-can`. An `extends` cycle is \
                 an error naming the files.",
                cosim::profile::file_schema(),
                cosim::profile::EXAMPLE_FORK,
            ),
        },
        Page {
            file: "waiver-format.md",
            markdown: page(
                "Waiver file format (`tb/waivers/*.toml`, `--waivers`)",
                "A waiver file lists the known deviations of a DUT from the golden model (`[[waiver]]`), each \
                 accepted only within its bounds, and scenarios that are expected to fail with an exact \
                 signature (`[[expected-failure]]`). A waiver that never matches in a run is reported stale.\n\n\
                 **DUT globs and profile families.** `dut` globs match the DUT's name (`\"<profile> (<dir>)\"` \
                 for an external core) and, when its profile `extends` others, its name under each ancestor; \
                 the report then says through which family member the waiver applied.",
                waivers::file_schema(),
                waivers::EXAMPLE,
            ),
        },
    ]
}

/// One object of the schema to document: where it appears, and its schema.
struct Section {
    /// Dotted paths (`access.wishbone`), each marked when an array of tables.
    paths: Vec<(String, bool)>,
    def: Option<String>,
    schema: Value,
}

fn page(title: &str, intro: &str, schema: schemars::Schema, example: &str) -> String {
    let root = schema.as_value().clone();
    let defs = root.get("$defs").cloned().unwrap_or(Value::Null);
    let mut sections = vec![Section { paths: vec![(String::new(), false)], def: None, schema: root.clone() }];
    // Breadth first: each object definition once, under every path it appears at.
    let mut i = 0;
    while i < sections.len() {
        let (parent, schema) = (sections[i].paths[0].0.clone(), sections[i].schema.clone());
        for (key, prop) in properties(&schema) {
            let array = is_array(&prop, &defs);
            let Some((name, def)) = object_def(&prop, &defs) else { continue };
            let path = if parent.is_empty() { key.clone() } else { format!("{parent}.{key}") };
            let path = (path, array);
            match sections.iter_mut().find(|s| s.def.as_deref() == Some(name.as_str())) {
                Some(s) => s.paths.push(path),
                None => sections.push(Section { paths: vec![path], def: Some(name), schema: def }),
            }
        }
        i += 1;
    }
    let mut s = format!("# {title}\n\nGenerated from the code by `cancosim gen reference`; do not edit.\n\n{intro}\n\n");
    if let Some(d) = root.get("description").and_then(Value::as_str) {
        let _ = writeln!(s, "{}\n", one_line(d));
    }
    let _ = writeln!(s, "## Example\n\n```toml\n{}\n```\n", example.trim_end());
    for sec in &sections {
        let heading = if sec.def.is_none() {
            "Top level".to_string()
        } else {
            sec.paths.iter().map(|p| format!("`{}`", header(p))).collect::<Vec<_>>().join(", ")
        };
        let _ = writeln!(s, "## {heading}\n");
        if sec.def.is_some() {
            if let Some(d) = sec.schema.get("description").and_then(Value::as_str) {
                let _ = writeln!(s, "{}\n", one_line(d));
            }
        }
        let required: Vec<&str> = sec.schema.get("required").and_then(Value::as_array).map(|r| r.iter().filter_map(Value::as_str).collect()).unwrap_or_default();
        s += "| key | type | default | meaning |\n|---|---|---|---|\n";
        for (key, prop) in properties(&sec.schema) {
            let desc = one_line(prop.get("description").and_then(Value::as_str).unwrap_or(""));
            let (meaning, default) = match desc.rfind("Default: ") {
                Some(at) => (desc[..at].trim().to_string(), desc[at + "Default: ".len()..].trim().trim_end_matches('.').to_string()),
                None => (desc.clone(), String::new()),
            };
            let default = if required.contains(&key.as_str()) {
                "required".to_string()
            } else if default.is_empty() {
                "optional".to_string()
            } else {
                default
            };
            let _ = writeln!(s, "| `{key}` | {} | {} | {} |", cell(&type_of(&prop, &defs, &sections)), cell(&default), cell(&meaning));
        }
        s.push('\n');
    }
    s
}

/// The keys of an object schema, in schema order.
fn properties(schema: &Value) -> Vec<(String, Value)> {
    schema.get("properties").and_then(Value::as_object).map(|m| m.iter().map(|(k, v)| (k.clone(), v.clone())).collect()).unwrap_or_default()
}

fn deref<'a>(v: &'a Value, defs: &'a Value) -> Option<(String, &'a Value)> {
    let r = v.get("$ref")?.as_str()?.rsplit('/').next()?.to_string();
    let d = defs.get(&r)?;
    Some((r, d))
}

/// The schema without its `null` alternative (an `Option`).
fn non_null(v: &Value) -> Value {
    if let Some(any) = v.get("anyOf").and_then(Value::as_array) {
        let rest: Vec<&Value> = any.iter().filter(|x| x.get("type").and_then(Value::as_str) != Some("null")).collect();
        if rest.len() == 1 {
            return rest[0].clone();
        }
    }
    v.clone()
}

fn is_array(v: &Value, _defs: &Value) -> bool {
    let v = non_null(v);
    match v.get("type") {
        Some(Value::String(t)) => t == "array",
        Some(Value::Array(ts)) => ts.iter().any(|t| t == "array"),
        _ => false,
    }
}

/// The object definition a key holds (directly, optionally, or as array items).
fn object_def(v: &Value, defs: &Value) -> Option<(String, Value)> {
    let v = non_null(v);
    let target = if is_array(&v, defs) { v.get("items")?.clone() } else { v };
    let (name, d) = deref(&target, defs)?;
    d.get("properties").is_some().then(|| (name, d.clone()))
}

fn type_of(v: &Value, defs: &Value, sections: &[Section]) -> String {
    let v = non_null(v);
    if let Some((name, d)) = deref(&v, defs) {
        if d.get("properties").is_some() {
            let at = sections.iter().find(|s| s.def.as_deref() == Some(name.as_str())).map(|s| header(&s.paths[0])).unwrap_or(name);
            return format!("table (see `{at}`)");
        }
        return type_of(d, defs, sections);
    }
    if let Some(e) = v.get("enum").and_then(Value::as_array) {
        return e.iter().map(|x| format!("`{x}`")).collect::<Vec<_>>().join(" or ");
    }
    if let Some(alts) = v.get("anyOf").or(v.get("oneOf")).and_then(Value::as_array) {
        return alts.iter().map(|a| type_of(a, defs, sections)).collect::<Vec<_>>().join(" or ");
    }
    let types: Vec<String> = match v.get("type") {
        Some(Value::String(t)) => vec![t.clone()],
        Some(Value::Array(ts)) => ts.iter().filter_map(Value::as_str).filter(|t| *t != "null").map(str::to_string).collect(),
        _ => Vec::new(),
    };
    let Some(t) = types.first() else { return "any".into() };
    match t.as_str() {
        "array" => format!("array of {}", v.get("items").map(|i| type_of(i, defs, sections)).unwrap_or_else(|| "any".into())),
        "object" => match v.get("properties") {
            Some(_) => "inline table".into(),
            None => format!(
                "table of name = {}",
                v.get("additionalProperties").map(|i| type_of(i, defs, sections)).unwrap_or_else(|| "any".into())
            ),
        },
        "integer" => {
            let min = v.get("minimum").and_then(Value::as_i64);
            match (v.get("format").and_then(Value::as_str), min) {
                (Some(f), _) if f.starts_with('u') => "unsigned integer".into(),
                _ => "integer".into(),
            }
        }
        "number" => "number".into(),
        other => other.into(),
    }
}

/// `[path]`, or `[[path]]` for an array of tables.
fn header((path, array): &(String, bool)) -> String {
    if *array { format!("[[{path}]]") } else { format!("[{path}]") }
}

fn one_line(t: &str) -> String {
    t.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn cell(t: &str) -> String {
    t.replace('|', "\\|")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scenario_example_loads() {
        let s = scenario::Scenario::parse(SCENARIO_EXAMPLE, "example.toml").unwrap();
        assert_eq!(s.name, "tx-acked");
    }

    /// Every key of every format has a meaning, and a key that is neither
    /// required nor an alternative states its default.
    #[test]
    fn every_key_is_described() {
        for p in pages() {
            for line in p.markdown.lines().filter(|l| l.starts_with("| `")) {
                let cells: Vec<&str> = line.split(" | ").collect();
                assert!(cells.len() == 4 && !cells[3].trim_end_matches(" |").trim().is_empty(), "{}: no meaning: {line}", p.file);
            }
        }
        let profile = &pages()[1].markdown;
        assert!(profile.contains("| `extends` | string | none"), "{profile}");
        // One section documents the access keys every host bus shares.
        let access = profile.lines().find(|l| l.starts_with("## `[access.")).expect("an [access.<bus>] section");
        for bus in ["apb", "avalon", "axi4-lite", "i8051", "pio", "wishbone"] {
            assert!(access.contains(&format!("`[access.{bus}]`")), "{bus} missing: {access}");
        }
        let waiver = &pages()[2].markdown;
        assert!(waiver.contains("## `[[waiver]]`") && waiver.contains("applied via family member"), "{waiver}");
    }
}
