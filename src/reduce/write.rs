//! Writes a map directory: Parquet tables, summary.json (docs/maps.md).

use super::{MapData, ReduceError, MODES};
use arrow::array::{ArrayRef, BooleanArray, Float64Array, Int32Array, Int64Array};
use arrow::datatypes::{DataType, Field, Schema};
use arrow::record_batch::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;
use std::path::Path;
use std::sync::Arc;

/// Columns built up by name, then turned into one record batch.
#[derive(Default)]
struct Table {
    fields: Vec<Field>,
    columns: Vec<ArrayRef>,
}

impl Table {
    fn f64(&mut self, name: &str, values: Vec<Option<f64>>) {
        self.fields.push(Field::new(name, DataType::Float64, values.iter().any(Option::is_none)));
        self.columns.push(Arc::new(Float64Array::from(values)));
    }
    fn f64_all(&mut self, name: &str, values: Vec<f64>) {
        self.f64(name, values.into_iter().map(Some).collect());
    }
    fn i32(&mut self, name: &str, values: Vec<i32>) {
        self.fields.push(Field::new(name, DataType::Int32, false));
        self.columns.push(Arc::new(Int32Array::from(values)));
    }
    fn i64(&mut self, name: &str, values: Vec<i64>) {
        self.fields.push(Field::new(name, DataType::Int64, false));
        self.columns.push(Arc::new(Int64Array::from(values)));
    }
    fn bool(&mut self, name: &str, values: Vec<bool>) {
        self.fields.push(Field::new(name, DataType::Boolean, false));
        self.columns.push(Arc::new(BooleanArray::from(values)));
    }
    fn write(self, path: &Path) -> Result<(), ReduceError> {
        let err = |e: &dyn std::fmt::Display| ReduceError::Write { path: path.display().to_string(), message: e.to_string() };
        let schema = Arc::new(Schema::new(self.fields));
        let batch = RecordBatch::try_new(schema.clone(), self.columns).map_err(|e| err(&e))?;
        let props = WriterProperties::builder().set_compression(Compression::ZSTD(ZstdLevel::default())).build();
        let mut buf = Vec::new();
        let mut writer = ArrowWriter::try_new(&mut buf, schema, Some(props)).map_err(|e| err(&e))?;
        writer.write(&batch).map_err(|e| err(&e))?;
        writer.close().map_err(|e| err(&e))?;
        crate::io::write_atomic(path, &buf).map_err(|e| err(&e))
    }
}


/// Writes cells.parquet, modes.parquet, designs.parquet and summary.json.
pub fn write_tables(dir: &Path, map: &MapData) -> Result<(), ReduceError> {
    let mut cells = Table::default();
    let c = &map.cells;
    cells.i32("ix", c.iter().map(|c| c.ix).collect());
    cells.i32("iy", c.iter().map(|c| c.iy).collect());
    cells.f64_all("x_mm", c.iter().map(|c| c.x_mm).collect());
    cells.f64_all("y_mm", c.iter().map(|c| c.y_mm).collect());
    cells.i64("count", c.iter().map(|c| c.count).collect());
    let nk = c.first().map_or(0, |c| c.coefficients.len());
    for k in 0..nk {
        cells.f64_all(&format!("a{k}_p10"), c.iter().map(|c| c.coefficients[k].p10).collect());
        cells.f64_all(&format!("a{k}_p90"), c.iter().map(|c| c.coefficients[k].p90).collect());
        cells.f64_all(&format!("a{k}_gap"), c.iter().map(|c| c.coefficients[k].p90 - c.coefficients[k].p10).collect());
        cells.f64_all(&format!("a{k}_min"), c.iter().map(|c| c.coefficients[k].min).collect());
        cells.f64_all(&format!("a{k}_max"), c.iter().map(|c| c.coefficients[k].max).collect());
    }
    for m in 0..MODES {
        cells.i64(&format!("mode_{m}"), c.iter().map(|c| c.modes[m]).collect());
    }
    cells.write(&dir.join("cells.parquet"))?;

    let mut modes = Table::default();
    let m = &map.modes;
    modes.i32("mode", m.iter().map(|m| m.mode as i32).collect());
    modes.i32("a0_range", m.iter().map(|m| m.a0_range as i32).collect());
    modes.i32("a1_range", m.iter().map(|m| m.a1_range as i32).collect());
    modes.f64_all("a0_lo", m.iter().map(|m| m.a0_bounds.0).collect());
    modes.f64_all("a0_hi", m.iter().map(|m| m.a0_bounds.1).collect());
    modes.f64_all("a1_lo", m.iter().map(|m| m.a1_bounds.0).collect());
    modes.f64_all("a1_hi", m.iter().map(|m| m.a1_bounds.1).collect());
    modes.i64("count", m.iter().map(|m| m.count).collect());
    modes.i64("cells", m.iter().map(|m| m.cells).collect());
    let rep = |f: &dyn Fn(&super::Design) -> f64| -> Vec<Option<f64>> {
        m.iter().map(|m| m.representative.as_ref().map(f)).collect()
    };
    for k in 0..5 {
        modes.f64(&format!("rep_y{k}_mm"), rep(&|d| d.y_mm[k]));
    }
    modes.f64("rep_tension_n", rep(&|d| d.tension_n));
    modes.f64("rep_tip_x_mm", rep(&|d| d.tip_x_mm));
    modes.f64("rep_tip_y_mm", rep(&|d| d.tip_y_mm));
    modes.f64("rep_a0", rep(&|d| d.a[0]));
    modes.f64("rep_a1", rep(&|d| d.a[1]));
    modes.write(&dir.join("modes.parquet"))?;

    let mut designs = Table::default();
    let d = &map.designs;
    designs.i32("ix", d.iter().map(|d| d.ix).collect());
    designs.i32("iy", d.iter().map(|d| d.iy).collect());
    designs.i64("routing_id", d.iter().map(|d| d.routing_id).collect());
    designs.bool("mirrored", d.iter().map(|d| d.mirrored).collect());
    for k in 0..5 {
        designs.f64_all(&format!("y{k}_mm"), d.iter().map(|d| d.y_mm[k]).collect());
    }
    designs.f64_all("tension_n", d.iter().map(|d| d.tension_n).collect());
    designs.f64_all("tip_x_mm", d.iter().map(|d| d.tip_x_mm).collect());
    designs.f64_all("tip_y_mm", d.iter().map(|d| d.tip_y_mm).collect());
    designs.f64_all("tip_angle_rad", d.iter().map(|d| d.tip_angle_rad).collect());
    for k in 0..=map.summary.order {
        designs.f64_all(&format!("a{k}"), d.iter().map(|d| d.a[k]).collect());
    }
    designs.write(&dir.join("designs.parquet"))?;

    let json = serde_json::to_vec_pretty(&map.summary).map_err(|e| ReduceError::Write {
        path: "summary.json".into(),
        message: e.to_string(),
    })?;
    let path = dir.join("summary.json");
    crate::io::write_atomic(&path, &json).map_err(|e| ReduceError::Write { path: path.display().to_string(), message: e.to_string() })?;
    Ok(())
}
