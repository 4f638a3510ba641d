//! `cablemap sweep-cables` as a user runs it: rows with one tension column
//! per cable and the 3-D tip, reach maps on the three coordinate planes and
//! in 3-D, rejected routings, and agreement with `simulate --cable`.

mod process;

use arrow::array::{Array, Float64Array, Int64Array, StringArray};
use arrow::record_batch::RecordBatch;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::Path;

const SPEC: &str = r#"
gravity_direction = [0.6, 0, 0.8]
[output]
order = 2
cell_mm = 2.0

[[cable]]
y_mm = [2, 2, 2, 2, 2]
z_mm = [0, 1, 2, 2, 2]
tension_n = { min = 0.5, max = 1.5, count = 3 }
[[cable.sweep]]
axis = "z"
points = [4]
levels_mm = [1.0, 3.0]

[[cable]]
y_mm = [-2, -2, -2, -2, -2]
tension_n = { min = 0.0, max = 1.0, count = 2 }
[[cable.sweep]]
axis = "y"
points = [0]
levels_mm = [-2.0, -1.0, 2.0]
"#;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = process::cablemap().args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn read(path: &Path) -> RecordBatch {
    let file = std::fs::File::open(path).unwrap();
    let reader = ParquetRecordBatchReaderBuilder::try_new(file).unwrap().build().unwrap();
    let batches: Vec<RecordBatch> = reader.map(|b| b.unwrap()).collect();
    arrow::compute::concat_batches(&batches[0].schema(), &batches).unwrap()
}

fn f64s(batch: &RecordBatch, name: &str) -> Vec<Option<f64>> {
    let col = batch.column_by_name(name).unwrap_or_else(|| panic!("no column {name}"));
    let a = col.as_any().downcast_ref::<Float64Array>().unwrap();
    (0..a.len()).map(|i| a.is_valid(i).then(|| a.value(i))).collect()
}

#[test]
fn a_spatial_pair_sweep_writes_rows_and_reach_maps() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("pair.toml");
    std::fs::write(&spec, SPEC).unwrap();
    let out = dir.path().join("run");
    let (ok, stdout, stderr) = run(&["sweep-cables", spec.to_str().unwrap(), "--out", out.to_str().unwrap(), "--threads", "2"]);
    assert!(ok, "{stderr}");
    // 2 × 3 routings (cable 2 with y0 = 2 is still inside and apart), 3 × 2 tension pairs.
    assert!(stdout.contains("6 routings"), "{stdout}");
    let rows = read(&out.join("rows.parquet"));
    assert_eq!(rows.num_rows(), 6 * 6);
    for name in ["tension1_n", "tension2_n", "tip_x_mm", "tip_y_mm", "tip_z_mm", "tip_tangent_z", "a0", "a2", "a_bend_y2", "a_twist0", "cable2_y0_mm", "cable1_z4_mm"] {
        assert!(rows.column_by_name(name).is_some(), "{name}");
    }
    assert!(rows.column_by_name("a3").is_none(), "order 2 stores a0…a2");
    let status = rows.column_by_name("status").unwrap().as_any().downcast_ref::<StringArray>().unwrap();
    let ok_rows = (0..rows.num_rows()).filter(|&i| status.value(i) == "ok").count();
    assert_eq!(ok_rows, 36);
    // Every solved tip is counted once in each map.
    for file in ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"] {
        let m = read(&out.join("maps").join(file));
        let counts = m.column_by_name("count").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
        assert_eq!(counts.iter().map(|c| c.unwrap()).sum::<i64>(), 36, "{file}");
    }
    let png = image::open(out.join("maps/reach.png")).unwrap();
    assert!(png.width() > 1000 && png.height() > 500);
    let m = read(&out.join("maps/reach_3d.parquet"));
    for name in ["ix", "iy", "iz", "x_mm", "y_mm", "z_mm", "count"] {
        assert!(m.column_by_name(name).is_some(), "{name}");
    }
    // A row agrees with `simulate --cable` on the same actuator (continuation
    // along the ladder vs from zero: the same solution).
    let k = 17;
    let get = |name: &str| f64s(&rows, name)[k].unwrap();
    let list = |c: usize, axis: &str| (0..5).map(|p| get(&format!("cable{c}_{axis}{p}_mm")).to_string()).collect::<Vec<_>>().join(",");
    let c1 = format!("y={} z={} tension={}", list(1, "y"), list(1, "z"), get("tension1_n"));
    let c2 = format!("y={} z={} tension={}", list(2, "y"), list(2, "z"), get("tension2_n"));
    let (ok, json, err) = run(&["simulate", "--cable", &c1, "--cable", &c2, "--gravity-direction", "0.6,0,0.8", "--order", "2", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    for (col, key) in [("tip_x_mm", "tip_x_mm"), ("tip_y_mm", "tip_y_mm"), ("tip_z_mm", "tip_z_mm")] {
        assert!((get(col) - v[key].as_f64().unwrap()).abs() < 1e-6, "{col}: {} vs {}", get(col), v[key]);
    }
    assert!((get("a_twist1") - v["a_twist"][1].as_f64().unwrap()).abs() < 1e-7);
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rows"], 36);
    assert_eq!(summary["planar"], false);
    assert!(!out.join("maps/planar").exists(), "a spatial run has no planar maps");
    // Not resumable: the same directory again is refused.
    let (ok, _, stderr) = run(&["sweep-cables", spec.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(!ok && stderr.contains("not empty"), "{stderr}");
}

#[test]
fn rejected_routings_are_rows_with_a_status() {
    // Cable 2 swept onto cable 1's path at its second level.
    let spec_text = r#"
[rod.gravity]
enabled = false
[[cable]]
y_mm = [2, 2, 2, 2, 2]
tension_n = { min = 1.0, max = 1.0, count = 1 }
[[cable]]
y_mm = [2, 2, 2, 2, -2]
tension_n = { min = 0.5, max = 1.0, count = 2 }
[[cable.sweep]]
axis = "y"
points = [4]
levels_mm = [-2.0, 2.0]
"#;
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("s.toml");
    std::fs::write(&spec, spec_text).unwrap();
    let out = dir.path().join("run");
    let (ok, stdout, stderr) = run(&["sweep-cables", spec.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("(1 rejected)"), "{stdout}");
    let rows = read(&out.join("rows.parquet"));
    let status = rows.column_by_name("status").unwrap().as_any().downcast_ref::<StringArray>().unwrap();
    let statuses: Vec<&str> = (0..rows.num_rows()).map(|i| status.value(i)).collect();
    assert_eq!(statuses, ["ok", "ok", "invalid_routing", "invalid_routing"]);
    assert_eq!(f64s(&rows, "tip_x_mm")[2], None);
    // A planar run: tips on the x–y plane, and the planar sweep's map tables.
    assert!(f64s(&rows, "tip_z_mm")[0].unwrap().abs() < 1e-12);
    let cells = read(&out.join("maps/planar/cells.parquet"));
    let counts = cells.column_by_name("count").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
    assert_eq!(counts.iter().map(|c| c.unwrap()).sum::<i64>(), 2, "the two solved rows");
    let designs = read(&out.join("maps/planar/designs.parquet"));
    let ids = designs.column_by_name("routing_id").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
    let tips = f64s(&rows, "tip_x_mm");
    for (k, id) in ids.iter().enumerate() {
        // routing_id there is the row number in rows.parquet.
        assert_eq!(f64s(&designs, "tip_x_mm")[k], tips[id.unwrap() as usize]);
    }
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("maps/planar/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rows_converged"], 2);
}

#[test]
fn bad_specs_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("bad.toml");
    std::fs::write(&spec, SPEC.replace("points = [4]", "points = [9]")).unwrap();
    let (ok, _, stderr) = run(&["sweep-cables", spec.to_str().unwrap(), "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(!ok && stderr.contains("bad.toml") && stderr.contains("control point 9"), "{stderr}");
    let (ok, _, stderr) = run(&["sweep-cables", "/nonexistent.toml", "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(!ok && stderr.contains("/nonexistent.toml"), "{stderr}");
}

#[test]
fn the_shipped_job_specs_are_valid() {
    for name in ["antagonistic-pair.toml", "spatial-pair.toml"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs").join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let spec = cablemap::sweep::cables::CableSweepSpec::from_toml(&text, name).unwrap();
        assert!(spec.routings() > 1 && spec.tension_combinations() > 1);
    }
}
