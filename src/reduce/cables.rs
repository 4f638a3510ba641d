//! Maps of a cable sweep (issue 16; docs/schema.md, "Cable sweeps"): reach
//! counts per cell on the three coordinate planes and per 3-D voxel, a
//! picture of the three planes, and for a planar run the planar map tables
//! by the same reducer as a planar sweep. [`run_cable_sweep`] runs the whole
//! job: the rows ([`crate::sweep::cables`]), then these maps.

use super::ReduceError;
use crate::model::routing::CONTROL_POINTS;
use crate::model::STATUS_OK;
use crate::shape::LengthBasis;
use crate::sweep::cables::{
    prepare_out_dir, solve_cable_sweep, write_parquet, write_rows, Axis, CableSweepError, CableSweepSpec, Row, STATUS_INVALID_ROUTING,
};
use arrow::array::{ArrayRef, Float64Array, Int32Array, Int64Array, StringArray};
use arrow::datatypes::{DataType, Field, Schema};
use arrow::record_batch::RecordBatch;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

/// The three reach maps drawn side by side, in `maps/`.
pub const REACH_PICTURE: &str = "reach.png";
/// Map tables written into `maps/` of a run directory.
pub const MAP_FILES: [&str; 4] = ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"];

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

/// Runs a cable sweep into `out` (created; must be new or empty): solves the
/// rows ([`crate::sweep::cables`]), writes rows.parquet and spec.toml, the
/// reach maps in `maps/` (and a planar run's map tables in `maps/planar/`)
/// and summary.json.
pub fn run_cable_sweep(spec: &CableSweepSpec, out: &Path, threads: Option<usize>) -> Result<CableSweepSummary, ReduceError> {
    let write_err = |context: String, e: &dyn std::fmt::Display| CableSweepError::Write { context, message: e.to_string() };
    spec.validate("(given)")?;
    prepare_out_dir(out)?;
    let start = std::time::Instant::now();
    let solved = solve_cable_sweep(spec, threads)?;
    let rows = &solved.rows;
    write_rows(spec, rows, out)?;
    let cells = write_maps(&out.join("maps"), rows, spec.output.cell_mm).map_err(|e| write_err(format!("writing maps in {}", out.display()), &e))?;
    let planar = spec.cables.iter().all(|c| c.z_mm.iter().all(|&z| z == 0.0) && c.sweeps.iter().all(|s| s.axis == Axis::Y))
        && spec.gravity_direction.is_none_or(|g| g[2] == 0.0);
    if planar && spec.output.order >= 1 {
        write_planar_maps(spec, rows, out)?;
    }
    let ok = rows.iter().filter(|r| r.status == STATUS_OK).count() as u64;
    let invalid_rows = rows.iter().filter(|r| r.status == STATUS_INVALID_ROUTING).count() as u64;
    let summary = CableSweepSummary {
        routings: solved.routings,
        invalid_routings: invalid_rows / solved.tension_combinations as u64,
        rows: rows.len() as u64,
        ok,
        failed: rows.len() as u64 - ok - invalid_rows,
        planar,
        cells,
        wall_s: start.elapsed().as_secs_f64(),
        threads: solved.threads,
    };
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
fn write_planar_maps(spec: &CableSweepSpec, rows: &[Row], out: &Path) -> Result<(), ReduceError> {
    use super::tables::write_tables;
    use super::{reduce_batches, ReduceOptions, RunInfo};
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
        body: super::MapBody::of(&spec.rod),
    };
    let options = ReduceOptions { cell_mm: spec.output.cell_mm, ..ReduceOptions::default() };
    let map = reduce_batches(&info, &options, || Ok(std::iter::once(Ok::<_, ReduceError>(batch.clone()))))?;
    let dir = out.join(PLANAR_MAP_DIR);
    std::fs::create_dir_all(&dir).map_err(|e| CableSweepError::Write { context: format!("creating {}", dir.display()), message: e.to_string() })?;
    write_tables(&dir, &map)?;
    Ok(())
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
        write_parquet(&dir.join(file), counts_batch(&counts, names, cell_mm))?;
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
    write_parquet(&dir.join(MAP_FILES[3]), counts_batch(&counts, &["x", "y", "z"], cell_mm))?;
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

