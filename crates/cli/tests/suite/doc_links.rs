//! Every relative link in the tree's Markdown resolves: file paths, `#anchors`
//! (GitHub's heading slugs) and images. External `http(s):`/`mailto:` links are
//! not fetched. The checker itself is tested on a temporary tree first, so a
//! broken link or anchor is known to fail it.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Component, Path, PathBuf};

use pulldown_cmark::{BrokenLink, Event, LinkType, Options, Parser, Tag, TagEnd};

/// One link that does not resolve: the file it is in, its destination, why.
#[derive(Debug, PartialEq, Eq)]
struct Broken {
    file: PathBuf,
    dest: String,
    why: String,
}

/// What one Markdown file offers and asks for.
struct Page {
    anchors: BTreeSet<String>,
    links: Vec<String>,
    broken_refs: Vec<String>,
}

/// GitHub's heading slug: lowercase; letters, digits, `_`, `-` and spaces kept,
/// every other character dropped; each space becomes `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '_' || *c == '-' || *c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// `id="x"` and `name="x"` attributes of inline or block HTML (explicit anchors).
fn html_ids(html: &str, out: &mut BTreeSet<String>) {
    for attr in ["id=\"", "name=\""] {
        let mut rest = html;
        while let Some(at) = rest.find(attr) {
            let after = &rest[at + attr.len()..];
            if let Some(end) = after.find('"') {
                out.insert(after[..end].to_string());
            }
            rest = after;
        }
    }
}

fn parse(text: &str) -> Page {
    let mut broken_refs = Vec::new();
    let mut callback = |link: BrokenLink<'_>| {
        // `[text][label]` and `[text][]` with no definition are mistakes; a bare
        // `[word]` is ordinary text in prose.
        if matches!(
            link.link_type,
            LinkType::Reference | LinkType::Collapsed | LinkType::ReferenceUnknown | LinkType::CollapsedUnknown
        ) {
            broken_refs.push(link.reference.to_string());
        }
        None
    };
    let parser = Parser::new_with_broken_link_callback(text, Options::all(), Some(&mut callback));
    let mut anchors = BTreeSet::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut links = Vec::new();
    let mut heading: Option<String> = None;
    for event in parser {
        match event {
            Event::Start(Tag::Heading { id, .. }) => {
                if let Some(id) = id {
                    anchors.insert(id.to_string());
                }
                heading = Some(String::new());
            }
            Event::End(TagEnd::Heading(_)) => {
                let base = slug(&heading.take().unwrap_or_default());
                let n = seen.entry(base.clone()).or_insert(0);
                // GitHub numbers repeated headings: x, x-1, x-2, ...
                anchors.insert(if *n == 0 { base } else { format!("{base}-{n}") });
                *n += 1;
            }
            Event::Text(t) | Event::Code(t) => {
                if let Some(h) = heading.as_mut() {
                    h.push_str(&t);
                }
            }
            Event::Html(h) | Event::InlineHtml(h) => html_ids(&h, &mut anchors),
            Event::Start(Tag::Link { dest_url, .. }) | Event::Start(Tag::Image { dest_url, .. }) => {
                links.push(dest_url.to_string())
            }
            _ => {}
        }
    }
    Page { anchors, links, broken_refs }
}

/// A destination with a scheme (`https:`, `mailto:`) is external: not fetched.
fn is_external(dest: &str) -> bool {
    match dest.find(':') {
        Some(colon) => {
            let scheme = &dest[..colon];
            !scheme.is_empty()
                && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+.-".contains(c))
                && !dest[..colon].contains('/')
        }
        None => false,
    }
}

fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let Ok(b) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `a/./b/../c` to `a/c`, without touching the file system.
fn normalise(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// The Markdown files of a tree, build output and hidden directories left out.
fn markdown_files(root: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = fs::read_dir(dir) else { return };
        let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
        entries.sort();
        for path in entries {
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                if !(name.starts_with('.') || name == "target" || name == "out") {
                    walk(&path, out);
                }
            } else if name.ends_with(".md") {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    walk(root, &mut out);
    out
}

/// Every relative link of every Markdown file under `root` that does not resolve.
fn check_tree(root: &Path) -> Vec<Broken> {
    let files = markdown_files(root);
    let mut pages: BTreeMap<PathBuf, Page> = BTreeMap::new();
    for f in &files {
        let text = fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        pages.insert(normalise(f), parse(&text));
    }
    let mut broken = Vec::new();
    for (file, page) in &pages {
        let rel = file.strip_prefix(root).unwrap_or(file).to_path_buf();
        for r in &page.broken_refs {
            broken.push(Broken { file: rel.clone(), dest: format!("[{r}]"), why: "no link reference definition".into() });
        }
        for dest in &page.links {
            if dest.is_empty() {
                broken.push(Broken { file: rel.clone(), dest: dest.clone(), why: "empty destination".into() });
                continue;
            }
            if is_external(dest) {
                continue;
            }
            let (path_part, anchor) = match dest.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (dest.as_str(), None),
            };
            let path_part = path_part.split('?').next().unwrap_or("");
            let target = if path_part.is_empty() {
                file.clone()
            } else if let Some(from_root) = path_part.strip_prefix('/') {
                normalise(&root.join(percent_decode(from_root)))
            } else {
                normalise(&file.parent().unwrap_or(root).join(percent_decode(path_part)))
            };
            if !target.exists() {
                broken.push(Broken { file: rel.clone(), dest: dest.clone(), why: "no such file".into() });
                continue;
            }
            if !target.starts_with(normalise(root)) {
                broken.push(Broken { file: rel.clone(), dest: dest.clone(), why: "points outside the repository".into() });
                continue;
            }
            let Some(anchor) = anchor.filter(|a| !a.is_empty()) else { continue };
            // Anchors are checked in Markdown targets; `#L10` into source is GitHub's.
            if let Some(target_page) = pages.get(&target) {
                let anchor = percent_decode(anchor);
                if !target_page.anchors.contains(&anchor) {
                    broken.push(Broken { file: rel.clone(), dest: dest.clone(), why: "no such heading anchor".into() });
                }
            }
        }
    }
    broken
}

fn repo_root() -> PathBuf {
    normalise(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

#[test]
fn every_relative_link_in_the_trees_markdown_resolves() {
    let root = repo_root();
    let files = markdown_files(&root);
    for must in ["README.md", "docs/README.md", "docs/ARCHITECTURE.md"] {
        assert!(files.contains(&root.join(must)), "{must} not found among the checked files");
    }
    let broken = check_tree(&root);
    let listing: Vec<String> =
        broken.iter().map(|b| format!("{}: ({}) {}", b.file.display(), b.dest, b.why)).collect();
    assert!(broken.is_empty(), "{} broken link(s):\n{}", broken.len(), listing.join("\n"));
}

#[test]
fn slugs_follow_githubs_rules() {
    assert_eq!(slug("The command line (`cancosim`)"), "the-command-line-cancosim");
    assert_eq!(slug("Bisect a core"), "bisect-a-core");
    assert_eq!(slug("D6: why the reference does not imitate"), "d6-why-the-reference-does-not-imitate");
    assert_eq!(slug("rx-7.7.4 (two scenarios): still open"), "rx-774-two-scenarios-still-open");
    assert_eq!(slug("a  b"), "a--b");
    assert_eq!(slug("snake_case and-dash"), "snake_case-and-dash");
}

fn write(root: &Path, rel: &str, text: &str) {
    let p = root.join(rel);
    fs::create_dir_all(p.parent().unwrap()).unwrap();
    fs::write(p, text).unwrap();
}

#[test]
fn the_checker_finds_a_broken_file_a_broken_anchor_and_a_missing_image() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    write(
        root,
        "README.md",
        "# Top\n\n## Two words\n\n## Two words\n\n\
         [ok](docs/guide.md#reading-a-divergence) [ok2](#two-words-1) [web](https://example.invalid/x)\n\
         [bad file](docs/missing.md) [bad anchor](docs/guide.md#no-such-heading) \
         [bad local](#two-words-2) ![img](docs/img/none.png) ![img ok](docs/img/a.png)\n\
         [ref][nodef] `[not a link](nowhere.md)`\n\n```\n[nor this](nowhere.md)\n```\n",
    );
    write(root, "docs/guide.md", "# Guide\n\n## Reading a divergence\n\n[back](../README.md#top)\n");
    write(root, "docs/img/a.png", "png");
    write(root, "target/skipped.md", "[broken](nowhere.md)\n");
    let broken = check_tree(root);
    let got: Vec<(&str, &str)> = broken.iter().map(|b| (b.dest.as_str(), b.why.as_str())).collect();
    assert_eq!(
        got,
        vec![
            ("[nodef]", "no link reference definition"),
            ("docs/missing.md", "no such file"),
            ("docs/guide.md#no-such-heading", "no such heading anchor"),
            ("#two-words-2", "no such heading anchor"),
            ("docs/img/none.png", "no such file"),
        ],
        "{broken:#?}"
    );
    assert!(broken.iter().all(|b| b.file == Path::new("README.md")), "{broken:#?}");
}

#[test]
fn a_tree_whose_links_all_resolve_passes() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    write(root, "README.md", "# A\n\n[guide](docs/README.md) [dir](docs/) [space](docs/a%20b.md#x)\n");
    write(root, "docs/README.md", "# Contents\n\n<a id=\"custom\"></a>\n\n[self](#custom) [up](/README.md#a)\n");
    write(root, "docs/a b.md", "# X\n");
    assert_eq!(check_tree(root), vec![]);
}
