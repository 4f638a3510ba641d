//! Typed access to the sweep's row columns (docs/schema.md) in Arrow batches.

use crate::model::routing::{ControlPoints, CONTROL_POINTS};
use super::{Design, ReduceError};
use crate::sweep::schema::{coefficient_column, ROUTING_ID, STATUS, TENSION_N, TIP_ANGLE_RAD, TIP_X_MM, TIP_Y_MM, Y_MM};
use arrow::array::{Array, AsArray, Float64Array, Int64Array, StringArray};
use arrow::compute::cast;
use arrow::datatypes::DataType;
use arrow::record_batch::RecordBatch;

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
            && self.status.value(i) == crate::model::STATUS_OK
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
