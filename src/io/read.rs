//! Reading files: UTF-8 text with a typed error naming the path, and the
//! subdirectories holding a given file.

use std::path::{Path, PathBuf};

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

/// An I/O error that can be cloned and compared, for the errors that are
/// (the model's): the cause is shared, and two are equal when they say the
/// same thing of the same kind.
#[derive(Debug, Clone, thiserror::Error)]
#[error(transparent)]
pub struct SharedIoError(pub std::sync::Arc<std::io::Error>);

impl PartialEq for SharedIoError {
    fn eq(&self, other: &Self) -> bool {
        self.0.kind() == other.0.kind() && self.0.to_string() == other.0.to_string()
    }
}

impl From<std::io::Error> for SharedIoError {
    fn from(e: std::io::Error) -> Self {
        SharedIoError(std::sync::Arc::new(e))
    }
}

/// [`read_utf8`] with the path in the error.
pub fn read_text(path: &Path, op: &'static str) -> Result<String, FileError> {
    read_utf8(path).map_err(FileError::on(op, path))
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
