//! `cablemap reduce` and `cablemap map` as a user runs them.

use arrow::array::AsArray;
use arrow::datatypes::Int64Type;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use std::path::Path;
use std::process::Command;

const QUICK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/jobs/quick.toml");

fn run(args: &[&str]) -> (bool, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cablemap"));
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "SLURM_CPUS_PER_TASK"] {
        c.env_remove(v);
    }
    let out = c.args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn int_column_sum(path: &Path, name: &str) -> i64 {
    let file = std::fs::File::open(path).unwrap();
    let reader = ParquetRecordBatchReaderBuilder::try_new(file).unwrap().build().unwrap();
    let mut sum = 0;
    for batch in reader {
        let batch = batch.unwrap();
        let col = batch.column_by_name(name).unwrap().as_primitive::<Int64Type>();
        sum += (0..col.len()).map(|i| col.value(i)).sum::<i64>();
    }
    sum
}

#[test]
fn map_runs_sweep_then_reduce_and_counts_add_up() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("quick");
    let (ok, stdout, stderr) = run(&["map", QUICK, "--out", out.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let last = stdout.lines().last().unwrap();
    let v: serde_json::Value = serde_json::from_str(last).unwrap();
    let s = &v["summary"];
    // jobs/quick.toml: 122 routings (mirror pairs dropped) x 5 tensions; the
    // all-zero routing is its own mirror, so restoring mirrors gives 2·610 − 5.
    assert_eq!(s["rows_total"], 2 * 610 - 5);
    let converged = s["rows_converged"].as_i64().unwrap();
    assert_eq!(converged + s["rows_failed"].as_i64().unwrap(), 2 * 610 - 5);
    let map = out.join("map");
    assert_eq!(int_column_sum(&map.join("cells.parquet"), "count"), converged);
    let modes_total: i64 = (0..12).map(|m| int_column_sum(&map.join("cells.parquet"), &format!("mode_{m}"))).sum();
    assert_eq!(modes_total, converged, "mode counts sum to the cell counts");
    assert_eq!(int_column_sum(&map.join("modes.parquet"), "count"), converged);
    for file in ["reach.png", "a0_p10.png", "a0_p90.png", "a0_gap.png", "a1_gap.png", "a2_gap.png", "modes.png", "index.html", "designs.parquet"] {
        assert!(map.join(file).exists(), "{file} missing");
    }
    // 610 solves over 1 mm cells are speckle: the summary (stderr beside
    // --json) and the page say so, with the cell size that reads as regions.
    assert!(stderr.contains("sparse map") && stderr.contains("--cell-mm 2"), "{stderr}");
    let page_data = std::fs::read_to_string(map.join("explorer-data.js")).unwrap();
    assert!(page_data.contains("\"sparse_note\":\"sparse map") && page_data.contains("--cell-mm 2"), "no note on the page");
    let coarse = dir.path().join("m2");
    let (ok, stdout, stderr) = run(&["reduce", out.join("run").to_str().unwrap(), "--out", coarse.to_str().unwrap(), "--cell-mm", "2"]);
    assert!(ok && !stdout.contains("sparse"), "{stdout}{stderr}");
    // Resumable like the sweep: a second run solves nothing new and maps the same.
    let (ok, stdout2, stderr) = run(&["map", QUICK, "--out", out.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let v2: serde_json::Value = serde_json::from_str(stdout2.lines().last().unwrap()).unwrap();
    assert_eq!(v2["summary"], v["summary"]);
}

#[test]
fn reduce_refuses_an_unfinished_run_unless_partial() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    let (ok, _, stderr) = run(&["sweep", QUICK, "--out", run_dir.to_str().unwrap(), "--shard", "0", "--shards", "2", "--quiet"]);
    assert!(ok, "{stderr}");
    let map_dir = dir.path().join("map");
    let (ok, _, stderr) = run(&["reduce", run_dir.to_str().unwrap(), "--out", map_dir.to_str().unwrap()]);
    assert!(!ok);
    assert!(stderr.contains("--partial") || stderr.contains("incomplete") || stderr.contains("not complete"), "{stderr}");
    assert!(!map_dir.join("cells.parquet").exists(), "nothing written for a refused run");
    let (ok, stdout, stderr) = run(&["reduce", run_dir.to_str().unwrap(), "--out", map_dir.to_str().unwrap(), "--partial", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert!(v["summary"]["rows_total"].as_i64().unwrap() < 2 * 610 - 5);
}

#[test]
fn reduce_bad_options_and_missing_runs_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = dir.path().join("run");
    assert!(run(&["sweep", QUICK, "--out", run_dir.to_str().unwrap(), "--quiet"]).0);
    let out = dir.path().join("map");
    let r = run_dir.to_str().unwrap();
    let o = out.to_str().unwrap();
    let nothing = dir.path().join("nothing");
    let cases: &[(&[&str], &str)] = &[
        (&["reduce", r, "--out", o, "--cell-mm", "0"], "cell size"),
        (&["reduce", r, "--out", o, "--a0-bounds", "-0.01,0,0.01"], "both --a0-bounds and --a1-bounds"),
        (&["reduce", r, "--out", o, "--a0-bounds", "0.01,0,0.02", "--a1-bounds", "-0.01,0.01"], "ascending"),
        (&["reduce", r, "--out", o, "--a0-bounds", "0,1", "--a1-bounds", "-0.01,0.01"], "three values"),
        (&["reduce", nothing.to_str().unwrap(), "--out", o], "holds no sweep"),
    ];
    for (args, needle) in cases {
        let (ok, _, stderr) = run(args);
        assert!(!ok, "{args:?} should fail");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
    // Explicit boundaries are used.
    let (ok, stdout, stderr) =
        run(&["reduce", r, "--out", o, "--a0-bounds", "-0.01,0,0.01", "--a1-bounds", "-0.005,0.005", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert_eq!(v["summary"]["mode_boundaries_source"], "explicit");
    assert_eq!(v["summary"]["mode_boundaries"]["a1"][1], 0.005);
}
