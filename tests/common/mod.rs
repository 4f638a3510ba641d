//! Builds a small but real feasibility map for tests: simulates a coarse
//! sweep with the library's solver (one routing of each mirror pair, as a
//! de-duplicated run), hands the rows to the reducer in the sweep's column
//! layout and writes the map tables (`docs/maps.md`).

use arrow::array::{ArrayRef, Float64Array, Int64Array, RecordBatch, StringArray};
use cablemap::model::{Rod, Routing};
use cablemap::solver::{Simulator, SolverOptions, STATUS_OK};
use cablemap::reduce::{reduce_batches, tables::write_tables, ReduceOptions, RunInfo};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Control-point levels of the test sweep, mm (0.4 r steps: coarser than the thesis's 0.2 r).
pub const LEVELS_MM: [f64; 5] = [-4.0, -2.0, 0.0, 2.0, 4.0];
/// Tensions of the test sweep, N.
pub const TENSIONS_N: [f64; 5] = [1.0, 1.25, 1.5, 1.75, 2.0];

/// One simulated row (the routing as simulated; the reducer adds mirrors).
#[derive(Debug, Clone)]
pub struct Row {
    pub routing_id: i64,
    pub y_mm: [f64; 5],
    pub tension_n: f64,
    pub tip_x_mm: f64,
    pub tip_y_mm: f64,
    pub tip_angle_rad: f64,
    pub a: [f64; 3],
}

/// Simulates the sweep: one routing of each mirror pair.
pub fn simulate_rows() -> Vec<Row> {
    let actuator = Rod::default();
    let mut sim = Simulator::for_rod(&actuator, &SolverOptions::default()).unwrap();
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
            sim.coefficients_into(cablemap::shape::LengthBasis::Rest, &mut a);
            rows.push(Row { routing_id: id as i64, y_mm: y, tension_n: t, tip_x_mm: p.tip_x_mm, tip_y_mm: p.tip_y_mm, tip_angle_rad: p.tip_angle_rad, a });
        }
    }
    rows
}

/// The rows in the sweep's column layout.
fn batch(rows: &[Row]) -> RecordBatch {
    let f = |g: &dyn Fn(&Row) -> f64| Arc::new(Float64Array::from_iter_values(rows.iter().map(g))) as ArrayRef;
    let mut columns: Vec<(String, ArrayRef)> = vec![
        ("status".into(), Arc::new(StringArray::from_iter_values(rows.iter().map(|_| STATUS_OK))) as ArrayRef),
        ("routing_id".into(), Arc::new(Int64Array::from_iter_values(rows.iter().map(|r| r.routing_id)))),
    ];
    for i in 0..5 {
        columns.push((format!("y{i}_mm"), f(&|r| r.y_mm[i])));
    }
    columns.push(("tension_n".into(), f(&|r| r.tension_n)));
    columns.push(("tip_x_mm".into(), f(&|r| r.tip_x_mm)));
    columns.push(("tip_y_mm".into(), f(&|r| r.tip_y_mm)));
    columns.push(("tip_angle_rad".into(), f(&|r| r.tip_angle_rad)));
    for k in 0..3 {
        columns.push((format!("a{k}"), f(&|r| r.a[k])));
    }
    RecordBatch::try_from_iter(columns).unwrap()
}

/// Reduces `rows` (a de-duplicated run: mirrors restored by the reducer)
/// into a map directory at `dir`.
pub fn write_map(dir: &Path, rows: &[Row]) {
    let info = RunInfo {
        mirrored: true,
        order: 2,
        tension_range_n: [TENSIONS_N[0], TENSIONS_N[TENSIONS_N.len() - 1]],
        tensions_found: false,
        radius_mm: 5.0,
        length_mm: 65.0,
        run_dir: "tests/common (simulated in the test)".into(),
        spec_hash: "test".into(),
        length_basis: cablemap::shape::LengthBasis::Rest,
        body: Default::default(),
    };
    let b = batch(rows);
    let map = reduce_batches(&info, &ReduceOptions::default(), || Ok(vec![Ok(b.clone())].into_iter())).unwrap();
    std::fs::create_dir_all(dir).unwrap();
    write_tables(dir, &map).unwrap();
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
