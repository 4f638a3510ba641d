//! `cablemap status DIR`: what a run directory holds: rows done per shard,
//! failures by status, chunks in progress, and whether the run is complete.

use super::store::{failures, total_status_counts, DamagedChunk, Manifest, RunDir};
use super::SweepError;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Progress of one shard.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShardStatus {
    /// Shard index.
    pub shard: u64,
    /// Chunk files written.
    pub chunks_done: u64,
    /// Chunks the shard owns.
    pub chunks_total: u64,
    /// Rows written.
    pub rows_done: u64,
    /// Rows the shard owns.
    pub rows_total: u64,
    /// Written rows whose solve failed.
    pub failures: u64,
}

/// The state of a run directory.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunStatus {
    /// The run directory.
    pub dir: PathBuf,
    /// The manifest.
    pub manifest: Manifest,
    /// One entry per shard.
    pub shards: Vec<ShardStatus>,
    /// Rows written over all shards.
    pub rows_done: u64,
    /// Rows of the complete sweep.
    pub rows_total: u64,
    /// Written rows per status (`ok` and failures).
    pub status_counts: BTreeMap<String, u64>,
    /// Temporary chunk files: chunks being written now, or left by a killed run.
    pub chunks_in_progress: u64,
    /// Chunk files that failed their checksum or footer check (not counted
    /// as done; the owning shard's rerun moves them aside and redoes them).
    pub damaged: Vec<DamagedChunk>,
    /// Every row is written.
    pub complete: bool,
}

impl RunStatus {
    /// Written rows whose solve failed.
    pub fn failures(&self) -> u64 {
        failures(&self.status_counts)
    }

    /// The record `cablemap status --json` prints (and `sweep --json` under
    /// "run"): the manifest's identity, not the whole spec.
    pub fn to_json_value(&self) -> serde_json::Value {
        let mut value = serde_json::json!({
            "dir": self.dir,
            "spec_sha256": self.manifest.spec_sha256,
            "tool_version": self.manifest.tool_version,
            "length_basis": self.manifest.length_basis,
            "rows_done": self.rows_done,
            "rows_total": self.rows_total,
            "failures": self.failures(),
            "status_counts": self.status_counts,
            "chunks_in_progress": self.chunks_in_progress,
            "damaged": self.damaged,
            "complete": self.complete,
            "shards": self.shards,
        });
        // Planar records stay as they were; other kinds say what they are.
        let format = self.manifest.spec.kind().format();
        if format != super::store::FORMAT {
            value["format"] = format.into();
        }
        value
    }
}

impl SweepError {
    /// The error for a directory without a sweep manifest, saying what the
    /// directory is instead: missing (with the runs beside it, for a typo in
    /// its name), or the parent of runs (`cablemap map --out DIR` keeps its
    /// sweep in `DIR/run`), so the advice points at the run, not at a new
    /// sweep into a folder the sweep would refuse.
    pub fn no_run(dir: &Path) -> Self {
        let runs_in = |d: &Path| -> Vec<PathBuf> {
            crate::io::subdirs_holding(d, super::store::MANIFEST).into_iter().filter(|p| crate::io::is_run_dir(p)).collect()
        };
        if std::fs::symlink_metadata(dir).is_err() {
            let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            return SweepError::NoRunDir { dir: dir.to_path_buf(), runs_beside: runs_in(parent) };
        }
        SweepError::NoRun { dir: dir.to_path_buf(), runs_inside: runs_in(dir) }
    }
}

/// The text of [`SweepError::NoRun`].
pub(super) fn no_run_text(dir: &Path, runs_inside: &[PathBuf]) -> String {
    let list = || runs_inside.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
    match runs_inside {
        [] => format!(
            "{} holds no sweep: {} is missing (run `cablemap sweep SPEC --out {}` first)",
            dir.display(),
            dir.join(super::store::MANIFEST).display(),
            dir.display()
        ),
        [run] if run.file_name().is_some_and(|n| n == "run") => format!(
            "{} holds no sweep itself: it is the folder `cablemap map --out {}` writes, whose sweep is {}; give {}",
            dir.display(),
            dir.display(),
            run.display(),
            run.display()
        ),
        _ => format!("{} holds no sweep itself, but the run directories inside it do: give one of {}", dir.display(), list()),
    }
}

/// The end of [`SweepError::NoRunDir`]'s text: the run directories beside
/// the missing one, if any.
pub(super) fn runs_beside_text(runs_beside: &[PathBuf]) -> String {
    if runs_beside.is_empty() {
        return String::new();
    }
    let list: Vec<String> = runs_beside.iter().map(|p| p.display().to_string()).collect();
    format!(" (the run directories beside it: {}; a typo?)", list.join(", "))
}

/// Reads and checks a run directory of any kind (manifest and every chunk footer).
pub fn run_status(dir: &Path) -> Result<RunStatus, SweepError> {
    let run = RunDir::new(dir);
    let manifest: Manifest = run.read_manifest()?.ok_or_else(|| SweepError::no_run(dir))?;
    let plan = manifest.spec.layout();
    let scan = run.scan(&manifest)?;
    let shards = manifest.shards.max(1);
    let mut per_shard: Vec<ShardStatus> = (0..shards)
        .map(|s| ShardStatus {
            shard: s,
            chunks_done: 0,
            chunks_total: plan.shard_chunks(s, shards).count() as u64,
            rows_done: 0,
            rows_total: plan.shard_rows(s, shards),
            failures: 0,
        })
        .collect();
    for info in scan.chunks.values() {
        let entry = &mut per_shard[plan.chunk_shard(info.chunk, shards) as usize];
        entry.chunks_done += 1;
        entry.rows_done += info.rows;
        entry.failures += failures(&info.status_counts);
    }
    let status_counts = total_status_counts(scan.chunks.values());
    let rows_done = per_shard.iter().map(|s| s.rows_done).sum();
    Ok(RunStatus {
        dir: dir.to_path_buf(),
        shards: per_shard,
        rows_done,
        rows_total: plan.total_rows(),
        status_counts,
        chunks_in_progress: scan.temporaries.len() as u64,
        damaged: scan.damaged,
        complete: scan.chunks.len() as u64 == plan.chunks,
        manifest,
    })
}
