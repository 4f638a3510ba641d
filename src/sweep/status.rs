//! `cablemap status DIR`: what a run directory holds: rows done per shard,
//! failures by status, chunks in progress, and whether the run is complete.

use super::kind::RunSpec;
use super::spec::SweepSpec;
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
pub struct RunStatus<S = SweepSpec> {
    /// The run directory.
    pub dir: PathBuf,
    /// The manifest.
    pub manifest: Manifest<S>,
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

impl<S: RunSpec> RunStatus<S> {
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
        if S::FORMAT != super::store::FORMAT {
            value["format"] = S::FORMAT.into();
        }
        value
    }
}

/// Reads and checks a run directory (manifest and every chunk footer).
pub fn run_status(dir: &Path) -> Result<RunStatus, SweepError> {
    run_status_of::<SweepSpec>(dir)
}

/// [`run_status`] for a sweep of kind `S`.
pub fn run_status_of<S: RunSpec>(dir: &Path) -> Result<RunStatus<S>, SweepError> {
    let run = RunDir::new(dir);
    let manifest: Manifest<S> = run.read_manifest()?.ok_or_else(|| SweepError::NoRun { dir: dir.to_path_buf() })?;
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
