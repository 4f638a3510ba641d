//! Small file helpers shared by every stage.

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

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
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
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
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

/// What marks a directory as a sweep run: its manifest's file name and
/// each kind's format tag. The one owner of these markers: the sweep engine
/// writes them from here ([`crate::sweep::store`], [`crate::sweep::spec`])
/// and [`is_run_dir`] recognises them from here, so a new kind of run is
/// protected from stray outputs as soon as its tag is added.
pub mod run_markers {
    /// Manifest file name in a run directory.
    pub const MANIFEST: &str = "manifest.json";
    /// Format tag of planar single-cable sweep runs. Version 2: the a_i
    /// columns are in the basis the manifest names (`length_basis`, the
    /// thesis's rest-length basis by default); version 1 runs had
    /// deformed-length a_i and no such field.
    pub const PLANAR_FORMAT: &str = "cablemap-sweep/2";
    /// Format tag of sweeps of several or spatial cables.
    pub const CABLES_FORMAT: &str = "cablemap-cables/1";
    /// Every kind's current tag.
    pub const FORMATS: [&str; 2] = [PLANAR_FORMAT, CABLES_FORMAT];

    /// The family of a format tag: its text up to and including the `/`
    /// before the version (`cablemap-sweep/`), so runs of every version of
    /// a kind are recognised.
    pub fn family(format: &str) -> &str {
        format.find('/').map_or(format, |k| &format[..=k])
    }
}

/// Bytes of a manifest read to find its format tag: the tag is its first
/// key, so a user's huge file named `manifest.json` is never read whole.
const MANIFEST_HEAD_BYTES: u64 = 64 << 10;

/// Whether `dir` is a sweep run directory of any kind: its manifest's
/// `format` names a run kind of [`run_markers::FORMATS`] (any version).
/// The tag is found in the text rather than by parsing the JSON, so a
/// damaged (truncated) manifest still marks the run; a `manifest.json` of
/// something else that only mentions a tag elsewhere does not.
pub fn is_run_dir(dir: &Path) -> bool {
    use std::io::Read;
    let Ok(file) = File::open(dir.join(run_markers::MANIFEST)) else { return false };
    let mut head = Vec::new();
    if file.take(MANIFEST_HEAD_BYTES).read_to_end(&mut head).is_err() {
        return false;
    }
    manifest_format(&String::from_utf8_lossy(&head)).is_some_and(|format| {
        run_markers::FORMATS.iter().any(|kind| format.starts_with(run_markers::family(kind)))
    })
}

/// The string value of the first `"format"` key of a JSON text
/// (`"format": "cablemap-sweep/2"` → `cablemap-sweep/2`), whatever follows.
fn manifest_format(text: &str) -> Option<&str> {
    let mut rest = text;
    while let Some(k) = rest.find("\"format\"") {
        rest = rest[k + "\"format\"".len()..].trim_start();
        if let Some(value) = rest.strip_prefix(':').map(str::trim_start).and_then(|v| v.strip_prefix('"')) {
            return value.find('"').map(|end| &value[..end]);
        }
    }
    None
}

/// The sweep run directory that `path` is, or lies inside at any depth,
/// if any. The path is resolved through its deepest existing ancestor
/// (symbolic links and `..` included), so `RUN/shards/new/map`,
/// `RUN/../RUN/x` and a relative path from inside the run are all found.
pub fn enclosing_run_dir(path: &Path) -> Option<PathBuf> {
    let mut existing = path;
    let resolved = loop {
        if let Ok(p) = std::fs::canonicalize(existing) {
            break p;
        }
        let parent = parent_dir(existing);
        if parent == existing {
            return None;
        }
        existing = parent;
    };
    resolved.ancestors().find(|d| is_run_dir(d)).map(Path::to_path_buf)
}

/// An output that is, or lies inside, a sweep run directory
/// ([`check_outside_run_dir`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} {} {} the sweep run directory {}; writing there would make the run unusable: give a path outside the run",
    out.display(),
    if *is_the_run { "is" } else { "is inside" },
    run.display()
)]
pub struct InsideRunDir {
    /// What the output is, for the message (e.g. "the map directory").
    pub what: String,
    /// The output asked for.
    pub out: PathBuf,
    /// The run directory it is or lies in.
    pub run: PathBuf,
    /// The output is the run directory itself.
    pub is_the_run: bool,
}

/// Refuses an output (a directory or a file) that is a sweep run
/// directory or lies inside one at any depth: the run would then hold
/// files cablemap's checks reject, or lose its own, and be unusable until
/// cleaned by hand. `what` names the output in the message (the command
/// line adds its flag).
pub fn check_outside_run_dir(out: &Path, what: &str) -> Result<(), InsideRunDir> {
    let Some(run) = enclosing_run_dir(out) else { return Ok(()) };
    let is_the_run = std::fs::canonicalize(out).is_ok_and(|o| o == run);
    Err(InsideRunDir { what: what.to_string(), out: out.to_path_buf(), run, is_the_run })
}

/// A file operation that failed: which file, what was being done, and why.
/// The one I/O error of every layer, so each names the path the same way
/// (as a path, not a pre-formatted string) and keeps the cause.
#[derive(Debug, thiserror::Error)]
#[error("{op} {}: {source}", path.display())]
pub struct FileError {
    /// The file or directory.
    pub path: PathBuf,
    /// What was being done, as a verb phrase before the path ("reading", "writing", "creating").
    pub op: &'static str,
    /// The cause.
    pub source: std::io::Error,
}

impl FileError {
    /// The error of `op` on `path`.
    pub fn new(op: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self { path: path.into(), op, source }
    }

    /// A closure for `map_err`: `std::fs::read(p).map_err(FileError::on("reading", p))`.
    pub fn on(op: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.to_path_buf();
        move |source| Self { path, op, source }
    }

    /// Whether the cause is a missing file.
    pub fn is_not_found(&self) -> bool {
        self.source.kind() == std::io::ErrorKind::NotFound
    }
}

/// [`read_utf8`] with the path in the error.
pub fn read_text(path: &Path, op: &'static str) -> Result<String, FileError> {
    read_utf8(path).map_err(FileError::on(op, path))
}

/// A number for a message: plain for ordinary magnitudes, scientific for
/// extreme ones (1e308 is not printed as 309 digits).
pub fn fmt_num(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A byte count for a message, in binary units: `512 B`, `3.2 MiB`, `236.7 GiB`.
pub fn fmt_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// Memory this process may still use, bytes: the kernel's estimate of
/// available memory (`MemAvailable`), or less where a cgroup (a container,
/// a SLURM job) limits the process more. `None` where neither can be read
/// (then no size is refused for memory alone).
pub fn available_memory_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|text| {
        let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib.saturating_mul(1024))
    });
    let read_u64 = |path: &str| std::fs::read_to_string(path).ok().and_then(|t| t.trim().parse::<u64>().ok());
    // cgroup v2, then v1 (whose "no limit" is a huge number, harmless here).
    let cgroup = match (read_u64("/sys/fs/cgroup/memory.max"), read_u64("/sys/fs/cgroup/memory.current")) {
        (Some(max), Some(current)) => Some(max.saturating_sub(current)),
        _ => match (read_u64("/sys/fs/cgroup/memory/memory.limit_in_bytes"), read_u64("/sys/fs/cgroup/memory/memory.usage_in_bytes")) {
            (Some(max), Some(current)) => Some(max.saturating_sub(current)),
            _ => None,
        },
    };
    match (meminfo, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// A number rounded to `digits` significant digits for people to read (whole
/// numbers keep their integer digits: 1234, not 1230):
/// plain decimal for ordinary magnitudes (1e-4 ≤ |v| < 1e6), scientific
/// otherwise, trailing zeros dropped (`1.54`, `-0.01235`, `3.2e-7`, not
/// `1.5400e0` or `-0.012345678901234567`). Files keep full precision.
pub fn fmt_sig(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = digits.max(1);
    let trim = |m: &str| if m.contains('.') { m.trim_end_matches('0').trim_end_matches('.').to_string() } else { m.to_string() };
    if !(1e-4..1e6).contains(&v.abs()) {
        let text = format!("{v:.prec$e}", prec = digits - 1);
        let (mantissa, exponent) = text.split_once('e').expect("scientific format has an exponent");
        return format!("{}e{exponent}", trim(mantissa));
    }
    let decimals = (digits as i32 - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    trim(&format!("{v:.decimals$}"))
}

/// The subdirectories of `dir` that hold a file named `file` (sorted; none
/// when `dir` is unreadable): where a user who gave the parent of a run or a
/// map meant to point.
pub fn subdirs_holding(dir: &Path, file: &str) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut found: Vec<PathBuf> = entries.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.join(file).is_file()).collect();
    found.sort();
    found
}

/// Reads a UTF-8 text file. A file in another encoding (Latin-1, UTF-16
/// from a spreadsheet) is an error saying so and how to fix it, instead of
/// the bare "stream did not contain valid UTF-8".
pub fn read_utf8(path: &Path) -> std::io::Result<String> {
    let bytes = std::fs::read(path)?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "the file is not UTF-8 text (invalid byte 0x{:02x} at offset {at}): save it as UTF-8, e.g. \
                 `iconv -f latin1 -t utf-8 FILE > FILE.utf8`",
                e.as_bytes()[at]
            ),
        )
    })
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

/// SHA-256 of a file's bytes, hex.
pub fn sha256_file(path: &Path) -> std::io::Result<String> {
    use sha2::{Digest, Sha256};
    let mut file = File::open(path)?;
    let mut hasher = Sha256::new();
    std::io::copy(&mut file, &mut hasher)?;
    Ok(hex(&hasher.finalize()))
}

/// Lower-case hex of `bytes`.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_for_people_have_the_significant_digits_asked_for() {
        assert_eq!(fmt_sig(1.54, 3), "1.54");
        assert_eq!(fmt_sig(1.5400000001, 5), "1.54");
        assert_eq!(fmt_sig(-0.012345678901234567, 4), "-0.01235");
        assert_eq!(fmt_sig(115.1172, 5), "115.12");
        assert_eq!(fmt_sig(12345.67, 5), "12346");
        assert_eq!(fmt_sig(9.99996, 5), "10");
        assert_eq!(fmt_sig(3.2e-7, 3), "3.2e-7");
        assert_eq!(fmt_sig(-4.56789e8, 3), "-4.57e8");
        assert_eq!(fmt_sig(0.0, 3), "0");
        assert_eq!(fmt_sig(f64::NAN, 3), "NaN");
    }

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
    fn run_directories_of_either_kind_are_found_at_any_depth() {
        let dir = tempfile::tempdir().unwrap();
        for (name, format) in [("planar", run_markers::PLANAR_FORMAT), ("cables", run_markers::CABLES_FORMAT)] {
            let run = dir.path().join(name);
            std::fs::create_dir_all(run.join("shards")).unwrap();
            std::fs::write(run.join("manifest.json"), format!("{{\"format\": \"{format}\"}}")).unwrap();
            let run = std::fs::canonicalize(&run).unwrap();
            for inside in ["", "manifest.json", "shards/map", "shards/new/deeper/map", "shards/../x"] {
                let path = run.join(inside);
                assert_eq!(enclosing_run_dir(&path), Some(run.clone()), "{}", path.display());
                let e = check_outside_run_dir(&path, "the map directory").unwrap_err().to_string();
                assert!(
                    e.contains("sweep run directory") && e.contains(if inside.is_empty() { " is the " } else { " is inside the " }),
                    "{e}"
                );
            }
            assert!(write_atomic(&run.join("shards/x.csv"), b"x").is_err());
            write_atomic_in_run(&run.join("shards/x.csv"), b"x").unwrap();
        }
        assert_eq!(enclosing_run_dir(&dir.path().join("elsewhere/map")), None);
        assert!(check_outside_run_dir(Path::new("relative/new/map"), "x").is_ok());
    }

    /// A run is told by its manifest's `format`, of any version and even
    /// when the manifest is cut short; a `manifest.json` of something else
    /// is not a run for mentioning a tag in another field.
    #[test]
    fn a_run_is_told_by_its_manifests_format_key() {
        let dir = tempfile::tempdir().unwrap();
        for (manifest, is_run) in [
            (r#"{"format": "cablemap-cables/1", "tool_version": "0.1.0"}"#, true),
            ("{\n  \"format\" : \"cablemap-sweep/1\",\n  \"spec\": {", true),
            (r#"{"format":"cablemap-cables/7"}"#, true),
            (r#"{"format": "cablemap-map/1"}"#, false),
            (r#"{"format": "photos/3", "note": "made from cablemap-sweep/2 and cablemap-cables/1 runs"}"#, false),
            (r#"{"name": "cablemap-cables/1"}"#, false),
            ("", false),
        ] {
            std::fs::write(dir.path().join(run_markers::MANIFEST), manifest).unwrap();
            assert_eq!(is_run_dir(dir.path()), is_run, "{manifest}");
        }
    }

    #[test]
    fn byte_counts_read_in_binary_units() {
        assert_eq!(fmt_bytes(512), "512 B");
        assert_eq!(fmt_bytes(512 << 20), "512.0 MiB");
        assert_eq!(fmt_bytes(u64::MAX), "16384.0 PiB");
        assert!(available_memory_bytes().is_none_or(|b| b > 0));
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
