//! What a kind of sweep is to the engine: a spec that enumerates routings
//! (ids 0..routings, each with the same number of rows) and solves one
//! routing into rows of a fixed Arrow schema ([`RunSpec`]). The one spec
//! ([`crate::sweep::SweepSpec`]), the one engine ([`crate::sweep::run`]) and
//! the one run directory ([`crate::sweep::store`]) serve every kind; each
//! kind declares itself once, in its `impl RunSpec`
//! ([`crate::sweep::spec::planar`], [`crate::sweep::spec::cables`]).
//!
//! Chunks, shards and row counts follow from [`ChunkLayout`] alone, so
//! sharding, resume, checksums and status are the same code for every kind,
//! within the same limits ([`MAX_CHUNK_ROWS`], [`MAX_ROWS`]).

use super::spec::{OutputSpec, SpecError};
use super::SweepError;
use crate::solver::SolverOptions;
use arrow::datatypes::SchemaRef;
use arrow::record_batch::RecordBatch;
use std::ops::Range;

/// Most rows per chunk file, of any kind of sweep (a chunk is built in
/// memory before writing).
pub const MAX_CHUNK_ROWS: u64 = 2_000_000;
/// Most rows of a sweep of any kind without `--allow-large` (≈1600 × the
/// thesis sweep).
pub const MAX_ROWS: u64 = 1_000_000_000;

/// Routings cut into chunks and chunks dealt to shards: index arithmetic only.
///
/// Chunk c holds routing ids [c·C, min((c+1)·C, R)); shard s of S owns the
/// chunks with c mod S = s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkLayout {
    /// Routings (ids 0..routings).
    pub routings: u64,
    /// Rows per routing.
    pub tensions: u64,
    /// Routings per chunk (≥ 1).
    pub chunk_routings: u64,
    /// Number of chunks.
    pub chunks: u64,
}

impl ChunkLayout {
    /// The layout of `routings` routings of `tensions` rows each, cut into
    /// chunks of `chunk_routings`.
    pub fn new(routings: u64, tensions: u64, chunk_routings: u64) -> Self {
        Self { routings, tensions, chunk_routings, chunks: routings.div_ceil(chunk_routings.max(1)) }
    }

    /// Rows of the whole sweep.
    pub fn total_rows(&self) -> u64 {
        self.routings * self.tensions
    }

    /// Routing ids of chunk `chunk`.
    pub fn chunk_ids(&self, chunk: u64) -> Range<u64> {
        let start = chunk * self.chunk_routings;
        start.min(self.routings)..(start + self.chunk_routings).min(self.routings)
    }

    /// Rows in chunk `chunk`.
    pub fn chunk_rows(&self, chunk: u64) -> u64 {
        let ids = self.chunk_ids(chunk);
        (ids.end - ids.start) * self.tensions
    }

    /// Chunks owned by shard `shard` of `shards` (ascending).
    pub fn shard_chunks(&self, shard: u64, shards: u64) -> impl Iterator<Item = u64> {
        assert!(shard < shards, "shard {shard} of {shards}");
        (shard..self.chunks).step_by(shards as usize)
    }

    /// Which shard of `shards` owns `chunk`.
    pub fn chunk_shard(&self, chunk: u64, shards: u64) -> u64 {
        chunk % shards
    }

    /// Rows owned by shard `shard` of `shards`.
    pub fn shard_rows(&self, shard: u64, shards: u64) -> u64 {
        self.shard_chunks(shard, shards).map(|c| self.chunk_rows(c)).sum()
    }
}

/// A kind of sweep ([`super::spec::RoutingGrid`]'s variants): what the
/// engine needs of it besides the spec's solver settings and
/// [`OutputSpec`] (given to the methods that read them): its run kind, its
/// chunk layout and row schema, and how one routing is solved.
pub trait RunSpec {
    /// The kind of run (its format tag and name).
    const KIND: RunKind;
    /// Per-thread solver state, cloned from a prototype for each worker.
    type Worker: Clone + Send + Sync;
    /// One solved routing (all its rows), ready for [`Self::batch`].
    type Solved: Send;

    /// Checks the settings; the error names the setting.
    fn check(&self, solver: &SolverOptions, output: &OutputSpec) -> Result<(), SpecError>;
    /// What a row of a routing is, for [`SweepError::TooLarge`].
    fn rows_counted(&self) -> RowsCounted;
    /// Routings, rows per routing, chunks.
    fn layout(&self, output: &OutputSpec) -> ChunkLayout;
    /// The Arrow schema of the rows (docs/schema.md).
    fn schema(&self, output: &OutputSpec) -> SchemaRef;
    /// Estimated bytes one row takes in memory while its chunk is built
    /// (every copy: solved rows, Arrow batch, encoder buffer); sizes the
    /// engine's memory check.
    fn row_bytes(&self, solver: &SolverOptions, output: &OutputSpec) -> u64;
    /// The prototype worker.
    fn worker(&self, solver: &SolverOptions) -> Result<Self::Worker, SweepError>;
    /// Solves routing `id`: [`ChunkLayout::tensions`] rows.
    fn solve(&self, solver: &SolverOptions, output: &OutputSpec, worker: &mut Self::Worker, id: u64) -> Result<Self::Solved, SweepError>;
    /// The rows of a chunk's solved routings (in id order) as one batch of [`Self::schema`].
    fn batch(&self, output: &OutputSpec, schema: &SchemaRef, solved: &[Self::Solved]) -> RecordBatch;
}

/// What a kind of sweep counts per routing, and where the counts are set
/// (for [`super::SweepError::TooLarge`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowsCounted {
    /// A planar sweep's actuations, set by the grid and the ladder's table.
    Actuations {
        /// `[tension]` or `[displacement]`.
        ladder_table: &'static str,
    },
    /// A cable sweep's tension combinations.
    TensionCombinations,
}

impl RowsCounted {
    /// What a row of a routing is.
    pub fn per_routing(&self) -> &'static str {
        match self {
            RowsCounted::Actuations { .. } => "actuations",
            RowsCounted::TensionCombinations => "tension combinations",
        }
    }

    /// The settings that set the count.
    pub fn settings(&self) -> String {
        match self {
            RowsCounted::Actuations { ladder_table } => format!("[grid] levels and {ladder_table} count"),
            RowsCounted::TensionCombinations => "the levels and tension counts".to_string(),
        }
    }
}

/// The kind of sweep a spec makes and a run directory holds (from its
/// manifest's format tag, [`crate::sweep::store::run_kind`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunKind {
    /// A planar single-cable sweep ([`crate::sweep::spec::PlanarGrid`]).
    Planar,
    /// A sweep of several or spatial cables ([`crate::sweep::spec::CablesGrid`]).
    Cables,
}

impl RunKind {
    /// The format tag of the kind's manifest and chunk footers.
    pub fn format(self) -> &'static str {
        match self {
            RunKind::Planar => crate::io::run_markers::PLANAR_FORMAT,
            RunKind::Cables => crate::io::run_markers::CABLES_FORMAT,
        }
    }

    /// What `cablemap status` calls the kind.
    pub fn name(self) -> &'static str {
        match self {
            RunKind::Planar => "planar single-cable sweep",
            RunKind::Cables => "cable sweep",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_covers_every_routing_once() {
        let l = ChunkLayout::new(10, 3, 4);
        assert_eq!(l.chunks, 3);
        assert_eq!(l.chunk_ids(2), 8..10);
        assert_eq!(l.chunk_rows(2), 6);
        assert_eq!((0..2).map(|s| l.shard_rows(s, 2)).sum::<u64>(), l.total_rows());
        assert_eq!(l.shard_chunks(1, 2).collect::<Vec<_>>(), vec![1]);
    }

}
