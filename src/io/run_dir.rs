//! What marks a directory as a sweep run, and the refusal to write an
//! output inside one.

use super::parent_dir;
use std::fs::File;
use std::path::{Path, PathBuf};

/// What marks a directory as a sweep run: its manifest's file name and
/// each kind's format tag. The one owner of these markers: the sweep engine
/// writes them from here (`sweep::store`, `sweep::spec`)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{write_atomic, write_atomic_in_run};

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
}
