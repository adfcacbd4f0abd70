//! One mutation as `yosys mutate -list` writes it, and what it means in words.

use serde::{Deserialize, Serialize};

/// A mutation of the flattened design: the yosys options that apply it and
/// the parts a report needs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Mutation {
    /// Its select value, from 1 (0 runs the original design).
    pub id: u32,
    /// The options after `mutate` (as listed, without `-ctrl`).
    pub args: String,
    /// inv, const0, const1, cnot0, cnot1.
    pub mode: String,
    /// Cell mutated.
    pub cell: String,
    /// Port of that cell.
    pub port: String,
    /// Bit of that port.
    pub portbit: u32,
    /// Control bit (cnot modes).
    pub ctrlbit: Option<u32>,
    /// Wire the port drives or reads, when yosys names one.
    pub wire: Option<String>,
    /// Source locations yosys attached, outermost first (`file:line.col-line.col`).
    pub src: Vec<String>,
}

/// Splits a yosys option line into words; cell names hold no spaces, so
/// whitespace splitting is exact.
fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

impl Mutation {
    /// Parses one line of `mutate -list` output (`mutate -mode ... -src ...`).
    pub fn parse(id: u32, line: &str) -> Result<Mutation, String> {
        let w = words(line);
        if w.first() != Some(&"mutate") {
            return Err(format!("not a mutate command: `{line}`"));
        }
        let mut m = Mutation {
            id,
            args: w[1..].join(" "),
            mode: String::new(),
            cell: String::new(),
            port: String::new(),
            portbit: 0,
            ctrlbit: None,
            wire: None,
            src: Vec::new(),
        };
        let mut i = 1;
        while i < w.len() {
            let (k, v) = (w[i], w.get(i + 1).copied().ok_or_else(|| format!("option {} without a value in `{line}`", w[i]))?);
            let num = |v: &str| v.parse::<u32>().map_err(|_| format!("{k} {v}: not a number in `{line}`"));
            match k {
                "-mode" => m.mode = v.into(),
                "-module" => {}
                "-cell" => m.cell = v.into(),
                "-port" => m.port = v.into(),
                "-portbit" => m.portbit = num(v)?,
                "-ctrlbit" => m.ctrlbit = Some(num(v)?),
                "-wire" => m.wire = Some(v.into()),
                "-wirebit" => {}
                "-src" => m.src.push(v.into()),
                other => return Err(format!("unknown option {other} in `{line}`")),
            }
            i += 2;
        }
        if m.mode.is_empty() || m.cell.is_empty() {
            return Err(format!("no -mode or -cell in `{line}`"));
        }
        Ok(m)
    }

    /// The innermost source location as `file:line` with the file's
    /// directory dropped (yosys lists the instance first, the expression last).
    pub fn location(&self) -> String {
        let real: Vec<&String> = self.src.iter().filter(|s| !s.ends_with(":0.0-0.0")).collect();
        let Some(s) = real.last() else { return "?".into() };
        let (file, pos) = s.rsplit_once(':').unwrap_or((s.as_str(), ""));
        let file = std::path::Path::new(file).file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_else(|| file.to_string());
        let line = pos.split('.').next().unwrap_or("");
        format!("{file}:{line}")
    }

    /// The kind of cell in words, from its yosys name.
    fn cell_kind(&self) -> String {
        // `$flatten\u_acf.$ternary$/path/can_acf.v:57$924`: the part after
        // the last instance dot; named cells (memories) keep their name.
        // (the source path in the name has dots of its own).
        let kind = if self.cell.starts_with("$flatten") {
            self.cell.split_once(".$").map(|(_, t)| t)
        } else {
            self.cell.strip_prefix('$')
        }
        .and_then(|t| t.split('$').next());
        let Some(kind) = kind else { return format!("memory/cell {}", self.cell.trim_start_matches('\\')) };
        let words = match kind {
            "ternary" => "?: select",
            "procmux" => "if/case multiplexer",
            "procdff" => "register",
            "pmux" => "case multiplexer",
            "mux" => "multiplexer",
            "logic_and" => "&&",
            "logic_or" => "||",
            "logic_not" => "!",
            "and" => "&",
            "or" => "|",
            "xor" => "^",
            "not" => "~",
            "eq" => "==",
            "ne" => "!=",
            "lt" => "<",
            "le" => "<=",
            "gt" => ">",
            "ge" => ">=",
            "add" => "+",
            "sub" => "-",
            "reduce_or" => "reduction |",
            "reduce_and" => "reduction &",
            "reduce_bool" => "reduction to bool",
            "shl" | "sshl" => "<<",
            "shr" | "sshr" => ">>",
            "eqx" => "===",
            other => other,
        };
        words.to_string()
    }

    /// The mutation in words, e.g. "output bit 0 of ?: select (u_acf.accept) stuck at 0".
    pub fn describe(&self) -> String {
        let port = match self.port.as_str() {
            "Y" => "output".to_string(),
            "Q" => "output".to_string(),
            "A" => "input A".to_string(),
            "B" => "input B".to_string(),
            "S" => "select".to_string(),
            "D" => "input D".to_string(),
            "WR_EN" => "write enable".to_string(),
            "WR_DATA" => "write data".to_string(),
            "WR_ADDR" => "write address".to_string(),
            "RD_ADDR" => "read address".to_string(),
            "RD_DATA" => "read data".to_string(),
            p => format!("port {p}"),
        };
        let wire = self.wire.as_ref().map(|w| format!(" ({})", w.trim_start_matches('\\'))).unwrap_or_default();
        let what = format!("{port} bit {} of {}{wire}", self.portbit, self.cell_kind());
        // A register's output is also its own hold input after `proc`, so an
        // inverted Q is not "stored inverted": the bit flips on every clock
        // the register keeps its value (mutants 14 and 17).
        let held = if self.port == "Q" && self.cell_kind() == "register" {
            ", its own hold path included (the bit toggles on each clock it is not written)"
        } else {
            ""
        };
        match (self.mode.as_str(), self.ctrlbit) {
            ("inv", _) => format!("{what} inverted{held}"),
            ("const0", _) => format!("{what} stuck at 0"),
            ("const1", _) => format!("{what} stuck at 1"),
            ("cnot0", Some(c)) => format!("{what} inverted while bit {c} of the same port is 0"),
            ("cnot1", Some(c)) => format!("{what} inverted while bit {c} of the same port is 1"),
            (m, _) => format!("{what}: {m}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_listed_mutation_reads_back_with_its_innermost_source_line() {
        let l = r"mutate -mode const0 -module can_top -cell $flatten\u_acf.$ternary$/w/rtl/can_acf.v:57$924 -port Y -portbit 0 -wire u_acf.accept -wirebit 0 -src /w/rtl/can_acf.v:19.24-19.30 -src /w/rtl/can_top.v:140.13-143.6 -src /w/rtl/can_acf.v:57.21-57.46";
        let m = Mutation::parse(3, l).unwrap();
        assert_eq!(m.mode, "const0");
        assert_eq!(m.location(), "can_acf.v:57");
        assert_eq!(m.describe(), "output bit 0 of ?: select (u_acf.accept) stuck at 0");
        let c = Mutation::parse(1, r"mutate -mode cnot1 -module t -cell $flatten\u.$procmux$1 -port A -portbit 1 -ctrlbit 2 -src a.v:5.1-5.2 -src b.v:0.0-0.0").unwrap();
        assert_eq!(c.location(), "a.v:5", "a 0.0-0.0 location is no location");
        assert!(c.describe().contains("inverted while bit 2 of the same port is 1"), "{}", c.describe());
        let r = Mutation::parse(2, r"mutate -mode inv -module can_top -cell $flatten\u_bsp.$procdff$7026 -port Q -portbit 0 -wire u_bsp.rcnt -wirebit 0 -src /w/rtl/can_bsp.v:254.5-473.8").unwrap();
        assert_eq!(
            r.describe(),
            "output bit 0 of register (u_bsp.rcnt) inverted, its own hold path included (the bit toggles on each clock it is not written)"
        );
        assert!(Mutation::parse(1, "mutate -mode").is_err());
        assert!(Mutation::parse(1, "hello").is_err());
    }
}
