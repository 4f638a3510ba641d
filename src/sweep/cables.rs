//! Sweeps of several and spatial cables (issue 16): a TOML spec says which
//! control points of which cable (y or z) are swept over which levels, and
//! a tension grid per cable; every routing is solved through the product of
//! the tension grids by the 3-D solver ([`crate::model::spatial`]). The run
//! writes one Parquet table of rows (one tension column per cable, the 3-D
//! tip) and reach maps: counts of solutions per cell on the three coordinate
//! planes and per voxel in 3-D (docs/schema.md, "Cable sweeps").
//!
//! ```toml
//! gravity_direction = [1, 0, 0]   # optional, as in the actuator file
//! [rod]                            # optional: model::Rod
//! [solver]                         # optional: SpatialOptions
//! [output]
//! order = 3                        # a0…a3, a_bend_y0…, a_twist0…
//! cell_mm = 1.0                    # reach-map cell / voxel size
//! chunk_routings = 64              # routings per chunk file (engine chunks)
//!
//! [[cable]]                        # an antagonistic pair
//! y_mm = [2, 2, 2, 2, 2]           # fixed values (swept points override them)
//! tension_n = { min = 0.0, max = 2.0, count = 11 }
//! [[cable.sweep]]
//! axis = "y"
//! points = [1, 2, 3]               # each swept independently over the levels
//! levels_mm = [1.0, 2.5, 4.0]
//!
//! [[cable]]
//! y_mm = [-2, -2, -2, -2, -2]
//! tension_n = { min = 0.0, max = 2.0, count = 11 }
//! ```
//!
//! It runs on the same engine as the planar sweep ([`super::run_sweep_of`]:
//! sharded, resumable, checksummed chunks; [`super::kind::RunSpec`]): routing
//! ids are the mixed-radix numbers of the swept levels (the first swept point
//! fastest), and each routing's rows are its tension combinations in grid
//! order (cable 1's tension slowest), solved in snake order for warm starts.
//! The run's format tag is [`CABLES_FORMAT`]; a chunk holds
//! `output.chunk_routings` routings.

use crate::model::routing::CONTROL_POINTS;
use crate::model::spatial::{Cable, Actuator, SpatialError, SpatialOptions, SpatialSolver};
use crate::model::{Rod, STATUS_OK};
use crate::shape::LengthBasis;
use super::kind::{ChunkLayout, RunSpec};
use super::SweepError;
use arrow::array::{ArrayRef, Float64Array, Int32Array, Int64Array, StringArray};
use arrow::datatypes::{DataType, Field, Schema, SchemaRef};
use arrow::record_batch::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;
use std::sync::Arc;

/// Format tag of cable sweep runs (manifest and chunk footers;
/// [`crate::io::run_markers::CABLES_FORMAT`], where every run kind's tag is kept).
pub const CABLES_FORMAT: &str = crate::io::run_markers::CABLES_FORMAT;
/// Most values in one tension grid.
pub const MAX_TENSION_COUNT: u32 = 10_000;
/// Status of rows whose routing was rejected (e.g. two cables on one path).
pub const STATUS_INVALID_ROUTING: &str = "invalid_routing";
/// Status of rows whose solve failed.
pub const STATUS_FAILED: &str = "failed";
/// Why a cable sweep could not run.
#[derive(Debug, thiserror::Error)]
pub enum CableSweepError {
    /// The spec is malformed or invalid.
    #[error("bad cable sweep spec {origin}: {message}")]
    BadSpec { origin: String, message: String },
    /// A file could not be written.
    #[error("{context}: {message}")]
    Write { context: String, message: String },
}

/// A cable sweep job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CableSweepSpec {
    /// Rod parameters (thesis defaults).
    #[serde(default)]
    pub rod: Rod,
    /// Torsional rigidity, N·mm² (default EI/1.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gj_n_mm2: Option<f64>,
    /// Gravity direction, global (default: the rod's in-plane direction).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity_direction: Option<[f64; 3]>,
    /// Numerical settings of the 3-D solver.
    #[serde(default)]
    pub solver: SpatialOptions,
    /// What each row stores; the map resolution.
    #[serde(default)]
    pub output: CableOutputSpec,
    /// The cables, each with its fixed control points, swept points and tension grid.
    #[serde(rename = "cable")]
    pub cables: Vec<CableSweep>,
}

/// One cable of a sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CableSweep {
    /// y control points, mm (those swept are overridden).
    pub y_mm: [f64; CONTROL_POINTS],
    /// z control points, mm (default 0).
    #[serde(default)]
    pub z_mm: [f64; CONTROL_POINTS],
    /// Anchor s_k, mm (default: the tip).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_mm: Option<f64>,
    /// The tension grid of this cable.
    pub tension_n: TensionGrid,
    /// Swept control points.
    #[serde(default, rename = "sweep")]
    pub sweeps: Vec<PointSweep>,
}

/// Control points of one axis of a cable, each swept over `levels_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSweep {
    /// `y` or `z`.
    pub axis: Axis,
    /// Control-point indices 0…4; each is swept independently (a product).
    pub points: Vec<usize>,
    /// The levels, mm.
    pub levels_mm: Vec<f64>,
}

/// A body-frame lateral axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Body y.
    Y,
    /// Body z.
    Z,
}

/// `count` tensions evenly spaced from `min` to `max`, N.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TensionGrid {
    /// First tension, N (≥ 0).
    pub min: f64,
    /// Last tension, N (≥ min).
    pub max: f64,
    /// Number of tensions (1: `min` only).
    pub count: u32,
}

impl TensionGrid {
    /// The tensions, N.
    pub fn values(&self) -> Vec<f64> {
        if self.count <= 1 {
            return vec![self.min];
        }
        (0..self.count).map(|k| self.min + (self.max - self.min) * k as f64 / (self.count - 1) as f64).collect()
    }
}

/// Output settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CableOutputSpec {
    /// Highest Legendre order stored (each of the three series).
    pub order: usize,
    /// Basis of the coefficients.
    pub length_basis: LengthBasis,
    /// Cell size of the reach maps, mm.
    pub cell_mm: f64,
    /// Routings per chunk file (each chunk is built in memory: at most
    /// [`super::spec::MAX_CHUNK_ROWS`] rows with the tension combinations).
    pub chunk_routings: u32,
}

impl Default for CableOutputSpec {
    fn default() -> Self {
        Self { order: 3, length_basis: LengthBasis::Rest, cell_mm: 1.0, chunk_routings: 64 }
    }
}

/// One swept dimension: cable, axis, control point, levels.
#[derive(Debug, Clone)]
struct Dimension {
    cable: usize,
    axis: Axis,
    point: usize,
    levels: Vec<f64>,
}

impl CableSweepSpec {
    /// Reads a spec; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, CableSweepError> {
        let spec: Self = toml::from_str(text).map_err(|e| CableSweepError::BadSpec { origin: origin.into(), message: e.to_string() })?;
        spec.validate(origin)?;
        Ok(spec)
    }

    fn dimensions(&self) -> Vec<Dimension> {
        let mut dims = Vec::new();
        for (cable, c) in self.cables.iter().enumerate() {
            for s in &c.sweeps {
                for &point in &s.points {
                    dims.push(Dimension { cable, axis: s.axis, point, levels: s.levels_mm.clone() });
                }
            }
        }
        dims
    }

    /// Number of routings (the product of the swept levels).
    pub fn routings(&self) -> u64 {
        self.dimensions().iter().map(|d| d.levels.len() as u64).product()
    }

    /// Number of tension combinations per routing.
    pub fn tension_combinations(&self) -> u64 {
        self.cables.iter().map(|c| u64::from(c.tension_n.count.max(1))).product()
    }

    /// Checks the spec; messages name the field.
    pub fn validate(&self, origin: &str) -> Result<(), CableSweepError> {
        let bad = |message: String| CableSweepError::BadSpec { origin: origin.into(), message };
        if self.cables.is_empty() || self.cables.len() > crate::model::spatial::MAX_CABLES {
            return Err(bad(format!("give 1 to {} [[cable]] tables, got {}", crate::model::spatial::MAX_CABLES, self.cables.len())));
        }
        for (i, c) in self.cables.iter().enumerate() {
            let n = i + 1;
            let t = &c.tension_n;
            if !(t.min.is_finite() && t.max.is_finite() && t.min >= 0.0 && t.max >= t.min) {
                return Err(bad(format!("cable {n}: tension_n needs 0 ≤ min ≤ max (finite), got min = {}, max = {}", t.min, t.max)));
            }
            if t.count == 0 || t.count > MAX_TENSION_COUNT {
                return Err(bad(format!("cable {n}: tension_n.count = {} must be 1 … {MAX_TENSION_COUNT}", t.count)));
            }
            // The anchor is not swept: outside the rod, every routing's rows
            // would be invalid_routing.
            if let Some(anchor) = c.anchor_mm {
                let length = self.rod.length_mm;
                if !(anchor.is_finite() && anchor > 0.0 && anchor <= length) {
                    return Err(bad(format!(
                        "cable {n}: anchor_mm = {} must lie on the rod, in (0, {length}] mm (the rod's length_mm; leave \
                         anchor_mm out for the tip)",
                        crate::io::fmt_num(anchor)
                    )));
                }
            }
            let mut seen = std::collections::BTreeSet::new();
            for s in &c.sweeps {
                if s.levels_mm.is_empty() || s.levels_mm.iter().any(|v| !v.is_finite()) {
                    return Err(bad(format!("cable {n}: a sweep needs at least one finite level in levels_mm")));
                }
                if s.points.is_empty() {
                    return Err(bad(format!("cable {n}: a sweep needs at least one control point in points (0 … 4)")));
                }
                for &p in &s.points {
                    if p >= CONTROL_POINTS {
                        return Err(bad(format!("cable {n}: control point {p} does not exist (points are 0 … 4)")));
                    }
                    if !seen.insert((s.axis, p)) {
                        return Err(bad(format!("cable {n}: {:?} control point {p} is swept twice", s.axis).to_lowercase()));
                    }
                }
            }
        }
        crate::model::spatial::check_order(self.output.order, &self.solver).map_err(|e| bad(e.to_string()))?;
        if !(self.output.cell_mm.is_finite() && self.output.cell_mm > 0.0) {
            return Err(bad(format!("output.cell_mm = {} must be a positive length", self.output.cell_mm)));
        }
        if self.output.chunk_routings == 0 {
            return Err(bad("output.chunk_routings = 0: a chunk needs at least one routing".into()));
        }
        let max_chunk = super::spec::MAX_CHUNK_ROWS;
        let combos = self.tension_combinations();
        let chunk_rows = u64::from(self.output.chunk_routings).saturating_mul(combos);
        if chunk_rows > max_chunk {
            return Err(bad(if combos > max_chunk {
                format!("{combos} tension combinations per routing (the product of the cables' tension_n.count) is more than {max_chunk} rows per chunk: use fewer tensions")
            } else {
                format!(
                    "output.chunk_routings = {} × {combos} tension combinations gives {chunk_rows} rows per chunk, more than {max_chunk} (each chunk is built in memory): lower chunk_routings to ≤ {}",
                    self.output.chunk_routings,
                    max_chunk / combos
                )
            }));
        }
        // The base actuator (swept points at their first level) must be a
        // rod the 3-D solver models; a routing's own faults are its rows' status.
        let base = self.actuator_for(0, &self.dimensions());
        match base.validate() {
            Err(SpatialError::Parameter(e)) => return Err(bad(e.to_string())),
            Err(e @ SpatialError::Unsupported(_)) => return Err(bad(format!("[rod] {e}"))),
            Err(e @ SpatialError::GravityDirection(_)) => return Err(bad(e.to_string())),
            _ => {}
        }
        Ok(())
    }

    /// The actuator of routing `id` (mixed radix over the dimensions, the
    /// first fastest), tensions at zero.
    fn actuator_for(&self, id: u64, dims: &[Dimension]) -> Actuator {
        let mut cables: Vec<Cable> = self
            .cables
            .iter()
            .map(|c| Cable { y_mm: c.y_mm, z_mm: c.z_mm, tension_n: 0.0, anchor_mm: c.anchor_mm })
            .collect();
        let mut k = id;
        for d in dims {
            let n = d.levels.len() as u64;
            let level = d.levels[(k % n) as usize];
            k /= n;
            let c = &mut cables[d.cable];
            match d.axis {
                Axis::Y => c.y_mm[d.point] = level,
                Axis::Z => c.z_mm[d.point] = level,
            }
        }
        Actuator { rod: self.rod.clone(), gj_n_mm2: self.gj_n_mm2, gravity_direction: self.gravity_direction, cables }
    }
}

/// One solved (or failed) row of a cable sweep.
#[derive(Debug, Clone)]
pub struct Row {
    /// Routing number in the spec's enumeration.
    pub routing_id: i64,
    /// Each cable's (y, z) control points, mm.
    pub cables: Vec<([f64; CONTROL_POINTS], [f64; CONTROL_POINTS])>,
    /// Each cable's tension, N.
    pub tensions: Vec<f64>,
    /// `ok`, [`STATUS_FAILED`] or [`STATUS_INVALID_ROUTING`].
    pub status: &'static str,
    /// Solver passes (0 when not solved).
    pub passes: i32,
    /// The pose of a solved row.
    pub pose: Option<crate::model::TipPose>,
    /// Twist, out-of-plane and in-plane coefficient series of a solved row.
    pub a: Option<[Vec<f64>; 3]>,
}

/// Tension combinations of one routing in snake order: each step changes
/// one cable's tension by one grid step, so the solver's warm start (and
/// its extrapolation along a straight run) stays close.
fn snake(grids: &[Vec<f64>]) -> Vec<Vec<usize>> {
    let mut out: Vec<Vec<usize>> = vec![vec![]];
    for grid in grids {
        let mut next = Vec::with_capacity(out.len() * grid.len());
        for (k, prefix) in out.iter().enumerate() {
            let order: Vec<usize> = if k % 2 == 0 { (0..grid.len()).collect() } else { (0..grid.len()).rev().collect() };
            for j in order {
                let mut p = prefix.clone();
                p.push(j);
                next.push(p);
            }
        }
        out = next;
    }
    out
}

fn solve_routing(spec: &CableSweepSpec, id: u64, dims: &[Dimension], grids: &[Vec<f64>], combos: &[Vec<usize>]) -> Vec<Row> {
    let mut actuator = spec.actuator_for(id, dims);
    let geometry: Vec<_> = actuator.cables.iter().map(|c| (c.y_mm, c.z_mm)).collect();
    let tensions_of = |combo: &[usize]| -> Vec<f64> { combo.iter().zip(grids).map(|(&j, g)| g[j]).collect() };
    let row = |combo: &[usize], status, passes, pose, a| Row {
        routing_id: id as i64,
        cables: geometry.clone(),
        tensions: tensions_of(combo),
        status,
        passes,
        pose,
        a,
    };
    // Build with the first combination's tensions so validation sees them.
    for (c, t) in actuator.cables.iter_mut().zip(tensions_of(&combos[0])) {
        c.tension_n = t;
    }
    let mut solver = match SpatialSolver::new(&actuator, &spec.solver) {
        Ok(s) => s,
        Err(_) => return combos.iter().map(|c| row(c, STATUS_INVALID_ROUTING, 0, None, None)).collect(),
    };
    let mut rows: Vec<Option<Row>> = vec![None; combos.len()];
    // Continuation from zero to the first combination (rungs of ≤ 0.25 N).
    let first = tensions_of(&combos[0]);
    let top = first.iter().copied().fold(0.0, f64::max);
    let rungs = ((top / 0.25).ceil() as usize).max(1);
    for k in 1..rungs {
        let t: Vec<f64> = first.iter().map(|t| t * k as f64 / rungs as f64).collect();
        // A rung that fails only leaves a worse warm start; the rows report failures.
        let _ = solver.solve(&t);
    }
    for combo in combos {
        let t = tensions_of(combo);
        let solved = match solver.solve(&t) {
            Ok(pose) => match solver.coefficients(spec.output.order, spec.output.length_basis) {
                Ok(a) if finite_row(&pose, &a) => row(combo, STATUS_OK, pose.iterations as i32, Some(pose), Some(a)),
                _ => row(combo, STATUS_FAILED, 0, None, None),
            },
            Err(_) => row(combo, STATUS_FAILED, 0, None, None),
        };
        rows[combination_index(combo, grids)] = Some(solved);
    }
    // Rows in grid order (cable 1's tension slowest), whatever the snake.
    rows.into_iter().map(|r| r.expect("the snake visits every combination")).collect()
}

/// A solve whose outputs are all finite (others are stored as failures, so
/// that no output is NaN).
fn finite_row(pose: &crate::model::TipPose, a: &[Vec<f64>; 3]) -> bool {
    let p = pose;
    p.tip_mm().iter().chain(&p.tip_tangent()).chain(&p.tip_body_y_axis()).chain([&p.angle_from_clamp_axis_rad(), &p.length_mm]).all(|v| v.is_finite())
        && a.iter().flatten().all(|v| v.is_finite())
}

/// Position of a tension combination (per-cable grid indices) in grid
/// order: cable 1's index most significant.
pub fn combination_index(combo: &[usize], grids: &[Vec<f64>]) -> usize {
    combo.iter().zip(grids).fold(0, |k, (&j, g)| k * g.len() + j)
}

impl CableSweepSpec {
    /// Each cable's tension grid, N.
    pub fn tension_grids(&self) -> Vec<Vec<f64>> {
        self.cables.iter().map(|c| c.tension_n.values()).collect()
    }

    /// Whether the run is planar: every cable and its swept points lie in
    /// the x–y plane (z ≡ 0) and gravity has no z component. Planar runs also
    /// get the planar feasibility maps.
    pub fn is_planar(&self) -> bool {
        self.cables.iter().all(|c| c.z_mm.iter().all(|&z| z == 0.0) && c.sweeps.iter().all(|s| s.axis == Axis::Y))
            && self.gravity_direction.is_none_or(|g| g[2] == 0.0)
    }

    /// Routing `id` and the tensions of its `k`-th combination (grid order):
    /// the actuator of the row with `routing_id = id` at that combination,
    /// e.g. to solve it again.
    pub fn actuator_at(&self, id: u64, k: usize) -> Actuator {
        let mut actuator = self.actuator_for(id, &self.dimensions());
        let grids = self.tension_grids();
        let mut rest = k;
        for (c, g) in actuator.cables.iter_mut().zip(&grids).rev() {
            c.tension_n = g[rest % g.len()];
            rest /= g.len();
        }
        actuator
    }
}

/// What a worker of a cable sweep holds: the swept dimensions, the tension
/// grids and their snake order (computed once per worker).
#[derive(Debug, Clone)]
pub struct CableWorker {
    dims: Vec<Dimension>,
    grids: Vec<Vec<f64>>,
    combos: Vec<Vec<usize>>,
}

/// The sweep of several or spatial cables on the shared engine: each routing
/// is solved by its own [`SpatialSolver`] through its tension combinations.
impl RunSpec for CableSweepSpec {
    const FORMAT: &'static str = CABLES_FORMAT;
    const KIND: &'static str = "cable sweep";
    type Worker = CableWorker;
    type Solved = Vec<Row>;

    fn check(&self) -> Result<(), super::kind::InvalidSpec> {
        self.validate("").map_err(|e| match e {
            CableSweepError::BadSpec { message, .. } => super::kind::InvalidSpec(message),
            other => super::kind::InvalidSpec(other.to_string()),
        })
    }

    fn check_run_size(&self, allow_large: bool) -> Result<(), SweepError> {
        let rows = self.routings().saturating_mul(self.tension_combinations());
        if rows > super::spec::MAX_ROWS && !allow_large {
            return Err(SweepError::InvalidSpec {
                origin: "(size)".into(),
                message: format!(
                    "the sweep has {rows} rows ({} routings × {} tension combinations), more than {}: check the levels and tension counts, \
                     or pass --allow-large if the job is meant to be this big",
                    self.routings(),
                    self.tension_combinations(),
                    super::spec::MAX_ROWS
                ),
            });
        }
        Ok(())
    }

    fn canonical_json(&self) -> String {
        serde_json::to_string(self).expect("spec serialises")
    }

    fn hash_hex(&self) -> String {
        Sha256::digest(self.canonical_json().as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
    }

    fn length_basis(&self) -> LengthBasis {
        self.output.length_basis
    }

    fn order(&self) -> usize {
        self.output.order
    }

    fn layout(&self) -> ChunkLayout {
        ChunkLayout::new(self.routings(), self.tension_combinations(), u64::from(self.output.chunk_routings))
    }

    fn schema(&self) -> SchemaRef {
        rows_schema(self.cables.len(), self.output.order)
    }

    fn row_bytes(&self) -> u64 {
        // Per copy: the Row (its cables' control points, tensions, pose and
        // three series) or its columns; three copies as for planar rows.
        let (cables, terms) = (self.cables.len() as u64, self.output.order as u64 + 1);
        3 * (256 + 96 * cables + 24 * terms)
    }

    fn worker(&self) -> Result<CableWorker, SweepError> {
        let grids = self.tension_grids();
        Ok(CableWorker { dims: self.dimensions(), combos: snake(&grids), grids })
    }

    fn solve(&self, worker: &mut CableWorker, id: u64) -> Result<Vec<Row>, SweepError> {
        Ok(solve_routing(self, id, &worker.dims, &worker.grids, &worker.combos))
    }

    fn batch(&self, schema: &SchemaRef, solved: &[Vec<Row>]) -> RecordBatch {
        let rows: Vec<&Row> = solved.iter().flatten().collect();
        rows_batch(schema, &rows, self.cables.len(), self.output.order)
    }
}

/// Reads a cable sweep spec file.
pub fn load_spec(path: &Path) -> Result<CableSweepSpec, CableSweepError> {
    let text = crate::io::read_utf8(path)
        .map_err(|e| CableSweepError::BadSpec { origin: path.display().to_string(), message: format!("cannot read it: {e}") })?;
    CableSweepSpec::from_toml(&text, &path.display().to_string())
}

/// Name of a control-point column, e.g. `cable2_z3_mm`.
pub fn control_point_column(cable: usize, axis: Axis, point: usize) -> String {
    format!("cable{cable}_{}{point}_mm", if axis == Axis::Y { "y" } else { "z" })
}

/// Name of a cable's tension column, e.g. `tension1_n`.
pub fn tension_column(cable: usize) -> String {
    format!("tension{cable}_n")
}

/// Pose columns of a cable sweep row (nullable f64).
pub const POSE_COLUMNS: [&str; 11] = [
    "tip_x_mm",
    "tip_y_mm",
    "tip_z_mm",
    "tip_tangent_x",
    "tip_tangent_y",
    "tip_tangent_z",
    "tip_body_y_x",
    "tip_body_y_y",
    "tip_body_y_z",
    "tip_angle_rad",
    "length_mm",
];

/// The row schema of a cable sweep of `n_cables` cables storing orders
/// 0…`order` (docs/schema.md, "Cable sweeps"): inputs non-null, outputs
/// nullable (null when the solve failed or the routing was rejected).
pub fn rows_schema(n_cables: usize, order: usize) -> SchemaRef {
    let mut fields = vec![Field::new("routing_id", DataType::Int64, false)];
    for c in 0..n_cables {
        for axis in [Axis::Y, Axis::Z] {
            fields.extend((0..CONTROL_POINTS).map(|p| Field::new(control_point_column(c + 1, axis, p), DataType::Float64, false)));
        }
    }
    fields.extend((0..n_cables).map(|c| Field::new(tension_column(c + 1), DataType::Float64, false)));
    fields.push(Field::new("status", DataType::Utf8, false));
    fields.push(Field::new("iterations", DataType::Int32, false));
    fields.extend(POSE_COLUMNS.iter().map(|n| Field::new(*n, DataType::Float64, true)));
    for prefix in ["a", "a_bend_y", "a_twist"] {
        fields.extend((0..=order).map(|i| Field::new(format!("{prefix}{i}"), DataType::Float64, true)));
    }
    Arc::new(Schema::new(fields))
}

/// The rows as one record batch of [`rows_schema`].
pub fn rows_batch(schema: &SchemaRef, rows: &[&Row], n_cables: usize, order: usize) -> RecordBatch {
    let mut columns: Vec<ArrayRef> = vec![Arc::new(Int64Array::from_iter_values(rows.iter().map(|r| r.routing_id)))];
    for c in 0..n_cables {
        for axis in [Axis::Y, Axis::Z] {
            for p in 0..CONTROL_POINTS {
                let v = rows.iter().map(|r| if axis == Axis::Y { r.cables[c].0[p] } else { r.cables[c].1[p] });
                columns.push(Arc::new(Float64Array::from_iter_values(v)));
            }
        }
    }
    for c in 0..n_cables {
        columns.push(Arc::new(Float64Array::from_iter_values(rows.iter().map(|r| r.tensions[c]))));
    }
    columns.push(Arc::new(StringArray::from_iter_values(rows.iter().map(|r| r.status))));
    columns.push(Arc::new(Int32Array::from_iter_values(rows.iter().map(|r| r.passes))));
    let pose_value = |r: &Row, k: usize| {
        r.pose.map(|p| match k {
            0..=2 => p.tip_mm()[k],
            3..=5 => p.tip_tangent()[k - 3],
            6..=8 => p.tip_body_y_axis()[k - 6],
            // The cable sweep's tip_angle_rad: unsigned, from the clamp axis.
            9 => p.angle_from_clamp_axis_rad(),
            _ => p.length_mm,
        })
    };
    for k in 0..POSE_COLUMNS.len() {
        columns.push(Arc::new(rows.iter().map(|r| pose_value(r, k)).collect::<Float64Array>()));
    }
    // In-plane series as a0… (the planar sweep's names), then the other two.
    for series in [2, 1, 0] {
        for i in 0..=order {
            columns.push(Arc::new(rows.iter().map(|r| r.a.as_ref().map(|a| a[series][i])).collect::<Float64Array>()));
        }
    }
    RecordBatch::try_new(schema.clone(), columns).expect("columns match the schema")
}

/// Writes one record batch as a zstd Parquet file, atomically.
pub fn write_parquet(path: &Path, batch: Result<RecordBatch, arrow::error::ArrowError>) -> Result<(), String> {
    let batch = batch.map_err(|e| e.to_string())?;
    let props = WriterProperties::builder().set_compression(Compression::ZSTD(ZstdLevel::default())).build();
    let mut buf = Vec::new();
    let mut writer = ArrowWriter::try_new(&mut buf, batch.schema(), Some(props)).map_err(|e| e.to_string())?;
    writer.write(&batch).map_err(|e| e.to_string())?;
    writer.close().map_err(|e| e.to_string())?;
    crate::io::write_atomic(path, &buf).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = r#"
[rod.gravity]
enabled = false
[[cable]]
y_mm = [2, 2, 2, 2, 2]
tension_n = { min = 0.0, max = 1.0, count = 3 }
[[cable.sweep]]
axis = "y"
points = [1, 3]
levels_mm = [1.0, 3.0]
[[cable]]
y_mm = [-2, -2, -2, -2, -2]
tension_n = { min = 0.5, max = 1.0, count = 2 }
[[cable.sweep]]
axis = "z"
points = [4]
levels_mm = [0.0, 1.5, -1.5]
"#;

    #[test]
    fn spec_counts_routings_and_tensions() {
        let spec = CableSweepSpec::from_toml(SPEC, "test").unwrap();
        assert_eq!(spec.routings(), 2 * 2 * 3);
        assert_eq!(spec.tension_combinations(), 6);
        let dims = spec.dimensions();
        // Id 0: every swept point at its first level; id 1 moves the first dimension.
        let a0 = spec.actuator_for(0, &dims);
        assert_eq!(a0.cables[0].y_mm, [2.0, 1.0, 2.0, 1.0, 2.0]);
        assert_eq!(a0.cables[1].z_mm, [0.0; 5]);
        let a1 = spec.actuator_for(1, &dims);
        assert_eq!(a1.cables[0].y_mm, [2.0, 3.0, 2.0, 1.0, 2.0]);
        let last = spec.actuator_for(11, &dims);
        assert_eq!(last.cables[0].y_mm, [2.0, 3.0, 2.0, 3.0, 2.0]);
        assert_eq!(last.cables[1].z_mm, [0.0, 0.0, 0.0, 0.0, -1.5]);
    }

    #[test]
    fn a_routings_rows_are_in_grid_order_and_actuator_at_rebuilds_each() {
        let spec = CableSweepSpec::from_toml(SPEC, "test").unwrap();
        let layout = spec.layout();
        assert_eq!((layout.routings, layout.tensions), (12, 6));
        let mut worker = spec.worker().unwrap();
        let rows = spec.solve(&mut worker, 7).unwrap();
        assert_eq!(rows.len(), 6);
        let grids = spec.tension_grids();
        for (k, row) in rows.iter().enumerate() {
            assert_eq!(row.routing_id, 7);
            let combo: Vec<usize> = row.tensions.iter().zip(&grids).map(|(t, g)| g.iter().position(|v| v == t).unwrap()).collect();
            assert_eq!(combination_index(&combo, &grids), k, "grid order, cable 1 slowest");
            let actuator = spec.actuator_at(7, k);
            assert_eq!(actuator.cables.iter().map(|c| c.tension_n).collect::<Vec<_>>(), row.tensions);
            assert_eq!(actuator.cables.iter().map(|c| (c.y_mm, c.z_mm)).collect::<Vec<_>>(), row.cables);
        }
        // The batch has the fixed schema whatever the rows' nulls.
        let schema = spec.schema();
        let batch = spec.batch(&schema, &[rows]);
        assert_eq!(batch.schema(), schema);
        assert_eq!(batch.num_rows(), 6);
    }

    #[test]
    fn snake_order_visits_every_combination_one_step_at_a_time() {
        let grids = vec![vec![0.0, 1.0, 2.0], vec![0.0, 1.0], vec![5.0, 6.0]];
        let s = snake(&grids);
        assert_eq!(s.len(), 12);
        let unique: std::collections::BTreeSet<_> = s.iter().cloned().collect();
        assert_eq!(unique.len(), 12);
        for w in s.windows(2) {
            let steps: usize = w[0].iter().zip(&w[1]).map(|(a, b)| a.abs_diff(*b)).sum();
            assert_eq!(steps, 1, "{w:?}");
        }
    }

    #[test]
    fn bad_specs_name_the_problem() {
        for (text, needle) in [
            (SPEC.replace("points = [1, 3]", "points = [1, 5]"), "control point 5"),
            (SPEC.replace("points = [1, 3]", "points = [1, 1]"), "swept twice"),
            (SPEC.replace("count = 3", "count = 0"), "count = 0"),
            (SPEC.replace("min = 0.5", "min = -0.5"), "0 ≤ min"),
            (SPEC.replace("levels_mm = [1.0, 3.0]", "levels_mm = []"), "levels_mm"),
            (SPEC.replace("[rod.gravity]", "[rod.effects]\nfriction_mu = 0.1\n[rod.gravity]"), "friction_mu"),
            (format!("{SPEC}\n[output]\norder = 7\n"), "steps_per_span"),
            (SPEC.replace("axis = \"z\"", "axis = \"x\""), "unknown variant"),
            (
                SPEC.replace("y_mm = [2, 2, 2, 2, 2]", "y_mm = [2, 2, 2, 2, 2]\nanchor_mm = -1"),
                "cable 1: anchor_mm = -1 must lie on the rod",
            ),
            (SPEC.replace("y_mm = [-2, -2, -2, -2, -2]", "y_mm = [-2, -2, -2, -2, -2]\nanchor_mm = 70"), "cable 2: anchor_mm = 70"),
            ("[rod]\n".to_string(), "cable"),
        ] {
            let e = CableSweepSpec::from_toml(&text, "spec.toml").unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains("spec.toml"), "{needle}: {e}");
        }
    }
}
