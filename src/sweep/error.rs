//! Why a sweep, a status query or a read failed.

use super::{kind, run, spec, status, store};
use crate::io::fmt_bytes;
use std::path::PathBuf;

/// Why a sweep, a status query or a read failed. Messages name the file or
/// setting and what to do.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The job spec is malformed or invalid.
    #[error("bad sweep spec {origin}: {source}")]
    BadSpec {
        /// The spec file, or where an in-memory spec came from.
        origin: String,
        /// What is wrong.
        source: spec::SpecError,
    },
    /// The whole sweep is larger than a sweep may be without `--allow-large`.
    #[error(
        "bad sweep spec (size): the sweep has {rows} rows ({routings} routings × {per_routing} {}), more than {}: check {}, or pass \
         --allow-large if the job is meant to be this big",
        counted.per_routing(),
        kind::MAX_ROWS,
        counted.settings()
    )]
    TooLarge {
        /// Rows of the sweep.
        rows: u64,
        /// Routings.
        routings: u64,
        /// Rows per routing.
        per_routing: u64,
        /// What the kind of sweep counts per routing, and where it is set.
        counted: kind::RowsCounted,
    },
    /// Shard index or count out of range.
    #[error("shard {shard} of {shards} is out of range: use 0 ≤ shard < shards (shards ≥ 1)")]
    BadShard { shard: u64, shards: u64 },
    /// More shards than a sweep may be split into.
    #[error(
        "a sweep is split into at most {} shards, not {shards}: use fewer shards (a shard per chunk file, {chunks} here, is the \
         finest useful split)",
        run::MAX_SHARDS
    )]
    TooManyShards {
        /// The shard count asked for.
        shards: u64,
        /// The run's chunk files.
        chunks: u64,
    },
    /// The sweep would need more memory than the machine has free.
    #[error(
        "the sweep would need about {} of memory, more than the {} available: {in_flight} chunk(s) of {chunk_rows} rows built at \
         once ({} each) and the tables of its {chunks} chunk files ({}): {advice}, or pass --allow-large to run it anyway",
        fmt_bytes(*needed_bytes),
        fmt_bytes(*available_bytes),
        fmt_bytes(*chunk_bytes),
        fmt_bytes(*tables_bytes)
    )]
    TooMuchMemory {
        /// Memory the sweep would take, bytes.
        needed_bytes: u64,
        /// Memory available, bytes.
        available_bytes: u64,
        /// Chunks built at once.
        in_flight: u64,
        /// Rows per chunk.
        chunk_rows: u64,
        /// Memory of one chunk while it is built, bytes.
        chunk_bytes: u64,
        /// Chunk files of the run.
        chunks: u64,
        /// Memory of the run's chunk and shard tables, bytes.
        tables_bytes: u64,
        /// What to lower or raise.
        advice: run::MemoryAdvice,
    },
    /// The run directory would lie inside another run directory.
    #[error(
        "{} is inside the sweep run directory {}; a run there would make that run unusable: give a directory outside the run",
        dir.display(),
        run.display()
    )]
    InsideRun {
        /// The directory asked for.
        dir: PathBuf,
        /// The run directory it lies in.
        run: PathBuf,
    },
    /// A thread count of 0.
    #[error("invalid thread count: 0: use at least 1 thread")]
    NoThreads,
    /// The thread pool could not be built with the thread count asked for.
    #[error("invalid thread count: {0}")]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
    /// DIR exists, has no manifest and is not empty.
    #[error("{} is not a cablemap sweep directory (it has no manifest.json but holds '{entry}'): give a new or empty directory to --out", dir.display())]
    NotARunDir { dir: PathBuf, entry: String },
    /// DIR has no manifest (reading or status); built by [`SweepError::no_run`].
    #[error("{}", status::no_run_text(dir, runs_inside))]
    NoRun {
        /// The directory given.
        dir: PathBuf,
        /// Run directories directly inside it (the `run` of `cablemap map --out DIR`).
        runs_inside: Vec<PathBuf>,
    },
    /// DIR does not exist (reading or status); built by [`SweepError::no_run`].
    #[error("{} holds no sweep: it does not exist{}", dir.display(), status::runs_beside_text(runs_beside))]
    NoRunDir {
        /// The directory given.
        dir: PathBuf,
        /// Run directories beside it (what a typo in its last name meant).
        runs_beside: Vec<PathBuf>,
    },
    /// DIR holds a sweep of another kind (planar vs cables).
    #[error("{} holds a sweep of another kind ('{found}', not '{wanted}'): a spec with [[cable]] tables and a planar spec need separate run directories; use another --out directory", dir.display())]
    OtherKind {
        /// The run directory.
        dir: PathBuf,
        /// Its manifest's format.
        found: String,
        /// The format this command reads or writes.
        wanted: String,
    },
    /// The manifest is unreadable.
    #[error("manifest {} is damaged: {problem}. Restore it, or start the sweep in a new directory", path.display())]
    CorruptManifest { path: PathBuf, problem: store::ManifestProblem },
    /// DIR belongs to a run of another spec.
    #[error("{} holds a sweep of a different spec (sha256 {existing}; this spec is {wanted}): use another --out directory, or the spec that run was started with", dir.display())]
    SpecMismatch { dir: PathBuf, existing: String, wanted: String },
    /// DIR was written by another version of cablemap.
    #[error("{} was written by cablemap {existing}, this is {}: finish it with that version or use a new --out directory", dir.display(), store::TOOL_VERSION)]
    VersionMismatch { dir: PathBuf, existing: String },
    /// DIR was started with another shard count.
    #[error("{} belongs to a sweep split into {existing} shards, not {wanted}: rerun with --shards {existing}", dir.display())]
    ShardCountMismatch { dir: PathBuf, existing: u64, wanted: u64 },
    /// A file in DIR that cablemap did not write.
    #[error("{} was not written by cablemap sweep: move it out of the run directory, then rerun", path.display())]
    ForeignFile { path: PathBuf },
    /// A chunk-named file from another job.
    #[error("{} does not belong to this sweep ({reason}): move it out of the run directory, then rerun", path.display())]
    ForeignChunk { path: PathBuf, reason: store::ForeignReason },
    /// A chunk file that cannot be read.
    #[error("chunk file {} is damaged ({problem}): delete it and rerun the sweep to recompute that chunk", path.display())]
    CorruptChunk { path: PathBuf, problem: store::ChunkProblem },
    /// Chunk files whose bytes changed since they were written (checksum
    /// mismatch) or whose footer is unreadable.
    #[error("{} holds damaged chunk files: {}. Rerun the sweep command of each named shard (same SPEC, --out, --shards): it moves damaged chunks to {} and recomputes them", dir.display(), store::damaged_text(damaged, *shards), dir.join(store::DAMAGED_DIR).display())]
    DamagedChunks {
        /// The run directory.
        dir: PathBuf,
        /// The damaged chunk files.
        damaged: Vec<store::DamagedChunk>,
        /// The run's shard count (each chunk belongs to one shard).
        shards: u64,
    },
    /// The run is not complete and the caller asked for a complete one.
    #[error("sweep in {} is incomplete ({done} of {total} rows): rerun the sweep command to finish it, or read it as partial", dir.display())]
    Incomplete { dir: PathBuf, done: u64, total: u64 },
    /// The solver rejected the actuator.
    #[error(transparent)]
    Parameter(#[from] crate::model::ParameterError),
    /// The solver refused the rod or its settings.
    #[error(transparent)]
    Simulate(#[from] crate::solver::SimulateError),
    /// A routing of the grid was rejected.
    #[error(transparent)]
    Routing(#[from] crate::model::RoutingError),
    /// Parquet encoding or decoding.
    #[error("{context}: {source}")]
    Parquet { context: FileOp, source: parquet::errors::ParquetError },
    /// Arrow decoding.
    #[error("{context}: {source}")]
    Arrow { context: FileOp, source: arrow::error::ArrowError },
    /// Reading the run's state after its sweep.
    #[error("checking {} after the sweep: {source}", dir.display())]
    After {
        /// The run directory.
        dir: PathBuf,
        /// Why it could not be read.
        source: Box<SweepError>,
    },
    /// A damaged chunk could not be moved aside.
    #[error("moving damaged chunk {} to {}: {source}", from.display(), to.display())]
    MoveAside {
        /// The damaged chunk.
        from: PathBuf,
        /// Where it was to go.
        to: PathBuf,
        /// Why it could not.
        source: std::io::Error,
    },
    /// A file operation.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
}

/// A file or directory being read or written, for an error's context.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{op} {}", path.display())]
pub struct FileOp {
    /// `reading` or `writing`.
    pub op: &'static str,
    /// The file or directory.
    pub path: PathBuf,
}

impl FileOp {
    /// Reading `path`.
    pub fn reading(path: &std::path::Path) -> Self {
        Self { op: "reading", path: path.to_path_buf() }
    }

    /// Writing `path`.
    pub fn writing(path: &std::path::Path) -> Self {
        Self { op: "writing", path: path.to_path_buf() }
    }
}
