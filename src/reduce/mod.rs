//! Reduce: bin a sweep's tip positions into feasibility maps (thesis Ch. 4,
//! model-notes §5; the output contract is docs/maps.md).
//!
//! [`reduce_batches`] runs the stages in order, each in its own module:
//! - `samples` (pass 1): tip and a_0…a_2 of every converged row, written to
//!   a scratch file (`spill`), the mirrored half restored on reading (the
//!   mirror rule lives in `mirror`);
//! - `modes::split`: mode boundaries, given or by exact quantiles (`select`:
//!   a counting pass and selection passes over the scratch file);
//! - `grid`: the cells over the reach;
//! - `partition`: the samples split by cell range into partitions that fit
//!   in memory; per partition, `cells` (count, percentiles, mode counts and
//!   the designs kept) and `modes::Nearest` (the simulation nearest each
//!   mode's median);
//! - `fetch` (pass 2): the full rows of the kept designs and representatives;
//! - assembly into [`MapData`].
//!
//! Memory is bounded by [`ReduceOptions::memory_samples`], whatever the
//! run's size, and the tables are the same for any bound (docs/maps.md).
//! [`parts`] splits pass 1 across processes (cluster tasks) and merges.
//!
//! The map format (file and column names, writer, reader) is [`tables`];
//! [`output`] writes a whole map directory, [`drawings`] the modes' bodies.

pub mod cables;
mod cells;
mod columns;
pub mod drawings;
pub mod explorer;
mod fetch;
mod grid;
pub mod map_cables;
mod mirror;
mod modes;
pub mod output;
pub mod parts;
mod partition;
pub mod plots;
mod samples;
mod select;
mod spill;
pub mod stats;
pub mod tables;

use crate::model::ControlPoints;
use crate::shape::LengthBasis;
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

pub use map_cables::{design_actuation, MapCables};
pub use output::{check_map_out, write_map, write_map_replacing};

/// Number of characteristic modes: a_0 in 4 ranges × a_1 in 3.
pub const MODES: usize = 12;

/// Highest coefficient order with per-cell statistics (a_0 … a_2).
pub const CELL_STATS_ORDER: usize = 2;

/// Why a reduction failed.
#[derive(Debug, thiserror::Error)]
pub enum ReduceError {
    /// A cable sweep's spec, solve or rows (issue 16).
    #[error(transparent)]
    CableSweep(#[from] crate::sweep::cables::CableSweepError),
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
    /// The cell is so small that the grid would exceed [`MAX_CELLS_PER_AXIS`].
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
    MapInRun(String),
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
    Parts(#[from] parts::PartsError),
    /// A several-cable map's cable spec ([`map_cables::CABLES_FILE`]) cannot be read.
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

/// What the reducer needs to know about the run it reads.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunInfo {
    /// Whether the run dropped mirror images (the reducer restores them).
    pub mirrored: bool,
    /// Highest coefficient order stored (columns a0 … a{order}).
    pub order: usize,
    /// Tension range of the run, N.
    pub tension_range_n: [f64; 2],
    /// Rod radius, mm.
    pub radius_mm: f64,
    /// Rod length, mm.
    pub length_mm: f64,
    /// Where the data came from.
    pub run_dir: String,
    /// Hash of the run's spec.
    pub spec_hash: String,
    /// The length the run's a_i are per unit of.
    pub length_basis: LengthBasis,
    /// The body beyond L and r (radius profile, segments, cable anchor).
    pub body: MapBody,
}

/// What a map records of its actuator's body beyond L and r: the radius
/// profile, segments and cable anchor. Empty for the thesis's uniform rod,
/// whose summary.json then has none of these fields (as before they existed).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MapBody {
    /// Radius profile (s, r) points, mm.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub radius_profile_mm: Vec<(f64, f64)>,
    /// Segments of their own material.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub segments: Vec<crate::model::body::Segment>,
    /// Where the cable is knotted, mm (none: the tip).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cable_anchor_mm: Option<f64>,
}

impl MapBody {
    /// The body of `actuator`.
    pub fn of(actuator: &crate::model::Rod) -> Self {
        MapBody {
            radius_profile_mm: actuator.radius_profile_mm.clone(),
            segments: actuator.segments.clone(),
            cable_anchor_mm: actuator.cable_anchor_mm.filter(|&k| k != actuator.length_mm),
        }
    }
}

/// Boundaries of the characteristic modes: a_0 split into 4 ranges by three
/// values, a_1 into 3 by two (both mm⁻¹, in the run's length basis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModeBoundaries {
    /// Ascending a_0 boundaries.
    pub a0: [f64; 3],
    /// Ascending a_1 boundaries.
    pub a1: [f64; 2],
}

impl ModeBoundaries {
    /// Checks that both lists are finite and ascending.
    pub fn validate(&self) -> Result<(), ReduceError> {
        let ok = |v: &[f64]| v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
        if ok(&self.a0) && ok(&self.a1) {
            Ok(())
        } else {
            Err(ReduceError::Boundaries { a0: self.a0, a1: self.a1 })
        }
    }

    /// (a_0 range, a_1 range) of a coefficient pair.
    pub fn ranges(&self, a0: f64, a1: f64) -> (usize, usize) {
        (self.a0.iter().filter(|&&b| a0 >= b).count(), self.a1.iter().filter(|&&b| a1 >= b).count())
    }

    /// Mode index 3·i + j.
    pub fn mode(&self, a0: f64, a1: f64) -> usize {
        let (i, j) = self.ranges(a0, a1);
        3 * i + j
    }

    /// Bounds (lo, hi) of range `i` of a list (open ends are ±inf).
    fn bounds(list: &[f64], i: usize) -> (f64, f64) {
        let lo = if i == 0 { f64::NEG_INFINITY } else { list[i - 1] };
        let hi = if i == list.len() { f64::INFINITY } else { list[i] };
        (lo, hi)
    }
}

/// Options of a reduction.
#[derive(Debug, Clone)]
pub struct ReduceOptions {
    /// Cell size of the grid, mm.
    pub cell_mm: f64,
    /// Explicit mode boundaries; `None` takes quantiles of the data.
    pub mode_boundaries: Option<ModeBoundaries>,
    /// Designs kept per cell in designs.parquet.
    pub designs_per_cell: usize,
    /// Samples (48 bytes each) held in memory at once: the bound on the
    /// reduction's memory, whatever the run's size (one cell's samples are
    /// always held together). The tables do not depend on it.
    pub memory_samples: usize,
    /// Where the scratch files go (about 48 bytes per converged row);
    /// `None` for the system's temporary directory.
    pub scratch_dir: Option<PathBuf>,
}

/// Default of [`ReduceOptions::memory_samples`]: 8 Mi samples, 384 MiB.
pub const DEFAULT_MEMORY_SAMPLES: usize = 8 << 20;

impl Default for ReduceOptions {
    fn default() -> Self {
        Self { cell_mm: 1.0, mode_boundaries: None, designs_per_cell: 16, memory_samples: DEFAULT_MEMORY_SAMPLES, scratch_dir: None }
    }
}

impl ReduceOptions {
    /// The directory scratch files go in.
    fn scratch_parent(&self) -> PathBuf {
        self.scratch_dir.clone().unwrap_or_else(std::env::temp_dir)
    }
}

/// The summary written as summary.json (docs/maps.md).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MapSummary {
    /// [`tables::MAP_FORMAT`]: marks the directory as a map written by
    /// cablemap (empty in maps written before the field existed).
    #[serde(default)]
    pub format: String,
    /// Cell size, mm.
    pub cell_mm: f64,
    /// Lower-left corner of cell (0, 0), mm.
    pub x_min_mm: f64,
    /// See `x_min_mm`.
    pub y_min_mm: f64,
    /// Grid size in cells.
    pub nx: usize,
    /// See `nx`.
    pub ny: usize,
    /// Highest coefficient order in the run.
    pub order: usize,
    /// Whether the mirrored half was restored.
    pub mirrored: bool,
    /// Rows after mirroring.
    pub rows_total: u64,
    /// Converged rows after mirroring (the sum of cell counts).
    pub rows_converged: u64,
    /// Failed rows after mirroring.
    pub rows_failed: u64,
    /// Failed rows by status.
    pub failed_by_status: BTreeMap<String, u64>,
    /// Mode boundaries used.
    pub mode_boundaries: ModeBoundaries,
    /// `quantiles` or `explicit`.
    pub mode_boundaries_source: String,
    /// Non-empty cells.
    pub cells: usize,
    /// Tension range of the run, N.
    pub tension_range_n: [f64; 2],
    /// Rod radius, mm.
    pub radius_mm: f64,
    /// Rod length, mm.
    pub length_mm: f64,
    /// Where the data came from.
    pub run_dir: String,
    /// Hash of the run's spec.
    pub spec_hash: String,
    /// The length the coefficients (statistics, mode boundaries, designs)
    /// are per unit of: `rest` (the thesis's basis) or `deformed`. Maps
    /// written before this field existed were in the deformed basis.
    #[serde(default = "basis_of_maps_without_the_field")]
    pub length_basis: LengthBasis,
    /// The actuator's body beyond L and r (absent: the uniform rod).
    #[serde(default, flatten)]
    pub body: MapBody,
}

/// Maps written before `length_basis` was recorded had deformed-length a_i.
fn basis_of_maps_without_the_field() -> LengthBasis {
    LengthBasis::Deformed
}

/// Statistics of one coefficient in one cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoefficientStats {
    /// 10th percentile.
    pub p10: f64,
    /// 90th percentile.
    pub p90: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// One non-empty cell.
#[derive(Debug, Clone)]
pub struct CellStats {
    /// Cell column (x).
    pub ix: i32,
    /// Cell row (y).
    pub iy: i32,
    /// Cell centre, mm.
    pub x_mm: f64,
    /// Cell centre, mm.
    pub y_mm: f64,
    /// Simulations whose tip lies in the cell.
    pub count: i64,
    /// a_0 … a_min(order,2).
    pub coefficients: Vec<CoefficientStats>,
    /// Simulations per mode.
    pub modes: [i64; MODES],
}

/// A simulated design (one row of the run, mirrored if flagged).
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Cell column.
    pub ix: i32,
    /// Cell row.
    pub iy: i32,
    /// Routing number in the run.
    pub routing_id: i64,
    /// Whether this is the mirror image of the stored row.
    pub mirrored: bool,
    /// Routing control points, mm.
    pub routing_mm: ControlPoints,
    /// Tension, N.
    pub tension_n: f64,
    /// Tip, mm.
    pub tip_x_mm: f64,
    /// Tip, mm.
    pub tip_y_mm: f64,
    /// Tip tangent angle, rad.
    pub tip_angle_rad: f64,
    /// a_0 … a_order.
    pub a: Vec<f64>,
}

/// One characteristic mode.
#[derive(Debug, Clone)]
pub struct ModeStats {
    /// Mode index 3·i + j.
    pub mode: usize,
    /// a_0 range i.
    pub a0_range: usize,
    /// a_1 range j.
    pub a1_range: usize,
    /// a_0 bounds.
    pub a0_bounds: (f64, f64),
    /// a_1 bounds.
    pub a1_bounds: (f64, f64),
    /// Simulations in the mode.
    pub count: i64,
    /// Cells where the mode occurs.
    pub cells: i64,
    /// The simulation nearest the mode's median (a_0, a_1).
    pub representative: Option<Design>,
}

/// Everything a map directory holds.
#[derive(Debug, Clone)]
pub struct MapData {
    /// summary.json.
    pub summary: MapSummary,
    /// cells.parquet.
    pub cells: Vec<CellStats>,
    /// modes.parquet.
    pub modes: Vec<ModeStats>,
    /// designs.parquet.
    pub designs: Vec<Design>,
}

/// Reduces a run. `batches` is called once per pass and must yield the same
/// rows in the same order each time.
///
/// What each stage needs of the run, so that it can be computed without
/// holding every row: the mode split, the run's a_0/a_1 quantiles; the
/// grid, the tips' extent; a cell, its own samples only (cells can be done
/// range by range and concatenated in (ix, iy) order); a mode's
/// representative, the mode's medians and its nearest member (ties to the
/// lowest simulation, so any partition gives the same pick); pass 2, the
/// row numbers wanted.
pub fn reduce_batches<F, I>(info: &RunInfo, options: &ReduceOptions, mut batches: F) -> Result<MapData, ReduceError>
where
    F: FnMut() -> Result<I, ReduceError>,
    I: Iterator<Item = Result<RecordBatch, ReduceError>>,
{
    check_options(info, options)?;
    let scratch = spill::ScratchDir::new(&options.scratch_parent())?;
    let mut out = spill::SampleSink::new(&scratch.path.join("samples"), options.memory_samples);
    let pass1 = samples::spill_samples(info, batches()?, 0, &mut out)?;
    reduce_spilled(info, options, out.finish()?, &pass1, &scratch.path, batches)
}

/// The reduction after pass 1: from its `samples` (in memory or in scratch
/// files) and results `pass1`, with pass 2 over `batches`.
fn reduce_spilled<F, I>(
    info: &RunInfo,
    options: &ReduceOptions,
    samples: spill::Samples,
    pass1: &samples::Pass1,
    scratch: &std::path::Path,
    mut batches: F,
) -> Result<MapData, ReduceError>
where
    F: FnMut() -> Result<I, ReduceError>,
    I: Iterator<Item = Result<RecordBatch, ReduceError>>,
{
    let tally = pass1.tally.clone();
    if pass1.samples == 0 {
        return Err(ReduceError::Empty { failed: tally.rows_failed() });
    }
    let split = modes::split(&samples, options.mode_boundaries)?;
    let grid = grid::Grid::spanning(&pass1.extent, options.cell_mm)?;
    let nk = info.order.min(CELL_STATS_ORDER) + 1;
    let setup = partition::CellSetup { grid: &grid, split: &split, nk, designs_per_cell: options.designs_per_cell };
    let tabulated = partition::tabulate(samples, pass1.samples, &setup, options.memory_samples, scratch)?;
    let (cells, representatives) = (tabulated.cells, tabulated.representatives);
    let rows_converged = pass1.samples;
    let wanted = cells.picks.iter().map(|p| p.at).chain(representatives.iter().flatten().copied());
    let rows = fetch::Fetched::read(info.order, wanted, batches()?)?;
    let designs = cells
        .picks
        .iter()
        .map(|p| Ok(Design { ix: p.ix, iy: p.iy, ..rows.design(p.at)? }))
        .collect::<Result<Vec<_>, ReduceError>>()?;
    let mut fetched: [Option<Design>; MODES] = Default::default();
    for (slot, at) in fetched.iter_mut().zip(representatives) {
        if let Some(at) = at {
            let d = rows.design(at)?;
            let (ix, iy) = grid.cell_of(d.tip_x_mm, d.tip_y_mm);
            *slot = Some(Design { ix, iy, ..d });
        }
    }
    let modes = modes::table(&cells, &split.boundaries, fetched);
    let summary = MapSummary {
        format: tables::MAP_FORMAT.into(),
        cell_mm: grid.cell_mm,
        x_min_mm: grid.x_min_mm,
        y_min_mm: grid.y_min_mm,
        nx: grid.nx,
        ny: grid.ny,
        order: info.order,
        mirrored: info.mirrored,
        rows_total: tally.rows_total,
        rows_converged,
        rows_failed: tally.rows_failed(),
        failed_by_status: tally.failed_by_status,
        mode_boundaries: split.boundaries,
        mode_boundaries_source: split.source.into(),
        cells: cells.cells.len(),
        tension_range_n: info.tension_range_n,
        radius_mm: info.radius_mm,
        length_mm: info.length_mm,
        run_dir: info.run_dir.clone(),
        spec_hash: info.spec_hash.clone(),
        length_basis: info.length_basis,
        body: info.body.clone(),
    };
    Ok(MapData { summary, cells: cells.cells, modes, designs })
}

/// Refuses options the reduction cannot use, before reading the run.
fn check_options(info: &RunInfo, options: &ReduceOptions) -> Result<(), ReduceError> {
    check_cell_mm(options.cell_mm, info.length_mm)?;
    if info.order < 1 {
        return Err(ReduceError::OrderTooLow);
    }
    if let Some(b) = &options.mode_boundaries {
        b.validate()?;
    }
    Ok(())
}

/// Refuses a cell size that is not positive and finite, or larger than
/// twice the rod's length `length_mm` (the whole reach, ±L about the clamp,
/// in one or two cells per axis): beyond that a map says nothing, and its
/// corners and pictures would overflow to infinity (a 1e308 mm cell hung
/// the drawing of its axes).
pub(crate) fn check_cell_mm(cell_mm: f64, length_mm: f64) -> Result<(), ReduceError> {
    if !(cell_mm.is_finite() && cell_mm > 0.0) {
        return Err(ReduceError::CellSize { cell_mm });
    }
    let largest_cell_mm = 2.0 * length_mm;
    if cell_mm > largest_cell_mm {
        return Err(ReduceError::CellTooLarge { cell_mm, largest_cell_mm });
    }
    Ok(())
}

/// Most cells along either axis of a map (cell indices are stored as i32;
/// 100 000 cells resolve a 100 mm reach to 1 µm).
pub const MAX_CELLS_PER_AXIS: usize = 100_000;

/// Unit of a_k for labels: κ = Σ a_k P_k(t) with t dimensionless, so every
/// coefficient is a curvature.
pub const COEFFICIENT_UNIT: &str = "mm⁻¹";

/// [`ReduceError::MapNotRun`] when `e` says a directory holds no sweep and
/// that directory holds a map: the map was given in its run's place.
pub fn map_given_as_run(e: &crate::sweep::SweepError) -> Option<ReduceError> {
    let crate::sweep::SweepError::NoRun { dir, .. } = e else { return None };
    tables::recorded_run_dir(dir).map(|run_dir| ReduceError::MapNotRun { dir: dir.clone(), run_dir })
}

/// A sweep error from opening a run directory, told as a map given in the
/// run's place when the directory holds one.
pub fn run_open_error(e: crate::sweep::SweepError) -> ReduceError {
    map_given_as_run(&e).unwrap_or(ReduceError::Sweep(e))
}

/// Reduces the sweep run in `run_dir` (refusing an unfinished run unless
/// `partial`). Returns the map and the run's spec (for drawing).
pub fn reduce_run(
    run_dir: &std::path::Path,
    partial: bool,
    options: &ReduceOptions,
) -> Result<(MapData, crate::sweep::SweepSpec), ReduceError> {
    use crate::sweep::{open_run, Completeness};
    let completeness = if partial { Completeness::AllowPartial } else { Completeness::Complete };
    let run = open_run(run_dir, completeness).map_err(run_open_error)?;
    let info = run_info(&run);
    let names = columns::RowColumns::names(info.order);
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let map = reduce_batches(&info, options, || Ok(run.batches_projected(&names)?.map(|b| b.map_err(ReduceError::from))))?;
    Ok((map, run.spec().clone()))
}

/// What the reducer needs to know of an opened run.
fn run_info(run: &crate::sweep::SweepRun) -> RunInfo {
    let spec = run.spec();
    RunInfo {
        mirrored: spec.grid.mirror_dedup,
        order: spec.output.order,
        tension_range_n: [spec.tension.min_n, spec.tension.max_n],
        radius_mm: spec.actuator.radius_mm,
        length_mm: spec.actuator.length_mm,
        run_dir: run.dir().display().to_string(),
        spec_hash: run.manifest().spec_sha256.clone(),
        length_basis: spec.output.length_basis,
        body: MapBody::of(&spec.actuator),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use arrow::array::{Array, ArrayRef, Float64Array, Int64Array, StringArray};
    use arrow::datatypes::{DataType, Field, Schema};
    use std::sync::Arc;

    /// Rows (routing, tension, status, tip x, tip y, a0, a1, a2) as a sweep batch.
    type Row = ([f64; 5], f64, &'static str, f64, f64, [f64; 3]);

    fn batch(rows: &[Row]) -> RecordBatch {
        let f = |name: &str, v: Vec<Option<f64>>| -> (Field, ArrayRef) {
            (Field::new(name, DataType::Float64, true), Arc::new(Float64Array::from(v)))
        };
        let ok = |r: &Row| r.2 == "ok";
        let mut cols: Vec<(Field, ArrayRef)> = vec![
            (Field::new("routing_id", DataType::Int64, false), Arc::new(Int64Array::from((0..rows.len() as i64).collect::<Vec<_>>()))),
            (Field::new("status", DataType::Utf8, false), Arc::new(StringArray::from(rows.iter().map(|r| r.2).collect::<Vec<_>>()))),
        ];
        for k in 0..5 {
            cols.push(f(&format!("y{k}_mm"), rows.iter().map(|r| Some(r.0[k])).collect()));
        }
        cols.push(f("tension_n", rows.iter().map(|r| Some(r.1)).collect()));
        cols.push(f("tip_x_mm", rows.iter().map(|r| ok(r).then_some(r.3)).collect()));
        cols.push(f("tip_y_mm", rows.iter().map(|r| ok(r).then_some(r.4)).collect()));
        cols.push(f("tip_angle_rad", rows.iter().map(|r| ok(r).then_some(0.1)).collect()));
        for k in 0..3 {
            cols.push(f(&format!("a{k}"), rows.iter().map(|r| ok(r).then_some(r.5[k])).collect()));
        }
        let (fields, arrays): (Vec<Field>, Vec<ArrayRef>) = cols.into_iter().unzip();
        RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).unwrap()
    }

    fn info(mirrored: bool) -> RunInfo {
        RunInfo {
            mirrored,
            order: 2,
            tension_range_n: [1.0, 2.0],
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "test".into(),
            spec_hash: "x".into(),
            length_basis: LengthBasis::Rest,
            body: MapBody::default(),
        }
    }

    fn run(rows: &[Row], mirrored: bool, options: &ReduceOptions) -> MapData {
        let b = batch(rows);
        reduce_batches(&info(mirrored), options, || Ok(vec![Ok(b.clone())].into_iter())).unwrap()
    }

    fn pseudo_rows(n: usize) -> Vec<Row> {
        // A deterministic scatter of tips over a few cells.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|i| {
                let y = [next() * 2.0 - 1.0, 1.0, 0.0, -1.0, 0.5];
                let status = if i % 17 == 3 { "shooting_not_converged" } else { "ok" };
                (y, 1.0 + next(), status, 50.0 + 4.0 * next(), 1.0 + 3.0 * next(), [next() - 0.5, next() - 0.3, next()])
            })
            .collect()
    }

    #[test]
    fn counts_sum_to_converged_rows_and_percentiles_match_a_reference() {
        let rows = pseudo_rows(400);
        let map = run(&rows, false, &ReduceOptions::default());
        let converged = rows.iter().filter(|r| r.2 == "ok").count() as i64;
        assert_eq!(map.cells.iter().map(|c| c.count).sum::<i64>(), converged);
        assert_eq!(map.summary.rows_failed, rows.len() as u64 - converged as u64);
        for c in &map.cells {
            // Straightforward reference: collect the cell's values, sort, interpolate.
            let mut a0: Vec<f64> = rows
                .iter()
                .filter(|r| r.2 == "ok")
                .filter(|r| (r.3 - map.summary.x_min_mm).div_euclid(1.0) as i32 == c.ix)
                .filter(|r| (r.4 - map.summary.y_min_mm).div_euclid(1.0) as i32 == c.iy)
                .map(|r| r.5[0])
                .collect();
            assert_eq!(a0.len() as i64, c.count);
            a0.sort_by(f64::total_cmp);
            let pos = 0.1 * (a0.len() - 1) as f64;
            let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
            let p10 = a0[lo] + (a0[hi] - a0[lo]) * (pos - lo as f64);
            assert!((c.coefficients[0].p10 - p10).abs() < 1e-15);
            assert_eq!(c.modes.iter().sum::<i64>(), c.count, "mode counts sum to the cell count");
        }
        assert_eq!(map.modes.iter().map(|m| m.count).sum::<i64>(), converged);
        // Designs come from their own cell.
        for d in &map.designs {
            let ix = ((d.tip_x_mm - map.summary.x_min_mm) / map.summary.cell_mm).floor() as i32;
            assert_eq!((ix, d.iy), (d.ix, ((d.tip_y_mm - map.summary.y_min_mm) / map.summary.cell_mm).floor() as i32));
        }
    }

    #[test]
    fn the_tables_do_not_depend_on_the_memory_bound() {
        // Bounds from one sample (a partition per cell) to all of them in
        // memory, mirrored and not, quantile and explicit modes.
        let rows = pseudo_rows(3000);
        for mirrored in [false, true] {
            for boundaries in [None, Some(ModeBoundaries { a0: [-0.2, 0.0, 0.2], a1: [-0.1, 0.1] })] {
                let options = |memory_samples| ReduceOptions { memory_samples, mode_boundaries: boundaries, ..Default::default() };
                let reference = format!("{:?}", run(&rows, mirrored, &options(usize::MAX)));
                for memory_samples in [1, 7, 100, 1000] {
                    assert_eq!(format!("{:?}", run(&rows, mirrored, &options(memory_samples))), reference, "memory {memory_samples}");
                }
            }
        }
    }

    #[test]
    fn mirroring_doubles_all_but_the_self_mirror_routing() {
        let mut rows = pseudo_rows(100);
        rows.push(([0.0; 5], 1.5, "ok", 60.0, 0.2, [0.0, 0.0, 0.0]));
        let converged = rows.iter().filter(|r| r.2 == "ok").count() as i64;
        let map = run(&rows, true, &ReduceOptions::default());
        assert_eq!(map.cells.iter().map(|c| c.count).sum::<i64>(), 2 * converged - 1);
        assert!(map.designs.iter().any(|d| d.mirrored && d.tip_y_mm < 0.0));
        for d in map.designs.iter().filter(|d| d.mirrored) {
            let original = rows.iter().find(|r| r.0 == *d.routing_mm.mirrored() && r.1 == d.tension_n).unwrap();
            assert_eq!(d.tip_y_mm, -original.4);
            assert_eq!(d.a[0], -original.5[0]);
        }
    }

    #[test]
    fn explicit_boundaries_are_used_and_checked() {
        let rows = pseudo_rows(50);
        let b = ModeBoundaries { a0: [-0.2, 0.0, 0.2], a1: [-0.1, 0.1] };
        let map = run(&rows, false, &ReduceOptions { mode_boundaries: Some(b), ..Default::default() });
        assert_eq!(map.summary.mode_boundaries_source, "explicit");
        for r in rows.iter().filter(|r| r.2 == "ok") {
            let m = b.mode(r.5[0], r.5[1]);
            assert!(map.modes[m].count > 0);
        }
        let bad = ModeBoundaries { a0: [0.2, 0.0, 0.3], a1: [-0.1, 0.1] };
        let e = reduce_batches(&info(false), &ReduceOptions { mode_boundaries: Some(bad), ..Default::default() }, || {
            Ok(Vec::<Result<RecordBatch, ReduceError>>::new().into_iter())
        })
        .unwrap_err();
        assert!(e.to_string().contains("ascending"), "{e}");
    }
    #[test]
    fn the_tables_read_back_as_written() {
        let map = run(&pseudo_rows(300), true, &ReduceOptions::default());
        let tmp = tempfile::tempdir().unwrap();
        tables::write_tables(tmp.path(), &map).unwrap();
        let summary = tables::read_summary(tmp.path()).unwrap();
        assert_eq!(serde_json::to_value(&summary).unwrap(), serde_json::to_value(&map.summary).unwrap());
        let cells = tables::read_cells(tmp.path(), summary.order).unwrap();
        assert_eq!(format!("{cells:?}"), format!("{:?}", map.cells));
        assert_eq!(tables::read_designs(tmp.path(), summary.order).unwrap(), map.designs);
        // A table without one of its columns is refused, naming the column.
        let e = tables::read_designs(tmp.path(), 3).unwrap_err();
        assert!(e.to_string().contains("`a3` is missing"), "{e}");
    }

    #[test]
    fn errors_name_the_problem_and_keep_their_source() {
        use std::error::Error as _;
        let tmp = tempfile::tempdir().unwrap();
        let e = reduce_run(tmp.path(), false, &ReduceOptions::default()).unwrap_err();
        assert!(matches!(e, ReduceError::Sweep(crate::sweep::SweepError::NoRun { .. })), "{e:?}");
        assert!(e.source().is_some());
        // A cell too small for the grid: the smallest that works, no flag names.
        let e = reduce_batches(&info(false), &ReduceOptions { cell_mm: 1e-300, ..Default::default() }, || {
            Ok(vec![Ok(batch(&pseudo_rows(40)))].into_iter())
        })
        .unwrap_err();
        match &e {
            ReduceError::CellTooSmall { smallest_cell_mm, .. } => assert!(*smallest_cell_mm > 1e-6 && *smallest_cell_mm < 1e-3),
            other => panic!("{other:?}"),
        }
        // A cell larger than the whole reach (its corners overflowed and hung the drawing).
        let e = reduce_batches(&info(false), &ReduceOptions { cell_mm: 1e308, ..Default::default() }, || {
            Ok(vec![Ok(batch(&pseudo_rows(40)))].into_iter())
        })
        .unwrap_err();
        assert!(matches!(e, ReduceError::CellTooLarge { largest_cell_mm, .. } if largest_cell_mm == 130.0), "{e:?}");
        // One routing cannot be split into modes by quantiles.
        let one: Vec<Row> = (0..5).map(|i| ([0.0, 1.0, 0.0, -1.0, 0.5], 1.0 + 0.1 * i as f64, "ok", 50.0, 2.0, [0.1, 0.2, 0.0])).collect();
        let e = reduce_batches(&info(false), &ReduceOptions::default(), || Ok(vec![Ok(batch(&one))].into_iter())).unwrap_err();
        assert!(matches!(e, ReduceError::ModesNotSplit { .. }), "{e:?}");
        for e in [e.to_string(), ReduceError::CellSize { cell_mm: 0.0 }.to_string()] {
            assert!(!e.contains("--"), "a library message names no flag: {e}");
        }
        // A sweep column of the wrong type keeps Arrow's error as its source.
        let b = batch(&pseudo_rows(3));
        let i = b.schema().index_of("tip_x_mm").unwrap();
        let mut cols = b.columns().to_vec();
        let lists = arrow::array::ListArray::from_iter_primitive::<arrow::datatypes::Float64Type, _, _>((0..3).map(|_| Some(vec![Some(1.0)])));
        let list_type = lists.data_type().clone();
        cols[i] = Arc::new(lists);
        let mut fields: Vec<Field> = b.schema().fields().iter().map(|f| f.as_ref().clone()).collect();
        fields[i] = Field::new("tip_x_mm", list_type, true);
        let bad = RecordBatch::try_new(Arc::new(Schema::new(fields)), cols).unwrap();
        let e = reduce_batches(&info(false), &ReduceOptions::default(), || Ok(vec![Ok(bad.clone())].into_iter())).unwrap_err();
        assert!(matches!(e, ReduceError::ColumnType { .. }) && e.source().is_some(), "{e:?}");
    }

    #[test]
    fn a_representative_that_cannot_be_drawn_is_reported() {
        let mut map = run(&pseudo_rows(200), false, &ReduceOptions::default());
        let actuator = crate::model::Rod::default();
        let m = map.modes.iter().position(|m| m.representative.is_some()).unwrap();
        // Outside the body: the routing is refused, and the drawing says so.
        map.modes[m].representative.as_mut().unwrap().routing_mm[2] = 2.0 * actuator.radius_mm;
        let drawings = drawings::ModeDrawings::of_map(&map, &actuator, &crate::model::SolverOptions::default());
        assert_eq!(drawings.shapes.len(), MODES);
        assert!(drawings.shapes[m].is_none());
        assert_eq!(drawings.failures.len(), 1);
        let note = drawings.failure_note();
        assert!(note.contains(&format!("mode {m}")) && note.contains("routing"), "{note}");
    }
}

#[cfg(test)]
mod picture_tests {
    use super::*;
    use crate::model::{Rod, Routing, Simulator, SolverOptions};
    use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
    use arrow::datatypes::{DataType, Field, Schema};
    use std::sync::Arc;

    /// A small real run: 3 levels per control point, 4 tensions, as one batch.
    fn small_run() -> RecordBatch {
        let actuator = Rod::default();
        let mut sim = Simulator::new(&actuator, &SolverOptions::default()).unwrap();
        let (mut ids, mut status, mut ys, mut t, mut out) = (vec![], vec![], vec![[0.0; 5]; 0], vec![], vec![]);
        for id in 0..243i64 {
            let mut k = id;
            let y: [f64; 5] = std::array::from_fn(|_| {
                let level = (k % 3) as f64 - 1.0;
                k /= 3;
                level * 3.0
            });
            sim.set_routing(&Routing::new(&y, 65.0, 5.0).unwrap());
            for tension in [1.0, 1.3, 1.6, 2.0] {
                let pose = sim.solve(tension).unwrap();
                let mut a = [0.0; 3];
                sim.coefficients_into(crate::shape::LengthBasis::default(), &mut a);
                ids.push(id);
                status.push("ok");
                ys.push(y);
                t.push(tension);
                out.push([pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad, a[0], a[1], a[2]]);
            }
        }
        let mut fields = vec![Field::new("routing_id", DataType::Int64, false), Field::new("status", DataType::Utf8, false)];
        let mut cols: Vec<ArrayRef> = vec![Arc::new(Int64Array::from(ids)), Arc::new(StringArray::from(status))];
        for k in 0..5 {
            fields.push(Field::new(format!("y{k}_mm"), DataType::Float64, false));
            cols.push(Arc::new(Float64Array::from(ys.iter().map(|y| y[k]).collect::<Vec<_>>())));
        }
        fields.push(Field::new("tension_n", DataType::Float64, false));
        cols.push(Arc::new(Float64Array::from(t)));
        for (j, name) in ["tip_x_mm", "tip_y_mm", "tip_angle_rad", "a0", "a1", "a2"].iter().enumerate() {
            fields.push(Field::new(*name, DataType::Float64, true));
            cols.push(Arc::new(Float64Array::from(out.iter().map(|o| o[j]).collect::<Vec<_>>())));
        }
        RecordBatch::try_new(Arc::new(Schema::new(fields)), cols).unwrap()
    }

    #[test]
    fn map_directory_has_tables_and_non_blank_pictures() {
        let b = small_run();
        let info = RunInfo {
            mirrored: false,
            order: 2,
            tension_range_n: [1.0, 2.0],
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "small".into(),
            spec_hash: "h".into(),
            length_basis: LengthBasis::Rest,
            body: MapBody::default(),
        };
        let map = reduce_batches(&info, &ReduceOptions::default(), || Ok(vec![Ok(b.clone())].into_iter())).unwrap();
        let dir = std::env::var_os("CABLEMAP_KEEP_MAP").map(std::path::PathBuf::from);
        let tmp = tempfile::tempdir().unwrap();
        let dir = dir.unwrap_or_else(|| tmp.path().to_path_buf());
        let pictures = write_map(&dir, &map, &Rod::default(), &SolverOptions::default()).unwrap();
        assert_eq!(pictures.len(), 1 + 3 * 3 + 1);
        for p in &pictures {
            let img = image::open(dir.join(&p.file)).unwrap().to_rgb8();
            // Sized from the map's extent at equal aspect (plots.rs checks the aspect).
            let (w, h) = img.dimensions();
            assert!(w >= 600 && h >= 400 && w <= 2400 && h <= 4000, "{}: {w}×{h}", p.file);
            // Not blank: many distinct colours and a good share of non-white pixels.
            let non_white = img.pixels().filter(|px| px.0 != [255, 255, 255]).count();
            let mut colours: Vec<[u8; 3]> = img.pixels().map(|px| px.0).collect();
            colours.sort_unstable();
            colours.dedup();
            assert!(non_white * 50 > img.pixels().len(), "{}: {non_white} non-white pixels", p.file);
            assert!(colours.len() > 20, "{}: only {} colours", p.file, colours.len());
        }
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert!(html.contains("<script src=\"explorer-data.js\">"));
        let data = std::fs::read_to_string(dir.join(explorer::DATA_FILE)).unwrap();
        let json = data.trim().strip_prefix("// Written by `cablemap reduce`: the map explorer's data (index.html).\nwindow.CABLEMAP_MAP = ").unwrap();
        let v: serde_json::Value = serde_json::from_str(json.strip_suffix(';').unwrap()).unwrap();
        for p in &pictures {
            assert!(v["pictures"].as_array().unwrap().iter().any(|f| f["file"] == p.file.as_str()), "{}", p.file);
        }
        assert_eq!(v["cells"]["ix"].as_array().unwrap().len(), map.cells.len());
        assert_eq!(v["designs"]["ix"].as_array().unwrap().len(), map.designs.len());
        // Every a_i is a curvature (mm⁻¹) and the page names the basis.
        assert!(!html.contains("mm⁻²") && !data.contains("mm⁻²"));
        assert_eq!(v["length_basis_description"], "per unit rest length L (the thesis's basis)");
        assert!(pictures.iter().filter(|p| p.file.starts_with("a2")).all(|p| !p.explanation.contains("Fig.")));
        for table in ["cells.parquet", "modes.parquet", "designs.parquet", "summary.json"] {
            assert!(dir.join(table).exists(), "{table}");
        }
    }
}

