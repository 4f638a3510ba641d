//! The map format (docs/maps.md, docs/schema.md), one owner: the file and
//! column names of a map directory's tables, their writer and their reader.
//! `summary.json` is [`MapSummary`] serialised; `cells.parquet`,
//! `modes.parquet` and `designs.parquet` hold [`CellStats`],
//! [`ModeStats`](super::ModeStats) and [`Design`] rows. The design columns
//! are the sweep's own (`sweep::schema`). A cable sweep's map holds
//! [`ReachMapSummary`] as its `summary.json`, the reach tables
//! ([`REACH_FILES`]) and, for a planar run, a feasibility map in
//! [`PLANAR_MAP_DIR`].

use super::reach::{Reach, PLANES, VOXEL_AXES};
use super::{ReachMapSummary, CellStats, CoefficientStats, Design, MapData, MapSummary, ReduceError, CELL_STATS_ORDER, MAX_CELLS_PER_AXIS, MODES};
use crate::model::ControlPoints;
use crate::sweep::schema::{coefficient_column, ROUTING_ID, TENSION_N, TIP_ANGLE_RAD, TIP_X_MM, TIP_Y_MM, Y_MM};
use arrow::array::{Array, ArrayRef, AsArray, BooleanArray, Float64Array, Int32Array, Int64Array};
use arrow::datatypes::{DataType, Field, Float64Type, Int32Type, Int64Type, Schema};
use arrow::record_batch::RecordBatch;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The map's summary (JSON).
pub const SUMMARY_FILE: &str = "summary.json";
/// Format tag in every map's summary.json (`format`), planar and cable
/// maps alike: the marker by which a reduce recognises a directory it may
/// replace as a whole (`output::check_map_out`).
pub const MAP_FORMAT: &str = "cablemap-map/1";
/// What every [`MAP_FORMAT`] begins with, whatever its version.
pub const MAP_FORMAT_PREFIX: &str = "cablemap-map/";
/// One row per non-empty cell.
pub const CELLS_FILE: &str = "cells.parquet";
/// One row per characteristic mode.
pub const MODES_FILE: &str = "modes.parquet";
/// The simulated designs kept per cell.
pub const DESIGNS_FILE: &str = "designs.parquet";
/// Reach tables of a cable sweep's map: solved tips per cell on the x–y,
/// x–z and y–z planes, and per 3-D voxel. Columns: `i{axis}` (cell index,
/// i32) and `{axis}_mm` (cell centre, f64) per axis, then `count` (i64).
pub const REACH_FILES: [&str; 4] = ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"];
/// Folder, inside a cable sweep's map, of a planar run's feasibility map.
pub const PLANAR_MAP_DIR: &str = "planar";
/// The tables of a feasibility map, in the order a reader lists them.
pub const FEASIBILITY_FILES: [&str; 3] = [CELLS_FILE, MODES_FILE, DESIGNS_FILE];

/// Columns of `cells.parquet`.
pub mod cell_columns {
    /// Cell column (i32).
    pub const IX: &str = "ix";
    /// Cell row (i32).
    pub const IY: &str = "iy";
    /// Cell centre (f64, mm).
    pub const X_MM: &str = "x_mm";
    /// Cell centre (f64, mm).
    pub const Y_MM: &str = "y_mm";
    /// Simulations in the cell (i64).
    pub const COUNT: &str = "count";

    /// A statistic of a coefficient over a cell's simulations.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Stat {
        /// 10th percentile.
        P10,
        /// 90th percentile.
        P90,
        /// p90 − p10.
        Gap,
        /// Smallest value.
        Min,
        /// Largest value.
        Max,
    }

    /// Column of statistic `stat` of a_k (f64, mm⁻¹): `a{k}_p10`, …
    pub fn stat(k: usize, stat: Stat) -> String {
        let suffix = match stat {
            Stat::P10 => "p10",
            Stat::P90 => "p90",
            Stat::Gap => "gap",
            Stat::Min => "min",
            Stat::Max => "max",
        };
        format!("a{k}_{suffix}")
    }

    /// Simulations of mode `m` in the cell (i64): `mode_{m}`.
    pub fn mode(m: usize) -> String {
        format!("mode_{m}")
    }
}

/// Columns of `modes.parquet`.
pub mod mode_columns {
    /// Mode index 3·i + j (i32).
    pub const MODE: &str = "mode";
    /// a_0 range i (i32).
    pub const A0_RANGE: &str = "a0_range";
    /// a_1 range j (i32).
    pub const A1_RANGE: &str = "a1_range";
    /// Bounds of the a_0 range (f64, mm⁻¹; open ends ±inf).
    pub const A0_LO: &str = "a0_lo";
    /// See `A0_LO`.
    pub const A0_HI: &str = "a0_hi";
    /// Bounds of the a_1 range.
    pub const A1_LO: &str = "a1_lo";
    /// See `A1_LO`.
    pub const A1_HI: &str = "a1_hi";
    /// Simulations in the mode (i64).
    pub const COUNT: &str = "count";
    /// Cells where the mode occurs (i64).
    pub const CELLS: &str = "cells";

    /// A representative's column: `rep_` and the design column (f64, null
    /// for a mode without simulations).
    pub fn representative(design_column: &str) -> String {
        format!("rep_{design_column}")
    }
}

/// Columns of `designs.parquet`: the cell, then the sweep row's own columns.
pub mod design_columns {
    /// Cell column (i32).
    pub const IX: &str = "ix";
    /// Cell row (i32).
    pub const IY: &str = "iy";
    /// Whether the design is the mirror image of the stored row (bool).
    pub const MIRRORED: &str = "mirrored";
    pub use crate::sweep::schema::{coefficient_column, ROUTING_ID, TENSION_N, TIP_ANGLE_RAD, TIP_X_MM, TIP_Y_MM, Y_MM};
}

/// Columns built up by name, then turned into one record batch.
#[derive(Default)]
struct Table {
    fields: Vec<Field>,
    columns: Vec<ArrayRef>,
}

impl Table {
    fn f64(&mut self, name: &str, values: Vec<Option<f64>>) {
        self.fields.push(Field::new(name, DataType::Float64, values.iter().any(Option::is_none)));
        self.columns.push(Arc::new(Float64Array::from(values)));
    }
    fn f64_all(&mut self, name: &str, values: Vec<f64>) {
        self.f64(name, values.into_iter().map(Some).collect());
    }
    fn i32(&mut self, name: &str, values: Vec<i32>) {
        self.fields.push(Field::new(name, DataType::Int32, false));
        self.columns.push(Arc::new(Int32Array::from(values)));
    }
    fn i64(&mut self, name: &str, values: Vec<i64>) {
        self.fields.push(Field::new(name, DataType::Int64, false));
        self.columns.push(Arc::new(Int64Array::from(values)));
    }
    fn bool(&mut self, name: &str, values: Vec<bool>) {
        self.fields.push(Field::new(name, DataType::Boolean, false));
        self.columns.push(Arc::new(BooleanArray::from(values)));
    }
    fn write(self, path: &Path) -> Result<(), ReduceError> {
        let schema = Arc::new(Schema::new(self.fields));
        let arrow = |source| ReduceError::WriteArrow { path: path.to_path_buf(), source };
        let parquet = |source| ReduceError::WriteParquet { path: path.to_path_buf(), source };
        let batch = RecordBatch::try_new(schema.clone(), self.columns).map_err(arrow)?;
        let props = WriterProperties::builder().set_compression(Compression::ZSTD(ZstdLevel::default())).build();
        let mut buf = Vec::new();
        let mut writer = ArrowWriter::try_new(&mut buf, schema, Some(props)).map_err(parquet)?;
        writer.write(&batch).map_err(parquet)?;
        writer.close().map_err(parquet)?;
        write_file(path, &buf)
    }
}

/// Writes `bytes` to `path` atomically.
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ReduceError> {
    crate::io::write_atomic(path, bytes).map_err(|source| ReduceError::Write { path: path.to_path_buf(), source })
}

/// Writes cells.parquet, modes.parquet, designs.parquet and summary.json.
pub fn write_tables(dir: &Path, map: &MapData) -> Result<(), ReduceError> {
    use cell_columns::Stat;
    let mut cells = Table::default();
    let c = &map.cells;
    cells.i32(cell_columns::IX, c.iter().map(|c| c.ix).collect());
    cells.i32(cell_columns::IY, c.iter().map(|c| c.iy).collect());
    cells.f64_all(cell_columns::X_MM, c.iter().map(|c| c.x_mm).collect());
    cells.f64_all(cell_columns::Y_MM, c.iter().map(|c| c.y_mm).collect());
    cells.i64(cell_columns::COUNT, c.iter().map(|c| c.count).collect());
    let nk = c.first().map_or(0, |c| c.coefficients.len());
    for k in 0..nk {
        let stats = |f: &dyn Fn(&CoefficientStats) -> f64| c.iter().map(|c| f(&c.coefficients[k])).collect();
        cells.f64_all(&cell_columns::stat(k, Stat::P10), stats(&|s| s.p10));
        cells.f64_all(&cell_columns::stat(k, Stat::P90), stats(&|s| s.p90));
        cells.f64_all(&cell_columns::stat(k, Stat::Gap), stats(&|s| s.p90 - s.p10));
        cells.f64_all(&cell_columns::stat(k, Stat::Min), stats(&|s| s.min));
        cells.f64_all(&cell_columns::stat(k, Stat::Max), stats(&|s| s.max));
    }
    for m in 0..MODES {
        cells.i64(&cell_columns::mode(m), c.iter().map(|c| c.modes[m]).collect());
    }
    cells.write(&dir.join(CELLS_FILE))?;

    use mode_columns as mc;
    let mut modes = Table::default();
    let m = &map.modes;
    modes.i32(mc::MODE, m.iter().map(|m| m.mode as i32).collect());
    modes.i32(mc::A0_RANGE, m.iter().map(|m| m.a0_range as i32).collect());
    modes.i32(mc::A1_RANGE, m.iter().map(|m| m.a1_range as i32).collect());
    modes.f64_all(mc::A0_LO, m.iter().map(|m| m.a0_bounds.0).collect());
    modes.f64_all(mc::A0_HI, m.iter().map(|m| m.a0_bounds.1).collect());
    modes.f64_all(mc::A1_LO, m.iter().map(|m| m.a1_bounds.0).collect());
    modes.f64_all(mc::A1_HI, m.iter().map(|m| m.a1_bounds.1).collect());
    modes.i64(mc::COUNT, m.iter().map(|m| m.count).collect());
    modes.i64(mc::CELLS, m.iter().map(|m| m.cells).collect());
    let rep = |f: &dyn Fn(&Design) -> f64| -> Vec<Option<f64>> { m.iter().map(|m| m.representative.as_ref().map(f)).collect() };
    for (k, name) in Y_MM.iter().enumerate() {
        modes.f64(&mc::representative(name), rep(&|d| d.routing_mm[k]));
    }
    modes.f64(&mc::representative(TENSION_N), rep(&|d| d.tension_n));
    modes.f64(&mc::representative(TIP_X_MM), rep(&|d| d.tip_x_mm));
    modes.f64(&mc::representative(TIP_Y_MM), rep(&|d| d.tip_y_mm));
    for k in 0..2 {
        modes.f64(&mc::representative(&coefficient_column(k)), rep(&|d| d.a[k]));
    }
    modes.write(&dir.join(MODES_FILE))?;

    use design_columns as dc;
    let mut designs = Table::default();
    let d = &map.designs;
    designs.i32(dc::IX, d.iter().map(|d| d.ix).collect());
    designs.i32(dc::IY, d.iter().map(|d| d.iy).collect());
    designs.i64(ROUTING_ID, d.iter().map(|d| d.routing_id).collect());
    designs.bool(dc::MIRRORED, d.iter().map(|d| d.mirrored).collect());
    for (k, name) in Y_MM.iter().enumerate() {
        designs.f64_all(name, d.iter().map(|d| d.routing_mm[k]).collect());
    }
    designs.f64_all(TENSION_N, d.iter().map(|d| d.tension_n).collect());
    designs.f64_all(TIP_X_MM, d.iter().map(|d| d.tip_x_mm).collect());
    designs.f64_all(TIP_Y_MM, d.iter().map(|d| d.tip_y_mm).collect());
    designs.f64_all(TIP_ANGLE_RAD, d.iter().map(|d| d.tip_angle_rad).collect());
    for k in 0..=map.summary.order {
        designs.f64_all(&coefficient_column(k), d.iter().map(|d| d.a[k]).collect());
    }
    designs.write(&dir.join(DESIGNS_FILE))?;

    let path = dir.join(SUMMARY_FILE);
    let json = serde_json::to_vec_pretty(&map.summary).map_err(|source| ReduceError::WriteJson { path: path.clone(), source })?;
    write_file(&path, &json)
}

/// Writes a cable sweep's reach tables ([`REACH_FILES`]) into `dir`.
pub(crate) fn write_reach(dir: &Path, reach: &Reach) -> Result<(), ReduceError> {
    for ((_, axes), (file, counts)) in PLANES.iter().zip(REACH_FILES.iter().zip(&reach.planes)) {
        counts_table(counts, axes, reach.cell_mm).write(&dir.join(file))?;
    }
    counts_table(&reach.voxels, &VOXEL_AXES, reach.cell_mm).write(&dir.join(REACH_FILES[3]))
}

/// One reach table: `i{axis}`, `{axis}_mm` per axis, then `count`.
fn counts_table<const N: usize>(counts: &BTreeMap<[i32; N], i64>, axes: &[&str; N], cell_mm: f64) -> Table {
    let mut table = Table::default();
    for (k, axis) in axes.iter().enumerate() {
        table.i32(&format!("i{axis}"), counts.keys().map(|c| c[k]).collect());
    }
    for (k, axis) in axes.iter().enumerate() {
        table.f64_all(&format!("{axis}_mm"), counts.keys().map(|c| (c[k] as f64 + 0.5) * cell_mm).collect());
    }
    table.i64("count", counts.values().copied().collect());
    table
}

/// Writes a cable sweep map's `summary.json` into `dir`.
pub(crate) fn write_cable_summary(dir: &Path, summary: &ReachMapSummary) -> Result<(), ReduceError> {
    let path = dir.join(SUMMARY_FILE);
    let json = serde_json::to_string_pretty(summary).map_err(|source| ReduceError::WriteJson { path: path.clone(), source })? + "\n";
    write_file(&path, json.as_bytes())
}

/// A map table that cannot be read, or breaks the map format.
#[derive(Debug, thiserror::Error)]
#[error("map {}: {problem}", path.display())]
pub struct ReadError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong, and what to do.
    pub problem: MapProblem,
}

fn read_error(path: &Path, problem: MapProblem) -> ReadError {
    ReadError { path: path.to_path_buf(), problem }
}

/// What is wrong with a map file.
#[derive(Debug, thiserror::Error)]
pub enum MapProblem {
    /// The directory has no `summary.json`.
    #[error("{0}")]
    NoSummary(MissingSummary),
    /// `summary.json` cannot be read.
    #[error("cannot read ({0}); give a map directory written by `cablemap reduce`")]
    Unreadable(#[source] std::io::Error),
    /// A cable sweep's map with a planar map inside, given as a feasibility map.
    #[error("is the map of a cable sweep (reach counts); its planar feasibility map is {}", planar.display())]
    CableMapWithPlanar {
        /// Its planar map's folder.
        planar: PathBuf,
    },
    /// A spatial cable sweep's map, given as a feasibility map.
    #[error("is the map of a spatial cable sweep (reach counts only): it has no feasibility map")]
    SpatialCableMap,
    /// `summary.json` breaks the map contract.
    #[error("does not match the map contract: {0}")]
    Contract(#[source] serde_json::Error),
    /// Its mode boundaries are not boundaries.
    #[error("mode_boundaries: {0}")]
    ModeBoundaries(#[source] Box<super::ReduceError>),
    /// Its cell size is not a length.
    #[error("cell_mm must be positive, got {cell_mm}")]
    CellSize {
        /// The cell size recorded, mm.
        cell_mm: f64,
    },
    /// Its tension range is not a range.
    #[error("tension_range_n [{lo}, {hi}] is not a range")]
    TensionRange {
        /// Lowest tension recorded, N.
        lo: f64,
        /// Highest, N.
        hi: f64,
    },
    /// A table cannot be opened.
    #[error("cannot open ({0}); is this a `cablemap reduce` output directory?")]
    CannotOpen(#[source] std::io::Error),
    /// A table is not Parquet.
    #[error("not a readable parquet file: {0}")]
    NotParquet(#[source] parquet::errors::ParquetError),
    /// A table's rows cannot be decoded.
    #[error("reading: {0}")]
    Reading(#[source] arrow::error::ArrowError),
    /// A column is missing.
    #[error("column `{name}` is missing (see docs/maps.md)")]
    ColumnMissing {
        /// The column.
        name: String,
    },
    /// A column has nulls.
    #[error("column `{name}` has nulls")]
    ColumnNulls {
        /// The column.
        name: String,
    },
    /// A column has another type.
    #[error("column `{name}` should be {wanted}, is {found}")]
    ColumnType {
        /// The column.
        name: String,
        /// The type the format gives it.
        wanted: &'static str,
        /// Its type in the file.
        found: arrow::datatypes::DataType,
    },
    /// A cell off the grid.
    #[error("cell ({ix}, {iy}) lies off the grid 0..{end}: the file is damaged; reduce the run again")]
    CellOffGrid {
        /// Its column.
        ix: i32,
        /// Its row.
        iy: i32,
        /// The grid's end along either axis.
        end: i32,
    },
    /// A cable sweep map's summary cannot be read.
    #[error("cannot read ({0}); give the map directory of a cable sweep (`cablemap map` of a spec with [[cable]] tables)")]
    CableMapUnreadable(#[source] std::io::Error),
    /// Not a cable sweep's map.
    #[error("is not the summary of a cable sweep's map (kind = \"cables\"): give the map of a cable sweep")]
    NotCableMap,
    /// A cable sweep map's summary, unreadable where its kind was already read.
    #[error("cannot read ({0})")]
    CannotRead(#[source] std::io::Error),
    /// A cable sweep map's summary breaks its contract.
    #[error("does not match the cable map contract: {0}")]
    CableContract(#[source] serde_json::Error),
}

/// Why a directory has no `summary.json`, pointing at the map the user
/// meant: the `map` folder of `cablemap map --out DIR`, maps inside it, or
/// the map still to be made of a run.
#[derive(Debug)]
pub enum MissingSummary {
    /// The directory does not exist.
    NoDir {
        /// The directory.
        dir: PathBuf,
    },
    /// The directory is a sweep run.
    RunNotMap {
        /// The directory.
        dir: PathBuf,
    },
    /// Nothing map-like inside it.
    NoMap,
    /// Maps inside it.
    MapsInside {
        /// The directory.
        dir: PathBuf,
        /// The maps inside it.
        maps: Vec<PathBuf>,
    },
}

impl MissingSummary {
    /// What `dir` holds instead of a map.
    fn of(dir: &Path) -> Self {
        if !dir.exists() {
            MissingSummary::NoDir { dir: dir.to_path_buf() }
        } else if crate::io::is_run_dir(dir) {
            MissingSummary::RunNotMap { dir: dir.to_path_buf() }
        } else {
            match crate::io::subdirs_holding(dir, SUMMARY_FILE) {
                maps if maps.is_empty() => MissingSummary::NoMap,
                maps => MissingSummary::MapsInside { dir: dir.to_path_buf(), maps },
            }
        }
    }
}

impl std::fmt::Display for MissingSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MissingSummary::NoDir { dir } => write!(f, "{} does not exist; give a map directory written by `cablemap reduce`", dir.display()),
            MissingSummary::RunNotMap { dir } => {
                let d = dir.display();
                write!(f, "is missing: {d} is a sweep run, not a map; reduce it first (`cablemap reduce {d} --out MAP_DIR`)")
            }
            MissingSummary::NoMap => write!(f, "is missing; give a map directory written by `cablemap reduce`"),
            MissingSummary::MapsInside { dir, maps } => match maps.as_slice() {
                [one] => {
                    let (d, one) = (dir.display(), one.display());
                    write!(f, "is missing: {d} holds no map itself, but {one} inside it does (the map `cablemap map --out {d}` writes); give {one}")
                }
                _ => {
                    let names: Vec<String> = maps.iter().map(|p| p.display().to_string()).collect();
                    write!(f, "is missing: {} holds no map itself; the maps inside it: {}; give one of them", dir.display(), names.join(", "))
                }
            },
        }
    }
}

/// Reads and checks `summary.json` of map directory `dir`.
pub fn read_summary(dir: &Path) -> Result<MapSummary, ReadError> {
    let path = dir.join(SUMMARY_FILE);
    let text = crate::io::read_utf8(&path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => read_error(&path, MapProblem::NoSummary(MissingSummary::of(dir))),
        _ => read_error(&path, MapProblem::Unreadable(e)),
    })?;
    let summary: MapSummary = serde_json::from_str(&text).map_err(|e| {
        // A cable sweep's map is not a feasibility map; a
        // planar one holds one in its `planar` folder.
        match serde_json::from_str::<serde_json::Value>(&text).ok().filter(|v| v["kind"] == "cables") {
            Some(v) if v["planar_map"].is_string() => read_error(&path, MapProblem::CableMapWithPlanar { planar: dir.join(PLANAR_MAP_DIR) }),
            Some(_) => read_error(&path, MapProblem::SpatialCableMap),
            None => read_error(&path, MapProblem::Contract(e)),
        }
    })?;
    summary.mode_boundaries.validate().map_err(|e| read_error(&path, MapProblem::ModeBoundaries(Box::new(e))))?;
    if !(summary.cell_mm > 0.0 && summary.cell_mm.is_finite()) {
        return Err(read_error(&path, MapProblem::CellSize { cell_mm: summary.cell_mm }));
    }
    let [lo, hi] = summary.tension_range_n;
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(read_error(&path, MapProblem::TensionRange { lo, hi }));
    }
    Ok(summary)
}

/// The run directory a map directory records it was made from (planar or
/// cable map), or `None` when `dir` holds no map: how a map given in place
/// of a run is told apart from an empty folder.
pub fn recorded_run_dir(dir: &Path) -> Option<String> {
    let text = crate::io::read_utf8(&dir.join(SUMMARY_FILE)).ok()?;
    let value: serde_json::Value = serde_json::from_str(&text).ok()?;
    value.get("run_dir")?.as_str().map(str::to_string)
}

/// Reads every record batch of a parquet file.
fn read_batches(path: &Path) -> Result<Vec<RecordBatch>, ReadError> {
    let file = std::fs::File::open(path)
        .map_err(|e| read_error(path, MapProblem::CannotOpen(e)))?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .and_then(|b| b.build())
        .map_err(|e| read_error(path, MapProblem::NotParquet(e)))?;
    reader.collect::<Result<Vec<_>, _>>().map_err(|e| read_error(path, MapProblem::Reading(e)))
}

/// Typed column access with errors that name the column.
struct Columns<'a> {
    path: &'a Path,
    batch: &'a RecordBatch,
}

impl<'a> Columns<'a> {
    fn column(&self, name: &str) -> Result<&'a dyn Array, ReadError> {
        let c = self
            .batch
            .column_by_name(name)
            .ok_or_else(|| read_error(self.path, MapProblem::ColumnMissing { name: name.to_string() }))?;
        if c.null_count() > 0 {
            return Err(read_error(self.path, MapProblem::ColumnNulls { name: name.to_string() }));
        }
        Ok(c.as_ref())
    }

    fn f64(&self, name: &str) -> Result<&'a [f64], ReadError> {
        let c = self.column(name)?;
        c.as_primitive_opt::<Float64Type>()
            .map(|a| a.values().as_ref())
            .ok_or_else(|| read_error(self.path, MapProblem::ColumnType { name: name.to_string(), wanted: "f64", found: c.data_type().clone() }))
    }

    fn i32(&self, name: &str) -> Result<&'a [i32], ReadError> {
        let c = self.column(name)?;
        c.as_primitive_opt::<Int32Type>()
            .map(|a| a.values().as_ref())
            .ok_or_else(|| read_error(self.path, MapProblem::ColumnType { name: name.to_string(), wanted: "i32", found: c.data_type().clone() }))
    }

    fn i64(&self, name: &str) -> Result<&'a [i64], ReadError> {
        let c = self.column(name)?;
        c.as_primitive_opt::<Int64Type>()
            .map(|a| a.values().as_ref())
            .ok_or_else(|| read_error(self.path, MapProblem::ColumnType { name: name.to_string(), wanted: "i64", found: c.data_type().clone() }))
    }

    fn bool(&self, name: &str) -> Result<Vec<bool>, ReadError> {
        let c = self.column(name)?;
        c.as_boolean_opt()
            .map(|a| a.iter().map(|v| v.unwrap_or(false)).collect())
            .ok_or_else(|| read_error(self.path, MapProblem::ColumnType { name: name.to_string(), wanted: "bool", found: c.data_type().clone() }))
    }
}

/// Reads `cells.parquet` of map directory `dir` for a map of coefficient
/// order `order` (statistics up to a_min(order, 2)); refuses cells off the grid.
pub fn read_cells(dir: &Path, order: usize) -> Result<Vec<CellStats>, ReadError> {
    use cell_columns::{self as cc, Stat};
    let path = dir.join(CELLS_FILE);
    let stats_order = order.min(CELL_STATS_ORDER);
    let mut cells = Vec::new();
    for batch in read_batches(&path)? {
        let c = Columns { path: &path, batch: &batch };
        let (ix, iy, x, y, count) = (c.i32(cc::IX)?, c.i32(cc::IY)?, c.f64(cc::X_MM)?, c.f64(cc::Y_MM)?, c.i64(cc::COUNT)?);
        let stats: Vec<[&[f64]; 4]> = (0..=stats_order)
            .map(|k| {
                Ok([c.f64(&cc::stat(k, Stat::P10))?, c.f64(&cc::stat(k, Stat::P90))?, c.f64(&cc::stat(k, Stat::Min))?, c.f64(&cc::stat(k, Stat::Max))?])
            })
            .collect::<Result<_, ReadError>>()?;
        let modes: Vec<&[i64]> = (0..MODES).map(|m| c.i64(&cc::mode(m))).collect::<Result<_, _>>()?;
        for r in 0..batch.num_rows() {
            cells.push(CellStats {
                ix: ix[r],
                iy: iy[r],
                x_mm: x[r],
                y_mm: y[r],
                count: count[r],
                coefficients: stats.iter().map(|s| CoefficientStats { p10: s[0][r], p90: s[1][r], min: s[2][r], max: s[3][r] }).collect(),
                modes: std::array::from_fn(|m| modes[m][r]),
            });
        }
    }
    let grid = 0..MAX_CELLS_PER_AXIS as i32;
    if let Some(c) = cells.iter().find(|c| !grid.contains(&c.ix) || !grid.contains(&c.iy)) {
        return Err(read_error(&path, MapProblem::CellOffGrid { ix: c.ix, iy: c.iy, end: grid.end }));
    }
    Ok(cells)
}

/// Reads every design of `designs.parquet` of map directory `dir` (a map of
/// coefficient order `order`).
pub fn read_designs(dir: &Path, order: usize) -> Result<Vec<Design>, ReadError> {
    use design_columns as dc;
    let path = dir.join(DESIGNS_FILE);
    let mut out = Vec::new();
    for batch in read_batches(&path)? {
        let c = Columns { path: &path, batch: &batch };
        let (ix, iy, id) = (c.i32(dc::IX)?, c.i32(dc::IY)?, c.i64(ROUTING_ID)?);
        let mirrored = c.bool(dc::MIRRORED)?;
        let ys: Vec<&[f64]> = Y_MM.iter().map(|name| c.f64(name)).collect::<Result<_, _>>()?;
        let (t, x, y, ang) = (c.f64(TENSION_N)?, c.f64(TIP_X_MM)?, c.f64(TIP_Y_MM)?, c.f64(TIP_ANGLE_RAD)?);
        let a: Vec<&[f64]> = (0..=order).map(|k| c.f64(&coefficient_column(k))).collect::<Result<_, _>>()?;
        for r in 0..batch.num_rows() {
            out.push(Design {
                ix: ix[r],
                iy: iy[r],
                routing_id: id[r],
                mirrored: mirrored[r],
                routing_mm: ControlPoints(std::array::from_fn(|i| ys[i][r])),
                tension_n: t[r],
                tip_x_mm: x[r],
                tip_y_mm: y[r],
                tip_angle_rad: ang[r],
                a: a.iter().map(|col| col[r]).collect(),
            });
        }
    }
    Ok(out)
}

/// The reach of a cable sweep's map, as its reach tables hold it.
#[derive(Debug, Clone)]
pub struct ReachTables {
    /// `summary.json`.
    pub summary: ReachMapSummary,
    /// Solved tips per cell of the x–y, x–z and y–z planes (cell indices along the plane's axes).
    pub planes: [std::collections::BTreeMap<[i32; 2], i64>; 3],
    /// Solved tips per voxel (indices along x, y, z).
    pub voxels: std::collections::BTreeMap<[i32; 3], i64>,
}

/// Reads a cable sweep map's `summary.json` and reach tables ([`REACH_FILES`]).
pub fn read_reach(dir: &Path) -> Result<ReachTables, ReadError> {
    let path = dir.join(SUMMARY_FILE);
    let text = crate::io::read_utf8(&path).map_err(|e| read_error(&path, MapProblem::CableMapUnreadable(e)))?;
    let summary: ReachMapSummary = serde_json::from_str(&text)
        .ok()
        .filter(|s: &ReachMapSummary| s.kind == "cables")
        .ok_or_else(|| read_error(&path, MapProblem::NotCableMap))?;
    if !(summary.cell_mm > 0.0 && summary.cell_mm.is_finite()) {
        return Err(read_error(&path, MapProblem::CellSize { cell_mm: summary.cell_mm }));
    }
    let mut planes: [std::collections::BTreeMap<[i32; 2], i64>; 3] = Default::default();
    for (k, ((_, axes), file)) in PLANES.iter().zip(REACH_FILES.iter()).enumerate() {
        let path = dir.join(file);
        for batch in read_batches(&path)? {
            let c = Columns { path: &path, batch: &batch };
            let (a, b, count) = (c.i32(&format!("i{}", axes[0]))?, c.i32(&format!("i{}", axes[1]))?, c.i64("count")?);
            for r in 0..batch.num_rows() {
                planes[k].insert([a[r], b[r]], count[r]);
            }
        }
    }
    let mut voxels = std::collections::BTreeMap::new();
    let path = dir.join(REACH_FILES[3]);
    for batch in read_batches(&path)? {
        let c = Columns { path: &path, batch: &batch };
        let (x, y, z, count) = (c.i32("ix")?, c.i32("iy")?, c.i32("iz")?, c.i64("count")?);
        for r in 0..batch.num_rows() {
            voxels.insert([x[r], y[r], z[r]], count[r]);
        }
    }
    Ok(ReachTables { summary, planes, voxels })
}

/// One table of a map directory: its name (the file's stem: `cells`,
/// `reach_xy`, …) and its file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MapTable {
    /// The table's name, its file name without `.parquet`.
    pub name: String,
    /// The Parquet file.
    pub path: PathBuf,
}

/// Every table of map directory `dir`, for readers outside cablemap (the
/// Python package's `read_map`): a feasibility map's [`FEASIBILITY_FILES`];
/// a cable sweep's map's [`REACH_FILES`] and, when it holds a planar map
/// ([`PLANAR_MAP_DIR`]), that map's feasibility tables under their own
/// names. The summary is checked first, so a run or an empty folder given
/// in place of a map is refused with what to give instead.
pub fn map_tables(dir: &Path) -> Result<Vec<MapTable>, ReadError> {
    let table = |dir: &Path, file: &str| MapTable { name: file.trim_end_matches(".parquet").to_string(), path: dir.join(file) };
    let feasibility = |dir: &Path| -> Result<Vec<MapTable>, ReadError> {
        read_summary(dir)?;
        Ok(FEASIBILITY_FILES.iter().map(|f| table(dir, f)).collect())
    };
    let is_cable_map = crate::io::read_utf8(&dir.join(SUMMARY_FILE))
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .is_some_and(|v| v["kind"] == "cables");
    if !is_cable_map {
        return feasibility(dir);
    }
    let path = dir.join(SUMMARY_FILE);
    let text = crate::io::read_utf8(&path).map_err(|e| read_error(&path, MapProblem::CannotRead(e)))?;
    let summary: ReachMapSummary = serde_json::from_str(&text).map_err(|e| read_error(&path, MapProblem::CableContract(e)))?;
    let mut tables: Vec<MapTable> = REACH_FILES.iter().map(|f| table(dir, f)).collect();
    if let Some(planar) = &summary.planar_map {
        tables.extend(feasibility(&dir.join(planar))?);
    }
    Ok(tables)
}
