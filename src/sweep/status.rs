//! `cablemap status DIR`: what a run directory holds: rows done per shard,
//! failures by status, chunks in progress, and whether the run is complete.

use super::enumerate::SweepPlan;
use super::store::{Manifest, RunDir};
use super::SweepError;
use crate::model::STATUS_OK;
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
    /// Every row is written.
    pub complete: bool,
}

impl RunStatus {
    /// Written rows whose solve failed.
    pub fn failures(&self) -> u64 {
        self.status_counts.iter().filter(|(s, _)| s.as_str() != STATUS_OK).map(|(_, n)| n).sum()
    }
}

/// Reads and checks a run directory (manifest and every chunk footer).
pub fn run_status(dir: &Path) -> Result<RunStatus, SweepError> {
    let run = RunDir::new(dir);
    let manifest = run.read_manifest()?.ok_or_else(|| SweepError::NoRun { dir: dir.to_path_buf() })?;
    let plan = SweepPlan::new(&manifest.spec);
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
    let mut status_counts = BTreeMap::new();
    for info in scan.chunks.values() {
        let entry = &mut per_shard[plan.chunk_shard(info.chunk, shards) as usize];
        entry.chunks_done += 1;
        entry.rows_done += info.rows;
        for (status, n) in &info.status_counts {
            *status_counts.entry(status.clone()).or_insert(0) += n;
            if status != STATUS_OK {
                entry.failures += n;
            }
        }
    }
    let rows_done = per_shard.iter().map(|s| s.rows_done).sum();
    Ok(RunStatus {
        dir: dir.to_path_buf(),
        shards: per_shard,
        rows_done,
        rows_total: plan.total_rows(),
        status_counts,
        chunks_in_progress: scan.temporaries.len() as u64,
        complete: scan.chunks.len() as u64 == plan.chunks,
        manifest,
    })
}
