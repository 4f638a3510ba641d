//! The sweep engine: solves one shard's chunks in parallel and writes each
//! chunk as soon as it is complete. Re-running the same command resumes:
//! chunk files already in place are checked (footer and checksum) and
//! skipped, damaged ones are moved to DIR/damaged and redone, missing ones
//! are computed, so the output never holds a duplicate or a missing row.
//! Temporary files are removed only when abandoned ([`crate::io::is_abandoned`]:
//! their writer's lock is gone): a locked one belongs to a live copy of the
//! same shard (a retried pod, a requeued array task), whose writes are unique
//! to it and idempotent.
//!
//! Parallelism is two-level with rayon: chunks in parallel, and the routings
//! of a chunk in parallel (so a shard with a single chunk still uses every
//! thread). Each worker has its own solver state ([`RunSpec::Worker`]); a
//! routing is solved cold (`sweep::solve`), independent of every other
//! routing, so results do not depend on threads or shards. Memory is
//! bounded by the chunks in flight, not by the number of rows.

use super::kind::{ChunkLayout, RunSpec};
use super::progress::{Progress, ProgressMode};
use super::spec::{RoutingGrid, SweepSpec};
use super::store::{total_status_counts, ChunkInfo, Manifest, RunDir};
use super::SweepError;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How to run a sweep.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// This process's shard, 0-based.
    pub shard: u64,
    /// Number of shards the sweep is split into.
    pub shards: u64,
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
    /// Progress display.
    pub progress: ProgressMode,
    /// Accept a sweep of more than [`super::kind::MAX_ROWS`] rows.
    pub allow_large: bool,
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self { shard: 0, shards: 1, threads: None, progress: ProgressMode::Auto, allow_large: false }
    }
}

/// Most worker threads per core: more only adds switching (10 000 threads
/// made a 610-solve job take over a minute), so larger requests are capped.
pub const MAX_THREADS_PER_CORE: usize = 4;

/// Most shards a sweep may be split into. Status keeps a line per shard
/// and a shard per chunk file is the finest useful split; far beyond any
/// cluster array (SLURM's default MaxArraySize is 1001).
pub const MAX_SHARDS: u64 = 1_000_000;

/// Estimated bytes the engine keeps per chunk file of the run: the shard's
/// chunk lists and, for each chunk found, its path and status counts (scan,
/// resume, status).
const CHUNK_TABLE_BYTES: u64 = 512;

/// Estimated bytes of one shard's line in a status.
const SHARD_STATUS_BYTES: u64 = 64;

/// Refuses, before anything is allocated or written, a sweep whose
/// estimated memory (chunks being built, one per thread, and the tables of
/// chunk files and shards) is more than the machine has available, unless
/// `allow_large`. The message gives the figures and what to change.
fn check_memory(spec: &SweepSpec, shards: u64, threads: usize, allow_large: bool) -> Result<(), SweepError> {
    let layout = spec.layout();
    let chunk_rows = layout.chunk_routings.min(layout.routings).saturating_mul(layout.tensions);
    let chunk_bytes = chunk_rows.saturating_mul(spec.row_bytes());
    let in_flight = (threads as u64).clamp(1, layout.chunks.max(1));
    let building = in_flight.saturating_mul(chunk_bytes);
    let tables = layout.chunks.saturating_mul(CHUNK_TABLE_BYTES).saturating_add(shards.saturating_mul(SHARD_STATUS_BYTES));
    let needed = building.saturating_add(tables);
    let Some(available) = crate::io::available_memory_bytes() else { return Ok(()) };
    if needed <= available || allow_large {
        return Ok(());
    }
    let advice = if tables >= building { MemoryAdvice::FewerChunks { chunk_routings: layout.chunk_routings } } else { MemoryAdvice::SmallerChunks };
    Err(SweepError::TooMuchMemory {
        needed_bytes: needed,
        available_bytes: available,
        in_flight,
        chunk_rows,
        chunk_bytes,
        chunks: layout.chunks,
        tables_bytes: tables,
        advice,
    })
}

/// What to change when a sweep needs more memory than is free.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MemoryAdvice {
    /// The chunk and shard tables dominate: fewer, larger chunks.
    #[error("raise output.chunk_routings (now {chunk_routings}) for fewer, larger chunk files")]
    FewerChunks {
        /// The spec's routings per chunk.
        chunk_routings: u64,
    },
    /// The chunks being built dominate: smaller chunks or fewer threads.
    #[error("lower output.chunk_routings or the thread count (--threads)")]
    SmallerChunks,
}

/// The thread count to use for a request of `requested` threads (`None`:
/// one per core), capped at [`MAX_THREADS_PER_CORE`] per core. Returns the
/// count and whether it was capped.
pub fn capped_threads(requested: Option<usize>) -> (Option<usize>, bool) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match requested {
        Some(n) if n > MAX_THREADS_PER_CORE * cores => (Some(MAX_THREADS_PER_CORE * cores), true),
        other => (other, false),
    }
}

/// What a sweep invocation did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SweepSummary {
    /// The run directory.
    pub dir: PathBuf,
    /// This shard.
    pub shard: u64,
    /// Shard count.
    pub shards: u64,
    /// Worker threads used.
    pub threads: usize,
    /// Rows this shard owns.
    pub shard_rows: u64,
    /// Rows solved and written by this invocation.
    pub rows_written: u64,
    /// Rows found already written (resumed).
    pub rows_skipped: u64,
    /// Chunk files written by this invocation.
    pub chunks_written: u64,
    /// Chunk files found already written.
    pub chunks_skipped: u64,
    /// Abandoned temporary files of interrupted chunks that were removed.
    pub partial_chunks_removed: u64,
    /// Damaged chunk files of this shard moved to DIR/damaged and recomputed.
    pub damaged_chunks_redone: u64,
    /// Rows per status over this shard (all of its rows).
    pub status_counts: BTreeMap<String, u64>,
    /// Wall time of this invocation, s.
    pub wall_s: f64,
    /// Rows written per second of wall time.
    pub solves_per_s: f64,
}

impl SweepSummary {
    /// Rows of this shard whose solve failed.
    pub fn failures(&self) -> u64 {
        super::store::failures(&self.status_counts)
    }
}

/// Runs (or resumes) shard `options.shard` of `spec` (of any kind) into `dir`.
pub fn run_sweep(spec: &SweepSpec, dir: &Path, options: &SweepOptions) -> Result<SweepSummary, SweepError> {
    let started = Instant::now();
    spec.validate().map_err(|source| SweepError::BadSpec { origin: "(in memory)".into(), source })?;
    let (shard, shards) = (options.shard, options.shards);
    if shards == 0 || shard >= shards {
        return Err(SweepError::BadShard { shard, shards });
    }
    if shards > MAX_SHARDS {
        return Err(SweepError::TooManyShards { shards, chunks: spec.layout().chunks });
    }
    if options.threads == Some(0) {
        return Err(SweepError::NoThreads);
    }
    spec.check_size(options.allow_large)?;
    let (threads_wanted, capped) = capped_threads(options.threads);
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    check_memory(spec, shards, threads_wanted.unwrap_or(cores), options.allow_large)?;
    if let Some(run) = crate::io::enclosing_run_dir(dir) {
        if std::fs::canonicalize(dir).ok().as_ref() != Some(&run) {
            return Err(SweepError::InsideRun { dir: dir.to_path_buf(), run });
        }
    }
    if capped && options.progress != ProgressMode::Quiet {
        eprintln!(
            "sweep: --threads {} is more than {MAX_THREADS_PER_CORE} per core; using {}",
            options.threads.unwrap_or(0),
            threads_wanted.unwrap_or(0)
        );
    }
    let run = RunDir::new(dir);
    let manifest = run.create_or_check(spec, shards)?;
    let plan: ChunkLayout = spec.layout();
    let scan = run.scan(&manifest)?;

    // Temporaries: an abandoned one is left by a killed writer; a locked one
    // is a live copy of this shard writing right now (its name is unique to
    // it), so it is left alone. Either way the chunk is absent and redone.
    let mut partial_chunks_removed = 0;
    for (_, path) in &scan.temporaries {
        if crate::io::is_abandoned(path) {
            match std::fs::remove_file(path) {
                Ok(()) => partial_chunks_removed += 1,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(source) => return Err(crate::io::FileError::new("removing", path, source).into()),
            }
        }
    }
    // Damaged chunks of this shard are moved aside and redone; those of
    // other shards are named (their own shard's rerun redoes them).
    let mut damaged_chunks_redone = 0;
    for damaged in &scan.damaged {
        let owner = plan.chunk_shard(damaged.chunk, shards);
        if owner == shard {
            let to = run.move_aside(damaged)?;
            damaged_chunks_redone += 1;
            if options.progress != ProgressMode::Quiet || to.is_some() {
                eprintln!(
                    "sweep shard {shard}/{shards}: chunk {} is damaged ({}): moved to {} and recomputing it",
                    damaged.path.display(),
                    damaged.reason,
                    to.map_or_else(|| "(already moved)".into(), |p| p.display().to_string())
                );
            }
        } else {
            eprintln!(
                "sweep shard {shard}/{shards}: warning: chunk {} of shard {owner} is damaged ({}): rerun shard {owner} to recompute it",
                damaged.path.display(),
                damaged.reason
            );
        }
    }
    let own: Vec<u64> = plan.shard_chunks(shard, shards).collect();
    let done: Vec<&ChunkInfo> = own.iter().filter_map(|c| scan.chunks.get(c)).collect();
    let pending: Vec<u64> = own.iter().copied().filter(|c| !scan.chunks.contains_key(c)).collect();
    let rows_skipped: u64 = done.iter().map(|c| c.rows).sum();
    let shard_rows = plan.shard_rows(shard, shards);

    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads_wanted {
        builder = builder.num_threads(n);
    }
    let pool = builder.build()?;
    let threads = pool.current_num_threads();

    let label = format!("sweep shard {shard}/{shards}");
    if options.progress != ProgressMode::Quiet {
        // Short lines: a terminal of 80 columns must not wrap them.
        eprintln!("{label}: {} of {} chunks to do, {} rows", pending.len(), own.len(), shard_rows - rows_skipped);
        eprintln!(
            "  ({rows_skipped} of {shard_rows} already written; {threads} thread{}; output {})",
            if threads == 1 { "" } else { "s" },
            dir.display()
        );
    }
    let progress = Progress::new(options.progress, label, shard_rows, rows_skipped);

    let chunks = Chunks { run: &run, manifest: &manifest, plan, pending: &pending, progress: &progress };
    let written = pool.install(|| match &spec.routings {
        RoutingGrid::Planar(grid) => chunks.solve(grid, spec),
        RoutingGrid::Cables(grid) => chunks.solve(grid, spec),
    })?;
    progress.finish();

    let status_counts = total_status_counts(done.iter().copied().chain(&written));
    let rows_written: u64 = written.iter().map(|c| c.rows).sum();
    let wall_s = started.elapsed().as_secs_f64();
    Ok(SweepSummary {
        dir: dir.to_path_buf(),
        shard,
        shards,
        threads,
        shard_rows,
        rows_written,
        rows_skipped,
        chunks_written: written.len() as u64,
        chunks_skipped: done.len() as u64,
        partial_chunks_removed,
        damaged_chunks_redone,
        status_counts,
        wall_s,
        solves_per_s: rows_written as f64 / wall_s.max(1e-9),
    })
}

/// The chunks a shard still has to solve and write.
struct Chunks<'a> {
    run: &'a RunDir,
    manifest: &'a Manifest,
    plan: ChunkLayout,
    pending: &'a [u64],
    progress: &'a Progress,
}

impl Chunks<'_> {
    /// Solves and writes the pending chunks of a sweep of kind `K` (in
    /// parallel: the chunks, and the routings of each chunk).
    fn solve<K: RunSpec + Sync>(&self, kind: &K, spec: &SweepSpec) -> Result<Vec<ChunkInfo>, SweepError> {
        let (solver, output) = (&spec.solver, &spec.output);
        let prototype = kind.worker(solver)?;
        let schema = kind.schema(output);
        let plan = self.plan;
        self.pending
            .par_iter()
            .map(|&chunk| {
                let routings = plan
                    .chunk_ids(chunk)
                    .into_par_iter()
                    .map_init(
                        || prototype.clone(),
                        |worker, id| {
                            let solved = kind.solve(solver, output, worker, id);
                            self.progress.add(plan.tensions);
                            solved
                        },
                    )
                    .collect::<Result<Vec<_>, _>>()?;
                let batch = kind.batch(output, &schema, &routings);
                self.run.write_chunk(self.manifest, chunk, &batch)
            })
            .collect()
    }
}
