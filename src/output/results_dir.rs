//! A results directory published whole or not at all.
//!
//! A command writes every file into a staging sibling `.<name>.partial` and publishes it with
//! one atomic rename (Linux: `renameat2(RENAME_EXCHANGE)` when a previous result is replaced, so
//! the name always points at a complete directory; elsewhere two renames, with the previous result
//! kept as `.<name>.old-<pid>` in between and restored by the next command if the process died
//! there). An advisory lock on `.<name>.lock` (std's `File::try_lock`, flock on Unix) refuses a
//! second writer of the same directory, and under it the stale staging directories of dead
//! processes are removed — except by `run --resume`, which continues from the one it finds. On
//! Unix the lock file is removed when the command ends, success or handled failure ([`DirLock`]
//! says why that keeps one writer per directory); a killed process leaves it, empty and unlocked.

use std::fs::{self, File};
use std::path::{Path, PathBuf};

/// Why a results directory cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum ResultsDirError {
    /// Another process holds the lock of this directory.
    #[error("{0}: another cryoslosh process is writing this results directory")]
    Busy(PathBuf),
    /// The directory holds something and `--force` was not given.
    #[error(
        "--out {path}: the directory is not empty ({listing}); choose another directory or pass \
         --force to replace the previous result"
    )]
    NotEmpty { path: PathBuf, listing: String },
    /// `--force` on a directory that is not a cryoslosh result: it would be deleted whole.
    #[error(
        "--out {path}: not a cryoslosh results directory (no {marker}; it holds {listing}): \
         only a previous result is replaced, so choose another directory"
    )]
    Foreign {
        path: PathBuf,
        listing: String,
        /// The file a previous result of this kind holds (`run.json`, a report's `index.html`).
        marker: &'static str,
    },
    /// `--resume` on a directory without an interrupted run.
    #[error("--resume {path}: there is no interrupted run to resume there{}", if *complete { " (it holds a complete result)" } else { "" })]
    NothingToResume { path: PathBuf, complete: bool },
    /// `--out` is a symbolic link.
    #[error("--out {0}: is a symbolic link; give the directory it points to, or another path")]
    Symlink(PathBuf),
    /// A component of `--out`'s parent is a file.
    #[error("--out: {0} is a file, so no directory can be created under it")]
    ParentIsAFile(PathBuf),
    /// `--out` names something other than a directory.
    #[error("--out {0}: exists and is not a directory")]
    NotADirectory(PathBuf),
    /// A filesystem operation failed.
    #[error("cannot write results directory {path}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ResultsDirError + '_ {
    move |source| ResultsDirError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Test hook: when the environment variable `CRYOSLOSH_FAILPOINT` equals `name`, the process
/// aborts here (as a kill would); when it equals `enospc:name`, the point fails with the "no
/// space left on device" error a full disk gives. Used by `tests/crash.rs` to stop a command
/// between any two writes and renames.
pub fn failpoint(name: &str) -> std::io::Result<()> {
    let Some(v) = std::env::var_os("CRYOSLOSH_FAILPOINT") else {
        return Ok(());
    };
    if v == name {
        std::process::abort();
    }
    if v.to_str().and_then(|v| v.strip_prefix("enospc:")) == Some(name) {
        return Err(std::io::Error::from_raw_os_error(28)); // ENOSPC
    }
    Ok(())
}

/// A results directory being written: files go to [`Self::path`]; [`Self::publish`] makes them
/// the result. Dropped unpublished, the staging directory is removed.
#[derive(Debug)]
pub struct Staging {
    target: PathBuf,
    work: PathBuf,
    staging: PathBuf,
    // Dropped after `Drop for Staging` has removed the working state: the lock is held until
    // the command has finished with the directory.
    _lock: DirLock,
    published: bool,
    keep: bool,
}

/// Sorted entry names of a directory, the first few joined for a message.
fn listing(dir: &Path) -> std::io::Result<(usize, String)> {
    let mut names: Vec<String> = fs::read_dir(dir)?
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let shown = names.iter().take(4).cloned().collect::<Vec<_>>().join(", ");
    let more = if names.len() > 4 { ", …" } else { "" };
    Ok((names.len(), format!("{shown}{more}")))
}

impl Staging {
    /// Lock `target`, clean up after dead writers, check it may be written, and create the
    /// staging directory. `force` allows replacing a previous result (a directory with a
    /// `run.json`); an empty or missing directory needs no `force`. `resume` keeps the staging
    /// directory an interrupted run left (`run --resume`); otherwise it is removed.
    pub fn begin(target: &Path, force: bool, resume: bool) -> Result<Staging, ResultsDirError> {
        Staging::begin_kind(target, force, resume, "run.json")
    }

    /// [`Self::begin`] for a directory of another kind, whose previous results are recognised
    /// by the file `marker` (a report: `index.html`); only such a directory is replaced.
    pub fn begin_kind(
        target: &Path,
        force: bool,
        resume: bool,
        marker: &'static str,
    ) -> Result<Staging, ResultsDirError> {
        let name = target
            .file_name()
            .ok_or_else(|| ResultsDirError::NotADirectory(target.to_path_buf()))?
            .to_string_lossy()
            .into_owned();
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        // Refuse a target that cannot be a results directory before anything is created.
        if let Ok(m) = fs::symlink_metadata(target) {
            if m.file_type().is_symlink() {
                return Err(ResultsDirError::Symlink(target.to_path_buf()));
            }
            if !m.is_dir() {
                return Err(ResultsDirError::NotADirectory(target.to_path_buf()));
            }
        }
        if matches!(name.as_str(), "." | "..") || target.parent().is_none() {
            return Err(ResultsDirError::NotADirectory(target.to_path_buf()));
        }
        if let Some(file) = parent.ancestors().find(|a| a.is_file()) {
            return Err(ResultsDirError::ParentIsAFile(file.to_path_buf()));
        }
        fs::create_dir_all(&parent).map_err(io(&parent))?;
        let lock = DirLock::take(&parent.join(format!(".{name}.lock")), target)?;
        recover(&parent, &name, target)?;
        match fs::symlink_metadata(target) {
            Ok(m) if !m.is_dir() => {
                return Err(ResultsDirError::NotADirectory(target.to_path_buf()))
            }
            Ok(_) => {
                let (count, list) = listing(target).map_err(io(target))?;
                if count > 0 {
                    if !force {
                        return Err(ResultsDirError::NotEmpty {
                            path: target.to_path_buf(),
                            listing: list,
                        });
                    }
                    if !target.join(marker).is_file() {
                        return Err(ResultsDirError::Foreign {
                            path: target.to_path_buf(),
                            listing: list,
                            marker,
                        });
                    }
                }
            }
            Err(_) => {}
        }
        // `.<name>.partial/` holds the command's working state (a run's committed blocks);
        // `.<name>.partial/result/` the directory that will be published.
        let work = parent.join(format!(".{name}.partial"));
        let staging = work.join("result");
        if resume {
            if !work.is_dir() {
                return Err(ResultsDirError::NothingToResume {
                    path: target.to_path_buf(),
                    complete: target.join("run.json").is_file(),
                });
            }
        } else {
            let _ = fs::remove_dir_all(&work);
            fs::create_dir(&work).map_err(io(&work))?;
        }
        fs::create_dir_all(&staging).map_err(io(&staging))?;
        Ok(Staging {
            target: target.to_path_buf(),
            work,
            staging,
            _lock: lock,
            published: false,
            keep: false,
        })
    }

    /// Where the command writes the files it publishes.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Where the command keeps working state that is not published (a run's committed blocks).
    pub fn work(&self) -> &Path {
        &self.work
    }

    /// Make the staged files the result: `manifest.json` (size and SHA-256 of every file) written
    /// last, then one atomic rename (or exchange) and a directory fsync.
    pub fn publish(mut self) -> Result<(), ResultsDirError> {
        let manifest = manifest(&self.staging).map_err(io(&self.staging))?;
        let text = serde_json::to_string_pretty(&manifest).unwrap_or_default();
        crate::output::atomic::write_atomic(&self.staging.join(MANIFEST), text.as_bytes())
            .map_err(|e| ResultsDirError::Io {
                path: self.staging.join(MANIFEST),
                source: std::io::Error::other(e.to_string()),
            })?;
        sync_dir(&self.staging);
        failpoint("before-publish").map_err(io(&self.target))?;
        let exists = fs::symlink_metadata(&self.target).is_ok();
        if !exists {
            fs::rename(&self.staging, &self.target).map_err(io(&self.target))?;
        } else {
            replace(&self.staging, &self.target)?;
        }
        self.published = true;
        // The working state (and, after an exchange, the previous result) goes; a kill before
        // this leaves it for the next command to remove.
        let _ = fs::remove_dir_all(&self.work);
        if let Some(parent) = self.target.parent() {
            sync_dir(if parent.as_os_str().is_empty() {
                Path::new(".")
            } else {
                parent
            });
        }
        Ok(())
    }
}

impl Staging {
    /// Keep the staging directory if the command fails (a run: `run --resume` continues from
    /// it; the next plain command on the path removes it).
    pub fn keep_on_failure(&mut self) {
        self.keep = true;
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.published && !self.keep {
            let _ = fs::remove_dir_all(&self.work);
        }
    }
}

/// The lock of a results directory: an exclusive advisory lock (flock on Unix) on the file
/// `.<name>.lock` beside it, held while the value lives and, on Unix, removed when dropped.
///
/// Removing a lock file is safe only with two rules, because a second writer may have opened
/// the file just before it was removed and be granted the lock on that orphaned file once the
/// first releases it, while a third creates a new file under the name and locks that:
/// the file is removed only by its holder, while it still holds the lock (here, in `drop`,
/// before the descriptor closes), and a lock counts only if the name still names the file that
/// was locked (same device and inode), otherwise the name is opened again. Then whoever holds
/// the lock of the file the name points at is the one writer: the name changes only when that
/// holder removes it, as its last act on the directory. Elsewhere the file stays (std has no
/// stable way to compare file identities there).
#[derive(Debug)]
struct DirLock {
    path: PathBuf,
    file: File,
}

impl DirLock {
    /// Lock `path` (created if missing) for a writer of `target`, or say that another process
    /// holds it.
    fn take(path: &Path, target: &Path) -> Result<DirLock, ResultsDirError> {
        // Each retry means another writer removed the file between our open and our lock; a
        // name that keeps changing under us is as good as busy.
        for _ in 0..64 {
            let file = File::options()
                .create(true)
                .truncate(false)
                .write(true)
                .open(path)
                .map_err(io(path))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(ResultsDirError::Busy(target.to_path_buf()))
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(io(path)(e)),
            }
            if names(path, &file) {
                return Ok(DirLock {
                    path: path.to_path_buf(),
                    file,
                });
            }
        }
        Err(ResultsDirError::Busy(target.to_path_buf()))
    }
}

/// Whether `path` still names the open `file` (Unix: same device and inode). Elsewhere the lock
/// file is never removed, so the name always does.
fn names(path: &Path, file: &File) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (fs::metadata(path), file.metadata()) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (path, file);
        true
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // Still holding the lock (the descriptor closes after this), and the name is still ours:
        // only the holder removes it.
        #[cfg(unix)]
        if names(&self.path, &self.file) {
            let _ = fs::remove_file(&self.path);
        }
        #[cfg(not(unix))]
        let _ = (&self.path, &self.file);
    }
}

/// Replace the directory `target` by `staging`; afterwards `staging` is gone and the previous
/// result deleted.
fn replace(staging: &Path, target: &Path) -> Result<(), ResultsDirError> {
    #[cfg(target_os = "linux")]
    {
        use std::ffi::CString;
        use std::os::unix::ffi::OsStrExt;
        let cstr = |p: &Path| CString::new(p.as_os_str().as_bytes()).ok();
        if let (Some(a), Some(b)) = (cstr(staging), cstr(target)) {
            // SAFETY: both are valid NUL-terminated paths; AT_FDCWD resolves them relative to
            // the working directory like std's rename.
            let rc = unsafe {
                libc::renameat2(
                    libc::AT_FDCWD,
                    a.as_ptr(),
                    libc::AT_FDCWD,
                    b.as_ptr(),
                    libc::RENAME_EXCHANGE,
                )
            };
            if rc == 0 {
                // `staging` now holds the previous result: removed with the working directory
                // (a kill here leaves it for the next command).
                let _ = failpoint("after-exchange");
                return Ok(());
            }
            // EINVAL/ENOSYS (a filesystem without exchange): fall back to two renames.
        }
    }
    let old = old_path(target);
    let _ = fs::remove_dir_all(&old);
    fs::rename(target, &old).map_err(io(target))?;
    if let Err(e) = failpoint("between-renames").and_then(|()| fs::rename(staging, target)) {
        // Put the previous result back rather than leave the name empty.
        let _ = fs::rename(&old, target);
        return Err(io(target)(e));
    }
    let _ = fs::remove_dir_all(&old);
    Ok(())
}

/// `.<name>.old-<pid>` beside `target`.
fn old_path(target: &Path) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    target.with_file_name(format!(".{name}.old-{}", std::process::id()))
}

/// Under the lock: restore a previous result that a writer killed between its two renames left
/// as `.<name>.old-*` (when the name is empty), and remove every other staging or old directory.
fn recover(parent: &Path, name: &str, target: &Path) -> Result<(), ResultsDirError> {
    // `.<name>.tmp-*`: staging of versions before `.partial`.
    let tmp_prefix = format!(".{name}.tmp-");
    let old_prefix = format!(".{name}.old-");
    let Ok(entries) = fs::read_dir(parent) else {
        return Ok(());
    };
    for e in entries.filter_map(Result::ok) {
        let file_name = e.file_name().to_string_lossy().into_owned();
        let path = e.path();
        if file_name.starts_with(&old_prefix) && fs::symlink_metadata(target).is_err() {
            fs::rename(&path, target).map_err(io(target))?;
        } else if file_name.starts_with(&tmp_prefix) || file_name.starts_with(&old_prefix) {
            let _ = fs::remove_dir_all(&path);
        }
    }
    Ok(())
}

/// Best-effort fsync of a directory (makes renames inside it durable).
fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// The manifest of a results directory: every other file's size and SHA-256, written last.
pub const MANIFEST: &str = "manifest.json";

/// Relative path (with `/`), size and SHA-256 (hex) of every file under `dir` but the manifest,
/// sorted by path.
fn manifest(dir: &Path) -> std::io::Result<serde_json::Value> {
    let mut files = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in fs::read_dir(&d)? {
            let p = e?.path();
            if p.is_dir() {
                stack.push(p);
            } else if p != dir.join(MANIFEST) {
                files.push(p);
            }
        }
    }
    files.sort();
    let mut map = serde_json::Map::new();
    for p in files {
        let rel = p
            .strip_prefix(dir)
            .unwrap_or(&p)
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/");
        let (bytes, sha) = digest(&p)?;
        map.insert(rel, serde_json::json!({ "bytes": bytes, "sha256": sha }));
    }
    Ok(serde_json::json!({ "version": crate::VERSION, "files": map }))
}

/// Size and SHA-256 (lower-case hex) of a file, read in 1 MiB blocks.
pub fn digest(path: &Path) -> std::io::Result<(u64, String)> {
    use sha2::{Digest, Sha256};
    use std::io::Read;
    let mut f = File::open(path)?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut bytes = 0u64;
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
        bytes += n as u64;
    }
    let hex = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    Ok((bytes, hex))
}

/// Check every file a results directory's manifest lists (size and SHA-256); `Err` names the
/// first that is missing or differs, or says the manifest is absent.
pub fn verify(dir: &Path) -> Result<(), String> {
    let text = fs::read_to_string(dir.join(MANIFEST))
        .map_err(|_| "no manifest.json: not a complete results directory".to_string())?;
    let m: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("manifest.json: {e}"))?;
    let files = m["files"]
        .as_object()
        .ok_or_else(|| "manifest.json lists no files".to_string())?;
    for (rel, want) in files {
        let (bytes, sha) = digest(&dir.join(rel)).map_err(|e| format!("{rel}: {e}"))?;
        if want["bytes"].as_u64() != Some(bytes) || want["sha256"].as_str() != Some(sha.as_str()) {
            return Err(format!(
                "{rel} differs from its manifest entry (changed after the run wrote it)"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The race that makes removing a lock file unsafe without the identity check: a writer
    /// that opened the file before its holder removed it gets the lock on the orphan once the
    /// holder is done, and must not count it, since a new file may already be locked by another.
    #[cfg(unix)]
    #[test]
    fn a_lock_on_a_removed_lock_file_does_not_count() {
        let dir = std::env::temp_dir().join(format!("cryoslosh-dirlock-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let (path, target) = (dir.join(".r.lock"), dir.join("r"));
        let first = DirLock::take(&path, &target).unwrap();
        assert!(matches!(
            DirLock::take(&path, &target),
            Err(ResultsDirError::Busy(_))
        ));
        let late = File::options().write(true).open(&path).unwrap();
        drop(first);
        assert!(!path.exists(), "the holder removes its lock file");
        late.try_lock().unwrap(); // the orphan's lock is free now...
        assert!(
            !names(&path, &late),
            "...but it is not the lock of the directory"
        );
        let second = DirLock::take(&path, &target).unwrap();
        assert!(names(&path, &second.file));
        assert!(matches!(
            DirLock::take(&path, &target),
            Err(ResultsDirError::Busy(_))
        ));
        drop(second);
        drop(late);
        fs::remove_dir_all(&dir).unwrap();
    }
}
