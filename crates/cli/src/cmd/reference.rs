//! `gen reference`: the reference pages generated from the code, so they
//! cannot drift from it: the command line (man pages by `clap_mangen`,
//! shell completions by `clap_complete`, a Markdown page from clap's own
//! description of every subcommand and flag) and the scenario, profile and
//! waiver file formats (from the serde structs' JSON schemas, their doc
//! comments being the descriptions). `--check` compares instead of writing.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::CommandFactory;
use clap_complete::Shell;

/// The command that rewrites the committed reference (named by the drift test).
pub const REGENERATE: &str = "cargo run --release -p cancosim -- gen reference --out docs/reference";

/// Arguments of `cancosim gen reference`.
#[derive(clap::Args)]
pub struct Args {
    /// Directory to write into (created if missing); files it holds that the code no longer generates are removed.
    #[arg(long, short, default_value = "docs/reference")]
    out: PathBuf,
    /// Write nothing: exit 1 and list the files that differ from what the code generates.
    #[arg(long)]
    check: bool,
}

/// Every generated file, by path relative to the reference directory.
pub fn files() -> anyhow::Result<BTreeMap<PathBuf, Vec<u8>>> {
    let mut out = BTreeMap::new();
    let cmd = crate::Cli::command();
    // Man pages: one for cancosim, one per subcommand (cancosim-run.1, ...).
    let mut stack = vec![(cmd.clone().bin_name("cancosim").name("cancosim"), String::from("cancosim"))];
    while let Some((c, name)) = stack.pop() {
        let c = c.name(name.clone());
        let mut buf = Vec::new();
        clap_mangen::Man::new(c.clone()).render(&mut buf).context("rendering a man page")?;
        out.insert(PathBuf::from(format!("man/{name}.1")), buf);
        for s in c.get_subcommands().filter(|s| !s.is_hide_set()) {
            stack.push((s.clone(), format!("{name}-{}", s.get_name())));
        }
    }
    for (shell, file) in [(Shell::Bash, "cancosim.bash"), (Shell::Zsh, "_cancosim"), (Shell::Fish, "cancosim.fish")] {
        let mut buf = Vec::new();
        clap_complete::generate(shell, &mut cmd.clone(), "cancosim", &mut buf);
        out.insert(PathBuf::from(format!("completions/{file}")), buf);
    }
    out.insert(PathBuf::from("cli.md"), cli_markdown(cmd).into_bytes());
    for page in crate::cmd::formats::pages() {
        out.insert(PathBuf::from(page.file), page.markdown.into_bytes());
    }
    Ok(out)
}

/// Runs the subcommand; returns the exit code (1: `--check` found differences).
pub fn run(a: Args) -> anyhow::Result<i32> {
    let want = files()?;
    let have = read_tree(&a.out)?;
    let differ: Vec<String> = want
        .keys()
        .chain(have.keys())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .filter_map(|p| match (want.get(p), have.get(p)) {
            (Some(w), Some(h)) if w == h => None,
            (Some(_), Some(_)) => Some(format!("{} differs", p.display())),
            (Some(_), None) => Some(format!("{} is missing", p.display())),
            (None, _) => Some(format!("{} is no longer generated", p.display())),
        })
        .collect();
    if a.check {
        if differ.is_empty() {
            println!("{}: the reference matches the code ({} files)", a.out.display(), want.len());
            return Ok(0);
        }
        for d in &differ {
            println!("{}/{d}", a.out.display());
        }
        println!("the reference is out of date; regenerate it with: {REGENERATE}");
        return Ok(1);
    }
    for p in have.keys().filter(|p| !want.contains_key(*p)) {
        std::fs::remove_file(a.out.join(p)).with_context(|| format!("removing {}", a.out.join(p).display()))?;
    }
    for (p, bytes) in &want {
        let f = a.out.join(p);
        if have.get(p) == Some(bytes) {
            continue;
        }
        std::fs::create_dir_all(f.parent().expect("a file under the directory")).with_context(|| format!("creating {}", f.display()))?;
        std::fs::write(&f, bytes).with_context(|| format!("writing {}", f.display()))?;
        println!("wrote {}", f.display());
    }
    println!("{}: {} files, {} changed", a.out.display(), want.len(), differ.len());
    Ok(0)
}

/// The files under `dir` (none if it does not exist), by relative path.
fn read_tree(dir: &Path) -> anyhow::Result<BTreeMap<PathBuf, Vec<u8>>> {
    let mut out = BTreeMap::new();
    if !dir.exists() {
        return Ok(out);
    }
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).with_context(|| format!("reading {}", d.display()))? {
            let p = e?.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).expect("under dir").to_path_buf();
                out.insert(rel, std::fs::read(&p).with_context(|| format!("reading {}", p.display()))?);
            }
        }
    }
    Ok(out)
}

/// The whole command line as Markdown: each subcommand, its usage, its
/// arguments with their value names, defaults and possible values.
fn cli_markdown(mut cmd: clap::Command) -> String {
    cmd.build();
    let mut s = String::from("# `cancosim` command line\n\n");
    s += "Generated from the code by `cancosim gen reference`; do not edit. Man pages: `man/`, shell completions: `completions/`.\n\n";
    let _ = writeln!(s, "{}\n", cmd.get_about().map(|a| a.to_string()).unwrap_or_default());
    s += "| command | what it does |\n|---|---|\n";
    let mut all = Vec::new();
    collect(&cmd, "cancosim", &mut all);
    for (path, c) in all.iter().skip(1) {
        let _ = writeln!(s, "| [`{path}`](#{}) | {} |", anchor(path), cell(&c.get_about().map(|a| a.to_string()).unwrap_or_default()));
    }
    s.push('\n');
    for (path, c) in &all {
        section(&mut s, path, c);
    }
    s
}

fn collect<'a>(c: &'a clap::Command, path: &str, out: &mut Vec<(String, &'a clap::Command)>) {
    out.push((path.to_string(), c));
    for sub in c.get_subcommands().filter(|s| !s.is_hide_set() && s.get_name() != "help") {
        collect(sub, &format!("{path} {}", sub.get_name()), out);
    }
}

fn section(s: &mut String, path: &str, c: &clap::Command) {
    let _ = writeln!(s, "## {path}\n");
    if let Some(a) = c.get_long_about().or(c.get_about()) {
        let _ = writeln!(s, "{a}\n");
    }
    let usage = c.clone().bin_name(path).render_usage().to_string();
    let _ = writeln!(s, "```text\n{}\n```\n", usage.trim_start_matches("Usage: "));
    let args: Vec<&clap::Arg> = c.get_arguments().filter(|a| !a.is_hide_set()).collect();
    if !args.is_empty() {
        s.push_str("| argument | value | default | meaning |\n|---|---|---|---|\n");
        for a in args {
            let name = match (a.get_long(), a.get_short()) {
                (Some(l), Some(sh)) => format!("`--{l}`, `-{sh}`"),
                (Some(l), None) => format!("`--{l}`"),
                (None, Some(sh)) => format!("`-{sh}`"),
                (None, None) => format!("`{}`", a.get_value_names().and_then(|v| v.first()).map(|v| v.to_string()).unwrap_or_else(|| a.get_id().to_string().to_uppercase())),
            };
            let takes = a.get_num_args().is_some_and(|n| n.takes_values());
            let mut value = if takes {
                a.get_value_names().map(|v| v.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(" ")).unwrap_or_else(|| a.get_id().to_string().to_uppercase())
            } else {
                String::new()
            };
            let pv: Vec<String> = a.get_possible_values().iter().filter(|p| !p.is_hide_set()).map(|p| p.get_name().to_string()).collect();
            if takes && !pv.is_empty() {
                value = pv.join(", ");
            }
            if matches!(a.get_action(), clap::ArgAction::Append) {
                value += " (repeatable)";
            }
            let default: Vec<String> = a.get_default_values().iter().map(|d| d.to_string_lossy().into_owned()).collect();
            let default = if default.is_empty() || !takes { String::new() } else { format!("`{}`", default.join(" ")) };
            let required = if a.is_required_set() { " Required." } else { "" };
            let help = a.get_long_help().or(a.get_help()).map(|h| h.to_string()).unwrap_or_default();
            let _ = writeln!(s, "| {name} | {} | {default} | {}{required} |", cell(&value), cell(&help));
        }
        s.push('\n');
    }
    if let Some(h) = c.get_after_long_help().or(c.get_after_help()) {
        let _ = writeln!(s, "```text\n{}\n```\n", h.to_string().trim_end());
    }
}

/// Text fit for one Markdown table cell.
fn cell(t: &str) -> String {
    t.trim().replace('|', "\\|").replace('[', "\\[").replace(']', "\\]").replace("\n\n", "<br>").replace('\n', " ")
}

/// GitHub's anchor of a heading.
fn anchor(h: &str) -> String {
    h.to_lowercase().chars().filter_map(|c| if c == ' ' { Some('-') } else if c.is_alphanumeric() || c == '-' || c == '_' { Some(c) } else { None }).collect()
}
