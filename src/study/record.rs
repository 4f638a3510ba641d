//! The study directory's record: `study.json` (the study and its
//! variants: written by [`StudySpec::prepare`], read by
//! [`mapped_variants`]) and each variant's `v{i}/spec.toml`.

use super::error::StudyError;
use super::spec::StudySpec;
use crate::io::FileError;
use std::path::{Path, PathBuf};

/// The study's record in its directory.
pub const STUDY_FILE: &str = "study.json";
/// Format tag of `study.json`.
pub const STUDY_FORMAT: &str = "cablemap-study/1";

impl StudySpec {
    /// The record written as `study.json`.
    fn record(&self) -> serde_json::Value {
        serde_json::json!({
            "format": STUDY_FORMAT,
            "name": self.name,
            "axes": self.axes.iter().map(|(n, k)| serde_json::json!({ "name": n, "values": k })).collect::<Vec<_>>(),
            "variants": self.variants.iter().map(|v| serde_json::json!({
                "index": v.index, "settings": v.settings, "label": v.label(), "spec_sha256": v.spec.hash_hex(),
                "dir": format!("v{}", v.index),
            })).collect::<Vec<_>>(),
        })
    }

    /// Prepares the study directory `dir`: writes `study.json` and each
    /// variant's `spec.toml` (refusing a directory of another study).
    pub fn prepare(&self, dir: &Path) -> Result<(), StudyError> {
        let io = |op: &'static str, path: &Path| FileError::on(op, path);
        std::fs::create_dir_all(dir).map_err(io("creating", dir))?;
        let path = dir.join(STUDY_FILE);
        let record = self.record();
        match std::fs::read(&path) {
            Ok(bytes) => {
                let existing: serde_json::Value = serde_json::from_slice(&bytes).unwrap_or_default();
                if existing["variants"] != record["variants"] {
                    return Err(StudyError::OtherStudy { dir: dir.to_path_buf() });
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let mut text = serde_json::to_string_pretty(&record).expect("serializes");
                text.push('\n');
                crate::io::write_atomic(&path, text.as_bytes()).map_err(io("writing", &path))?;
            }
            Err(e) => return Err(FileError::new("reading", path, e).into()),
        }
        for v in &self.variants {
            let vdir = v.dir(dir);
            std::fs::create_dir_all(&vdir).map_err(io("creating", &vdir))?;
            let spec_path = vdir.join("spec.toml");
            let text = format!(
                "# Variant {} of study '{}': {}\n# Written by `cablemap study`; `cablemap map` of this file gives the same run and map.\n{}",
                v.index,
                self.name,
                v.label(),
                toml::to_string(&v.spec).expect("a sweep spec serializes as TOML")
            );
            crate::io::write_atomic(&spec_path, text.as_bytes()).map_err(io("writing", &spec_path))?;
        }
        Ok(())
    }
}

/// Reads the study record of `dir` and the spec it was made from: the
/// variants' map directories, in order, with their labels.
pub fn mapped_variants(dir: &Path) -> Result<Vec<(usize, String, PathBuf)>, StudyError> {
    let path = dir.join(STUDY_FILE);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(StudyError::NoStudy { dir: dir.to_path_buf(), record: path }),
        Err(source) => return Err(FileError::new("reading", path, source).into()),
    };
    let v: serde_json::Value =
        serde_json::from_slice(&bytes).map_err(|source| StudyError::NotARecord { path: path.clone(), source })?;
    Ok(v["variants"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|x| {
            let index = x["index"].as_u64().unwrap_or(0) as usize;
            (
                index,
                x["label"].as_str().unwrap_or("").to_string(),
                dir.join(format!("v{index}")).join("map"),
            )
        })
        .collect())
}
