//! Reading a feasibility map directory (the contract of `docs/maps.md`):
//! `summary.json`, `cells.parquet` and `designs.parquet`.

use super::optimise::{Seed, SeedSource};
use super::target::{Component, Target, Weights};
use super::DesignError;
use crate::model::Actuator;
use crate::shape::LengthBasis;
use arrow::array::{Array, AsArray, RecordBatch};
use arrow::datatypes::{Float64Type, Int32Type, Int64Type};
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use serde::Serialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Number of characteristic modes (a_0 in 4 ranges × a_1 in 3).
pub use crate::reduce::MODES;

/// Highest coefficient order with per-cell statistics in `cells.parquet`.
pub const CELL_STATS_ORDER: usize = 2;

/// `summary.json`, read with the reducer's own type so that the contract
/// has one definition.
pub type Summary = crate::reduce::MapSummary;

/// One non-empty cell of `cells.parquet` (the reducer's own type).
pub type Cell = crate::reduce::CellStats;

/// Statistics of one coefficient in one cell (the reducer's own type).
pub type CoefficientStats = crate::reduce::CoefficientStats;

/// One simulated design of `designs.parquet` (the reducer's own type).
pub type MapDesign = crate::reduce::Design;

/// The value of `component` in a map design (None for an order the map does not store).
pub fn design_value(d: &MapDesign, component: Component) -> Option<f64> {
    match component {
        Component::TipX => Some(d.tip_x_mm),
        Component::TipY => Some(d.tip_y_mm),
        Component::A(k) => d.a.get(k).copied(),
    }
}

/// A design with its weighted distance to a target.
#[derive(Debug, Clone, PartialEq)]
pub struct NearDesign {
    /// The design.
    pub design: MapDesign,
    /// √(Σ λ_j (c_j − t_j)²) over the target's components the map stores.
    pub distance: f64,
}

impl NearDesign {
    /// As a starting design for the optimiser.
    pub fn seed(&self) -> Seed {
        Seed { routing_mm: self.design.y_mm, tension_n: self.design.tension_n, source: SeedSource::Map }
    }
}

/// JSON with the names `design` uses (`routing_mm`, `tension_n`, `tip_x_mm`, …).
impl Serialize for NearDesign {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let d = &self.design;
        serde_json::json!({
            "routing_mm": d.y_mm,
            "tension_n": d.tension_n,
            "tip_x_mm": d.tip_x_mm,
            "tip_y_mm": d.tip_y_mm,
            "tip_angle_rad": d.tip_angle_rad,
            "a": d.a,
            "ix": d.ix,
            "iy": d.iy,
            "routing_id": d.routing_id,
            "mirrored": d.mirrored,
            "distance": self.distance,
        })
        .serialize(s)
    }
}

/// An opened map directory.
#[derive(Debug, Clone)]
pub struct MapDir {
    /// The directory.
    pub path: PathBuf,
    /// `summary.json`.
    pub summary: Summary,
    /// Non-empty cells.
    pub cells: Vec<Cell>,
    index: HashMap<(i32, i32), usize>,
    designs_path: PathBuf,
}

fn map_error(path: &Path, message: impl Into<String>) -> DesignError {
    DesignError::Map { path: path.display().to_string(), message: message.into() }
}

/// Reads every record batch of a parquet file.
fn read_batches(path: &Path) -> Result<Vec<RecordBatch>, DesignError> {
    let file = std::fs::File::open(path)
        .map_err(|e| map_error(path, format!("cannot open ({e}); is this a `cablemap reduce` output directory?")))?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .and_then(|b| b.build())
        .map_err(|e| map_error(path, format!("not a readable parquet file: {e}")))?;
    reader.collect::<Result<Vec<_>, _>>().map_err(|e| map_error(path, format!("reading: {e}")))
}

/// Typed column access with errors that name the column.
struct Columns<'a> {
    path: &'a Path,
    batch: &'a RecordBatch,
}

impl<'a> Columns<'a> {
    fn column(&self, name: &str) -> Result<&'a dyn Array, DesignError> {
        let c = self
            .batch
            .column_by_name(name)
            .ok_or_else(|| map_error(self.path, format!("column `{name}` is missing (see docs/maps.md)")))?;
        if c.null_count() > 0 {
            return Err(map_error(self.path, format!("column `{name}` has nulls")));
        }
        Ok(c.as_ref())
    }

    fn f64(&self, name: &str) -> Result<&'a [f64], DesignError> {
        let c = self.column(name)?;
        c.as_primitive_opt::<Float64Type>()
            .map(|a| a.values().as_ref())
            .ok_or_else(|| map_error(self.path, format!("column `{name}` should be f64, is {}", c.data_type())))
    }

    fn i32(&self, name: &str) -> Result<&'a [i32], DesignError> {
        let c = self.column(name)?;
        c.as_primitive_opt::<Int32Type>()
            .map(|a| a.values().as_ref())
            .ok_or_else(|| map_error(self.path, format!("column `{name}` should be i32, is {}", c.data_type())))
    }

    fn i64(&self, name: &str) -> Result<&'a [i64], DesignError> {
        let c = self.column(name)?;
        c.as_primitive_opt::<Int64Type>()
            .map(|a| a.values().as_ref())
            .ok_or_else(|| map_error(self.path, format!("column `{name}` should be i64, is {}", c.data_type())))
    }

    fn bool(&self, name: &str) -> Result<Vec<bool>, DesignError> {
        let c = self.column(name)?;
        c.as_boolean_opt()
            .map(|a| a.iter().map(|v| v.unwrap_or(false)).collect())
            .ok_or_else(|| map_error(self.path, format!("column `{name}` should be bool, is {}", c.data_type())))
    }
}

/// Off-grid indices are clamped to ±2³⁰: far outside every map (cells lie in
/// 0..[`crate::reduce::MAX_CELLS_PER_AXIS`]) and small enough that index
/// differences cannot overflow.
fn clamp_index(i: i64) -> i32 {
    const FAR: i64 = 1 << 30;
    i.clamp(-FAR, FAR) as i32
}

impl MapDir {
    /// Opens a map directory: reads `summary.json` and `cells.parquet`
    /// (`designs.parquet` is read on demand).
    pub fn open(dir: &Path) -> Result<Self, DesignError> {
        let summary_path = dir.join("summary.json");
        let text = crate::io::read_utf8(&summary_path).map_err(|e| {
            map_error(&summary_path, format!("cannot read ({e}); give the directory written by `cablemap reduce RUN_DIR --out MAP_DIR`"))
        })?;
        let summary: Summary =
            serde_json::from_str(&text).map_err(|e| map_error(&summary_path, format!("does not match the map contract: {e}")))?;
        summary
            .mode_boundaries
            .validate()
            .map_err(|e| map_error(&summary_path, format!("mode_boundaries: {e}")))?;
        if !(summary.cell_mm > 0.0 && summary.cell_mm.is_finite()) {
            return Err(map_error(&summary_path, format!("cell_mm must be positive, got {}", summary.cell_mm)));
        }
        let [lo, hi] = summary.tension_range_n;
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(map_error(&summary_path, format!("tension_range_n [{lo}, {hi}] is not a range")));
        }
        let cells_path = dir.join("cells.parquet");
        let stats_order = summary.order.min(CELL_STATS_ORDER);
        let mut cells = Vec::new();
        for batch in read_batches(&cells_path)? {
            let c = Columns { path: &cells_path, batch: &batch };
            let (ix, iy, x, y, count) = (c.i32("ix")?, c.i32("iy")?, c.f64("x_mm")?, c.f64("y_mm")?, c.i64("count")?);
            let stats: Vec<[&[f64]; 4]> = (0..=stats_order)
                .map(|k| {
                    Ok([c.f64(&format!("a{k}_p10"))?, c.f64(&format!("a{k}_p90"))?, c.f64(&format!("a{k}_min"))?, c.f64(&format!("a{k}_max"))?])
                })
                .collect::<Result<_, DesignError>>()?;
            let modes: Vec<&[i64]> = (0..MODES).map(|m| c.i64(&format!("mode_{m}"))).collect::<Result<_, _>>()?;
            for r in 0..batch.num_rows() {
                cells.push(Cell {
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
        let grid = 0..crate::reduce::MAX_CELLS_PER_AXIS as i32;
        if let Some(c) = cells.iter().find(|c| !grid.contains(&c.ix) || !grid.contains(&c.iy)) {
            return Err(map_error(
                &cells_path,
                format!("cell ({}, {}) lies off the grid 0..{}: the file is damaged; reduce the run again", c.ix, c.iy, grid.end),
            ));
        }
        let index = cells.iter().enumerate().map(|(i, c)| ((c.ix, c.iy), i)).collect();
        Ok(Self { path: dir.to_path_buf(), summary, cells, index, designs_path: dir.join("designs.parquet") })
    }

    /// Refuses to use a map made for a different rod.
    pub fn check_actuator(&self, actuator: &Actuator) -> Result<(), DesignError> {
        let s = &self.summary;
        if (s.length_mm - actuator.length_mm).abs() > 1e-9 || (s.radius_mm - actuator.radius_mm).abs() > 1e-9 {
            return Err(map_error(
                &self.path,
                format!(
                    "the map was made for a rod of L = {} mm, r = {} mm but the actuator has L = {} mm, r = {} mm; use a matching map or --length-mm/--radius-mm",
                    s.length_mm, s.radius_mm, actuator.length_mm, actuator.radius_mm
                ),
            ));
        }
        Ok(())
    }

    /// Refuses a target whose coefficients are in another basis than the
    /// map's. There is no exact conversion: a_i change by ℓ/L, and ℓ differs
    /// from design to design within a cell, so percentiles do not convert.
    /// A target without coefficients is judged in either basis.
    pub fn check_length_basis(&self, basis: LengthBasis, target: &Target) -> Result<(), DesignError> {
        let map_basis = self.summary.length_basis;
        if map_basis == basis || target.highest_order().is_none() {
            return Ok(());
        }
        Err(map_error(
            &self.path,
            format!(
                "the map's coefficients are {} ({map_basis} basis) but the target's are {} ({basis} basis); they differ \
                 by ℓ/L, which varies from design to design, so they cannot be compared: give the target in the map's \
                 basis (length basis '{map_basis}'), or reduce a sweep made with [output] length_basis = \"{basis}\"",
                map_basis.describe(),
                basis.describe()
            ),
        ))
    }

    /// The cell index containing coordinate `v` along an axis starting at `min` (may be off the grid).
    fn cell_index(&self, v: f64, min: f64) -> i64 {
        ((v - min) / self.summary.cell_mm).floor() as i64
    }

    /// The non-empty cell at (ix, iy), if any.
    pub fn cell(&self, ix: i32, iy: i32) -> Option<&Cell> {
        self.index.get(&(ix, iy)).map(|&i| &self.cells[i])
    }

    /// Column index of the cells containing x (None when x is None: every
    /// column). A coordinate far off the map gives an index far off the
    /// grid (clamped, never wrapped onto it).
    pub fn column_of(&self, x_mm: Option<f64>) -> Option<i32> {
        x_mm.map(|x| clamp_index(self.cell_index(x, self.summary.x_min_mm)))
    }

    /// Row index of the cells containing y (None when y is None: every row).
    pub fn row_of(&self, y_mm: Option<f64>) -> Option<i32> {
        y_mm.map(|y| clamp_index(self.cell_index(y, self.summary.y_min_mm)))
    }

    /// Reads every design of `designs.parquet`.
    pub fn designs(&self) -> Result<Vec<MapDesign>, DesignError> {
        let path = &self.designs_path;
        let order = self.summary.order;
        let mut out = Vec::new();
        for batch in read_batches(path)? {
            let c = Columns { path, batch: &batch };
            let (ix, iy, id) = (c.i32("ix")?, c.i32("iy")?, c.i64("routing_id")?);
            let mirrored = c.bool("mirrored")?;
            let ys: Vec<&[f64]> = (0..5).map(|i| c.f64(&format!("y{i}_mm"))).collect::<Result<_, _>>()?;
            let (t, x, y, ang) = (c.f64("tension_n")?, c.f64("tip_x_mm")?, c.f64("tip_y_mm")?, c.f64("tip_angle_rad")?);
            let a: Vec<&[f64]> = (0..=order).map(|k| c.f64(&format!("a{k}"))).collect::<Result<_, _>>()?;
            for r in 0..batch.num_rows() {
                out.push(MapDesign {
                    ix: ix[r],
                    iy: iy[r],
                    routing_id: id[r],
                    mirrored: mirrored[r],
                    y_mm: std::array::from_fn(|i| ys[i][r]),
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

    /// The `count` designs of `designs.parquet` nearest to `target` by the
    /// weighted distance √(Σ λ_j (c_j − t_j)²) over the target components the
    /// map stores (coefficients above the map's order are ignored).
    pub fn nearest_designs(&self, target: &Target, weights: &Weights, count: usize) -> Result<Vec<NearDesign>, DesignError> {
        let mut near: Vec<NearDesign> = self
            .designs()?
            .into_iter()
            .map(|d| {
                let distance = target
                    .components
                    .iter()
                    .filter_map(|(c, t)| design_value(&d, *c).map(|v| weights.get(*c) * (v - t).powi(2)))
                    .sum::<f64>()
                    .sqrt();
                NearDesign { design: d, distance }
            })
            .collect();
        near.sort_by(|p, q| p.distance.total_cmp(&q.distance));
        near.truncate(count);
        Ok(near)
    }
}
