//! Files and directories written atomically: a writer's uniquely named,
//! locked temporary, renamed into place and synced, so a reader never sees
//! a half-written file and a killed writer's leftovers are told from a live
//! writer's.

use super::parent_dir;
use super::run_dir::check_outside_run_dir;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// A temporary file older than this (by modification time) is left over by
/// a killed writer and may be removed; a younger one may belong to a live
/// writer (another copy of the same shard, a concurrent reduce) and is left
/// alone. Writers create their temporaries only once the data is in memory
/// and write them in seconds, so ten minutes is far beyond any live write.
pub const STALE_TEMP_S: u64 = 600;

/// A name part unique to this writer: process id, a per-process random
/// value and a counter. The process id alone is not enough: every container
/// whose entrypoint is cablemap runs as pid 1, and array tasks on different
/// hosts share pids.
pub fn unique_token() -> String {
    static PROCESS: OnceLock<String> = OnceLock::new();
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let process = PROCESS.get_or_init(|| {
        use std::hash::{BuildHasher, Hasher};
        // RandomState is seeded from the OS's random source per process.
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos());
        h.write_u128(nanos);
        h.write_u32(std::process::id());
        format!("{}-{:016x}", std::process::id(), h.finish())
    });
    format!("{process}-{}", COUNTER.fetch_add(1, Ordering::Relaxed))
}

/// The temporary path a writer uses for `path`: `.NAME.tmp-TOKEN` in the
/// same directory (the leading dot hides it from dataset readers).
pub fn temp_path(path: &Path) -> PathBuf {
    let dir = parent_dir(path);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    dir.join(format!(".{name}.tmp-{}", unique_token()))
}

/// Whether `name` is a temporary file name made by [`temp_path`] (or the
/// pid-only names of earlier versions) for the file `final_name`.
pub fn is_temp_of(name: &str, final_name: &str) -> bool {
    name.strip_prefix('.')
        .and_then(|r| r.strip_prefix(final_name))
        .and_then(|r| r.strip_prefix(".tmp-"))
        .is_some_and(|token| !token.is_empty() && token.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-'))
}

/// Creates a writer's temporary file and takes an exclusive lock on it,
/// held until the file is closed (after its rename). [`is_abandoned`] uses
/// the lock to tell a live writer's file from a killed writer's: the
/// kernel drops the lock when the process dies, whatever pid namespace it
/// ran in.
///
/// On Linux the file appears under `path` already locked: it is created
/// unnamed (`O_TMPFILE`), locked, then linked in. Otherwise another process
/// cleaning up (another shard, a rerun) could find it unlocked in the
/// instant between creating and locking it, or hold the lock for that
/// instant itself, and take a live writer's file for a killed one's; and a
/// writer killed before the link leaves nothing behind. Where the file
/// system cannot do that, the file is created and then locked.
pub fn create_locked(path: &Path) -> std::io::Result<File> {
    #[cfg(target_os = "linux")]
    if let Some(file) = create_locked_unnamed(path)? {
        return Ok(file);
    }
    let file = File::create(path)?;
    // A file system without locks falls back on the age rule.
    let _ = file.try_lock();
    Ok(file)
}

/// [`create_locked`] by `O_TMPFILE` and `linkat`; `None` where the file
/// system or `/proc` does not allow it. Written by hand: std has no
/// unnamed temporary files, and the tempfile crate's are not locked first.
#[cfg(target_os = "linux")]
fn create_locked_unnamed(path: &Path) -> std::io::Result<Option<File>> {
    use std::ffi::CString;
    use std::os::fd::FromRawFd;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let dir = c(parent_dir(path))?;
    // SAFETY: a valid NUL-terminated path; the returned descriptor is owned below.
    let fd = unsafe { libc::open(dir.as_ptr(), libc::O_TMPFILE | libc::O_RDWR | libc::O_CLOEXEC, 0o644 as libc::c_uint) };
    if fd < 0 {
        let e = std::io::Error::last_os_error();
        return match e.raw_os_error() {
            Some(libc::EOPNOTSUPP | libc::EISDIR | libc::EINVAL) => Ok(None),
            _ => Err(e),
        };
    }
    // SAFETY: `fd` was just opened and is owned by nothing else.
    let file = unsafe { File::from_raw_fd(fd) };
    let _ = file.lock();
    let proc_path = CString::new(format!("/proc/self/fd/{fd}")).map_err(std::io::Error::other)?;
    let target = c(path)?;
    // SAFETY: valid NUL-terminated paths; linkat does not retain them.
    let linked = unsafe { libc::linkat(libc::AT_FDCWD, proc_path.as_ptr(), libc::AT_FDCWD, target.as_ptr(), libc::AT_SYMLINK_FOLLOW) };
    if linked != 0 {
        let e = std::io::Error::last_os_error();
        // No /proc (a bare container): fall back on create-then-lock.
        return if e.raw_os_error() == Some(libc::ENOENT) && !Path::new("/proc/self/fd").exists() { Ok(None) } else { Err(e) };
    }
    Ok(Some(file))
}

/// Whether the temporary file at `path` was left by a writer that is gone:
/// nobody holds its lock ([`create_locked`]), or, where locks are not
/// supported, it is older than [`STALE_TEMP_S`]. A file that vanished is
/// not abandoned (its writer renamed it into place).
pub fn is_abandoned(path: &Path) -> bool {
    let Ok(file) = File::open(path) else { return false };
    match file.try_lock() {
        Ok(()) => true,
        Err(std::fs::TryLockError::WouldBlock) => false,
        Err(std::fs::TryLockError::Error(_)) => is_stale(path),
    }
}

/// The file at `path` was last modified more than [`STALE_TEMP_S`] ago.
pub fn is_stale(path: &Path) -> bool {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age.as_secs() > STALE_TEMP_S)
}

/// Writes `bytes` to `path` atomically: a temporary file in the same
/// directory (named uniquely per writer), fsync, rename into place, fsync
/// the directory. A reader never sees a half-written file, a crash never
/// corrupts an existing one, and a failed write (a full disk) leaves no
/// temporary file behind.
///
/// Every output file cablemap writes goes through here, so every writer
/// gets the same two refusals, before anything is written: `path` must be
/// new or a regular file ([`check_regular_or_new`]: the rename would
/// otherwise replace a symlink, a FIFO or a device node such as
/// `/dev/full` by a regular file), and it must not lie inside a sweep run
/// directory at any depth ([`check_outside_run_dir`]: `--csv RUN/manifest.json`
/// would destroy the run). The sweep engine writes its own files inside
/// its run with [`write_atomic_in_run`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    check_outside_run_dir(path, "the output file").map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))?;
    write_atomic_in_run(path, bytes)
}

/// [`write_atomic`] for the sweep engine's own files inside its run
/// directory (checksum records): only the regular-file check.
pub fn write_atomic_in_run(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = parent_dir(path);
    if path.file_name().is_none() {
        return Err(std::io::Error::other("path has no file name"));
    }
    check_regular_or_new(path)?;
    let tmp = temp_path(path);
    let written = (|| {
        let mut f = File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written?;
    sync_dir(dir);
    Ok(())
}

/// Refuses to write over anything at `path` but a regular file: a
/// directory, a symbolic link (even to a regular file: the link itself
/// would be replaced), a FIFO, a socket or a device node. The error names
/// the path and what it is. A path that does not exist is fine.
pub fn check_regular_or_new(path: &Path) -> std::io::Result<()> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            if folder.is_dir() {
                return Ok(());
            }
            return Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("the folder {} does not exist: create it first, or give a path in an existing folder", folder.display()),
            ));
        }
        Err(e) => return Err(e),
    };
    let kind = file_kind(&meta.file_type());
    if kind == "regular file" {
        return Ok(());
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!(
            "{} is a {kind}, not a regular file: cablemap writes only regular files, and would replace it by one; \
             give the path of a new or a regular file",
            path.display()
        ),
    ))
}

/// What a directory entry is, in words ("regular file", "FIFO (named pipe)", …).
fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "character device";
        }
        if t.is_block_device() {
            return "block device";
        }
        if t.is_socket() {
            return "socket";
        }
    }
    if t.is_symlink() {
        "symbolic link"
    } else if t.is_dir() {
        "directory"
    } else if t.is_file() {
        "regular file"
    } else {
        "special file"
    }
}

/// Fsyncs a directory so a rename in it is durable (best effort: some file
/// systems refuse to open directories).
pub fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

/// Swaps two existing paths atomically (Linux `renameat2` with
/// `RENAME_EXCHANGE`): a reader of either path sees the old or the new entry,
/// never a gap. Returns `Ok(false)` where the system or file system cannot
/// (the caller then falls back on two renames).
pub fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::ffi::OsStrExt;
        let c = |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
        let (ca, cb) = (c(a)?, c(b)?);
        // SAFETY: both pointers are valid NUL-terminated strings for the call.
        let rc = unsafe { libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE) };
        if rc == 0 {
            return Ok(true);
        }
        let e = std::io::Error::last_os_error();
        match e.raw_os_error() {
            Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::EOPNOTSUPP) => Ok(false),
            _ => Err(e),
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = (a, b);
        Ok(false)
    }
}

/// Which step of [`write_dir_replacing`] failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirStep {
    /// Creating the parent or the staging directory (the path given).
    Create,
    /// Putting the staging directory in place of the output (the output given).
    Replace,
}

/// Writes the directory `dir` as a whole: `write` fills a staging directory
/// beside it (`.NAME.tmp-TOKEN`, locked while it is written), which then
/// replaces `dir` ([`replace_dir`]), so a reader sees the old directory or
/// the new one, never a mix, and a killed writer leaves the old one whole
/// (the next writer clears its leftovers). `name` is `dir`'s file name;
/// the caller has checked that `dir` may be replaced. `fail` makes the
/// caller's error for a failed step.
pub fn write_dir_replacing<T, E>(
    dir: &Path,
    name: &str,
    write: impl FnOnce(&Path) -> Result<T, E>,
    fail: impl Fn(DirStep, PathBuf, std::io::Error) -> E,
) -> Result<T, E> {
    let parent = parent_dir(dir).to_path_buf();
    std::fs::create_dir_all(&parent).map_err(|source| fail(DirStep::Create, parent.clone(), source))?;
    remove_abandoned_staging(&parent, name);
    let staging = parent.join(format!(".{name}.tmp-{}", unique_token()));
    std::fs::create_dir(&staging).map_err(|source| fail(DirStep::Create, staging.clone(), source))?;
    // Held while writing so that another writer does not clear it away.
    let lock = match File::open(&staging) {
        Ok(lock) => lock,
        Err(source) => {
            let _ = std::fs::remove_dir_all(&staging);
            return Err(fail(DirStep::Create, staging, source));
        }
    };
    // Best effort: where locks are unsupported, staging is judged by its age.
    let _ = lock.try_lock();
    let written = write(&staging).and_then(|out| {
        sync_dir(&staging);
        replace_dir(&staging, dir, &parent, name).map_err(|source| fail(DirStep::Replace, dir.to_path_buf(), source))?;
        Ok(out)
    });
    if written.is_err() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    drop(lock);
    written
}

/// Moves `staging` to `dir`: directly when `dir` is absent or empty, else
/// by an atomic exchange (Linux), else by moving the old directory aside
/// first and deleting it after (a moment without `dir`, never a mixed one).
fn replace_dir(staging: &Path, dir: &Path, parent: &Path, name: &str) -> std::io::Result<()> {
    match std::fs::rename(staging, dir) {
        Ok(()) => {}
        Err(_) if dir.is_dir() && exchange(staging, dir)? => {
            // `staging` now holds the old directory.
            let _ = std::fs::remove_dir_all(staging);
        }
        Err(_) if dir.is_dir() => {
            let old = parent.join(format!(".{name}.old-{}", unique_token()));
            std::fs::rename(dir, &old)?;
            if let Err(e) = std::fs::rename(staging, dir) {
                let _ = std::fs::rename(&old, dir);
                return Err(e);
            }
            let _ = std::fs::remove_dir_all(&old);
        }
        Err(e) => return Err(e),
    }
    sync_dir(parent);
    Ok(())
}

/// Removes staging and old directories of `name` left by killed writers
/// (no writer holds their lock, or they are stale).
fn remove_abandoned_staging(parent: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else { return };
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let left = is_temp_of(&file_name, name) || file_name.strip_prefix(&format!(".{name}.old-")).is_some_and(|t| !t.is_empty());
        if left && entry.path().is_dir() && is_abandoned(&entry.path()) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::sha256_file;

    #[test]
    fn tokens_are_unique_and_temp_names_recognised() {
        let a = unique_token();
        let b = unique_token();
        assert_ne!(a, b);
        let t = temp_path(Path::new("/x/summary.json"));
        let name = t.file_name().unwrap().to_string_lossy().into_owned();
        assert!(is_temp_of(&name, "summary.json"), "{name}");
        assert!(is_temp_of(".summary.json.tmp-1234", "summary.json"));
        assert!(!is_temp_of(".summary.json.tmp-", "summary.json"));
        assert!(!is_temp_of("summary.json.tmp-12", "summary.json"));
        assert!(!is_temp_of(".summary.json.tmp-1/2", "summary.json"));
    }

    #[test]
    fn atomic_write_leaves_no_temporary_on_failure() {
        let dir = tempfile::tempdir().unwrap();
        // Renaming a file onto a non-empty directory fails after the data is written.
        let target = dir.path().join("occupied");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("x"), b"x").unwrap();
        assert!(write_atomic(&target, b"data").is_err());
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("occupied")]);
        write_atomic(&dir.path().join("f"), b"ok").unwrap();
        assert_eq!(std::fs::read(dir.path().join("f")).unwrap(), b"ok");
        assert_eq!(sha256_file(&dir.path().join("f")).unwrap().len(), 64);
    }

    #[test]
    fn only_regular_files_are_written_over() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let regular = dir.path().join("regular");
        std::fs::write(&regular, b"old").unwrap();
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&regular, &link).unwrap();
        let fifo = dir.path().join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        for (path, kind) in [(&link, "symbolic link"), (&fifo, "FIFO (named pipe)"), (&sub, "directory")] {
            let e = write_atomic(path, b"new").unwrap_err();
            assert!(e.to_string().contains(&format!("{} is a {kind}, not a regular file", path.display())), "{e}");
        }
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        assert_eq!(std::fs::read(&regular).unwrap(), b"old");
        write_atomic(&regular, b"new").unwrap();
        write_atomic(&dir.path().join("fresh"), b"new").unwrap();
        assert_eq!(std::fs::read(&regular).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 5, "no temporaries left: {names:?}");
    }

    #[test]
    fn exchange_swaps_two_directories_or_says_it_cannot() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        for (d, f) in [(&a, "from_a"), (&b, "from_b")] {
            std::fs::create_dir(d).unwrap();
            std::fs::write(d.join(f), b"x").unwrap();
        }
        if exchange(&a, &b).unwrap() {
            assert!(a.join("from_b").exists() && b.join("from_a").exists());
        } else {
            eprintln!("WARNING: this file system cannot exchange atomically; maps are replaced by two renames");
            assert!(a.join("from_a").exists() && b.join("from_b").exists());
        }
    }

    #[test]
    fn a_temporary_is_locked_before_it_appears_under_its_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = temp_path(&dir.path().join("chunk.parquet"));
        let mut file = create_locked(&path).unwrap();
        file.write_all(b"data").unwrap();
        let names: Vec<String> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        assert_eq!(names, vec![path.file_name().unwrap().to_string_lossy().into_owned()]);
        assert_eq!(std::fs::read(&path).unwrap(), b"data", "the named file is the one written");
        assert!(!is_abandoned(&path), "a live writer's temporary is locked from the start");
        drop(file);
        assert!(is_abandoned(&path));
    }

    #[test]
    fn a_locked_temporary_is_live_and_an_unlocked_one_abandoned() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".x.tmp-1");
        let file = create_locked(&path).unwrap();
        assert!(!is_abandoned(&path));
        drop(file);
        assert!(is_abandoned(&path));
        assert!(!is_abandoned(&dir.path().join("gone")));
    }
}
