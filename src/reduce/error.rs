//! Why a reduction failed: one enum for every stage and both kinds of run;
//! messages name the file or setting and what to do.

use super::{tables, MAX_CELLS_PER_AXIS};
use std::path::PathBuf;

/// Why a reduction failed.
#[derive(Debug, thiserror::Error)]
pub enum ReduceError {
    /// A cable sweep's row has a tension that is not on its cable's grid
    /// (the row cannot be placed in the planar map).
    #[error("reading the cable rows: tension {tension_n} N of cable {cable} is not on its grid")]
    TensionOffGrid {
        /// The cable, from 1.
        cable: usize,
        /// The tension read, N.
        tension_n: f64,
    },
    /// A cable sweep's rows could not be laid out as the planar reducer's rows.
    #[error("building the planar map rows: {0}")]
    PlanarRows(#[source] arrow::error::ArrowError),
    /// The shards lack a column the reducer reads.
    #[error("sweep data: column '{name}' is missing from the sweep shards")]
    MissingColumn {
        /// The column.
        name: String,
    },
    /// A column holds a type that cannot be read as the reducer's.
    #[error("sweep data: column '{name}' cannot be read as {to}: {source}")]
    ColumnType {
        /// The column.
        name: String,
        /// The type the reducer reads.
        to: arrow::datatypes::DataType,
        /// Arrow's cast error.
        source: arrow::error::ArrowError,
    },
    /// Opening or reading the run failed.
    #[error("reading the run: {0}")]
    Sweep(#[from] crate::sweep::SweepError),
    /// The second pass did not find a row the first pass saw.
    #[error("reading the run: the run changed between the two passes: reduce again")]
    RunChanged,
    /// No converged row to map.
    #[error("the run has no converged solves to map ({failed} failed): check the spec and `cablemap status`")]
    Empty {
        /// Failed rows (after mirroring).
        failed: u64,
    },
    /// The cell size is not a positive number.
    #[error("cell size {} mm must be positive", crate::io::fmt_num(*cell_mm))]
    CellSize {
        /// The cell size given, mm.
        cell_mm: f64,
    },
    /// The cell is larger than the rod's whole reach.
    #[error(
        "cell size {} mm is larger than the whole reach can be ({largest_cell_mm} mm: the tip stays within the rod's length \
         of the clamp): use a cell size ≤ {largest_cell_mm} mm",
        crate::io::fmt_num(*cell_mm)
    )]
    CellTooLarge {
        /// The cell size given, mm.
        cell_mm: f64,
        /// The largest useful cell, mm (twice the rod's length).
        largest_cell_mm: f64,
    },
    /// The run has no a_1 column.
    #[error("the run stores only a_0; modes need a_1: sweep with order ≥ 1")]
    OrderTooLow,
    /// Mode boundaries are not finite and ascending.
    #[error("mode boundaries must be finite and strictly ascending: a0 {a0:?}, a1 {a1:?}")]
    Boundaries {
        /// a_0 boundaries.
        a0: [f64; 3],
        /// a_1 boundaries.
        a1: [f64; 2],
    },
    /// The quantiles of the run's a_0 and a_1 do not split it into modes.
    #[error(
        "mode boundaries must be finite and strictly ascending: a0 {a0:?}, a1 {a1:?}: the run's a0/a1 values are too few \
         or too alike to split into modes by quantiles (one routing, or a grid whose routings all bend alike); give explicit \
         mode boundaries (three for a0, two for a1)"
    )]
    ModesNotSplit {
        /// The a_0 quantiles.
        a0: [f64; 3],
        /// The a_1 quantiles.
        a1: [f64; 2],
    },
    /// The cell is so small that the grid would exceed [`MAX_CELLS_PER_AXIS`](super::MAX_CELLS_PER_AXIS).
    #[error(
        "cell size {} mm is too small: the reach ({reach_x_mm:.3} × {reach_y_mm:.3} mm) would span more than \
         {MAX_CELLS_PER_AXIS} cells per axis; use a cell size ≥ {} mm",
        crate::io::fmt_num(*cell_mm),
        crate::io::fmt_num(*smallest_cell_mm)
    )]
    CellTooSmall {
        /// The cell size given, mm.
        cell_mm: f64,
        /// Extent of the tips along x, mm.
        reach_x_mm: f64,
        /// Extent of the tips along y, mm.
        reach_y_mm: f64,
        /// The smallest cell that works, mm.
        smallest_cell_mm: f64,
    },
    /// The map directory is, or lies inside, a sweep run directory.
    #[error("{0}")]
    MapInRun(#[source] crate::io::InsideRunDir),
    /// A map directory was given where a sweep run is read.
    #[error(
        "{} is a map (written by `cablemap reduce`), not a sweep run; it was made from the run {run_dir}: give that run directory",
        dir.display()
    )]
    MapNotRun {
        /// The directory given.
        dir: PathBuf,
        /// The run the map records it was made from.
        run_dir: String,
    },
    /// The map directory is given as `.` or `..`.
    #[error("map directory {}: give a map directory by name (not '.' or '..'): it is replaced as a whole", path.display())]
    MapDirUnnamed {
        /// The directory.
        path: PathBuf,
    },
    /// The map directory holds something other than a map.
    #[error(
        "map directory {}: exists and is not a cablemap map (no summary.json naming the format '{}'), and a map directory \
         is replaced as a whole: give a new directory, or an earlier map to replace",
        path.display(),
        tables::MAP_FORMAT
    )]
    NotAMap {
        /// The directory.
        path: PathBuf,
    },
    /// The map directory cannot be listed.
    #[error("map directory {}: cannot be read as a directory ({source})", path.display())]
    MapDirUnreadable {
        /// The directory.
        path: PathBuf,
        /// The error listing it.
        source: std::io::Error,
    },
    /// Creating a directory failed.
    #[error("writing {}: cannot create ({source})", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// Writing a file failed.
    #[error("writing {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// Encoding a table as Parquet failed.
    #[error("writing {}: {source}", path.display())]
    WriteParquet {
        /// The file.
        path: PathBuf,
        /// The error.
        source: parquet::errors::ParquetError,
    },
    /// Assembling a table failed.
    #[error("writing {}: {source}", path.display())]
    WriteArrow {
        /// The file.
        path: PathBuf,
        /// The error.
        source: arrow::error::ArrowError,
    },
    /// Encoding JSON failed.
    #[error("writing {}: {source}", path.display())]
    WriteJson {
        /// The file.
        path: PathBuf,
        /// The error.
        source: serde_json::Error,
    },
    /// Putting the new map in place of the old failed.
    #[error("writing {}: cannot put the new map in place ({source})", path.display())]
    Replace {
        /// The map directory.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// Drawing a picture.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// A scratch file of the reduction could not be written or read.
    #[error("scratch file {}: {source} (the reduction needs free disk space of about 48 bytes per converged row there)", path.display())]
    Scratch {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The parts of a split reduction do not make one map.
    #[error("{0}")]
    Parts(#[from] PartsError),
    /// A several-cable map's cable spec ([`CABLES_FILE`](super::map_cables::CABLES_FILE)) cannot be read.
    #[error(
        "reading {}: {source} (`cablemap reduce` writes it beside the tables of a map of several cables: reduce the run again)",
        path.display()
    )]
    CablesFile {
        /// The file.
        path: PathBuf,
        /// Why it cannot be read or parsed.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// Why a split reduction's parts do not make a map.
#[derive(Debug, thiserror::Error)]
pub enum PartsError {
    /// The part number is not below the number of parts, or there are
    /// more parts than a reduce may be split into.
    #[error(
        "part {shard} of {shards}: parts are numbered 0 to N-1, and the number of parts N must be 1 … {}",
        crate::sweep::MAX_SHARDS
    )]
    BadShard {
        /// The part asked for.
        shard: u64,
        /// The number of parts.
        shards: u64,
    },
    /// No part has been written.
    #[error("{}: no reduce parts found: run the parts first (part I of N for every I from 0 to N-1)", dir.display())]
    NoParts {
        /// The parts directory.
        dir: PathBuf,
    },
    /// Some parts are missing.
    #[error("{}: {} of {shards} parts missing (part {}): run those parts (again) before merging", dir.display(), missing.len(), list(missing))]
    Missing {
        /// The parts directory.
        dir: PathBuf,
        /// The number of parts.
        shards: u64,
        /// The missing parts.
        missing: Vec<u64>,
    },
    /// Parts of different splits are mixed.
    #[error("{}: holds parts of different splits (of {}): remove the directory and run the parts of one split", dir.display(), list(counts))]
    Mixed {
        /// The parts directory.
        dir: PathBuf,
        /// The numbers of parts found.
        counts: Vec<u64>,
    },
    /// A part does not belong to this run or is damaged.
    #[error("{}: {problem}: run this part again", path.display())]
    Mismatch {
        /// The part's file.
        path: PathBuf,
        /// What is wrong.
        problem: PartMismatch,
    },
    /// A part's files changed after they were written (a checksum differs).
    #[error("{}: {problem}: the part was damaged or edited after it was written; run part {shard} of {shards} again", path.display())]
    Damaged {
        /// The part's file that failed its check.
        path: PathBuf,
        /// The part.
        shard: u64,
        /// The number of parts.
        shards: u64,
        /// What differs.
        problem: PartDamage,
    },
    /// Part records of a split into more parts than a reduce may have.
    #[error(
        "{}: holds parts of a split into {shards} parts, more than {}: remove the directory and split into fewer parts",
        dir.display(),
        crate::sweep::MAX_SHARDS
    )]
    TooMany {
        /// The parts directory.
        dir: PathBuf,
        /// The number of parts the records name.
        shards: u64,
    },
    /// A part's record cannot be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

/// How a part does not belong to the run it is merged into.
#[derive(Debug, thiserror::Error)]
pub enum PartMismatch {
    /// A part numbered beyond the split.
    #[error("part {part} is beyond the {shards} parts: remove it")]
    BeyondParts {
        /// The part.
        part: u64,
        /// The number of parts.
        shards: u64,
    },
    /// Not a part record.
    #[error("not a reduce part record ({0})")]
    NotARecord(#[source] serde_json::Error),
    /// A record of another format.
    #[error("format '{found}', expected '{wanted}'")]
    Format {
        /// Its format tag.
        found: String,
        /// The tag this version writes.
        wanted: &'static str,
    },
    /// A record of another part.
    #[error("it records part {shard} of {shards}")]
    OtherPart {
        /// The part it records.
        shard: u64,
        /// Of so many parts.
        shards: u64,
    },
    /// A part of another run.
    #[error("it is a part of another run (its spec hash differs)")]
    OtherRun,
    /// A part of the run as it was before it changed.
    #[error("it covers other chunks or rows than the run has now")]
    OtherCoverage,
    /// A samples file of another length than its record says.
    #[error("{bytes} bytes where the part's record says {samples} samples")]
    SamplesLength {
        /// The file's length.
        bytes: u64,
        /// Samples in the record.
        samples: u64,
    },
}

/// What differs in a part changed after it was written.
#[derive(Debug, thiserror::Error)]
pub enum PartDamage {
    /// The record's content.
    #[error("its content hashes to {content}, not the recorded record_sha256 {recorded}")]
    Record {
        /// The content's digest, hex.
        content: String,
        /// The digest recorded, hex.
        recorded: String,
    },
    /// The samples file's bytes.
    #[error("its SHA-256 is {actual}, not the {recorded} recorded when it was written")]
    Samples {
        /// The file's digest, hex.
        actual: String,
        /// The digest recorded, hex.
        recorded: String,
    },
}

/// The numbers of `v` for a message: the first few, then how many more.
fn list(v: &[u64]) -> String {
    const SHOWN: usize = 20;
    let mut text = v.iter().take(SHOWN).map(u64::to_string).collect::<Vec<_>>().join(", ");
    if v.len() > SHOWN {
        text.push_str(&format!(", … ({} more)", v.len() - SHOWN));
    }
    text
}
