//! The columns of every run format, one owner (documented for users in
//! `docs/schema.md`): their names, the Arrow schema of each kind's rows, and
//! the builders that turn solved routings into a record batch. Readers take
//! the names from here (`reduce::columns` reads both kinds' rows).
//!
//! - Planar single-cable rows (`cablemap-sweep/2`): one row per (routing,
//!   tension): [`arrow_schema`], [`build_batch`].
//! - Cable sweep rows (`cablemap-cables/1`): one row per (routing, tension
//!   combination), a tension column per cable and the 3-D tip:
//!   [`cable_schema`], [`cable_batch`].
//!
//! Inputs are never null; outputs are null when the solve failed (never
//! NaN), and `status` says why.

use crate::model::routing::{ControlPoints, CONTROL_POINTS};
use crate::solver::TipPose;
use arrow::array::{ArrayRef, Float64Array, Float64Builder, Int32Array, Int32Builder, Int64Array, Int64Builder, ListBuilder, StringArray, StringBuilder};
use arrow::datatypes::{DataType, Field, Schema, SchemaRef};
use arrow::record_batch::RecordBatch;
use std::sync::Arc;

/// Routing id (i64, see [`super::enumerate`]).
pub const ROUTING_ID: &str = "routing_id";
/// Control-point columns y0_mm … y4_mm (f64, mm).
pub const Y_MM: [&str; CONTROL_POINTS] = ["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm"];
/// Cable tension (f64, N): the command of a tension ladder; of a
/// displacement ladder the tension found (null when the solve failed).
pub const TENSION_N: &str = "tension_n";
/// Cable displacement Δℓ at the base (nullable f64, mm): the command of a
/// displacement ladder; of a tension ladder the displacement it produced
/// (null when the solve failed, or with RK4, which does not integrate the
/// cable's path).
pub const DISPLACEMENT_MM: &str = "displacement_mm";
/// Solve status (utf8, non-null): `ok` or a failure status.
pub const STATUS: &str = "status";
/// Integration passes of the solve (i32, non-null; 0 for failed solves).
pub const ITERATIONS: &str = "iterations";
/// Tip position x (nullable f64, mm).
pub const TIP_X_MM: &str = "tip_x_mm";
/// Tip position y (nullable f64, mm).
pub const TIP_Y_MM: &str = "tip_y_mm";
/// Tip tangent angle (nullable f64, rad).
pub const TIP_ANGLE_RAD: &str = "tip_angle_rad";
/// Arc length of the deformed rod (nullable f64, mm).
pub const LENGTH_MM: &str = "length_mm";
/// Pose columns of a planar row (nullable f64), named as in `cablemap simulate --json`.
pub const POSE_COLUMNS: [&str; 5] = [TIP_X_MM, TIP_Y_MM, TIP_ANGLE_RAD, "base_angle_rad", LENGTH_MM];
/// Optional centreline x positions (list of f64, mm; clamp to tip).
pub const CENTRELINE_X_MM: &str = "centreline_x_mm";
/// Optional centreline y positions (list of f64, mm; clamp to tip).
pub const CENTRELINE_Y_MM: &str = "centreline_y_mm";

/// Name of the coefficient column a_i (`a0`, `a1`, …; nullable f64, mm⁻¹: κ = Σ a_i P_i(t)
/// with t dimensionless, so every a_i is a curvature).
pub fn coefficient_column(i: usize) -> String {
    format!("a{i}")
}

/// The Arrow schema of planar rows storing a_0 … a_`order` (and the
/// centreline lists when `centreline`).
pub fn arrow_schema(order: usize, centreline: bool) -> SchemaRef {
    let mut fields = vec![Field::new(ROUTING_ID, DataType::Int64, false)];
    fields.extend(Y_MM.iter().map(|n| Field::new(*n, DataType::Float64, false)));
    fields.push(Field::new(TENSION_N, DataType::Float64, true));
    fields.push(Field::new(DISPLACEMENT_MM, DataType::Float64, true));
    fields.push(Field::new(STATUS, DataType::Utf8, false));
    fields.push(Field::new(ITERATIONS, DataType::Int32, false));
    fields.extend(POSE_COLUMNS.iter().map(|n| Field::new(*n, DataType::Float64, true)));
    fields.extend((0..=order).map(|i| Field::new(coefficient_column(i), DataType::Float64, true)));
    if centreline {
        for name in [CENTRELINE_X_MM, CENTRELINE_Y_MM] {
            let item = Field::new_list_field(DataType::Float64, true);
            fields.push(Field::new(name, DataType::List(Arc::new(item)), true));
        }
    }
    Arc::new(Schema::new(fields))
}

/// The outcome of one planar solve, ready to become a row.
#[derive(Debug, Clone)]
pub struct SolvedRow {
    /// Tension, N ([`TENSION_N`]; NaN when unknown, stored as null).
    pub tension_n: f64,
    /// Displacement, mm ([`DISPLACEMENT_MM`]; NaN when unknown, stored as null).
    pub displacement_mm: f64,
    /// `ok` or the failure status.
    pub status: &'static str,
    /// The pose of a successful solve.
    pub pose: Option<TipPose>,
    /// a_0 … a_order of a successful solve (empty otherwise).
    pub a: Vec<f64>,
    /// Centreline (x, y) of a successful solve, mm, when stored.
    pub centreline: Option<(Vec<f64>, Vec<f64>)>,
}

/// All solves of one routing, in rising tension.
#[derive(Debug, Clone)]
pub struct SolvedRouting {
    /// Routing id.
    pub id: u64,
    /// Routing control points, mm.
    pub routing_mm: ControlPoints,
    /// One entry per tension.
    pub rows: Vec<SolvedRow>,
}

/// Builds the record batch of a planar chunk from its solved routings (in order).
pub fn build_batch(schema: &SchemaRef, order: usize, centreline: bool, routings: &[SolvedRouting]) -> RecordBatch {
    let rows: usize = routings.iter().map(|r| r.rows.len()).sum();
    let mut id = Int64Builder::with_capacity(rows);
    let mut y: Vec<Float64Builder> = (0..CONTROL_POINTS).map(|_| Float64Builder::with_capacity(rows)).collect();
    let mut tension = Float64Builder::with_capacity(rows);
    let mut displacement = Float64Builder::with_capacity(rows);
    let mut status = StringBuilder::with_capacity(rows, rows * 2);
    let mut iterations = Int32Builder::with_capacity(rows);
    let mut pose: Vec<Float64Builder> = (0..POSE_COLUMNS.len()).map(|_| Float64Builder::with_capacity(rows)).collect();
    let mut a: Vec<Float64Builder> = (0..=order).map(|_| Float64Builder::with_capacity(rows)).collect();
    let mut cx = ListBuilder::new(Float64Builder::new());
    let mut cy = ListBuilder::new(Float64Builder::new());
    for r in routings {
        for row in &r.rows {
            id.append_value(r.id as i64);
            for (b, v) in y.iter_mut().zip(r.routing_mm.0) {
                b.append_value(v);
            }
            tension.append_option(finite(row.tension_n));
            displacement.append_option(finite(row.displacement_mm));
            status.append_value(row.status);
            match &row.pose {
                Some(p) => {
                    iterations.append_value(p.iterations as i32);
                    let values = [p.tip_x_mm, p.tip_y_mm, p.tip_angle_rad, p.base_angle_rad, p.length_mm];
                    for (b, v) in pose.iter_mut().zip(values) {
                        b.append_option(finite(v));
                    }
                    for (i, b) in a.iter_mut().enumerate() {
                        b.append_option(row.a.get(i).copied().and_then(finite));
                    }
                }
                None => {
                    iterations.append_value(0);
                    pose.iter_mut().chain(a.iter_mut()).for_each(|b| b.append_null());
                }
            }
            if centreline {
                match &row.centreline {
                    Some((xs, ys)) => {
                        cx.values().append_slice(xs);
                        cx.append(true);
                        cy.values().append_slice(ys);
                        cy.append(true);
                    }
                    None => {
                        cx.append(false);
                        cy.append(false);
                    }
                }
            }
        }
    }
    let mut columns: Vec<ArrayRef> = vec![Arc::new(id.finish())];
    columns.extend(y.iter_mut().map(|b| Arc::new(b.finish()) as ArrayRef));
    columns.push(Arc::new(tension.finish()));
    columns.push(Arc::new(displacement.finish()));
    columns.push(Arc::new(status.finish()));
    columns.push(Arc::new(iterations.finish()));
    columns.extend(pose.iter_mut().chain(a.iter_mut()).map(|b| Arc::new(b.finish()) as ArrayRef));
    if centreline {
        columns.push(Arc::new(cx.finish()));
        columns.push(Arc::new(cy.finish()));
    }
    RecordBatch::try_new(schema.clone(), columns).expect("columns match the schema")
}

/// A successful solve yields finite numbers; anything else is stored as
/// null rather than NaN (pandas and polars treat NaN and null differently).
fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Status of a cable sweep's rows whose routing was rejected (e.g. two
/// cables on one path).
pub const STATUS_INVALID_ROUTING: &str = "invalid_routing";
/// Status of a cable sweep's rows whose solve failed.
pub const STATUS_FAILED: &str = "failed";

/// A body-frame lateral axis of a cable's channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Body y.
    Y,
    /// Body z.
    Z,
}

impl Axis {
    /// The axis's name in specs and columns: `y` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }
}

/// Name of a cable's control-point column (f64, mm), e.g. `cable2_z3_mm`
/// (cables from 1).
pub fn control_point_column(cable: usize, axis: Axis, point: usize) -> String {
    format!("cable{cable}_{}{point}_mm", axis.name())
}

/// Name of a cable's tension column (f64, N), e.g. `tension1_n` (cables from
/// 1): the command of a tension-driven cable, the tension found for a
/// displacement-driven one (null when its solve failed).
pub fn tension_column(cable: usize) -> String {
    format!("tension{cable}_n")
}

/// Name of a cable's displacement column (nullable f64, mm), e.g.
/// `displacement1_mm`: the command of a displacement-driven cable, what the
/// tension produced for a tension-driven one (null when the solve failed).
pub fn displacement_column(cable: usize) -> String {
    format!("displacement{cable}_mm")
}

/// Tip position z (nullable f64, mm; cable rows).
pub const TIP_Z_MM: &str = "tip_z_mm";
/// Tip tangent, global x component (nullable f64; cable rows).
pub const TIP_TANGENT_X: &str = "tip_tangent_x";
/// Tip tangent, global y component (nullable f64; cable rows).
pub const TIP_TANGENT_Y: &str = "tip_tangent_y";
/// Pose columns of a cable sweep row (nullable f64).
pub const CABLE_POSE_COLUMNS: [&str; 11] = [
    TIP_X_MM,
    TIP_Y_MM,
    TIP_Z_MM,
    TIP_TANGENT_X,
    TIP_TANGENT_Y,
    "tip_tangent_z",
    "tip_body_y_x",
    "tip_body_y_y",
    "tip_body_y_z",
    TIP_ANGLE_RAD,
    LENGTH_MM,
];

/// The three coefficient series of a cable sweep row, by column prefix:
/// in-plane bending `a0…` (the planar sweep's names), out-of-plane bending
/// `a_bend_y0…`, twist `a_twist0…`.
pub const CABLE_SERIES_PREFIXES: [&str; 3] = ["a", "a_bend_y", "a_twist"];

/// One solved (or failed) row of a cable sweep.
#[derive(Debug, Clone)]
pub struct CableRow {
    /// Routing number in the spec's enumeration.
    pub routing_id: i64,
    /// Each cable's (y, z) control points, mm.
    pub cables: Vec<([f64; CONTROL_POINTS], [f64; CONTROL_POINTS])>,
    /// Each cable's tension, N: its command, or (displacement-driven) the
    /// tension found; NaN (stored as null) when unknown.
    pub tensions: Vec<f64>,
    /// Each cable's displacement, mm: its command, or (tension-driven) what
    /// the tension produced; NaN (stored as null) when unknown.
    pub displacements: Vec<f64>,
    /// `ok`, [`STATUS_FAILED`] or [`STATUS_INVALID_ROUTING`].
    pub status: &'static str,
    /// Solver passes (0 when not solved).
    pub passes: i32,
    /// The pose of a solved row.
    pub pose: Option<TipPose>,
    /// Twist, out-of-plane and in-plane coefficient series of a solved row.
    pub a: Option<[Vec<f64>; 3]>,
}

/// The row schema of a cable sweep of `n_cables` cables storing orders
/// 0…`order` (docs/schema.md, "Cable sweeps"): inputs non-null, outputs
/// nullable (null when the solve failed or the routing was rejected).
pub fn cable_schema(n_cables: usize, order: usize) -> SchemaRef {
    let mut fields = vec![Field::new(ROUTING_ID, DataType::Int64, false)];
    for c in 0..n_cables {
        for axis in [Axis::Y, Axis::Z] {
            fields.extend((0..CONTROL_POINTS).map(|p| Field::new(control_point_column(c + 1, axis, p), DataType::Float64, false)));
        }
    }
    fields.extend((0..n_cables).map(|c| Field::new(tension_column(c + 1), DataType::Float64, true)));
    fields.extend((0..n_cables).map(|c| Field::new(displacement_column(c + 1), DataType::Float64, true)));
    fields.push(Field::new(STATUS, DataType::Utf8, false));
    fields.push(Field::new(ITERATIONS, DataType::Int32, false));
    fields.extend(CABLE_POSE_COLUMNS.iter().map(|n| Field::new(*n, DataType::Float64, true)));
    for prefix in CABLE_SERIES_PREFIXES {
        fields.extend((0..=order).map(|i| Field::new(format!("{prefix}{i}"), DataType::Float64, true)));
    }
    Arc::new(Schema::new(fields))
}

/// The rows of a cable chunk (in order) as one record batch of [`cable_schema`].
pub fn cable_batch(schema: &SchemaRef, rows: &[&CableRow], n_cables: usize, order: usize) -> RecordBatch {
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
        columns.push(Arc::new(rows.iter().map(|r| finite(r.tensions[c])).collect::<Float64Array>()));
    }
    for c in 0..n_cables {
        columns.push(Arc::new(rows.iter().map(|r| finite(r.displacements[c])).collect::<Float64Array>()));
    }
    columns.push(Arc::new(StringArray::from_iter_values(rows.iter().map(|r| r.status))));
    columns.push(Arc::new(Int32Array::from_iter_values(rows.iter().map(|r| r.passes))));
    let pose_value = |r: &CableRow, k: usize| {
        r.pose.map(|p| match k {
            0..=2 => p.tip_mm()[k],
            3..=5 => p.tip_tangent()[k - 3],
            6..=8 => p.tip_body_y_axis()[k - 6],
            // The cable sweep's tip_angle_rad: unsigned, from the clamp axis.
            9 => p.angle_from_clamp_axis_rad(),
            _ => p.length_mm,
        })
    };
    for k in 0..CABLE_POSE_COLUMNS.len() {
        columns.push(Arc::new(rows.iter().map(|r| pose_value(r, k)).collect::<Float64Array>()));
    }
    // The solver's series are (twist, out-of-plane, in-plane): stored in
    // the order of CABLE_SERIES_PREFIXES.
    for series in [2, 1, 0] {
        for i in 0..=order {
            columns.push(Arc::new(rows.iter().map(|r| r.a.as_ref().map(|a| a[series][i])).collect::<Float64Array>()));
        }
    }
    RecordBatch::try_new(schema.clone(), columns).expect("columns match the schema")
}
