//! A feasibility map directory opened for design: its summary, its cells
//! indexed by position, its simulated designs and, for a map of several
//! cables, their cables. The files are read by the map format's owners,
//! [`crate::reduce::tables`] and [`crate::reduce::MapCables`]; what a
//! target makes of them is [`crate::design::feasible`]'s.

use super::DesignError;
use crate::model::Rod;
use crate::reduce::{tables, MapCables};
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

/// An opened map directory.
#[derive(Debug, Clone)]
pub struct MapDir {
    /// The directory.
    pub path: PathBuf,
    /// `summary.json`.
    pub summary: Summary,
    /// Non-empty cells.
    pub cells: Vec<Cell>,
    /// Every design of `designs.parquet`.
    pub designs: Vec<MapDesign>,
    /// A map of several cables: the run's cables, from which each design's
    /// every cable follows (`None`: a map of one planar cable).
    pub cables: Option<MapCables>,
    index: HashMap<(i32, i32), usize>,
}

/// A map directory's file that breaks the map contract, or a map made for
/// another actuator.
pub(super) fn map_error(path: &Path, message: impl Into<String>) -> DesignError {
    DesignError::Map { path: path.display().to_string(), message: message.into() }
}

impl MapDir {
    /// Opens a map directory: reads `summary.json`, `cells.parquet`,
    /// `designs.parquet` and, beside a map of several cables, its cables.
    pub fn open(dir: &Path) -> Result<Self, DesignError> {
        let summary = tables::read_summary(dir)?;
        let cells = tables::read_cells(dir, summary.order)?;
        let designs = tables::read_designs(dir, summary.order)?;
        let cables = MapCables::open(dir).map_err(|e| map_error(dir, e.to_string()))?;
        let index = cells.iter().enumerate().map(|(i, c)| ((c.ix, c.iy), i)).collect();
        Ok(Self { path: dir.to_path_buf(), summary, cells, designs, cables, index })
    }

    /// Refuses to use a map made for another actuator than `rod` (a
    /// rod with its one planar cable): another rod or body, or several cables.
    pub fn check_actuator(&self, rod: &Rod) -> Result<(), DesignError> {
        if let Some(cables) = &self.cables {
            return Err(map_error(
                &self.path,
                format!(
                    "the map was made for an actuator of {} cables, but `design` searches the routing and tension of one planar cable, \
                     so the map's designs are not designs of the actuator searched: design without --map, or read the map's \
                     nearest designs (every cable, and the command that solves each) with `cablemap feasible --map {}`",
                    cables.count(),
                    self.path.display()
                ),
            ));
        }
        let s = &self.summary;
        if (s.length_mm - rod.length_mm).abs() > 1e-9 || (s.radius_mm - rod.radius_mm).abs() > 1e-9 {
            return Err(map_error(
                &self.path,
                format!(
                    "the map was made for a rod of L = {} mm, r = {} mm but the actuator has L = {} mm, r = {} mm; use a matching map or --length-mm/--radius-mm",
                    s.length_mm, s.radius_mm, rod.length_mm, rod.radius_mm
                ),
            ));
        }
        let body = crate::reduce::MapBody::of(rod);
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

    /// The non-empty cell at (ix, iy), if any.
    pub fn cell(&self, ix: i32, iy: i32) -> Option<&Cell> {
        self.index.get(&(ix, iy)).map(|&i| &self.cells[i])
    }
}
