//! A core named by git revision, `git:REPO@REV[:SUBDIR]`: the revision's
//! tree exported with `git archive` into the build cache (one entry per
//! commit), so two commits are compared without exporting them by hand.

use anyhow::{Context, bail};
use std::path::PathBuf;
use std::process::Command;

/// Splits `git:REPO@REV[:SUBDIR]`; None if `spec` is not a git name.
pub fn parse(spec: &str) -> Option<(&str, &str, Option<&str>)> {
    let rest = spec.strip_prefix("git:")?;
    let (repo, rev) = rest.rsplit_once('@')?;
    Some(match rev.split_once(':') {
        Some((r, sub)) => (repo, r, Some(sub)),
        None => (repo, rev, None),
    })
}

/// The directory of `git:REPO@REV[:SUBDIR]`, exported on first use.
pub fn export(spec: &str) -> anyhow::Result<PathBuf> {
    let Some((repo, rev, sub)) = parse(spec) else { bail!("{spec}: expected git:REPO@REV[:SUBDIR]") };
    let o = Command::new("git").args(["-C", repo, "rev-parse", "--verify", "--quiet"]).arg(format!("{rev}^{{commit}}")).output().context("running git")?;
    if !o.status.success() {
        bail!("{spec}: {rev} is not a commit of the git repository {repo}");
    }
    let sha = String::from_utf8_lossy(&o.stdout).trim().to_string();
    let dir = cosim::cache_dir().join(format!("git-{sha}"));
    let entry = buildcache::build_once(&dir, ".exported", |work| -> anyhow::Result<()> {
        let tar = work.join("tree.tar");
        let st = Command::new("git").args(["-C", repo, "archive", "--format=tar", "-o"]).arg(&tar).arg(&sha).status().context("running git archive")?;
        if !st.success() {
            bail!("git archive of {sha} in {repo} failed");
        }
        let st = Command::new("tar").arg("-xf").arg(&tar).arg("-C").arg(work).status().context("running tar")?;
        if !st.success() {
            bail!("unpacking git archive of {sha} failed");
        }
        std::fs::remove_file(&tar)?;
        std::fs::write(work.join(".exported"), format!("{repo}@{sha}\n"))?;
        Ok(())
    })
    .map_err(|e| anyhow::anyhow!("{spec}: {e}"))?;
    let out = match sub {
        Some(s) => entry.dir.join(s),
        None => entry.dir,
    };
    if !out.is_dir() {
        return Err(NotInRevision(format!("{spec}: {} is not a directory of {rev}", sub.unwrap_or("."))).into());
    }
    Ok(out)
}

/// The revision exists but holds no such directory: the revision's
/// content, not the user's input (`regress` exits 125 on it, so `git
/// bisect run` skips the revision).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct NotInRevision(pub String);

#[cfg(test)]
mod tests {
    #[test]
    fn git_names_split_into_repo_revision_and_subdirectory() {
        assert_eq!(super::parse("git:/r/x@HEAD~1:rtl"), Some(("/r/x", "HEAD~1", Some("rtl"))));
        assert_eq!(super::parse("git:.@v1.2"), Some((".", "v1.2", None)));
        assert_eq!(super::parse("/some/dir"), None);
    }
}
