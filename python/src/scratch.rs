//! Scratch directories for results the caller did not ask to keep: a fresh path under the
//! system temporary directory, removed (with what was written there) when dropped.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Scratch paths made by this process so far (part of each name, so they never collide).
static MADE: AtomicU64 = AtomicU64::new(0);

/// A directory path, removed on drop unless kept.
pub struct Scratch {
    path: PathBuf,
    remove: bool,
}

impl Scratch {
    /// A fresh path that does not exist yet (the run creates it).
    pub fn new() -> Result<Scratch, String> {
        let n = MADE.fetch_add(1, Ordering::Relaxed);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let path =
            std::env::temp_dir().join(format!("cryoslosh-py-{}-{n}-{nanos}", std::process::id()));
        if path.exists() {
            return Err(format!("{}: scratch path exists", path.display()));
        }
        Ok(Scratch { path, remove: true })
    }

    /// The caller's own directory, left in place.
    pub fn keep(path: PathBuf) -> Scratch {
        Scratch {
            path,
            remove: false,
        }
    }

    /// Where it is.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        if self.remove {
            let _ = std::fs::remove_dir_all(&self.path);
        }
    }
}
