//! The reducer's reader of run rows (docs/schema.md; names from
//! `sweep::schema`): typed access to the planar row columns in Arrow
//! batches ([`RowColumns`]), and a cable sweep's rows laid out as planar
//! rows ([`cable_planar_batch`]), so one pipeline maps both kinds.

use super::map_cables::row_key;
use super::{Design, ReduceError};
use crate::model::routing::{ControlPoints, CONTROL_POINTS};
use crate::shape::LengthBasis;
use crate::sweep::schema::{
    coefficient_column, control_point_column, displacement_column, tension_column, Axis, LENGTH_MM, ROUTING_ID, STATUS, TENSION_N, TIP_ANGLE_RAD,
    TIP_TANGENT_X, TIP_TANGENT_Y, TIP_X_MM, TIP_Y_MM, Y_MM,
};
use crate::sweep::spec::{CablesGrid, OutputSpec};
use arrow::array::{Array, ArrayRef, AsArray, Float64Array, Int64Array, StringArray};
use arrow::compute::cast;
use arrow::datatypes::{DataType, Field, Float64Type, Int64Type, Schema};
use arrow::record_batch::RecordBatch;
use std::sync::Arc;

/// The columns of one sweep batch that the reducer reads, as plain arrays.
pub struct RowColumns {
    /// `status` ("ok" for converged solves).
    pub status: StringArray,
    /// `routing_id`.
    pub routing_id: Int64Array,
    /// `y0_mm` … `y4_mm`.
    pub routing_mm: [Float64Array; CONTROL_POINTS],
    /// `tension_n`.
    pub tension_n: Float64Array,
    /// `tip_x_mm`, `tip_y_mm`, `tip_angle_rad`.
    pub tip_x_mm: Float64Array,
    /// See `tip_x_mm`.
    pub tip_y_mm: Float64Array,
    /// See `tip_x_mm`.
    pub tip_angle_rad: Float64Array,
    /// `a0` … `a{order}`.
    pub a: Vec<Float64Array>,
}

fn column(batch: &RecordBatch, name: &str, to: &DataType) -> Result<arrow::array::ArrayRef, ReduceError> {
    let col = batch.column_by_name(name).ok_or_else(|| ReduceError::MissingColumn { name: name.to_string() })?;
    if col.data_type() == to {
        return Ok(col.clone());
    }
    cast(col, to).map_err(|source| ReduceError::ColumnType { name: name.to_string(), to: to.clone(), source })
}

fn f64_column(batch: &RecordBatch, name: &str) -> Result<Float64Array, ReduceError> {
    Ok(column(batch, name, &DataType::Float64)?.as_primitive::<arrow::datatypes::Float64Type>().clone())
}

impl RowColumns {
    /// Extracts the columns, with coefficients a_0 … a_`order`.
    pub fn from_batch(batch: &RecordBatch, order: usize) -> Result<Self, ReduceError> {
        let status = column(batch, STATUS, &DataType::Utf8)?.as_string::<i32>().clone();
        let routing_id = column(batch, ROUTING_ID, &DataType::Int64)?.as_primitive::<arrow::datatypes::Int64Type>().clone();
        let [y0, y1, y2, y3, y4] = Y_MM.map(|name| f64_column(batch, name));
        let routing_mm = [y0?, y1?, y2?, y3?, y4?];
        let a = (0..=order).map(|k| f64_column(batch, &coefficient_column(k))).collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            status,
            routing_id,
            routing_mm,
            tension_n: f64_column(batch, TENSION_N)?,
            tip_x_mm: f64_column(batch, TIP_X_MM)?,
            tip_y_mm: f64_column(batch, TIP_Y_MM)?,
            tip_angle_rad: f64_column(batch, TIP_ANGLE_RAD)?,
            a,
        })
    }

    /// Rows in the batch.
    pub fn len(&self) -> usize {
        self.status.len()
    }

    /// Whether row `i` converged and has every value the reducer needs.
    pub fn converged(&self, i: usize) -> bool {
        !self.status.is_null(i)
            && self.status.value(i) == crate::solver::STATUS_OK
            && !self.tension_n.is_null(i)
            && !self.tip_x_mm.is_null(i)
            && !self.tip_y_mm.is_null(i)
            && self.a.iter().all(|a| !a.is_null(i))
    }

    /// Row `i` as a design (cell (0, 0), not mirrored).
    pub fn design(&self, i: usize) -> Design {
        Design {
            ix: 0,
            iy: 0,
            routing_id: self.routing_id.value(i),
            mirrored: false,
            routing_mm: ControlPoints(std::array::from_fn(|k| self.routing_mm[k].value(i))),
            tension_n: self.tension_n.value(i),
            tip_x_mm: self.tip_x_mm.value(i),
            tip_y_mm: self.tip_y_mm.value(i),
            tip_angle_rad: self.tip_angle_rad.value(i),
            a: self.a.iter().map(|a| a.value(i)).collect(),
        }
    }

    /// The columns the reducer reads for coefficient order `order`: give
    /// them to the run's projected reader.
    pub fn names(order: usize) -> Vec<String> {
        let mut names: Vec<String> = [ROUTING_ID, STATUS].into_iter().chain(Y_MM).map(String::from).collect();
        names.extend([TENSION_N, TIP_X_MM, TIP_Y_MM, TIP_ANGLE_RAD].map(String::from));
        names.extend((0..=order).map(coefficient_column));
        names
    }

    /// Status text of row `i` ("missing" when null).
    pub fn status_of(&self, i: usize) -> &str {
        if self.status.is_null(i) {
            "missing"
        } else {
            self.status.value(i)
        }
    }
}

/// The columns of a cable sweep's rows that [`cable_planar_batch`] reads:
/// give them to the run's projected reader.
pub(crate) fn cable_planar_columns(spec: &CablesGrid, output: &OutputSpec) -> Vec<String> {
    let mut names: Vec<String> = vec![ROUTING_ID.into(), STATUS.into()];
    names.extend((0..CONTROL_POINTS).map(|p| control_point_column(1, Axis::Y, p)));
    names.extend((1..=spec.actuator.cables.len()).map(tension_column));
    // A displacement-driven cable's command (its row key) is its displacement.
    names.extend(spec.grids.iter().enumerate().filter(|(_, g)| g.by_displacement).map(|(c, _)| displacement_column(c + 1)));
    names.extend([TIP_X_MM, TIP_Y_MM, TIP_TANGENT_X, TIP_TANGENT_Y, LENGTH_MM].map(String::from));
    names.extend((0..=output.order).map(coefficient_column));
    names
}

/// One batch of a planar cable run's rows ([`cable_planar_columns`]) in the
/// planar reducer's row layout: `routing_id` = the row's [`row_key`] (where
/// every cable's routing and tension are), `y0_mm`…`y4_mm` and `tension_n`
/// = cable 1's, and `tip_angle_rad` = the signed in-plane tangent angle,
/// continuous from the clamp. No mirror images are added (a pair's mirror
/// is another routing of the spec, if swept).
pub(crate) fn cable_planar_batch(spec: &CablesGrid, output: &OutputSpec, batch: &RecordBatch) -> Result<RecordBatch, ReduceError> {
    let grids = spec.actuation_grids();
    let f = |name: &str| batch.column_by_name(name).expect("projected").as_primitive::<Float64Type>().clone();
    let ids = batch.column_by_name(ROUTING_ID).expect("projected").as_primitive::<Int64Type>().clone();
    let tensions: Vec<Float64Array> = (1..=grids.len()).map(|c| f(&tension_column(c))).collect();
    // Each cable's command: its tension, or its displacement.
    let commands: Vec<Float64Array> =
        spec.grids.iter().enumerate().map(|(c, g)| if g.by_displacement { f(&displacement_column(c + 1)) } else { tensions[c].clone() }).collect();
    let combinations: u64 = grids.iter().map(|g| g.len() as u64).product();
    let n = batch.num_rows();
    let mut keys = Vec::with_capacity(n);
    for i in 0..n {
        // Stored commands are the grid's values bit for bit: find their indices.
        let mut k = 0u64;
        for (c, g) in grids.iter().enumerate() {
            let t = commands[c].value(i);
            let j = g.iter().position(|&v| v == t).ok_or(ReduceError::TensionOffGrid { cable: c + 1, tension_n: t })?;
            k = k * g.len() as u64 + j as u64;
        }
        keys.push(row_key(ids.value(i) as u64, k, combinations) as i64);
    }
    let mut fields = vec![Field::new(ROUTING_ID, DataType::Int64, false), Field::new(STATUS, DataType::Utf8, false)];
    let mut columns: Vec<ArrayRef> = vec![Arc::new(Int64Array::from(keys)), batch.column_by_name(STATUS).expect("projected").clone()];
    let mut push = |name: &str, column: ArrayRef| {
        fields.push(Field::new(name, DataType::Float64, true));
        columns.push(column);
    };
    for (p, name) in Y_MM.iter().enumerate() {
        push(name, batch.column_by_name(&control_point_column(1, Axis::Y, p)).expect("projected").clone());
    }
    push(TENSION_N, Arc::new(tensions[0].clone()));
    push(TIP_X_MM, batch.column_by_name(TIP_X_MM).expect("projected").clone());
    push(TIP_Y_MM, batch.column_by_name(TIP_Y_MM).expect("projected").clone());
    // The planar sweep's tip angle is continuous from the clamp, not wrapped:
    // unwrap atan2 toward θ_e − θ_0 = a_0·L (rest basis; a_0·ℓ deformed),
    // the clamp's shear angle θ_0 being far below π.
    let (tx, ty, len, a0) = (f(TIP_TANGENT_X), f(TIP_TANGENT_Y), f(LENGTH_MM), f(&coefficient_column(0)));
    let rest = output.length_basis == LengthBasis::Rest;
    let length_mm = spec.actuator.rod.length_mm;
    let angle: Float64Array = (0..n)
        .map(|i| {
            if tx.is_null(i) || ty.is_null(i) || a0.is_null(i) || len.is_null(i) {
                return None;
            }
            let wrapped = ty.value(i).atan2(tx.value(i));
            let turn = a0.value(i) * if rest { length_mm } else { len.value(i) };
            let tau = std::f64::consts::TAU;
            Some(wrapped + tau * ((turn - wrapped) / tau).round())
        })
        .collect();
    push(TIP_ANGLE_RAD, Arc::new(angle));
    for i in 0..=output.order {
        let name = coefficient_column(i);
        push(&name, batch.column_by_name(&name).expect("projected").clone());
    }
    RecordBatch::try_new(Arc::new(Schema::new(fields)), columns).map_err(ReduceError::PlanarRows)
}
