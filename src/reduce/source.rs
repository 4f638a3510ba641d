//! What the reducer reads of a run, for each kind of run: what it needs to
//! know of the run ([`RunInfo`]) and the run's rows in the planar row layout
//! ([`PlanarSource`]), so that one pipeline maps a planar sweep and a planar
//! cable sweep alike.

use super::columns::{cable_planar_batch, cable_planar_columns, RowColumns};
use super::{MapBody, ReduceError};
use crate::shape::LengthBasis;
use crate::sweep::{CableSweepSpec, RunSpec, SweepRun, SweepSpec};
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

/// A kind of run whose rows the planar reducer can map.
pub(crate) trait PlanarSource: RunSpec {
    /// What the reducer needs to know of an opened run of this kind.
    fn run_info(run: &SweepRun<Self>) -> RunInfo;
    /// The columns to read from the run.
    fn planar_columns(&self) -> Vec<String>;
    /// One batch of those columns in the planar row layout.
    fn planar_batch(&self, batch: RecordBatch) -> Result<RecordBatch, ReduceError>;
}

/// A planar sweep's rows are in the planar layout already.
impl PlanarSource for SweepSpec {
    fn run_info(run: &SweepRun<Self>) -> RunInfo {
        let spec = run.spec();
        RunInfo {
            mirrored: spec.grid.mirror_dedup,
            order: spec.output.order,
            tension_range_n: [spec.tension.min_n, spec.tension.max_n],
            tensions_found: spec.displacement.is_some(),
            radius_mm: spec.actuator.radius_mm,
            length_mm: spec.actuator.length_mm,
            run_dir: run.dir().display().to_string(),
            spec_hash: run.manifest().spec_sha256.clone(),
            length_basis: spec.output.length_basis,
            body: MapBody::of(&spec.actuator),
        }
    }

    fn planar_columns(&self) -> Vec<String> {
        RowColumns::names(self.output.order)
    }

    fn planar_batch(&self, batch: RecordBatch) -> Result<RecordBatch, ReduceError> {
        Ok(batch)
    }
}

/// A planar cable sweep's rows, each with cable 1's routing and tension
/// and its row key ([`cable_planar_batch`]); its tension range spans every
/// cable's grid.
impl PlanarSource for CableSweepSpec {
    fn run_info(run: &SweepRun<Self>) -> RunInfo {
        let spec = run.spec();
        let tensions: Vec<f64> = spec.grids.iter().filter(|g| !g.by_displacement).flat_map(|g| [g.actuation.min, g.actuation.max]).collect();
        let rod = &spec.actuator.rod;
        RunInfo {
            mirrored: false,
            order: spec.output.order,
            tension_range_n: [tensions.iter().copied().fold(f64::MAX, f64::min), tensions.iter().copied().fold(0.0, f64::max)],
            tensions_found: spec.grids.iter().any(|g| g.by_displacement),
            radius_mm: rod.radius_mm,
            length_mm: rod.length_mm,
            run_dir: run.dir().display().to_string(),
            spec_hash: run.manifest().spec_sha256.clone(),
            length_basis: spec.output.length_basis,
            body: MapBody::of(rod),
        }
    }

    fn planar_columns(&self) -> Vec<String> {
        cable_planar_columns(self)
    }

    fn planar_batch(&self, batch: RecordBatch) -> Result<RecordBatch, ReduceError> {
        cable_planar_batch(self, &batch)
    }
}
