//! Writing output files so that nothing half-written is ever left behind.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` atomically: to a temporary file in the same directory,
/// flushed to disk, then renamed over `path`. On any error the temporary is removed
/// and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .with_context(|| format!("{} is not a file path", path.display()))?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> Result<()> {
        let mut f = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot create {}", tmp.display()))?;
        f.write_all(bytes)
            .with_context(|| format!("cannot write {}", tmp.display()))?;
        f.sync_all()
            .with_context(|| format!("cannot flush {}", tmp.display()))?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot move {} to {}", tmp.display(), path.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Creates `dir` and its parents if needed.
pub fn ensure_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))
}

/// An output directory made at the start of a long run, so that an unusable
/// `--out` fails at once rather than after minutes of work, and taken away again
/// if the run fails before writing into it: dropping a `NewDir` that was not
/// [kept](NewDir::keep) removes the directories [`NewDir::create`] made, deepest
/// first, each only while it is empty (what was there before, and anything
/// written since, stays).
#[derive(Debug)]
pub struct NewDir {
    /// The directories this created, `dir` first, then its new parents.
    created: Vec<PathBuf>,
}

impl NewDir {
    /// Creates `dir` and its missing parents ([`ensure_dir`]'s error if it cannot).
    pub fn create(dir: &Path) -> Result<Self> {
        let created: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        let mut made = Self { created };
        if let Err(e) = ensure_dir(dir) {
            // create_dir_all may have made some parents before failing.
            made.created.retain(|d| d.exists());
            return Err(e);
        }
        Ok(made)
    }

    /// The run has written its outputs: the directory stays.
    pub fn keep(mut self) {
        self.created.clear();
    }
}

impl Drop for NewDir {
    fn drop(&mut self) {
        for dir in &self.created {
            // Only empty directories go; an error means something is in there.
            if std::fs::remove_dir(dir).is_err() {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_new_dir_not_kept_is_removed_with_the_parents_it_made_and_nothing_else() {
        let base = std::env::temp_dir().join(format!("nuld-newdir-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        ensure_dir(&base).unwrap();
        let deep = base.join("a").join("b");
        // Dropped without keep: `a/b` and `a` go, `base` (there before) stays.
        drop(NewDir::create(&deep).unwrap());
        assert!(!base.join("a").exists() && base.is_dir());
        // Something written into a parent it made keeps that parent.
        let made = NewDir::create(&deep).unwrap();
        std::fs::write(base.join("a").join("user.txt"), b"x").unwrap();
        drop(made);
        assert!(!deep.exists() && base.join("a").join("user.txt").is_file());
        // Kept: everything stays.
        NewDir::create(&deep).unwrap().keep();
        assert!(deep.is_dir());
        // An existing file in the way is an error at once, and nothing is made.
        let file = base.join("file");
        std::fs::write(&file, b"x").unwrap();
        let e = NewDir::create(&file.join("out")).unwrap_err().to_string();
        assert!(e.contains("cannot create directory"), "{e}");
        assert!(!file.join("out").exists());
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("nuld-output-test-{}", std::process::id()));
        ensure_dir(&dir).unwrap();
        let path = dir.join("a.bin");
        write_atomic(&path, b"one").unwrap();
        write_atomic(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        // A path in a missing directory fails and creates nothing.
        assert!(write_atomic(&dir.join("missing/b.bin"), b"x").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
