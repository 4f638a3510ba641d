//! What a map holds: the feasibility map of planar rows ([`MapData`]: its
//! summary, cells, modes and designs), which every planar run has, and the
//! reach map of a cable sweep's tips ([`ReachMapSummary`]; its directory
//! holds the feasibility map of a planar cable sweep beside it). The
//! pipeline computes them; the map format (`tables`) writes and reads them.

use super::ModeBoundaries;
use crate::model::ControlPoints;
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Number of characteristic modes: a_0 in 4 ranges × a_1 in 3.
pub const MODES: usize = 12;

/// Highest coefficient order with per-cell statistics (a_0 … a_2).
pub const CELL_STATS_ORDER: usize = 2;

/// Most cells along either axis of a map (cell indices are stored as i32;
/// 100 000 cells resolve a 100 mm reach to 1 µm).
pub const MAX_CELLS_PER_AXIS: usize = 100_000;

/// Unit of a_k for labels: κ = Σ a_k P_k(t) with t dimensionless, so every
/// coefficient is a curvature.
pub const COEFFICIENT_UNIT: &str = "mm⁻¹";

/// The summary of a feasibility map, written as its summary.json
/// (docs/maps.md).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MapSummary {
    /// [`MAP_FORMAT`](super::tables::MAP_FORMAT): marks the directory as a map written by
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

/// What a map records of its actuator's body beyond L and r: the radius
/// profile, segments and cable anchor. Empty for the thesis's uniform rod,
/// whose summary.json then has none of these fields (a reader of the
/// thesis's maps sees no new keys).
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
    pub fn of(rod: &crate::model::Rod) -> Self {
        MapBody {
            radius_profile_mm: rod.radius_profile_mm.clone(),
            segments: rod.segments.clone(),
            cable_anchor_mm: rod.cable_anchor_mm.filter(|&k| k != rod.length_mm),
        }
    }
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

/// `summary.json` of a cable sweep's reach map: the cells its tips reach
/// (the feasibility map of a planar cable sweep, in its folder
/// `planar_map`, has its own [`MapSummary`]).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ReachMapSummary {
    /// [`MAP_FORMAT`](super::tables::MAP_FORMAT): marks the directory as a
    /// map written by cablemap.
    #[serde(default)]
    pub format: String,
    /// Always `cables`: tells this summary from a planar map's.
    pub kind: String,
    /// The run read.
    pub run_dir: String,
    /// SHA-256 of the run's spec.
    pub spec_sha256: String,
    /// Cables per actuator.
    pub cables: usize,
    /// Routings of the complete sweep.
    pub routings: u64,
    /// Tension combinations per routing.
    pub tension_combinations: u64,
    /// Rows read (all rows unless the map is of a partial run).
    pub rows: u64,
    /// Rows of the complete sweep.
    pub rows_total: u64,
    /// Rows solved.
    pub ok: u64,
    /// Rows whose solve failed.
    pub failed: u64,
    /// Rows of rejected routings (channel outside the body, two cables on one path, …).
    pub invalid_rows: u64,
    /// Whether every cable is planar and gravity lies in the x–y plane.
    pub planar: bool,
    /// Reach cell / voxel size, mm.
    pub cell_mm: f64,
    /// Occupied cells: x–y, x–z, y–z, 3-D voxels.
    pub cells: [u64; 4],
    /// The planar map's folder (`planar`), when one was written.
    pub planar_map: Option<String>,
}
