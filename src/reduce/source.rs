//! What the reducer reads of a run, for each kind of run: what it needs to
//! know of the run ([`RunInfo`]) and the run's rows in the planar row layout
//! ([`planar_batch`]), so that one pipeline maps a planar sweep and a planar
//! cable sweep alike.

use super::columns::{cable_planar_batch, cable_planar_columns, RowColumns};
use super::{MapBody, ReduceError};
use crate::shape::LengthBasis;
use crate::sweep::{RoutingGrid, SweepRun, SweepSpec};
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};

/// What the reducer needs to know about the run it reads.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunInfo {
    /// Whether the run dropped mirror images (the reducer restores them).
    pub mirrored: bool,
    /// Highest coefficient order stored (columns a0 … a{order}).
    pub order: usize,
    /// Tension range of the run, N.
    pub tension_range_n: [f64; 2],
    /// Whether the run's tensions were found (its cables driven by their
    /// displacement): the map's tension range is then its designs'.
    #[serde(default)]
    pub tensions_found: bool,
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

/// What the reducer needs to know of an opened run: a planar sweep's grid
/// and ladder, or a planar cable sweep's grids (its tension range spans
/// every cable's grid).
pub(crate) fn run_info(run: &SweepRun) -> RunInfo {
    let spec = run.spec();
    let (mirrored, tension_range_n, tensions_found, rod) = match &spec.routings {
        RoutingGrid::Planar(p) => (p.grid.mirror_dedup, [p.tension.min_n, p.tension.max_n], p.displacement.is_some(), &p.actuator),
        RoutingGrid::Cables(c) => {
            let tensions: Vec<f64> = c.grids.iter().filter(|g| !g.by_displacement).flat_map(|g| [g.actuation.min, g.actuation.max]).collect();
            let range = [tensions.iter().copied().fold(f64::MAX, f64::min), tensions.iter().copied().fold(0.0, f64::max)];
            (false, range, c.grids.iter().any(|g| g.by_displacement), &c.actuator.rod)
        }
    };
    RunInfo {
        mirrored,
        order: spec.output.order,
        tension_range_n,
        tensions_found,
        radius_mm: rod.radius_mm,
        length_mm: rod.length_mm,
        run_dir: run.dir().display().to_string(),
        spec_hash: run.manifest().spec_sha256.clone(),
        length_basis: spec.output.length_basis,
        body: MapBody::of(rod),
    }
}

/// The columns to read from the run for its rows in the planar layout.
pub(crate) fn planar_columns(spec: &SweepSpec) -> Vec<String> {
    match &spec.routings {
        RoutingGrid::Planar(_) => RowColumns::names(spec.output.order),
        RoutingGrid::Cables(c) => cable_planar_columns(c, &spec.output),
    }
}

/// One batch of [`planar_columns`] in the planar row layout: a planar
/// sweep's rows are in it already; a planar cable sweep's rows carry cable
/// 1's routing and tension and their row key ([`cable_planar_batch`]).
pub(crate) fn planar_batch(spec: &SweepSpec, batch: RecordBatch) -> Result<RecordBatch, ReduceError> {
    match &spec.routings {
        RoutingGrid::Planar(_) => Ok(batch),
        RoutingGrid::Cables(c) => cable_planar_batch(c, &spec.output, &batch),
    }
}
