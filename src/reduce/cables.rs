//! Maps of a cable sweep run (issue 16; docs/schema.md, "Cable sweeps"):
//! reach counts per cell on the three coordinate planes and per 3-D voxel,
//! a picture of the three planes, and for a planar run (every cable and
//! gravity in the x–y plane) the planar feasibility map — tables, pictures
//! and explorer page — by the same reducer as a planar sweep, in `planar/`.
//!
//! The run is read chunk by chunk ([`crate::sweep::open_run_of`]): the reach
//! counts hold one entry per occupied cell, and the planar reducer streams
//! the rows twice, so memory does not grow with the number of rows.

use super::drawings::{DrawingError, ModeDrawings};
use super::output::{write_dir_replacing, write_map_drawn};
use super::plots::Picture;
use super::{reduce_batches, MapData, ReduceError, ReduceOptions, RunInfo};
use crate::model::routing::CONTROL_POINTS;
use crate::model::spatial::simulate_spatial;
use crate::model::STATUS_OK;
use crate::plot::BodyDrawing;
use crate::shape::LengthBasis;
use crate::sweep::cables::{control_point_column, tension_column, write_parquet, Axis, CableSweepError, CableSweepSpec, STATUS_INVALID_ROUTING};
use crate::sweep::{open_run_of, Completeness, RunSpec, SweepRun};
use arrow::array::{Array, ArrayRef, AsArray, Float64Array, Int32Array, Int64Array};
use arrow::datatypes::{DataType, Field, Float64Type, Int64Type, Schema};
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

/// The three reach maps drawn side by side.
pub const REACH_PICTURE: &str = "reach.png";
/// Reach tables of a cable map directory: x–y, x–z, y–z planes, 3-D voxels.
pub const MAP_FILES: [&str; 4] = ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"];
/// Folder (inside the map directory) of a planar run's feasibility map.
pub const PLANAR_MAP_DIR: &str = "planar";

/// `summary.json` of a cable map directory.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CableMapSummary {
    /// [`super::tables::MAP_FORMAT`]: marks the directory as a map written
    /// by cablemap.
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

/// What [`reduce_cable_run`] wrote.
#[derive(Debug, Clone)]
pub struct CableMap {
    /// summary.json.
    pub summary: CableMapSummary,
    /// The planar map and its pictures (planar runs of order ≥ 1).
    pub planar: Option<(MapData, Vec<Picture>)>,
}

/// Reduces the cable sweep in `run_dir` (refusing an unfinished run unless
/// `partial`) into the map directory `out`, written as a whole like a planar
/// map: reach tables and picture, summary.json, and for a planar run the
/// planar map in `out/planar`. `cell_mm` (default: the spec's
/// `output.cell_mm`) sizes the reach cells and the planar map's cells;
/// `options` sets the planar map's modes and designs.
pub fn reduce_cable_run(
    run_dir: &Path,
    partial: bool,
    cell_mm: Option<f64>,
    options: &ReduceOptions,
    out: &Path,
) -> Result<CableMap, ReduceError> {
    super::check_map_out(out)?;
    let completeness = if partial { Completeness::AllowPartial } else { Completeness::Complete };
    let run: SweepRun<CableSweepSpec> = open_run_of(run_dir, completeness).map_err(super::run_open_error)?;
    let spec = run.spec().clone();
    let cell_mm = cell_mm.unwrap_or(spec.output.cell_mm);
    super::check_cell_mm(cell_mm, spec.rod.length_mm)?;
    let reach = Reach::count(&run, cell_mm)?;
    let planar = spec.is_planar() && spec.output.order >= 1;
    let planar_map = if planar {
        let options = ReduceOptions { cell_mm, ..options.clone() };
        Some(planar_map(&run, &options)?)
    } else {
        None
    };
    let counts = run.status_counts();
    let count = |s: &str| counts.get(s).copied().unwrap_or(0);
    let rows = run.rows_done();
    let layout = spec.layout();
    let summary = CableMapSummary {
        format: super::tables::MAP_FORMAT.into(),
        kind: "cables".into(),
        run_dir: run_dir.display().to_string(),
        spec_sha256: run.manifest().spec_sha256.clone(),
        cables: spec.cables.len(),
        routings: layout.routings,
        tension_combinations: layout.tensions,
        rows,
        rows_total: run.rows_total(),
        ok: count(STATUS_OK),
        failed: rows - count(STATUS_OK) - count(STATUS_INVALID_ROUTING),
        invalid_rows: count(STATUS_INVALID_ROUTING),
        planar: spec.is_planar(),
        cell_mm,
        cells: reach.cells(),
        planar_map: planar_map.is_some().then(|| PLANAR_MAP_DIR.to_string()),
    };
    let planar = write_dir_replacing(out, |dir| {
        let write_err = |context: String, message: String| ReduceError::from(CableSweepError::Write { context, message });
        reach.write(dir).map_err(|m| write_err(format!("writing the reach maps in {}", dir.display()), m))?;
        let json = serde_json::to_string_pretty(&summary).expect("summary serialises") + "\n";
        let path = dir.join(super::tables::SUMMARY_FILE);
        crate::io::write_atomic(&path, json.as_bytes()).map_err(|e| write_err(format!("writing {}", path.display()), e.to_string()))?;
        planar_map
            .map(|(map, drawings)| {
                let cables = super::MapCables::of_spec(&spec);
                let pictures = write_map_drawn(&dir.join(PLANAR_MAP_DIR), &map, &spec.rod, &drawings, Some(&cables))?;
                Ok::<_, ReduceError>((map, pictures))
            })
            .transpose()
    })?;
    Ok(CableMap { summary, planar })
}

/// Solved rows per cell on the three planes and per voxel.
struct Reach {
    cell_mm: f64,
    planes: [BTreeMap<[i32; 2], i64>; 3],
    voxels: BTreeMap<[i32; 3], i64>,
    tips: u64,
}

/// The planes' files, axes (indices into the tip) and axis names.
const PLANES: [(&str, [usize; 2], [&str; 2]); 3] =
    [(MAP_FILES[0], [0, 1], ["x", "y"]), (MAP_FILES[1], [0, 2], ["x", "z"]), (MAP_FILES[2], [1, 2], ["y", "z"])];

impl Reach {
    /// Counts the solved tips of every written row, chunk by chunk.
    fn count(run: &SweepRun<CableSweepSpec>, cell_mm: f64) -> Result<Self, ReduceError> {
        let mut reach = Reach { cell_mm, planes: Default::default(), voxels: BTreeMap::new(), tips: 0 };
        let index = |v: f64| (v / cell_mm).floor() as i32;
        for batch in run.batches_projected(&["tip_x_mm", "tip_y_mm", "tip_z_mm"])? {
            let batch = batch?;
            let col = |name: &str| batch.column_by_name(name).expect("projected").as_primitive::<Float64Type>().clone();
            let (x, y, z) = (col("tip_x_mm"), col("tip_y_mm"), col("tip_z_mm"));
            for i in 0..batch.num_rows() {
                if x.is_null(i) || y.is_null(i) || z.is_null(i) {
                    continue;
                }
                let t = [x.value(i), y.value(i), z.value(i)];
                let c = t.map(index);
                for (k, (_, axes, _)) in PLANES.iter().enumerate() {
                    *reach.planes[k].entry([c[axes[0]], c[axes[1]]]).or_default() += 1;
                }
                *reach.voxels.entry(c).or_default() += 1;
                reach.tips += 1;
            }
        }
        Ok(reach)
    }

    fn cells(&self) -> [u64; 4] {
        [self.planes[0].len() as u64, self.planes[1].len() as u64, self.planes[2].len() as u64, self.voxels.len() as u64]
    }

    /// Writes the four tables and the picture into `dir`.
    fn write(&self, dir: &Path) -> Result<(), String> {
        let cell_mm = self.cell_mm;
        let mut pictures = Vec::new();
        for ((file, _, names), counts) in PLANES.iter().zip(&self.planes) {
            write_parquet(&dir.join(file), counts_batch(counts, names, cell_mm))?;
            // Page: x down, the other coordinate across; y–z: y across, z down.
            let plane = if names[0] == "x" {
                crate::plot::ReachPlane { axes: (names[1], "x"), cells: counts.iter().map(|(c, &n)| (c[1], c[0], n)).collect() }
            } else {
                crate::plot::ReachPlane { axes: (names[0], names[1]), cells: counts.iter().map(|(c, &n)| (c[0], c[1], n)).collect() }
            };
            pictures.push(plane);
        }
        let title = format!("reach: {} solutions, cells of {cell_mm} mm", self.tips);
        crate::plot::draw_reach_maps(&dir.join(REACH_PICTURE), &title, &pictures, cell_mm).map_err(|e| e.to_string())?;
        write_parquet(&dir.join(MAP_FILES[3]), counts_batch(&self.voxels, &["x", "y", "z"], cell_mm))
    }
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

/// The row key of a cable sweep's row in its planar map (the map's
/// `routing_id`): routing_id × tension combinations + the combination's
/// index in grid order (cable 1's tension slowest). [`row_of_key`] inverts it.
pub fn row_key(routing_id: u64, combination: u64, combinations: u64) -> u64 {
    routing_id * combinations + combination
}

/// (routing_id, combination index) of a planar map's `routing_id` (see [`row_key`]).
pub fn row_of_key(key: u64, combinations: u64) -> (u64, usize) {
    (key / combinations, (key % combinations) as usize)
}

/// A planar run's feasibility map by the planar reducer, and its mode
/// representatives drawn from a solve of all their cables. The reducer
/// reads the planar row layout, so each row is handed over with
/// `routing_id` = its [`row_key`] (where every cable's routing and tension
/// are), `y0_mm`…`y4_mm` and `tension_n` = cable 1's, and `tip_angle_rad` =
/// the signed in-plane tangent angle, continuous from the clamp. No mirror
/// images are added (a pair's mirror is another routing of the spec, if swept).
fn planar_map(run: &SweepRun<CableSweepSpec>, options: &ReduceOptions) -> Result<(MapData, ModeDrawings), ReduceError> {
    let spec = run.spec();
    let order = spec.output.order;
    let tensions: Vec<f64> = spec.cables.iter().flat_map(|c| [c.tension_n.min, c.tension_n.max]).collect();
    let info = RunInfo {
        mirrored: false,
        order,
        tension_range_n: [tensions.iter().copied().fold(f64::MAX, f64::min), tensions.iter().copied().fold(0.0, f64::max)],
        radius_mm: spec.rod.radius_mm,
        length_mm: spec.rod.length_mm,
        run_dir: run.dir().display().to_string(),
        spec_hash: run.manifest().spec_sha256.clone(),
        length_basis: spec.output.length_basis,
        body: super::MapBody::of(&spec.rod),
    };
    let mut wanted: Vec<String> = vec!["routing_id".into(), "status".into()];
    wanted.extend((0..CONTROL_POINTS).map(|p| control_point_column(1, Axis::Y, p)));
    wanted.extend((1..=spec.cables.len()).map(tension_column));
    wanted.extend(["tip_x_mm", "tip_y_mm", "tip_tangent_x", "tip_tangent_y", "length_mm"].map(String::from));
    wanted.extend((0..=order).map(|i| format!("a{i}")));
    let names: Vec<&str> = wanted.iter().map(String::as_str).collect();
    let grids = spec.tension_grids();
    let map = reduce_batches(&info, options, || {
        let batches = run.batches_projected(&names)?;
        Ok(batches.map(|b| planar_batch(spec, &grids, &b?)))
    })?;
    Ok((map.clone(), draw_modes(spec, &map)))
}

/// One batch of cable rows in the planar reducer's row layout.
fn planar_batch(spec: &CableSweepSpec, grids: &[Vec<f64>], batch: &RecordBatch) -> Result<RecordBatch, ReduceError> {
    let f = |name: &str| batch.column_by_name(name).expect("projected").as_primitive::<Float64Type>().clone();
    let ids = batch.column_by_name("routing_id").expect("projected").as_primitive::<Int64Type>().clone();
    let tensions: Vec<Float64Array> = (1..=grids.len()).map(|c| f(&tension_column(c))).collect();
    let combinations: u64 = grids.iter().map(|g| g.len() as u64).product();
    let n = batch.num_rows();
    let mut keys = Vec::with_capacity(n);
    for i in 0..n {
        // Stored tensions are the grid's values bit for bit: find their indices.
        let mut k = 0u64;
        for (c, g) in grids.iter().enumerate() {
            let t = tensions[c].value(i);
            let j = g.iter().position(|&v| v == t).ok_or_else(|| {
                CableSweepError::Write { context: "reading the cable rows".into(), message: format!("tension {t} N of cable {} is not on its grid", c + 1) }
            })?;
            k = k * g.len() as u64 + j as u64;
        }
        keys.push(row_key(ids.value(i) as u64, k, combinations) as i64);
    }
    let mut fields = vec![Field::new("routing_id", DataType::Int64, false), Field::new("status", DataType::Utf8, false)];
    let mut columns: Vec<ArrayRef> = vec![Arc::new(Int64Array::from(keys)), batch.column_by_name("status").expect("projected").clone()];
    let mut push = |name: String, column: ArrayRef| {
        fields.push(Field::new(name, DataType::Float64, true));
        columns.push(column);
    };
    for p in 0..CONTROL_POINTS {
        push(format!("y{p}_mm"), batch.column_by_name(&control_point_column(1, Axis::Y, p)).expect("projected").clone());
    }
    push("tension_n".into(), Arc::new(tensions[0].clone()));
    push("tip_x_mm".into(), batch.column_by_name("tip_x_mm").expect("projected").clone());
    push("tip_y_mm".into(), batch.column_by_name("tip_y_mm").expect("projected").clone());
    // The planar sweep's tip angle is continuous from the clamp, not wrapped:
    // unwrap atan2 toward θ_e − θ_0 = a_0·L (rest basis; a_0·ℓ deformed),
    // the clamp's shear angle θ_0 being far below π.
    let (tx, ty, len, a0) = (f("tip_tangent_x"), f("tip_tangent_y"), f("length_mm"), f("a0"));
    let rest = spec.output.length_basis == LengthBasis::Rest;
    let angle: Float64Array = (0..n)
        .map(|i| {
            if tx.is_null(i) || ty.is_null(i) || a0.is_null(i) || len.is_null(i) {
                return None;
            }
            let wrapped = ty.value(i).atan2(tx.value(i));
            let turn = a0.value(i) * if rest { spec.rod.length_mm } else { len.value(i) };
            let tau = std::f64::consts::TAU;
            Some(wrapped + tau * ((turn - wrapped) / tau).round())
        })
        .collect();
    push("tip_angle_rad".into(), Arc::new(angle));
    for i in 0..=spec.output.order {
        push(format!("a{i}"), batch.column_by_name(&format!("a{i}")).expect("projected").clone());
    }
    RecordBatch::try_new(Arc::new(Schema::new(fields)), columns)
        .map_err(|e| CableSweepError::Write { context: "building the planar map rows".into(), message: e.to_string() }.into())
}

/// Largest distance, mm, between a representative's stored tip and the tip
/// of its solve again for drawing.
const REDRAW_TOLERANCE_MM: f64 = 1e-3;

fn tip_gap_mm(tip: &[f64; 3], d: &super::Design) -> f64 {
    (tip[0] - d.tip_x_mm).hypot(tip[1] - d.tip_y_mm)
}

/// Each mode's representative solved again with all the cables of its row
/// (its [`row_key`]) and drawn in the x–y plane with every cable's path.
fn draw_modes(spec: &CableSweepSpec, map: &MapData) -> ModeDrawings {
    let combinations = spec.tension_combinations();
    let mut drawings = ModeDrawings::default();
    for m in &map.modes {
        let Some(d) = &m.representative else {
            drawings.shapes.push(None);
            continue;
        };
        let (id, k) = row_of_key(d.routing_id as u64, combinations);
        let actuator = spec.actuator_at(id, k);
        match simulate_spatial(&actuator, &spec.solver, 1, spec.output.length_basis) {
            // The sweep reached the row along its tension path; a solve from
            // zero could in principle land on another equilibrium: then the
            // drawing would not be the row's, and is not made.
            Ok(sim) if tip_gap_mm(&sim.pose.tip_mm(), d) > REDRAW_TOLERANCE_MM => {
                drawings.shapes.push(None);
                let message = format!(
                    "the solve from zero ends at ({:.3}, {:.3}) mm, not at the row's tip ({:.3}, {:.3}) mm",
                    sim.pose.tip_x_mm, sim.pose.tip_y_mm, d.tip_x_mm, d.tip_y_mm
                );
                drawings.failures.push(DrawingError::Simulation { mode: m.mode, source: message.into() });
            }
            Ok(sim) => {
                let label = format!("mode {}", m.mode);
                drawings.shapes.push(Some(BodyDrawing::of_body(&sim, &spec.rod, label, plotters::style::full_palette::BLUE_800)));
            }
            Err(e) => {
                drawings.shapes.push(None);
                drawings.failures.push(DrawingError::Simulation { mode: m.mode, source: Box::new(e) });
            }
        }
    }
    drawings
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_keys_round_trip() {
        for (id, k, n) in [(0, 0, 1), (3, 5, 6), (12, 120, 121)] {
            assert_eq!(row_of_key(row_key(id, k, n), n), (id, k as usize));
        }
    }
}
