//! A feasibility map directory opened for design: its summary, its cells
//! indexed by position, its simulated designs and, for a map of several
//! cables, their cables. The files are read by the map format's owners,
//! [`crate::reduce::tables`] and [`crate::reduce::MapCables`]; what a
//! target makes of them is [`crate::design::feasible`]'s.

use super::DesignError;
use crate::model::Rod;
use crate::reduce::{tables, MapBody, MapCables};
use crate::shape::LengthBasis;
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

/// How a map directory fails a design: its cables' file is unreadable, or
/// it was made for another actuator or length basis.
#[derive(Debug, thiserror::Error)]
pub enum MapMismatch {
    /// The spec of a map of several cables cannot be read.
    #[error("{0}")]
    Cables(#[source] Box<crate::reduce::ReduceError>),
    /// A map of several cables for the one-cable design.
    #[error(
        "the map was made for an actuator of {cables} cables, but `design` searches the routing and tension of one planar cable, \
         so the map's designs are not designs of the actuator searched: design without --map, or read the map's \
         nearest designs (every cable, and the command that solves each) with `cablemap feasible --map {}`",
        path.display()
    )]
    SeveralCables {
        /// Cables of the map's actuator.
        cables: usize,
        /// The map directory.
        path: PathBuf,
    },
    /// A map of one planar cable for a several-cable design.
    #[error(
        "a map of one planar cable: its designs are not designs of the several-cable actuator; give the map of a cable sweep \
         (`cablemap map` of a spec with [[cable]] tables)"
    )]
    OnePlanarCable,
    /// A map of another number of cables.
    #[error("the map was made for {map} cables, the actuator has {actuator}")]
    CableCount {
        /// The map's cables.
        map: usize,
        /// The actuator's.
        actuator: usize,
    },
    /// A map of another rod's length or radius.
    #[error(
        "the map was made for a rod of L = {map_length_mm} mm, r = {map_radius_mm} mm but the actuator has L = {length_mm} mm, \
         r = {radius_mm} mm; use a matching map or --length-mm/--radius-mm"
    )]
    Rod {
        /// The map's rod length, mm.
        map_length_mm: f64,
        /// The map's rod radius, mm.
        map_radius_mm: f64,
        /// The actuator's rod length, mm.
        length_mm: f64,
        /// The actuator's rod radius, mm.
        radius_mm: f64,
    },
    /// A map of another body.
    #[error(
        "the map was made for another body ({}) than the actuator's ({}); use a map swept for this body (the same radius profile, \
         segments and cable anchor)",
        describe_body(map),
        describe_body(actuator)
    )]
    Body {
        /// The map's body.
        map: MapBody,
        /// The actuator's.
        actuator: MapBody,
    },
    /// A target's coefficients in another length basis than the map's.
    #[error(
        "the map's coefficients are {} ({map} basis) but the target's are {} ({target} basis); they differ \
         by ℓ/L, which varies from design to design, so they cannot be compared: give the target in the map's \
         basis (length basis '{map}'), or reduce a sweep made with [output] length_basis = \"{target}\"",
        map.describe(),
        target.describe()
    )]
    LengthBasis {
        /// The map's basis.
        map: LengthBasis,
        /// The target's.
        target: LengthBasis,
    },
}

/// A body in words, for [`MapMismatch::Body`].
fn describe_body(b: &MapBody) -> String {
    if *b == MapBody::default() {
        "the uniform rod with the cable knotted at the tip".to_string()
    } else {
        format!(
            "radius profile {:?} mm, {} segment(s), cable anchor {}",
            b.radius_profile_mm,
            b.segments.len(),
            b.cable_anchor_mm.map_or("at the tip".into(), |k| format!("at {k} mm"))
        )
    }
}

/// A map directory that fails a design.
pub(super) fn map_error(path: &Path, problem: MapMismatch) -> DesignError {
    DesignError::Map { path: path.to_path_buf(), problem }
}

impl MapDir {
    /// Opens a map directory: reads `summary.json`, `cells.parquet`,
    /// `designs.parquet` and, beside a map of several cables, its cables.
    pub fn open(dir: &Path) -> Result<Self, DesignError> {
        let summary = tables::read_summary(dir)?;
        let cells = tables::read_cells(dir, summary.order)?;
        let designs = tables::read_designs(dir, summary.order)?;
        let cables = MapCables::open(dir).map_err(|e| map_error(dir, MapMismatch::Cables(Box::new(e))))?;
        let index = cells.iter().enumerate().map(|(i, c)| ((c.ix, c.iy), i)).collect();
        Ok(Self { path: dir.to_path_buf(), summary, cells, designs, cables, index })
    }

    /// Refuses to use a map made for another actuator than `rod` (a
    /// rod with its one planar cable): another rod or body, or several cables.
    pub fn check_actuator(&self, rod: &Rod) -> Result<(), DesignError> {
        if let Some(cables) = &self.cables {
            return Err(map_error(&self.path, MapMismatch::SeveralCables { cables: cables.count(), path: self.path.clone() }));
        }
        let s = &self.summary;
        if (s.length_mm - rod.length_mm).abs() > 1e-9 || (s.radius_mm - rod.radius_mm).abs() > 1e-9 {
            let (map_length_mm, map_radius_mm, length_mm, radius_mm) = (s.length_mm, s.radius_mm, rod.length_mm, rod.radius_mm);
            return Err(map_error(&self.path, MapMismatch::Rod { map_length_mm, map_radius_mm, length_mm, radius_mm }));
        }
        let body = MapBody::of(rod);
        if s.body != body {
            return Err(map_error(&self.path, MapMismatch::Body { map: s.body.clone(), actuator: body }));
        }
        Ok(())
    }

    /// The non-empty cell at (ix, iy), if any.
    pub fn cell(&self, ix: i32, iy: i32) -> Option<&Cell> {
        self.index.get(&(ix, iy)).map(|&i| &self.cells[i])
    }
}
