//! The row schema of sweep output (documented for users in `docs/schema.md`)
//! and the builder that turns solved routings into an Arrow record batch.
//!
//! One row per (routing, tension). Inputs are never null; outputs are null
//! when the solve failed (never NaN), and `status` says why.

use crate::model::routing::{ControlPoints, CONTROL_POINTS};
use super::spec::SweepSpec;
use crate::model::TipPose;
use arrow::array::{ArrayRef, Float64Builder, Int32Builder, Int64Builder, ListBuilder, StringBuilder};
use arrow::datatypes::{DataType, Field, Schema, SchemaRef};
use arrow::record_batch::RecordBatch;
use std::sync::Arc;

/// Routing id (i64, see [`super::enumerate`]).
pub const ROUTING_ID: &str = "routing_id";
/// Control-point columns y0_mm … y4_mm (f64, mm).
pub const Y_MM: [&str; CONTROL_POINTS] = ["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm"];
/// Cable tension (f64, N).
pub const TENSION_N: &str = "tension_n";
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
/// Pose columns (nullable f64), named as in `cablemap simulate --json`.
pub const POSE_COLUMNS: [&str; 5] = [TIP_X_MM, TIP_Y_MM, TIP_ANGLE_RAD, "base_angle_rad", "length_mm"];
/// Optional centreline x positions (list of f64, mm; clamp to tip).
pub const CENTRELINE_X_MM: &str = "centreline_x_mm";
/// Optional centreline y positions (list of f64, mm; clamp to tip).
pub const CENTRELINE_Y_MM: &str = "centreline_y_mm";

/// Name of the coefficient column a_i (`a0`, `a1`, …; nullable f64, mm⁻¹: κ = Σ a_i P_i(t)
/// with t dimensionless, so every a_i is a curvature).
pub fn coefficient_column(i: usize) -> String {
    format!("a{i}")
}

/// The Arrow schema of a spec's rows.
pub fn arrow_schema(spec: &SweepSpec) -> SchemaRef {
    let mut fields = vec![Field::new(ROUTING_ID, DataType::Int64, false)];
    fields.extend(Y_MM.iter().map(|n| Field::new(*n, DataType::Float64, false)));
    fields.push(Field::new(TENSION_N, DataType::Float64, false));
    fields.push(Field::new(STATUS, DataType::Utf8, false));
    fields.push(Field::new(ITERATIONS, DataType::Int32, false));
    fields.extend(POSE_COLUMNS.iter().map(|n| Field::new(*n, DataType::Float64, true)));
    fields.extend((0..=spec.output.order).map(|i| Field::new(coefficient_column(i), DataType::Float64, true)));
    if spec.output.centreline {
        for name in [CENTRELINE_X_MM, CENTRELINE_Y_MM] {
            let item = Field::new_list_field(DataType::Float64, true);
            fields.push(Field::new(name, DataType::List(Arc::new(item)), true));
        }
    }
    Arc::new(Schema::new(fields))
}

/// The outcome of one solve, ready to become a row.
#[derive(Debug, Clone)]
pub struct SolvedRow {
    /// Tension, N.
    pub tension_n: f64,
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

/// Builds the record batch of a chunk from its solved routings (in order).
pub fn build_batch(schema: &SchemaRef, order: usize, centreline: bool, routings: &[SolvedRouting]) -> RecordBatch {
    let rows: usize = routings.iter().map(|r| r.rows.len()).sum();
    let mut id = Int64Builder::with_capacity(rows);
    let mut y: Vec<Float64Builder> = (0..CONTROL_POINTS).map(|_| Float64Builder::with_capacity(rows)).collect();
    let mut tension = Float64Builder::with_capacity(rows);
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
            tension.append_value(row.tension_n);
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
