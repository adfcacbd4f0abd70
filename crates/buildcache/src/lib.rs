//! Build-once directories keyed on disk, safe under concurrency.
//!
//! A cache entry is a directory `<cache>/<key>` holding a product file; the
//! entry is complete exactly when the product exists. [`build_once`] builds
//! a missing entry in a directory of its own (unique per call, not per
//! process: test threads share a pid), next to the final one so that the
//! move is one atomic `rename`. Two builders of one key, in threads or in
//! processes, never share a work directory; the first rename wins, and the
//! loser drops its copy and uses the winner's. Nobody ever sees half a build.
//!
//! No lock: a key built twice at once costs two builds, never a wrong one
//! (and a lock held by a killed process cannot block anyone).

use std::io;
use std::path::{Path, PathBuf};

/// Why an entry could not be had.
#[derive(Debug, thiserror::Error)]
pub enum Error<E> {
    /// The build itself failed (its work directory is removed).
    #[error(transparent)]
    Build(E),
    /// The cache directory could not be prepared or the result moved.
    #[error("build cache: {what}: {source}")]
    Io {
        /// What was being done, with the path.
        what: String,
        /// The OS error.
        source: io::Error,
    },
}

/// Where an entry came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// It was complete before the call.
    Cached,
    /// This call built it and moved it into place.
    Built,
    /// This call built it, but another builder moved its copy in first:
    /// that copy is used, ours was deleted.
    BuiltElsewhere,
}

/// A complete cache entry.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The entry directory (`dir` as given).
    pub dir: PathBuf,
    /// `dir/product`.
    pub product: PathBuf,
    /// Where it came from.
    pub origin: Origin,
}

/// Returns the entry `dir` (complete when `dir/product` exists), building it
/// first if needed: `build` gets an empty directory of its own, which must
/// hold `product` when it returns `Ok`.
pub fn build_once<E>(
    dir: &Path,
    product: &str,
    build: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<Entry, Error<E>> {
    let done = dir.join(product);
    let entry = |origin| Entry {
        dir: dir.to_path_buf(),
        product: done.clone(),
        origin,
    };
    if done.exists() {
        return Ok(entry(Origin::Cached));
    }
    let io = |what: String| move |source| Error::Io { what, source };
    let parent = dir.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(io(format!("creating {}", parent.display())))?;
    remove_abandoned_work_dirs(parent);
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // Unique per call; removed on every early return (build error, panic).
    let work = tempfile::Builder::new()
        .prefix(&format!(".{name}.build-"))
        .tempdir_in(parent)
        .map_err(io(format!("creating a build directory in {}", parent.display())))?;
    build(work.path()).map_err(Error::Build)?;
    if !work.path().join(product).exists() {
        return Err(Error::Io {
            what: format!("the build left no {product} in {}", work.path().display()),
            source: io::Error::from(io::ErrorKind::NotFound),
        });
    }
    match std::fs::rename(work.path(), dir) {
        Ok(()) => {
            // Moved: nothing of ours is left to delete.
            let _ = work.keep();
            Ok(entry(Origin::Built))
        }
        // `dir` exists and is not empty: someone else's complete entry.
        // Dropping `work` deletes our copy.
        Err(_) if done.exists() => Ok(entry(Origin::BuiltElsewhere)),
        // Never delete someone else's directory here: a complete entry may
        // land in it at any moment. An incomplete one is not ours to judge.
        Err(source) => Err(Error::Io {
            what: format!(
                "moving the build into {} (if that directory exists without {product}, it was not made by this cache: delete it)",
                dir.display()
            ),
            source,
        }),
    }
}

/// Work directories older than this were left by a killed build.
const ABANDONED_AFTER: std::time::Duration = std::time::Duration::from_secs(24 * 3600);

/// Deletes work directories (`.<key>.build-*`) in `parent` untouched for
/// [`ABANDONED_AFTER`]: a build killed midway cannot delete its own, and
/// no live build is a day old. Best effort: errors are ignored.
fn remove_abandoned_work_dirs(parent: &Path) {
    let Ok(rd) = std::fs::read_dir(parent) else { return };
    for e in rd.flatten() {
        let name = e.file_name();
        let name = name.to_string_lossy();
        if !(name.starts_with('.') && name.contains(".build-")) {
            continue;
        }
        let old = e
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age > ABANDONED_AFTER);
        if old {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_once_then_reads_the_cache_and_a_failed_build_leaves_nothing() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("k1");
        let e = build_once::<()>(&dir, "out", |w| {
            std::fs::write(w.join("out"), "1").map_err(|_| ())
        })
        .unwrap();
        assert_eq!(e.origin, Origin::Built);
        assert_eq!(std::fs::read_to_string(&e.product).unwrap(), "1");
        let e = build_once::<()>(&dir, "out", |_| panic!("must not build again")).unwrap();
        assert_eq!(e.origin, Origin::Cached);

        let bad = root.path().join("k2");
        let r = build_once(&bad, "out", |w| {
            std::fs::write(w.join("half"), "x").unwrap();
            Err("compiler said no")
        });
        assert!(matches!(r, Err(Error::Build("compiler said no"))));
        let r = build_once::<()>(&bad, "out", |_| Ok(()));
        assert!(matches!(r, Err(Error::Io { .. })), "no product is an error");
        let left: Vec<_> = std::fs::read_dir(root.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left, vec![std::ffi::OsString::from("k1")], "no work directory left behind");
    }

    #[test]
    fn work_dirs_of_killed_builds_are_removed_after_a_day_and_young_ones_kept() {
        let root = tempfile::tempdir().unwrap();
        let (old, young) = (root.path().join(".k1.build-AAAAAA"), root.path().join(".k2.build-BBBBBB"));
        for d in [&old, &young] {
            std::fs::create_dir_all(d.join("obj")).unwrap();
        }
        let two_days_ago = std::time::SystemTime::now() - 2 * ABANDONED_AFTER;
        std::fs::File::open(&old).unwrap().set_modified(two_days_ago).unwrap();
        build_once::<()>(&root.path().join("k3"), "out", |w| std::fs::write(w.join("out"), "").map_err(|_| ())).unwrap();
        assert!(!old.exists(), "a day-old work directory is abandoned");
        assert!(young.exists(), "a live build's work directory stays");
    }

    #[test]
    fn an_incomplete_foreign_directory_is_an_error_naming_it_and_left_alone() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("k");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        let r = build_once(&dir, "out", |w| std::fs::write(w.join("out"), "new").map_err(|e| e.to_string()));
        let msg = r.unwrap_err().to_string();
        assert!(msg.contains("delete it") && msg.contains(&dir.display().to_string()), "{msg}");
        assert_eq!(std::fs::read_to_string(dir.join("notes.txt")).unwrap(), "mine");
        assert_eq!(std::fs::read_dir(root.path()).unwrap().count(), 1, "our work directory removed");
    }
}
