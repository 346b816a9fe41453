//! Atomic file replacement: write to a temporary sibling, fsync, rename.
//!
//! The temporary file lives in the same directory as the target so that the
//! final `rename` is atomic (same filesystem). Readers see either the old file
//! or the complete new one, never a partial write.

use std::ffi::OsString;
use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};

use super::OutputError;

/// Returns the temporary sibling used while writing `path`: `<path>.tmp-<pid>`.
///
/// The name depends only on `path` and the process id: a process must not
/// write the same `path` from two places at once.
///
/// Fails with [`OutputError::InvalidPath`] when `path` has no file name
/// component (for example `/` or a path ending in `..`).
pub fn temp_path(path: &Path) -> Result<PathBuf, OutputError> {
    let name = path.file_name().ok_or_else(|| OutputError::InvalidPath {
        path: path.to_path_buf(),
    })?;
    let mut tmp_name = OsString::from(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}

/// Atomically replaces the file at `path` with `bytes`.
///
/// Writes `<path>.tmp-<pid>`, fsyncs it, renames it over `path` and fsyncs the
/// parent directory (best effort). On failure the temporary file is removed
/// and any existing file at `path` is left untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let tmp = temp_path(path)?;
    let result = File::create(&tmp)
        .and_then(|mut file| {
            file.write_all(bytes)?;
            file.sync_all()
        })
        .map_err(|source| io_error(path, source))
        .and_then(|()| commit(&tmp, path));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Renames the (already fsynced and closed) temporary file `tmp` over `path`
/// and fsyncs the parent directory so the rename itself is durable.
///
/// Directory fsync is best effort: some platforms and filesystems do not
/// support it, and the data itself is already on disk at that point.
pub(crate) fn commit(tmp: &Path, path: &Path) -> Result<(), OutputError> {
    fs::rename(tmp, path).map_err(|source| io_error(path, source))?;
    sync_parent_dir(path);
    Ok(())
}

/// Best-effort fsync of the directory containing `path`.
fn sync_parent_dir(path: &Path) {
    #[cfg(unix)]
    {
        let dir = match path.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        if let Ok(dir) = File::open(dir) {
            let _ = dir.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

/// Wraps an I/O error with the final output path.
pub(crate) fn io_error(path: &Path, source: std::io::Error) -> OutputError {
    OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}
