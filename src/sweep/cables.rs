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
//! [rod]                            # optional: model::Actuator
//! [solver]                         # optional: SpatialOptions
//! [output]
//! order = 3                        # a0…a3, a_bend_y0…, a_twist0…
//! cell_mm = 1.0                    # reach-map cell / voxel size
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
//! Unlike the planar sweep this run is neither sharded nor resumable: it is
//! solved in memory (at most [`MAX_CABLE_SWEEP_ROWS`] rows) and written at
//! the end.

use crate::model::routing::CONTROL_POINTS;
use crate::model::spatial::{Cable, SpatialActuator, SpatialError, SpatialOptions, SpatialSolver};
use crate::model::{Actuator, STATUS_OK};
use crate::shape::LengthBasis;
use arrow::array::{ArrayRef, Float64Array, Int32Array, Int64Array, StringArray};
use arrow::datatypes::{DataType, Field, Schema};
use arrow::record_batch::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Most rows of one cable sweep (it is built in memory).
pub const MAX_CABLE_SWEEP_ROWS: u64 = 2_000_000;
/// Most values in one tension grid.
pub const MAX_TENSION_COUNT: u32 = 10_000;
/// Status of rows whose routing was rejected (e.g. two cables on one path).
pub const STATUS_INVALID_ROUTING: &str = "invalid_routing";
/// Status of rows whose solve failed.
pub const STATUS_FAILED: &str = "failed";
/// Rows file of a run directory.
pub const ROWS_FILE: &str = "rows.parquet";
/// The three reach maps drawn side by side, in `maps/`.
pub const REACH_PICTURE: &str = "reach.png";
/// Map tables written into `maps/` of a run directory.
pub const MAP_FILES: [&str; 4] = ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"];

/// Why a cable sweep could not run.
#[derive(Debug, thiserror::Error)]
pub enum CableSweepError {
    /// The spec is malformed or invalid.
    #[error("bad cable sweep spec {origin}: {message}")]
    BadSpec { origin: String, message: String },
    /// The output directory holds something.
    #[error("{} is not empty: a cable sweep writes into a new or empty directory (it is not resumable)", .0.display())]
    NotEmpty(PathBuf),
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
    pub rod: Actuator,
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
}

impl Default for CableOutputSpec {
    fn default() -> Self {
        Self { order: 3, length_basis: LengthBasis::Rest, cell_mm: 1.0 }
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
        let rows = self.routings().saturating_mul(self.tension_combinations());
        if rows > MAX_CABLE_SWEEP_ROWS {
            return Err(bad(format!(
                "{rows} rows ({} routings × {} tension combinations) is more than {MAX_CABLE_SWEEP_ROWS}: this sweep is built in memory; split the spec",
                self.routings(),
                self.tension_combinations()
            )));
        }
        // The base actuator (swept points at their first level) must be a valid rod.
        let base = self.actuator_for(0, &self.dimensions());
        base.rod.validate().map_err(|e| bad(e.to_string()))?;
        match base.validate() {
            Err(SpatialError::Parameter(e)) => return Err(bad(e.to_string())),
            Err(e @ (SpatialError::GravityDirection(_) | SpatialError::UnsupportedEffect(_))) => return Err(bad(e.to_string())),
            _ => {}
        }
        Ok(())
    }

    /// The actuator of routing `id` (mixed radix over the dimensions, the
    /// first fastest), tensions at zero.
    fn actuator_for(&self, id: u64, dims: &[Dimension]) -> SpatialActuator {
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
        SpatialActuator { rod: self.rod.clone(), gj_n_mm2: self.gj_n_mm2, gravity_direction: self.gravity_direction, cables }
    }
}

/// One solved (or failed) row.
#[derive(Debug, Clone)]
struct Row {
    routing_id: i64,
    cables: Vec<([f64; CONTROL_POINTS], [f64; CONTROL_POINTS])>,
    tensions: Vec<f64>,
    status: &'static str,
    passes: i32,
    pose: Option<crate::model::spatial::SpatialPose>,
    a: Option<[Vec<f64>; 3]>,
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
    let mut rows = Vec::with_capacity(combos.len());
    // Continuation from zero to the first combination (rungs of ≤ 0.25 N).
    let first = tensions_of(&combos[0]);
    let top = first.iter().copied().fold(0.0, f64::max);
    let rungs = ((top / 0.25).ceil() as usize).max(1);
    let mut warm_ok = true;
    for k in 1..rungs {
        let t: Vec<f64> = first.iter().map(|t| t * k as f64 / rungs as f64).collect();
        warm_ok &= solver.solve(&t).is_ok();
    }
    let _ = warm_ok;
    for combo in combos {
        let t = tensions_of(combo);
        match solver.solve(&t) {
            Ok(pose) => match solver.coefficients(spec.output.order, spec.output.length_basis) {
                Ok(a) => rows.push(row(combo, STATUS_OK, pose.passes as i32, Some(pose), Some(a))),
                Err(_) => rows.push(row(combo, STATUS_FAILED, 0, None, None)),
            },
            Err(_) => rows.push(row(combo, STATUS_FAILED, 0, None, None)),
        }
    }
    rows
}

/// What a cable sweep did.
#[derive(Debug, Clone, Serialize)]
pub struct CableSweepSummary {
    /// Routings (swept combinations).
    pub routings: u64,
    /// Routings rejected (channel outside the body, two cables on one path, …).
    pub invalid_routings: u64,
    /// Rows written.
    pub rows: u64,
    /// Rows solved.
    pub ok: u64,
    /// Rows whose solve failed.
    pub failed: u64,
    /// Whether every cable is planar and gravity lies in the x–y plane.
    pub planar: bool,
    /// Reach-map cells: x–y, x–z, y–z, 3-D voxels.
    pub cells: [u64; 4],
    /// Wall time, s.
    pub wall_s: f64,
    /// Worker threads.
    pub threads: usize,
}

/// Runs the sweep into `out` (created; must be new or empty): rows.parquet,
/// maps/reach_*.parquet, spec.toml and summary.json.
pub fn run_cable_sweep(spec: &CableSweepSpec, out: &Path, threads: Option<usize>) -> Result<CableSweepSummary, crate::Error> {
    let write_err = |context: String, e: &dyn std::fmt::Display| CableSweepError::Write { context, message: e.to_string() };
    spec.validate("(given)")?;
    if out.exists() && std::fs::read_dir(out).map(|mut d| d.next().is_some()).unwrap_or(true) {
        return Err(CableSweepError::NotEmpty(out.to_path_buf()).into());
    }
    std::fs::create_dir_all(out.join("maps")).map_err(|source| crate::Error::Io { context: format!("creating {}", out.display()), source })?;
    let start = std::time::Instant::now();
    let dims = spec.dimensions();
    let grids: Vec<Vec<f64>> = spec.cables.iter().map(|c| c.tension_n.values()).collect();
    let combos = snake(&grids);
    let routings = spec.routings();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| write_err("starting worker threads".into(), &e))?;
    let threads_used = pool.current_num_threads();
    let mut rows: Vec<Row> =
        pool.install(|| (0..routings).into_par_iter().flat_map_iter(|id| solve_routing(spec, id, &dims, &grids, &combos)).collect());
    // Rows in (routing, tension grid) order, independent of the snake and the threads.
    let n_cables = spec.cables.len();
    rows.sort_by(|a, b| a.routing_id.cmp(&b.routing_id).then_with(|| a.tensions.partial_cmp(&b.tensions).unwrap()));
    let path = out.join(ROWS_FILE);
    write_batch(&path, rows_batch(&rows, n_cables, spec.output.order)).map_err(|e| write_err(format!("writing {}", path.display()), &e))?;
    let cells = write_maps(&out.join("maps"), &rows, spec.output.cell_mm).map_err(|e| write_err(format!("writing maps in {}", out.display()), &e))?;
    let planar = spec.cables.iter().all(|c| c.z_mm.iter().all(|&z| z == 0.0) && c.sweeps.iter().all(|s| s.axis == Axis::Y))
        && spec.gravity_direction.is_none_or(|g| g[2] == 0.0);
    if planar && spec.output.order >= 1 {
        write_planar_maps(spec, &rows, out)?;
    }
    let ok = rows.iter().filter(|r| r.status == STATUS_OK).count() as u64;
    let invalid_rows = rows.iter().filter(|r| r.status == STATUS_INVALID_ROUTING).count() as u64;
    let summary = CableSweepSummary {
        routings,
        invalid_routings: invalid_rows / combos.len() as u64,
        rows: rows.len() as u64,
        ok,
        failed: rows.len() as u64 - ok - invalid_rows,
        planar,
        cells,
        wall_s: start.elapsed().as_secs_f64(),
        threads: threads_used,
    };
    let spec_text = toml::to_string(spec).map_err(|e| write_err("writing spec.toml".into(), &e))?;
    crate::io::write_atomic(&out.join("spec.toml"), spec_text.as_bytes()).map_err(|e| write_err("writing spec.toml".into(), &e))?;
    let json = serde_json::to_string_pretty(&summary).map_err(|e| write_err("writing summary.json".into(), &e))?;
    crate::io::write_atomic(&out.join("summary.json"), json.as_bytes()).map_err(|e| write_err("writing summary.json".into(), &e))?;
    Ok(summary)
}

/// Directory (inside the run) of a planar run's feasibility-map tables.
pub const PLANAR_MAP_DIR: &str = "maps/planar";

/// A planar run (every cable and gravity in the x–y plane) also gets the
/// planar sweep's map tables (cells, modes, designs, summary.json;
/// docs/maps.md) by the same reducer, in `maps/planar/`. The reducer reads
/// the planar row layout, so each row is handed over with `routing_id` =
/// its row number in rows.parquet (where every cable's routing and tension
/// are), `y0_mm`…`y4_mm` and `tension_n` = cable 1's, and `tip_angle_rad` =
/// the signed in-plane tangent angle, continuous from the clamp. No mirror images are added (a pair's
/// mirror is another routing of the spec, if swept). The reducer's pictures
/// are not drawn: they re-simulate single-cable representatives.
fn write_planar_maps(spec: &CableSweepSpec, rows: &[Row], out: &Path) -> Result<(), crate::Error> {
    use crate::reduce::{reduce_batches, write::write_tables, ReduceError, ReduceOptions, RunInfo};
    use sha2::{Digest, Sha256};
    let order = spec.output.order;
    let mut fields = vec![Field::new("routing_id", DataType::Int64, false), Field::new("status", DataType::Utf8, false)];
    let mut columns: Vec<ArrayRef> = vec![
        Arc::new(Int64Array::from_iter_values(0..rows.len() as i64)),
        Arc::new(StringArray::from(rows.iter().map(|r| r.status).collect::<Vec<_>>())),
    ];
    let mut push = |name: String, values: Vec<Option<f64>>| {
        fields.push(Field::new(name, DataType::Float64, true));
        columns.push(Arc::new(Float64Array::from(values)));
    };
    for p in 0..CONTROL_POINTS {
        push(format!("y{p}_mm"), rows.iter().map(|r| Some(r.cables[0].0[p])).collect());
    }
    push("tension_n".into(), rows.iter().map(|r| Some(r.tensions[0])).collect());
    push("tip_x_mm".into(), rows.iter().map(|r| r.pose.map(|p| p.tip_mm[0])).collect());
    push("tip_y_mm".into(), rows.iter().map(|r| r.pose.map(|p| p.tip_mm[1])).collect());
    // The planar sweep's tip angle is continuous from the clamp, not wrapped:
    // unwrap atan2 toward θ_e − θ_0 = a_0·L (rest basis; a_0·ℓ deformed),
    // the clamp's shear angle θ_0 being far below π.
    let length = spec.rod.length_mm;
    let basis = spec.output.length_basis;
    let unwrapped = |r: &Row| {
        let (p, a) = (r.pose?, r.a.as_ref()?);
        let wrapped = p.tip_tangent[1].atan2(p.tip_tangent[0]);
        let turn = a[2][0] * if basis == LengthBasis::Rest { length } else { p.length_mm };
        let tau = std::f64::consts::TAU;
        Some(wrapped + tau * ((turn - wrapped) / tau).round())
    };
    push("tip_angle_rad".into(), rows.iter().map(unwrapped).collect());
    for i in 0..=order {
        push(format!("a{i}"), rows.iter().map(|r| r.a.as_ref().map(|a| a[2][i])).collect());
    }
    let batch = RecordBatch::try_new(Arc::new(Schema::new(fields)), columns)
        .map_err(|e| CableSweepError::Write { context: "building the planar map rows".into(), message: e.to_string() })?;
    let tensions: Vec<f64> = spec.cables.iter().flat_map(|c| [c.tension_n.min, c.tension_n.max]).collect();
    let info = RunInfo {
        mirrored: false,
        order,
        tension_range_n: [tensions.iter().copied().fold(f64::MAX, f64::min), tensions.iter().copied().fold(0.0, f64::max)],
        radius_mm: spec.rod.radius_mm,
        length_mm: spec.rod.length_mm,
        run_dir: out.display().to_string(),
        spec_hash: format!("{:x}", Sha256::digest(toml::to_string(spec).unwrap_or_default().as_bytes())),
        length_basis: spec.output.length_basis,
    };
    let options = ReduceOptions { cell_mm: spec.output.cell_mm, ..ReduceOptions::default() };
    let map = reduce_batches(&info, &options, || Ok(std::iter::once(Ok::<_, ReduceError>(batch.clone()))))?;
    let dir = out.join(PLANAR_MAP_DIR);
    std::fs::create_dir_all(&dir).map_err(|source| crate::Error::Io { context: format!("creating {}", dir.display()), source })?;
    write_tables(&dir, &map)?;
    Ok(())
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

fn rows_batch(rows: &[Row], n_cables: usize, order: usize) -> Result<RecordBatch, arrow::error::ArrowError> {
    let mut fields = vec![Field::new("routing_id", DataType::Int64, false)];
    let mut columns: Vec<ArrayRef> = vec![Arc::new(Int64Array::from_iter_values(rows.iter().map(|r| r.routing_id)))];
    let mut f64_col = |name: String, values: Vec<Option<f64>>, fields: &mut Vec<Field>| {
        fields.push(Field::new(name, DataType::Float64, values.iter().any(Option::is_none)));
        columns.push(Arc::new(Float64Array::from(values)));
    };
    for c in 0..n_cables {
        for axis in [Axis::Y, Axis::Z] {
            for p in 0..CONTROL_POINTS {
                let v = rows.iter().map(|r| Some(if axis == Axis::Y { r.cables[c].0[p] } else { r.cables[c].1[p] })).collect();
                f64_col(control_point_column(c + 1, axis, p), v, &mut fields);
            }
        }
    }
    for c in 0..n_cables {
        f64_col(tension_column(c + 1), rows.iter().map(|r| Some(r.tensions[c])).collect(), &mut fields);
    }
    let pose_value = |r: &Row, k: usize| {
        r.pose.map(|p| match k {
            0..=2 => p.tip_mm[k],
            3..=5 => p.tip_tangent[k - 3],
            6..=8 => p.tip_body_y_axis[k - 6],
            9 => p.tip_angle_rad,
            _ => p.length_mm,
        })
    };
    for (k, name) in POSE_COLUMNS.iter().enumerate() {
        f64_col(name.to_string(), rows.iter().map(|r| pose_value(r, k)).collect(), &mut fields);
    }
    // In-plane series as a0… (the planar sweep's names), then the other two.
    for (series, prefix) in [(2, "a"), (1, "a_bend_y"), (0, "a_twist")] {
        for i in 0..=order {
            let v = rows.iter().map(|r| r.a.as_ref().map(|a| a[series][i])).collect();
            f64_col(format!("{prefix}{i}"), v, &mut fields);
        }
    }
    let status: Vec<&str> = rows.iter().map(|r| r.status).collect();
    fields.insert(1 + 10 * n_cables + n_cables, Field::new("status", DataType::Utf8, false));
    columns.insert(1 + 10 * n_cables + n_cables, Arc::new(StringArray::from(status)));
    fields.insert(2 + 11 * n_cables, Field::new("iterations", DataType::Int32, false));
    columns.insert(2 + 11 * n_cables, Arc::new(Int32Array::from_iter_values(rows.iter().map(|r| r.passes))));
    RecordBatch::try_new(Arc::new(Schema::new(fields)), columns)
}

fn write_batch(path: &Path, batch: Result<RecordBatch, arrow::error::ArrowError>) -> Result<(), String> {
    let batch = batch.map_err(|e| e.to_string())?;
    let props = WriterProperties::builder().set_compression(Compression::ZSTD(ZstdLevel::default())).build();
    let mut buf = Vec::new();
    let mut writer = ArrowWriter::try_new(&mut buf, batch.schema(), Some(props)).map_err(|e| e.to_string())?;
    writer.write(&batch).map_err(|e| e.to_string())?;
    writer.close().map_err(|e| e.to_string())?;
    crate::io::write_atomic(path, &buf).map_err(|e| e.to_string())
}

/// Counts of solved rows per cell (i = ⌊coordinate / cell⌋) on the three
/// coordinate planes and per 3-D voxel; writes the four tables and returns
/// their cell counts.
fn write_maps(dir: &Path, rows: &[Row], cell_mm: f64) -> Result<[u64; 4], String> {
    let tips: Vec<[f64; 3]> = rows.iter().filter_map(|r| r.pose.map(|p| p.tip_mm)).collect();
    let index = |v: f64| (v / cell_mm).floor() as i32;
    let planes: [(&str, [usize; 2], [&str; 2]); 3] =
        [(MAP_FILES[0], [0, 1], ["x", "y"]), (MAP_FILES[1], [0, 2], ["x", "z"]), (MAP_FILES[2], [1, 2], ["y", "z"])];
    let mut cells = [0u64; 4];
    let mut pictures = Vec::new();
    for (k, (file, axes, names)) in planes.iter().enumerate() {
        let mut counts: BTreeMap<[i32; 2], i64> = BTreeMap::new();
        for t in &tips {
            *counts.entry([index(t[axes[0]]), index(t[axes[1]])]).or_default() += 1;
        }
        cells[k] = counts.len() as u64;
        write_batch(&dir.join(file), counts_batch(&counts, names, cell_mm))?;
        // Page: x down, the other coordinate across; y–z: y across, z down.
        let plane = if names[0] == "x" {
            crate::plot::spatial::ReachPlane { axes: (names[1], "x"), cells: counts.iter().map(|(c, &n)| (c[1], c[0], n)).collect() }
        } else {
            crate::plot::spatial::ReachPlane { axes: (names[0], names[1]), cells: counts.iter().map(|(c, &n)| (c[0], c[1], n)).collect() }
        };
        pictures.push(plane);
    }
    let title = format!("reach: {} solutions, cells of {cell_mm} mm", tips.len());
    crate::plot::spatial::draw_reach_maps(&dir.join(REACH_PICTURE), &title, &pictures, cell_mm).map_err(|e| e.to_string())?;
    let mut counts: BTreeMap<[i32; 3], i64> = BTreeMap::new();
    for t in &tips {
        *counts.entry([index(t[0]), index(t[1]), index(t[2])]).or_default() += 1;
    }
    cells[3] = counts.len() as u64;
    write_batch(&dir.join(MAP_FILES[3]), counts_batch(&counts, &["x", "y", "z"], cell_mm))?;
    Ok(cells)
}

/// `i{axis}` (i32), `{axis}_mm` (cell centre, f64) per axis, then `count` (i64).
fn counts_batch<const N: usize>(counts: &BTreeMap<[i32; N], i64>, names: &[&str; N], cell_mm: f64) -> Result<RecordBatch, arrow::error::ArrowError> {
    let mut fields = Vec::new();
    let mut columns: Vec<ArrayRef> = Vec::new();
    for (k, name) in names.iter().enumerate() {
        fields.push(Field::new(format!("i{name}"), DataType::Int32, false));
        columns.push(Arc::new(Int32Array::from_iter_values(counts.keys().map(|c| c[k]))));
    }
    for (k, name) in names.iter().enumerate() {
        fields.push(Field::new(format!("{name}_mm"), DataType::Float64, false));
        columns.push(Arc::new(Float64Array::from_iter_values(counts.keys().map(|c| (c[k] as f64 + 0.5) * cell_mm))));
    }
    fields.push(Field::new("count", DataType::Int64, false));
    columns.push(Arc::new(Int64Array::from_iter_values(counts.values().copied())));
    RecordBatch::try_new(Arc::new(Schema::new(fields)), columns)
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
            ("[rod]\n".to_string(), "cable"),
        ] {
            let e = CableSweepSpec::from_toml(&text, "spec.toml").unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains("spec.toml"), "{needle}: {e}");
        }
    }
}
