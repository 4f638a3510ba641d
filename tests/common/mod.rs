//! Builds a small but real feasibility map for tests: simulates a coarse
//! sweep with the library's solver and bins it into the files of the map
//! contract (`docs/maps.md`: summary.json, cells.parquet, designs.parquet).
//! modes.parquet is not written: `feasible` and `design` do not read it.

use arrow::array::{ArrayRef, BooleanArray, Float64Array, Int32Array, Int64Array, RecordBatch};
use cablemap::model::{Actuator, Routing, Simulator, SolverOptions};
use parquet::arrow::ArrowWriter;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Control-point levels of the test sweep, mm (0.4 r steps: coarser than the thesis's 0.2 r).
pub const LEVELS_MM: [f64; 5] = [-4.0, -2.0, 0.0, 2.0, 4.0];
/// Tensions of the test sweep, N.
pub const TENSIONS_N: [f64; 5] = [1.0, 1.25, 1.5, 1.75, 2.0];
/// Cell size, mm.
pub const CELL_MM: f64 = 1.0;

/// One simulated row.
#[derive(Debug, Clone)]
pub struct Row {
    pub routing_id: i64,
    pub mirrored: bool,
    pub y_mm: [f64; 5],
    pub tension_n: f64,
    pub tip_x_mm: f64,
    pub tip_y_mm: f64,
    pub tip_angle_rad: f64,
    pub a: [f64; 3],
}

/// Simulates the sweep: one routing of each mirror pair, the mirror restored.
pub fn simulate_rows() -> Vec<Row> {
    let actuator = Actuator::default();
    let mut sim = Simulator::new(&actuator, &SolverOptions::default()).unwrap();
    let mut rows = Vec::new();
    for id in 0..LEVELS_MM.len().pow(5) {
        let mut k = id;
        let y: [f64; 5] = std::array::from_fn(|_| {
            let v = LEVELS_MM[k % LEVELS_MM.len()];
            k /= LEVELS_MM.len();
            v
        });
        if y.iter().find(|v| **v != 0.0).is_some_and(|v| *v < 0.0) {
            continue;
        }
        sim.set_routing(&Routing::new(&y, actuator.length_mm, actuator.radius_mm).unwrap());
        for t in [0.25, 0.5, 0.75].into_iter().chain(TENSIONS_N) {
            let Ok(p) = sim.solve(t) else { break };
            if t < TENSIONS_N[0] {
                continue;
            }
            let mut a = [0.0; 3];
            sim.coefficients_into(&mut a);
            let row = Row { routing_id: id as i64, mirrored: false, y_mm: y, tension_n: t, tip_x_mm: p.tip_x_mm, tip_y_mm: p.tip_y_mm, tip_angle_rad: p.tip_angle_rad, a };
            if y.iter().any(|v| *v != 0.0) {
                rows.push(Row {
                    mirrored: true,
                    y_mm: y.map(|v| -v),
                    tip_y_mm: -row.tip_y_mm,
                    tip_angle_rad: -row.tip_angle_rad,
                    a: row.a.map(|v| -v),
                    ..row.clone()
                });
            }
            rows.push(row);
        }
    }
    rows
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    let pos = q * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

fn write_parquet(path: &Path, columns: Vec<(&str, ArrayRef)>) {
    let batch = RecordBatch::try_from_iter(columns).unwrap();
    let file = std::fs::File::create(path).unwrap();
    let mut w = ArrowWriter::try_new(file, batch.schema(), None).unwrap();
    w.write(&batch).unwrap();
    w.close().unwrap();
}

fn f64s(v: impl IntoIterator<Item = f64>) -> ArrayRef {
    Arc::new(Float64Array::from_iter_values(v))
}

/// Bins `rows` into a map directory at `dir`.
pub fn write_map(dir: &Path, rows: &[Row]) {
    std::fs::create_dir_all(dir).unwrap();
    let x_min = rows.iter().map(|r| r.tip_x_mm).fold(f64::INFINITY, f64::min).floor();
    let y_min = rows.iter().map(|r| r.tip_y_mm).fold(f64::INFINITY, f64::min).floor();
    let x_max = rows.iter().map(|r| r.tip_x_mm).fold(f64::NEG_INFINITY, f64::max);
    let y_max = rows.iter().map(|r| r.tip_y_mm).fold(f64::NEG_INFINITY, f64::max);
    let nx = ((x_max - x_min) / CELL_MM).floor() as i64 + 1;
    let ny = ((y_max - y_min) / CELL_MM).floor() as i64 + 1;
    let a0 = sorted(rows.iter().map(|r| r.a[0]).collect());
    let a1 = sorted(rows.iter().map(|r| r.a[1]).collect());
    let b0 = [0.25, 0.5, 0.75].map(|q| percentile(&a0, q));
    let b1 = [1.0 / 3.0, 2.0 / 3.0].map(|q| percentile(&a1, q));
    let mode = |r: &Row| 3 * b0.iter().filter(|b| r.a[0] >= **b).count() + b1.iter().filter(|b| r.a[1] >= **b).count();
    let mut cells: BTreeMap<(i32, i32), Vec<&Row>> = BTreeMap::new();
    for r in rows {
        let ix = ((r.tip_x_mm - x_min) / CELL_MM).floor() as i32;
        let iy = ((r.tip_y_mm - y_min) / CELL_MM).floor() as i32;
        cells.entry((ix, iy)).or_default().push(r);
    }
    // cells.parquet
    let keys: Vec<(i32, i32)> = cells.keys().copied().collect();
    let mut columns: Vec<(String, ArrayRef)> = vec![
        ("ix".into(), Arc::new(Int32Array::from_iter_values(keys.iter().map(|k| k.0))) as ArrayRef),
        ("iy".into(), Arc::new(Int32Array::from_iter_values(keys.iter().map(|k| k.1)))),
        ("x_mm".into(), f64s(keys.iter().map(|k| x_min + (k.0 as f64 + 0.5) * CELL_MM))),
        ("y_mm".into(), f64s(keys.iter().map(|k| y_min + (k.1 as f64 + 0.5) * CELL_MM))),
        ("count".into(), Arc::new(Int64Array::from_iter_values(cells.values().map(|v| v.len() as i64)))),
    ];
    for k in 0..3 {
        let s: Vec<Vec<f64>> = cells.values().map(|v| sorted(v.iter().map(|r| r.a[k]).collect())).collect();
        let p10: Vec<f64> = s.iter().map(|v| percentile(v, 0.1)).collect();
        let p90: Vec<f64> = s.iter().map(|v| percentile(v, 0.9)).collect();
        columns.push((format!("a{k}_p10"), f64s(p10.clone())));
        columns.push((format!("a{k}_p90"), f64s(p90.clone())));
        columns.push((format!("a{k}_gap"), f64s(p10.iter().zip(&p90).map(|(a, b)| b - a))));
        columns.push((format!("a{k}_min"), f64s(s.iter().map(|v| v[0]))));
        columns.push((format!("a{k}_max"), f64s(s.iter().map(|v| *v.last().unwrap()))));
    }
    for m in 0..12 {
        columns.push((
            format!("mode_{m}"),
            Arc::new(Int64Array::from_iter_values(cells.values().map(|v| v.iter().filter(|r| mode(r) == m).count() as i64))),
        ));
    }
    write_parquet(&dir.join("cells.parquet"), columns.iter().map(|(n, a)| (n.as_str(), a.clone())).collect());
    // designs.parquet: up to 16 per cell spanning the cell's a0 range.
    let mut picks: Vec<(i32, i32, &Row)> = Vec::new();
    for (key, v) in &cells {
        let mut v = v.clone();
        v.sort_by(|p, q| p.a[0].total_cmp(&q.a[0]));
        let n = v.len();
        let chosen: Vec<usize> = if n <= 16 { (0..n).collect() } else { (0..16).map(|i| (i * (n - 1) + 7) / 15).collect() };
        picks.extend(chosen.into_iter().map(|i| (key.0, key.1, v[i])));
    }
    let mut columns: Vec<(String, ArrayRef)> = vec![
        ("ix".into(), Arc::new(Int32Array::from_iter_values(picks.iter().map(|p| p.0))) as ArrayRef),
        ("iy".into(), Arc::new(Int32Array::from_iter_values(picks.iter().map(|p| p.1)))),
        ("routing_id".into(), Arc::new(Int64Array::from_iter_values(picks.iter().map(|p| p.2.routing_id)))),
        ("mirrored".into(), Arc::new(BooleanArray::from(picks.iter().map(|p| p.2.mirrored).collect::<Vec<_>>()))),
    ];
    for i in 0..5 {
        columns.push((format!("y{i}_mm"), f64s(picks.iter().map(|p| p.2.y_mm[i]))));
    }
    columns.push(("tension_n".into(), f64s(picks.iter().map(|p| p.2.tension_n))));
    columns.push(("tip_x_mm".into(), f64s(picks.iter().map(|p| p.2.tip_x_mm))));
    columns.push(("tip_y_mm".into(), f64s(picks.iter().map(|p| p.2.tip_y_mm))));
    columns.push(("tip_angle_rad".into(), f64s(picks.iter().map(|p| p.2.tip_angle_rad))));
    for k in 0..3 {
        columns.push((format!("a{k}"), f64s(picks.iter().map(|p| p.2.a[k]))));
    }
    write_parquet(&dir.join("designs.parquet"), columns.iter().map(|(n, a)| (n.as_str(), a.clone())).collect());
    let summary = serde_json::json!({
        "cell_mm": CELL_MM, "x_min_mm": x_min, "y_min_mm": y_min, "nx": nx, "ny": ny, "order": 2,
        "mirrored": true, "rows_total": rows.len(), "rows_converged": rows.len(), "rows_failed": 0,
        "failed_by_status": {}, "mode_boundaries": {"a0": b0, "a1": b1}, "mode_boundaries_source": "quantiles",
        "tension_range_n": [TENSIONS_N[0], TENSIONS_N[TENSIONS_N.len() - 1]], "radius_mm": 5.0, "length_mm": 65.0,
        "run_dir": "tests/common (simulated in the test)", "spec_hash": "test",
    });
    std::fs::write(dir.join("summary.json"), serde_json::to_string_pretty(&summary).unwrap()).unwrap();
}

/// The shared test map directory (built once per test binary) and its rows.
pub fn map() -> (&'static Path, &'static [Row]) {
    static MAP: OnceLock<(tempfile::TempDir, PathBuf, Vec<Row>)> = OnceLock::new();
    let (_, path, rows) = MAP.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map");
        let rows = simulate_rows();
        write_map(&path, &rows);
        (dir, path, rows)
    });
    (path, rows)
}
