//! Reading a sweep back: the entry point for the later stages (reduce,
//! maps, design).
//!
//! ```no_run
//! use cablemap::sweep::{open_run, schema, Completeness};
//! use arrow::array::{AsArray, Float64Array};
//! use arrow::datatypes::Float64Type;
//!
//! let run = open_run("runs/thesis".as_ref(), Completeness::Complete)?;
//! println!("{} rows of order {}", run.rows_done(), run.spec().output.order);
//! for batch in run.batches_projected(&["tip_x_mm", "tip_y_mm", "a0", "status"])? {
//!     let batch = batch?;
//!     let x: &Float64Array = batch.column_by_name("tip_x_mm").unwrap().as_primitive::<Float64Type>();
//!     // x.is_null(i) for failed solves (status != "ok").
//! #   let _ = x;
//! }
//! # Ok::<(), cablemap::sweep::SweepError>(())
//! ```
//!
//! [`open_run`] checks the manifest and every chunk (recorded checksum, footer spec hash,
//! chunk index, row count) before anything is read; batches then stream one
//! chunk file at a time, in chunk order (routing id, then tension, rising),
//! so memory does not grow with the number of rows.

use super::spec::SweepSpec;
use super::store::{ChunkInfo, ChunkProblem, Manifest, RunDir};
use super::error::FileOp;
use super::SweepError;
use arrow::datatypes::SchemaRef;
use arrow::record_batch::RecordBatch;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ProjectionMask;
use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};

/// Rows per record batch yielded by the reader.
pub const BATCH_ROWS: usize = 8192;

/// Whether [`open_run`] accepts a run that is not finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Completeness {
    /// Every row must be written, else [`SweepError::Incomplete`].
    Complete,
    /// Read whatever chunks are complete (a run still going, or stopped).
    AllowPartial,
}

/// A checked run directory of any kind, ready to read.
#[derive(Debug, Clone)]
pub struct SweepRun {
    dir: PathBuf,
    manifest: Manifest,
    chunks: Vec<ChunkInfo>,
}

/// Opens and checks the sweep in `dir`: the manifest must be intact, every
/// file in `DIR/shards` must be a chunk of this run with the right row
/// count, and with [`Completeness::Complete`] every chunk must be present.
pub fn open_run(dir: &Path, completeness: Completeness) -> Result<SweepRun, SweepError> {
    let run = RunDir::new(dir);
    let manifest: Manifest = run.read_manifest()?.ok_or_else(|| SweepError::no_run(dir))?;
    let scan = run.scan(&manifest)?;
    if !scan.damaged.is_empty() {
        return Err(SweepError::DamagedChunks { dir: dir.to_path_buf(), damaged: scan.damaged, shards: manifest.shards });
    }
    let chunks: Vec<ChunkInfo> = scan.chunks.into_values().collect();
    let sweep = SweepRun { dir: dir.to_path_buf(), manifest, chunks };
    if completeness == Completeness::Complete && !sweep.is_complete() {
        return Err(SweepError::Incomplete { done: sweep.rows_done(), total: sweep.rows_total(), dir: sweep.dir });
    }
    Ok(sweep)
}

impl SweepRun {
    /// The run directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The spec the run was made with (all defaults filled in).
    pub fn spec(&self) -> &SweepSpec {
        &self.manifest.spec
    }

    /// The manifest (spec hash, tool version, counts).
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// Every row of the sweep is written.
    pub fn is_complete(&self) -> bool {
        self.chunks.len() as u64 == self.manifest.chunks
    }

    /// Rows written.
    pub fn rows_done(&self) -> u64 {
        self.chunks.iter().map(|c| c.rows).sum()
    }

    /// Rows of the complete sweep.
    pub fn rows_total(&self) -> u64 {
        self.manifest.total_rows
    }

    /// Written rows per status (`ok` and failure statuses).
    pub fn status_counts(&self) -> BTreeMap<String, u64> {
        super::store::total_status_counts(&self.chunks)
    }

    /// The complete chunk files, in chunk order.
    pub fn chunk_paths(&self) -> Vec<&Path> {
        self.chunks.iter().map(|c| c.path.as_path()).collect()
    }

    /// The Arrow schema of the rows (see `docs/schema.md`).
    pub fn schema(&self) -> SchemaRef {
        self.spec().schema()
    }

    /// All rows, as record batches of up to [`BATCH_ROWS`] rows, chunk by
    /// chunk in chunk order. Each batch has [`Self::schema`].
    pub fn batches(&self) -> impl Iterator<Item = Result<RecordBatch, SweepError>> + '_ {
        self.stream(None)
    }

    /// Like [`Self::batches`], decoding only the named columns (in schema
    /// order, whatever the order of `columns`). Unknown names are an error.
    pub fn batches_projected<'a>(
        &'a self,
        columns: &[&str],
    ) -> Result<impl Iterator<Item = Result<RecordBatch, SweepError>> + 'a, SweepError> {
        Ok(self.stream(Some(self.projection(columns)?)))
    }

    /// Number of complete chunk files (the unit for reading in parallel).
    pub fn chunk_count(&self) -> usize {
        self.chunks.len()
    }

    /// Rows of the `index`-th complete chunk file.
    pub fn chunk_rows(&self, index: usize) -> u64 {
        self.chunks[index].rows
    }

    /// The rows of the `index`-th complete chunk file (0 ≤ index <
    /// [`Self::chunk_count`]), optionally only the named columns. Chunks
    /// are independent, so a reader can process them in parallel, e.g.
    /// `(0..run.chunk_count()).into_par_iter().map(|i| run.chunk_batches(i, Some(&cols)))`.
    pub fn chunk_batches(
        &self,
        index: usize,
        columns: Option<&[&str]>,
    ) -> Result<impl Iterator<Item = Result<RecordBatch, SweepError>> + '_, SweepError> {
        let projection = columns.map(|c| self.projection(c)).transpose()?;
        let chunk = &self.chunks[index];
        let reader = open_chunk(&chunk.path, &self.schema(), projection.as_deref())?;
        Ok(reader.map(move |b| b.map_err(|source| SweepError::Arrow { context: FileOp::reading(&chunk.path), source })))
    }

    /// Root column indices of `columns`, sorted.
    fn projection(&self, columns: &[&str]) -> Result<Vec<usize>, SweepError> {
        let schema = self.schema();
        let mut indices = Vec::with_capacity(columns.len());
        for name in columns {
            let i = schema.index_of(name).map_err(|_| SweepError::Arrow {
                context: FileOp::reading(&self.dir),
                source: arrow::error::ArrowError::SchemaError(format!(
                    "no column '{name}' (columns: {})",
                    schema.fields().iter().map(|f| f.name().as_str()).collect::<Vec<_>>().join(", ")
                )),
            })?;
            indices.push(i);
        }
        indices.sort_unstable();
        indices.dedup();
        Ok(indices)
    }

    fn stream(&self, projection: Option<Vec<usize>>) -> impl Iterator<Item = Result<RecordBatch, SweepError>> + '_ {
        let expected = self.schema();
        self.chunks.iter().flat_map(move |chunk| {
            match open_chunk(&chunk.path, &expected, projection.as_deref()) {
                Ok(reader) => {
                    let path = chunk.path.clone();
                    Box::new(reader.map(move |b| {
                        b.map_err(|source| SweepError::Arrow { context: FileOp::reading(&path), source })
                    })) as Box<dyn Iterator<Item = _>>
                }
                Err(e) => Box::new(std::iter::once(Err(e))),
            }
        })
    }
}

/// Opens one chunk file for reading, checking its schema.
fn open_chunk(
    path: &Path,
    expected: &SchemaRef,
    projection: Option<&[usize]>,
) -> Result<parquet::arrow::arrow_reader::ParquetRecordBatchReader, SweepError> {
    let file = File::open(path).map_err(crate::io::FileError::on("opening", path))?;
    let corrupt = |problem| SweepError::CorruptChunk { path: path.to_path_buf(), problem };
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| corrupt(ChunkProblem::parquet(e)))?;
    let found = builder.schema();
    let same = found.fields().len() == expected.fields().len()
        && found.fields().iter().zip(expected.fields()).all(|(a, b)| a.name() == b.name() && a.data_type() == b.data_type());
    if !same {
        return Err(corrupt(ChunkProblem::Columns));
    }
    let builder = match projection {
        Some(indices) => {
            let mask = ProjectionMask::roots(builder.parquet_schema(), indices.iter().copied());
            builder.with_projection(mask)
        }
        None => builder,
    };
    builder.with_batch_size(BATCH_ROWS).build().map_err(|e| corrupt(ChunkProblem::parquet(e)))
}
