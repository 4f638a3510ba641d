//! Typed access to the sweep's row columns (docs/schema.md) in Arrow batches.

use super::ReduceError;
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
    pub y_mm: [Float64Array; 5],
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
    let col = batch
        .column_by_name(name)
        .ok_or_else(|| ReduceError::Schema(format!("column '{name}' is missing from the sweep shards")))?;
    if col.data_type() == to {
        return Ok(col.clone());
    }
    cast(col, to).map_err(|e| ReduceError::Schema(format!("column '{name}' cannot be read as {to}: {e}")))
}

fn f64_column(batch: &RecordBatch, name: &str) -> Result<Float64Array, ReduceError> {
    Ok(column(batch, name, &DataType::Float64)?.as_primitive::<arrow::datatypes::Float64Type>().clone())
}

impl RowColumns {
    /// Extracts the columns, with coefficients a_0 … a_`order`.
    pub fn from_batch(batch: &RecordBatch, order: usize) -> Result<Self, ReduceError> {
        let status = column(batch, "status", &DataType::Utf8)?.as_string::<i32>().clone();
        let routing_id = column(batch, "routing_id", &DataType::Int64)?.as_primitive::<arrow::datatypes::Int64Type>().clone();
        let y_mm = [
            f64_column(batch, "y0_mm")?,
            f64_column(batch, "y1_mm")?,
            f64_column(batch, "y2_mm")?,
            f64_column(batch, "y3_mm")?,
            f64_column(batch, "y4_mm")?,
        ];
        let a = (0..=order).map(|k| f64_column(batch, &format!("a{k}"))).collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            status,
            routing_id,
            y_mm,
            tension_n: f64_column(batch, "tension_n")?,
            tip_x_mm: f64_column(batch, "tip_x_mm")?,
            tip_y_mm: f64_column(batch, "tip_y_mm")?,
            tip_angle_rad: f64_column(batch, "tip_angle_rad")?,
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

    /// Status text of row `i` ("missing" when null).
    pub fn status_of(&self, i: usize) -> &str {
        if self.status.is_null(i) {
            "missing"
        } else {
            self.status.value(i)
        }
    }
}
