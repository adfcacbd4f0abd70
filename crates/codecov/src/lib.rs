//! Code coverage of a Verilated DUT over a regression (`regress --coverage`):
//! each run writes Verilator's coverage counters (`.dat`, "SystemC::Coverage-3"
//! format); this crate merges them (`verilator_coverage --write`), writes the
//! lcov `.info` (`verilator_coverage --write-info`) and the HTML report
//! (`genhtml`, Debian's `lcov`), and summarises line, toggle and branch
//! coverage per source file from the merged `.dat` itself: Verilator's
//! `.info` folds every kind of point of a line into one line count, so the
//! three figures come from the points' own `page` (`v_line`, `v_toggle`,
//! `v_branch`).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// What can go wrong.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A tool is not installed.
    #[error("`{tool}` was not found ({package}); run scripts/setup.sh")]
    MissingTool {
        /// The program.
        tool: &'static str,
        /// Where it comes from.
        package: &'static str,
    },
    /// A tool failed.
    #[error("{tool} failed: {message}")]
    Tool {
        /// The program.
        tool: &'static str,
        /// Its output.
        message: String,
    },
    /// A `.dat` line that is not a coverage point.
    #[error("{file}:{line}: not a Verilator coverage point: {text}")]
    Parse {
        /// The file.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// The line, cut.
        text: String,
    },
    /// File-system trouble.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// The error.
        source: std::io::Error,
    },
    /// Nothing to merge.
    #[error("no coverage .dat files to merge (did any run build a Verilated DUT?)")]
    NoData,
}

/// The kind of a coverage point (Verilator's `page` prefix).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Kind {
    /// A statement block (`v_line`).
    Line,
    /// One bit of a signal toggling (`v_toggle`).
    Toggle,
    /// An arm of an `if`/`case` (`v_branch`).
    Branch,
    /// Anything else (user `cover`, ...).
    Other,
}

/// One coverage point.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Point {
    /// Source file.
    pub file: String,
    /// Source line.
    pub line: u32,
    /// Source column (Verilator's `n`).
    pub column: u32,
    /// Kind.
    pub kind: Kind,
    /// Verilator's comment: the signal of a toggle point, `if`/`else`/`case`/`block`...
    pub comment: String,
    /// Instance path.
    pub hier: String,
    /// Hits.
    pub count: u64,
}

/// Reads a `.dat` file.
pub fn read_dat(path: &Path) -> Result<Vec<Point>, Error> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { what: format!("reading {}", path.display()), source })?;
    parse_dat(&text, &path.display().to_string())
}

/// Parses a `.dat` file's text: `C '<\x01key\x02value...>' count` lines.
pub fn parse_dat(text: &str, name: &str) -> Result<Vec<Point>, Error> {
    let mut out = Vec::new();
    for (n, l) in text.lines().enumerate() {
        if l.starts_with('#') || l.trim().is_empty() {
            continue;
        }
        let bad = || Error::Parse { file: name.to_string(), line: n + 1, text: l.chars().take(80).collect() };
        let rest = l.strip_prefix("C '").ok_or_else(bad)?;
        let (keys, count) = rest.rsplit_once("' ").ok_or_else(bad)?;
        let count: u64 = count.trim().parse().map_err(|_| bad())?;
        let mut p = Point { file: String::new(), line: 0, column: 0, kind: Kind::Other, comment: String::new(), hier: String::new(), count };
        for kv in keys.split('\x01').filter(|s| !s.is_empty()) {
            let (k, v) = kv.split_once('\x02').ok_or_else(bad)?;
            match k {
                "f" => p.file = v.to_string(),
                "l" => p.line = v.parse().map_err(|_| bad())?,
                "n" => p.column = v.parse().map_err(|_| bad())?,
                "o" => p.comment = v.to_string(),
                "h" => p.hier = v.to_string(),
                "page" => {
                    p.kind = match v.split('/').next() {
                        Some("v_line") => Kind::Line,
                        Some("v_toggle") => Kind::Toggle,
                        Some("v_branch") => Kind::Branch,
                        _ => Kind::Other,
                    }
                }
                _ => {}
            }
        }
        out.push(p);
    }
    Ok(out)
}

/// Points hit and total.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Points with a count above zero.
    pub hit: u64,
    /// Points.
    pub total: u64,
}

impl Counts {
    /// Percent hit (100 when there are no points).
    pub fn percent(&self) -> f64 {
        if self.total == 0 { 100.0 } else { 100.0 * self.hit as f64 / self.total as f64 }
    }

    fn add(&mut self, hit: bool) {
        self.total += 1;
        self.hit += hit as u64;
    }
}

/// Line, toggle and branch coverage of one source file (or of all).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileCoverage {
    /// Source file ("total" for the sum).
    pub file: String,
    /// `v_line` points.
    pub line: Counts,
    /// `v_toggle` points.
    pub toggle: Counts,
    /// `v_branch` points.
    pub branch: Counts,
}

/// The points of the source, each counted once: a module instantiated
/// twice (or in two tops' runs) has its points hit when any instance hit
/// them (the count is the sum).
pub fn by_source(points: &[Point]) -> Vec<Point> {
    let mut m: BTreeMap<(&str, u32, u32, Kind, &str), Point> = BTreeMap::new();
    for p in points {
        m.entry((&p.file, p.line, p.column, p.kind, &p.comment))
            .and_modify(|q| q.count += p.count)
            .or_insert_with(|| Point { hier: String::new(), ..p.clone() });
    }
    m.into_values().collect()
}

/// Per file (sorted by path), and the total last; points counted per
/// source ([`by_source`]), not per instance.
pub fn summarize(points: &[Point]) -> Vec<FileCoverage> {
    let mut by: BTreeMap<&str, FileCoverage> = BTreeMap::new();
    let mut total = FileCoverage { file: "total".into(), ..Default::default() };
    let points = by_source(points);
    for p in &points {
        let f = by.entry(&p.file).or_insert_with(|| FileCoverage { file: p.file.clone(), ..Default::default() });
        for fc in [f, &mut total] {
            match p.kind {
                Kind::Line => fc.line.add(p.count > 0),
                Kind::Toggle => fc.toggle.add(p.count > 0),
                Kind::Branch => fc.branch.add(p.count > 0),
                Kind::Other => {}
            }
        }
    }
    let mut v: Vec<FileCoverage> = by.into_values().collect();
    v.push(total);
    v
}

/// The summary as a table: file, then line/toggle/branch as `%  (hit/total)`.
pub fn to_table(files: &[FileCoverage]) -> String {
    let w = files.iter().map(|f| f.file.len()).max().unwrap_or(4).max(4);
    let cell = |c: &Counts| format!("{:>5.1}% ({}/{})", c.percent(), c.hit, c.total);
    let mut s = String::new();
    let _ = writeln!(s, "{:<w$}  {:<20} {:<20} {:<20}", "file", "line", "toggle", "branch");
    for f in files {
        let _ = writeln!(s, "{:<w$}  {:<20} {:<20} {:<20}", f.file, cell(&f.line), cell(&f.toggle), cell(&f.branch));
    }
    s
}

fn tool(name: &'static str, package: &'static str) -> Result<Command, Error> {
    match Command::new(name).arg("--version").output() {
        Ok(_) => Ok(Command::new(name)),
        Err(_) => Err(Error::MissingTool { tool: name, package }),
    }
}

fn run(tool_name: &'static str, cmd: &mut Command) -> Result<(), Error> {
    let o = cmd.output().map_err(|source| Error::Io { what: format!("running {tool_name}"), source })?;
    if o.status.success() {
        Ok(())
    } else {
        Err(Error::Tool { tool: tool_name, message: format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)).trim().to_string() })
    }
}

/// What [`report`] wrote and found.
#[derive(Clone, Debug)]
pub struct Report {
    /// The runs' `.dat` files merged.
    pub runs: usize,
    /// The merged counters (`merged.dat`).
    pub merged: PathBuf,
    /// The lcov file (`coverage.info`).
    pub info: PathBuf,
    /// genhtml's page (`html/index.html`).
    pub html: PathBuf,
    /// Per file and total.
    pub files: Vec<FileCoverage>,
    /// Every point of the merged counters.
    pub points: Vec<Point>,
}

/// Merges `dats` into `out` (created): `merged.dat`, `coverage.info`,
/// `html/`, and the summary.
pub fn report(dats: &[PathBuf], out: &Path) -> Result<Report, Error> {
    if dats.is_empty() {
        return Err(Error::NoData);
    }
    std::fs::create_dir_all(out).map_err(|source| Error::Io { what: format!("creating {}", out.display()), source })?;
    let merged = out.join("merged.dat");
    let info = out.join("coverage.info");
    let html = out.join("html");
    run("verilator_coverage", tool("verilator_coverage", "Debian package verilator")?.arg("--write").arg(&merged).args(dats))?;
    run("verilator_coverage", tool("verilator_coverage", "Debian package verilator")?.arg("--write-info").arg(&info).arg(&merged))?;
    run("genhtml", tool("genhtml", "Debian package lcov")?.arg("--quiet").arg("--output-directory").arg(&html).arg(&info))?;
    let points = read_dat(&merged)?;
    Ok(Report { runs: dats.len(), files: summarize(&points), merged, info, html: html.join("index.html"), points })
}
