//! A feasibility map directory opened for design: its summary and cells
//! indexed by position, its designs on demand. The files are read by the
//! map format's owner, [`crate::reduce::tables`].

use super::optimise::{Seed, SeedSource};
use super::target::{Component, Target, Weights};
use super::DesignError;
use crate::model::Rod;
use crate::reduce::tables;
use crate::shape::LengthBasis;
use serde::Serialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Number of characteristic modes (a_0 in 4 ranges × a_1 in 3).
pub use crate::reduce::MODES;

/// Highest coefficient order with per-cell statistics in `cells.parquet`.
pub use crate::reduce::CELL_STATS_ORDER;

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
        Seed { routing_mm: self.design.routing_mm, tension_n: self.design.tension_n, source: SeedSource::Map }
    }
}

/// JSON with the names `design` uses (`routing_mm`, `tension_n`, `tip_x_mm`, …).
impl Serialize for NearDesign {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let d = &self.design;
        serde_json::json!({
            "routing_mm": d.routing_mm,
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
}

fn map_error(path: &Path, message: impl Into<String>) -> DesignError {
    DesignError::Map { path: path.display().to_string(), message: message.into() }
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
        let summary = tables::read_summary(dir)?;
        let cells = tables::read_cells(dir, summary.order)?;
        let index = cells.iter().enumerate().map(|(i, c)| ((c.ix, c.iy), i)).collect();
        Ok(Self { path: dir.to_path_buf(), summary, cells, index })
    }

    /// Refuses to use a map made for a different rod.
    pub fn check_actuator(&self, actuator: &Rod) -> Result<(), DesignError> {
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
        let body = crate::reduce::MapBody::of(actuator);
        if s.body != body {
            let describe = |b: &crate::reduce::MapBody| {
                if *b == crate::reduce::MapBody::default() {
                    "the uniform rod with the cable knotted at the tip".to_string()
                } else {
                    format!(
                        "radius profile {:?} mm, {} segment(s), cable anchor {}",
                        b.radius_profile_mm,
                        b.segments.len(),
                        b.cable_anchor_mm.map_or("at the tip".into(), |k| format!("at {k} mm"))
                    )
                }
            };
            return Err(map_error(
                &self.path,
                format!(
                    "the map was made for another body ({}) than the actuator's ({}); use a map swept for this body (the same radius profile, segments and cable anchor)",
                    describe(&s.body),
                    describe(&body)
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
        Ok(tables::read_designs(&self.path, self.summary.order)?)
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
