//! Small file helpers shared by every stage, one job per file:
//!
//! - [`atomic`]: files and directories written atomically (temporaries,
//!   locks, rename into place);
//! - [`run_dir`]: what marks a sweep run directory, and the refusal to
//!   write inside one;
//! - [`read`]: reading UTF-8 text with a typed error naming the path;
//! - [`format`]: numbers, byte counts and settings' names for people;
//! - [`memory`]: the memory still available;
//! - [`sha256`]: file digests.

pub mod atomic;
pub mod format;
pub mod memory;
pub mod read;
pub mod run_dir;
pub mod sha256;

pub use atomic::{
    check_regular_or_new, create_locked, exchange, is_abandoned, is_stale, is_temp_of, sync_dir, temp_path, unique_token, write_atomic,
    write_atomic_in_run, write_dir_replacing, DirStep, STALE_TEMP_S,
};
pub use format::{fmt_bytes, fmt_num, fmt_sig, SettingNames};
pub use memory::available_memory_bytes;
pub use read::{read_text, read_utf8, subdirs_holding, FileError, SharedIoError};
pub use run_dir::{check_outside_run_dir, enclosing_run_dir, is_run_dir, run_markers, InsideRunDir};
pub use sha256::{hex, sha256_file};

use std::path::Path;

/// The directory `path` lies in (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}
