//! `cablemap sweep` and `cablemap status` as a user (or a cluster) runs them:
//! resume after SIGKILL, sharding, agreement with `simulate`, and errors
//! that leave written data alone.

use arrow::array::{Array, AsArray};
use arrow::datatypes::{DataType, Float64Type, Int32Type, Int64Type};
use cablemap::sweep::{open_run, Completeness};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod process;
use process::{cablemap, snapshot};

const QUICK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/jobs/quick.toml");


fn run(args: &[&str]) -> (bool, String, String) {
    let out = cablemap().args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn sweep(spec: &Path, dir: &Path, extra: &[&str]) -> (bool, String, String) {
    let mut args = vec!["sweep", spec.to_str().unwrap(), "--out", dir.to_str().unwrap(), "--quiet"];
    args.extend_from_slice(extra);
    run(&args)
}

/// Chunk files committed (renamed into place) in a run directory.
fn committed_chunks(dir: &Path) -> u64 {
    std::fs::read_dir(dir.join("shards"))
        .map(|r| r.filter_map(Result::ok).filter(|e| e.file_name().to_string_lossy().starts_with("chunk-")).count() as u64)
        .unwrap_or(0)
}

fn write_spec(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Every row as a vector of exact values (floats by bit pattern), keyed by
/// (routing_id, tension bits), so runs can be compared regardless of order.
type Rows = BTreeMap<(i64, u64), Vec<String>>;

fn read_rows(dir: &Path, completeness: Completeness) -> Rows {
    let run = open_run(dir, completeness).unwrap();
    let mut rows = Rows::new();
    for batch in run.batches() {
        let batch = batch.unwrap();
        assert_eq!(batch.schema(), run.schema());
        let ids = batch.column_by_name("routing_id").unwrap().as_primitive::<Int64Type>();
        let tensions = batch.column_by_name("tension_n").unwrap().as_primitive::<Float64Type>();
        for r in 0..batch.num_rows() {
            let values: Vec<String> = batch.columns().iter().map(|c| cell(c.as_ref(), r)).collect();
            let key = (ids.value(r), tensions.value(r).to_bits());
            assert!(rows.insert(key, values).is_none(), "duplicate row {key:?} in {}", dir.display());
        }
    }
    rows
}

fn cell(column: &dyn Array, r: usize) -> String {
    if column.is_null(r) {
        return "null".into();
    }
    match column.data_type() {
        DataType::Int64 => column.as_primitive::<Int64Type>().value(r).to_string(),
        DataType::Int32 => column.as_primitive::<Int32Type>().value(r).to_string(),
        DataType::Float64 => {
            let v = column.as_primitive::<Float64Type>().value(r);
            assert!(!v.is_nan(), "NaN stored");
            format!("{:016x}", v.to_bits())
        }
        DataType::Utf8 => column.as_string::<i32>().value(r).to_string(),
        DataType::List(_) => {
            let list = column.as_list::<i32>().value(r);
            (0..list.len()).map(|i| cell(list.as_ref(), i)).collect::<Vec<_>>().join(",")
        }
        other => panic!("unexpected column type {other}"),
    }
}


#[test]
fn quick_sweep_has_every_row_once_with_the_documented_columns() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let (ok, stdout, stderr) = run(&["sweep", QUICK, "--out", dir.to_str().unwrap(), "--log-interval-s", "0"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("610 rows solved and written"), "{stdout}");
    // Lines fit an 80-column terminal (the temporary path is short), and the
    // summary names the next command.
    for line in stdout.lines().chain(stderr.lines()) {
        assert!(line.chars().count() <= 80, "over 80 columns: {line}");
    }
    assert!(stdout.contains(&format!("next: cablemap reduce {} --out MAP_DIR", dir.display())), "{stdout}");
    // stderr is not a terminal here: plain progress lines, no bar.
    assert!(stderr.contains("rows (") && stderr.contains("solves/s") && stderr.contains("ETA"), "{stderr}");
    assert!(stdout.contains("610/610 rows, complete"), "{stdout}");
    let run = open_run(&dir, Completeness::Complete).unwrap();
    assert_eq!((run.rows_done(), run.rows_total()), (610, 610));
    let names: Vec<String> = run.schema().fields().iter().map(|f| f.name().clone()).collect();
    let expected = [
        "routing_id", "y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm", "tension_n", "displacement_mm", "status", "iterations", "tip_x_mm", "tip_y_mm",
        "tip_angle_rad", "base_angle_rad", "length_mm", "a0", "a1", "a2", "a3",
    ];
    assert_eq!(names, expected);
    let rows = read_rows(&dir, Completeness::Complete);
    assert_eq!(rows.len(), 610);
    let ids: std::collections::BTreeSet<i64> = rows.keys().map(|k| k.0).collect();
    assert_eq!(ids, (0..122).collect());
    // Every level is one of the three of the quick spec, and each routing
    // is the lexicographically smaller of its mirror pair.
    let levels = [-4.0f64, 0.0, 4.0];
    let mut by_id: BTreeMap<i64, Vec<f64>> = BTreeMap::new();
    for batch in run.batches_projected(&["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm", "routing_id"]).unwrap() {
        let batch = batch.unwrap();
        assert_eq!(batch.num_columns(), 6);
        for r in 0..batch.num_rows() {
            let id = batch.column(0).as_primitive::<Int64Type>().value(r);
            let y: Vec<f64> = (1..6).map(|c| batch.column(c).as_primitive::<Float64Type>().value(r)).collect();
            assert!(y.iter().all(|v| levels.contains(v)), "{y:?}");
            by_id.insert(id, y);
        }
    }
    let routings: std::collections::BTreeSet<Vec<i64>> = by_id.values().map(|y| y.iter().map(|v| *v as i64).collect()).collect();
    for y in &routings {
        let mirror: Vec<i64> = y.iter().map(|v| -v).collect();
        assert!(y <= &mirror, "{y:?} kept but its mirror is smaller");
        assert!(y == &mirror || !routings.contains(&mirror), "both {y:?} and its mirror kept");
    }
    assert!(run.batches_projected(&["nope"]).is_err());
    // Chunk by chunk (the unit for parallel readers), projected.
    let mut rows = 0;
    for i in 0..run.chunk_count() {
        for batch in run.chunk_batches(i, Some(&["status", "a1"])).unwrap() {
            let batch = batch.unwrap();
            assert_eq!(batch.schema().fields().iter().map(|f| f.name().as_str()).collect::<Vec<_>>(), ["status", "a1"]);
            rows += batch.num_rows();
        }
    }
    assert_eq!((rows, run.chunk_count()), (610, 8));
}

#[test]
fn sweep_rows_agree_with_simulate() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir, &[]).0);
    let run = open_run(&dir, Completeness::Complete).unwrap();
    let batch = run.batches().next().unwrap().unwrap();
    let f = |name: &str, r: usize| batch.column_by_name(name).unwrap().as_primitive::<Float64Type>().value(r);
    // A spread of rows of the first chunk: different routings and tensions.
    for r in [0, 7, 23, 41, 58, 79] {
        assert_eq!(batch.column_by_name("status").unwrap().as_string::<i32>().value(r), "ok");
        let y: Vec<String> = ["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm"].iter().map(|c| format!("{}", f(c, r))).collect();
        let t = format!("{}", f("tension_n", r));
        let (ok, stdout, stderr) = run_simulate(&y.join(","), &t);
        assert!(ok, "{stderr}");
        let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
        for (name, tol) in [("tip_x_mm", 1e-5), ("tip_y_mm", 1e-5), ("tip_angle_rad", 1e-6), ("base_angle_rad", 1e-6), ("length_mm", 1e-5)] {
            let (a, b) = (f(name, r), v[name].as_f64().unwrap());
            assert!((a - b).abs() < tol, "row {r} {name}: sweep {a} vs simulate {b}");
        }
        for i in 0..4 {
            let (a, b) = (f(&format!("a{i}"), r), v["a"][i].as_f64().unwrap());
            assert!((a - b).abs() < 1e-6, "row {r} a{i}: sweep {a} vs simulate {b}");
        }
    }
}

/// A displacement ladder (`[displacement]` in place of `[tension]`): each
/// row stores its commanded displacement and the tension found; `simulate
/// --displacement-mm` gives the same rows; the tension ladder's rows carry
/// the displacement they produced, which given back returns their tension;
/// the map reduces it, its tension range the designs'. Bad ladders are
/// refused before anything is written.
#[test]
fn a_displacement_ladder_sweeps_and_maps_like_a_tension_ladder() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), "d.toml", "[grid]\nlevels = 2\n[displacement]\nmin_mm = 0.5\nmax_mm = 3.0\ncount = 4\n[output]\nchunk_routings = 4\n");
    let dir = tmp.path().join("run");
    let (ok, stdout, stderr) = sweep(&spec, &dir, &[]);
    assert!(ok, "{stdout}{stderr}");
    let drun = open_run(&dir, Completeness::Complete).unwrap();
    assert_eq!(drun.rows_total(), 16 * 4);
    let mut checked = 0;
    for batch in drun.batches() {
        let batch = batch.unwrap();
        let f = |name: &str, r: usize| batch.column_by_name(name).unwrap().as_primitive::<Float64Type>().value(r);
        for r in 0..batch.num_rows() {
            assert_eq!(batch.column_by_name("status").unwrap().as_string::<i32>().value(r), "ok");
            let d = f("displacement_mm", r);
            assert!([0.5, 0.5 + 2.5 / 3.0, 0.5 + 5.0 / 3.0, 3.0].iter().any(|v| (v - d).abs() < 1e-12), "{d}");
            if r % 5 != 0 {
                continue;
            }
            let y: Vec<String> = ["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm"].iter().map(|c| format!("{}", f(c, r))).collect();
            let (ok, out, err) = run(&["simulate", "--routing", &y.join(","), "--displacement-mm", &format!("{d}"), "--json"]);
            assert!(ok, "{err}");
            let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
            for (name, tol) in [("tension_n", 1e-7), ("tip_x_mm", 1e-6), ("tip_y_mm", 1e-6), ("tip_angle_rad", 1e-7)] {
                assert!((f(name, r) - v[name].as_f64().unwrap()).abs() < tol, "row {r} {name}: {} vs {v}", f(name, r));
            }
            checked += 1;
        }
    }
    assert!(checked >= 4, "{checked}");
    // A tension ladder's rows carry the displacement they produced.
    let tdir = tmp.path().join("t");
    assert!(sweep(Path::new(QUICK), &tdir, &[]).0);
    let trun = open_run(&tdir, Completeness::Complete).unwrap();
    let batch = trun.batches().next().unwrap().unwrap();
    let f = |name: &str, r: usize| batch.column_by_name(name).unwrap().as_primitive::<Float64Type>().value(r);
    let y: Vec<String> = ["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm"].iter().map(|c| format!("{}", f(c, 7))).collect();
    let (ok, out, err) = run(&["simulate", "--routing", &y.join(","), "--displacement-mm", &format!("{:e}", f("displacement_mm", 7)), "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert!((v["tension_n"].as_f64().unwrap() - f("tension_n", 7)).abs() < 1e-7, "{v}");
    // The map of the displacement run.
    let map = tmp.path().join("map");
    let (ok, _, err) = run(&["reduce", dir.to_str().unwrap(), "--out", map.to_str().unwrap()]);
    assert!(ok, "{err}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(map.join("summary.json")).unwrap()).unwrap();
    let range = &summary["tension_range_n"];
    assert!(range[0].as_f64().unwrap() > 0.0 && range[1].as_f64().unwrap() > range[0].as_f64().unwrap(), "{summary}");
    // Refused before writing: both tables; RK4; a negative or absurd displacement.
    for (text, needle) in [
        ("[tension]\ncount = 2\n[displacement]\nmin_mm = 0.0\nmax_mm = 1.0\ncount = 2\n", "not both"),
        ("[solver]\nmethod = \"rk4\"\n[displacement]\nmin_mm = 0.0\nmax_mm = 1.0\ncount = 2\n", "rk4"),
        ("[displacement]\nmin_mm = -1.0\nmax_mm = 1.0\ncount = 2\n", "min_mm = -1"),
        ("[displacement]\nmin_mm = 0.0\nmax_mm = 100.0\ncount = 2\n", "max_mm = 100"),
        ("[displacement]\nmin_mm = 0.0\nmax_mm = 1.0\ncount = 2\ncable_ea_n = 0\n", "cable_ea_n"),
    ] {
        let bad = write_spec(tmp.path(), "bad.toml", text);
        let out_dir = tmp.path().join("bad-run");
        let (ok, _, err) = sweep(&bad, &out_dir, &[]);
        assert!(!ok && err.contains(needle), "{text}: {err}");
        assert!(!out_dir.exists(), "{text}: nothing written");
    }
}

fn run_simulate(routing: &str, tension: &str) -> (bool, String, String) {
    run(&["simulate", "--routing", routing, "--tension", tension, "--json"])
}

/// A spec that takes a while (so kills land mid-run) and has many chunks.
const KILL_SPEC: &str = "[grid]\nlevels = 5\n[tension]\ncount = 6\n[output]\nchunk_routings = 20\n";

#[test]
fn sigkill_after_written_chunks_then_resume_gives_the_uninterrupted_rows() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), "kill.toml", KILL_SPEC);
    let reference_dir = tmp.path().join("reference");
    let (ok, _, stderr) = sweep(&spec, &reference_dir, &[]);
    assert!(ok, "{stderr}");
    let reference = read_rows(&reference_dir, Completeness::Complete);
    assert_eq!(reference.len(), 1563 * 6);
    // 1563 routings in chunks of 20: 79 chunks, far more than the kills
    // below wait for, so every kill lands mid-run whatever the machine's speed.
    let total_chunks = 1563u64.div_ceil(20);

    let dir = tmp.path().join("killed");
    // Kill points are counted in committed chunk files, not in time, from a
    // fixed seed (xorshift): the same schedule on every machine.
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let mut interrupted = 0;
    let rounds = 6;
    for round in 0..rounds {
        let mut child = cablemap()
            .args(["sweep", spec.to_str().unwrap(), "--out", dir.to_str().unwrap(), "--quiet"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Round 0: as soon as the manifest exists (no chunk yet, or the first
        // ones in flight); later rounds: after 1–6 more committed chunks.
        let before = committed_chunks(&dir);
        let wait_chunks = if round == 0 { 0 } else { 1 + next(6) };
        let ready = |d: &Path| d.join("manifest.json").exists() && committed_chunks(d) >= before + wait_chunks;
        // A generous safety net only (a hung child), never the kill point.
        let deadline = Instant::now() + Duration::from_secs(300);
        while !ready(&dir) && Instant::now() < deadline && child.try_wait().unwrap().is_none() {
            std::thread::sleep(Duration::from_micros(200));
        }
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        assert!(ready(&dir), "round {round}: the sweep neither wrote {wait_chunks} more chunk(s) nor kept running");
        // Whatever the moment, the directory is consistent: readable
        // chunks, no duplicate row, every row present equal to the reference.
        let partial = read_rows(&dir, Completeness::AllowPartial);
        for (key, values) in &partial {
            assert_eq!(Some(values), reference.get(key), "row {key:?} differs after a kill in round {round}");
        }
        if partial.len() < reference.len() {
            interrupted += 1;
        }
    }
    eprintln!("kills that left the run partial: {interrupted} of {rounds}");
    assert!(committed_chunks(&dir) < total_chunks);
    assert_eq!(interrupted, rounds, "every kill must land mid-run");
    let (ok, stdout, stderr) = sweep(&spec, &dir, &[]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("complete"), "{stdout}");
    assert_eq!(read_rows(&dir, Completeness::Complete), reference);
    let names: Vec<String> =
        std::fs::read_dir(dir.join("shards")).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
    assert!(names.iter().all(|n| n.starts_with("chunk-") && n.ends_with(".parquet")), "leftovers: {names:?}");
}

#[test]
fn shards_from_flags_and_cluster_variables_make_up_the_single_run() {
    let tmp = tempfile::tempdir().unwrap();
    let single = tmp.path().join("single");
    assert!(sweep(Path::new(QUICK), &single, &["--threads", "1"]).0);
    let reference = read_rows(&single, Completeness::Complete);

    let sharded = tmp.path().join("sharded");
    let args = |extra: &[&str]| {
        let mut a = vec!["sweep", QUICK, "--out", sharded.to_str().unwrap(), "--shards", "3", "--quiet"];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let out = cablemap().args(args(&[])).env("SLURM_ARRAY_TASK_ID", "1").env("SLURM_CPUS_PER_TASK", "1").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("shard 1/3") && stdout.contains("1 thread\n") && !stdout.contains("1 threads"), "{stdout}");
    assert!(stdout.contains("partial"), "{stdout}");
    let (ok, status, _) = run(&["status", sharded.to_str().unwrap()]);
    assert!(ok);
    assert!(status.contains("partial"), "{status}");
    let out = cablemap().args(args(&[])).env("JOB_COMPLETION_INDEX", "2").output().unwrap();
    assert!(out.status.success());
    assert!(open_run(&sharded, Completeness::Complete).is_err(), "shard 0 is still missing");
    let out = cablemap().args(args(&["--shard", "0"])).env("SLURM_ARRAY_TASK_ID", "2").output().unwrap();
    assert!(out.status.success());
    assert_eq!(read_rows(&sharded, Completeness::Complete), reference);
    let (ok, status, _) = run(&["status", sharded.to_str().unwrap(), "--json"]);
    assert!(ok);
    let v: serde_json::Value = serde_json::from_str(status.trim()).unwrap();
    assert_eq!(v["complete"], true);
    assert_eq!(v["rows_done"], 610);
    assert_eq!(v["shards"].as_array().unwrap().len(), 3);
    let per_shard: u64 = v["shards"].as_array().unwrap().iter().map(|s| s["rows_done"].as_u64().unwrap()).sum();
    assert_eq!(per_shard, 610);

    // All shards started at once into a new directory (an array job
    // starting): they race to create the manifest, and all succeed.
    let together = tmp.path().join("together");
    let children: Vec<_> = (0..4)
        .map(|i| {
            cablemap()
                .args(["sweep", QUICK, "--out", together.to_str().unwrap(), "--shards", "4", "--quiet", "--threads", "1"])
                .env("SLURM_ARRAY_TASK_ID", i.to_string())
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for child in children {
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    assert_eq!(read_rows(&together, Completeness::Complete), reference);

    // Resuming with another shard count is refused.
    let (ok, _, stderr) = sweep(Path::new(QUICK), &sharded, &["--shards", "2"]);
    assert!(!ok && stderr.contains("rerun with --shards 3"), "{stderr}");
    let (ok, _, stderr) = sweep(Path::new(QUICK), &sharded, &["--shards", "3", "--shard", "3"]);
    assert!(!ok && stderr.contains("out of range"), "{stderr}");
}

#[test]
fn centreline_columns_are_lists_of_solver_nodes() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(
        tmp.path(),
        "c.toml",
        "[grid]\nlevels = 2\n[tension]\ncount = 2\n[output]\ncentreline = true\norder = 5\nchunk_routings = 7\n",
    );
    let dir = tmp.path().join("run");
    let (ok, stdout, stderr) = sweep(&spec, &dir, &["--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!((v["summary"]["rows_written"].as_u64(), v["summary"]["status_counts"]["ok"].as_u64()), (Some(32), Some(32)));
    assert_eq!((v["run"]["complete"].as_bool(), v["run"]["rows_total"].as_u64()), (Some(true), Some(32)));
    let run = open_run(&dir, Completeness::Complete).unwrap();
    assert_eq!(run.rows_done(), 16 * 2);
    for batch in run.batches() {
        let batch = batch.unwrap();
        assert!(batch.column_by_name("a5").is_some());
        let xs = batch.column_by_name("centreline_x_mm").unwrap().as_list::<i32>();
        let tip = batch.column_by_name("tip_x_mm").unwrap().as_primitive::<Float64Type>();
        for r in 0..batch.num_rows() {
            let x = xs.value(r);
            let x = x.as_primitive::<Float64Type>();
            assert_eq!(x.len(), 49);
            assert_eq!(x.value(0), 0.0);
            assert_eq!(x.value(48), tip.value(r), "last centreline point is the tip");
        }
    }
}

#[test]
fn a_different_spec_in_the_same_dir_is_refused_and_nothing_changes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir, &[]).0);
    let before = snapshot(&dir);
    let other = write_spec(tmp.path(), "other.toml", &std::fs::read_to_string(QUICK).unwrap().replace("count = 5", "count = 4"));
    let (ok, _, stderr) = sweep(&other, &dir, &[]);
    assert!(!ok);
    assert!(stderr.contains("different spec") && stderr.contains("another --out"), "{stderr}");
    assert_eq!(snapshot(&dir), before);
    // The same spec reformatted is the same job.
    let same = write_spec(tmp.path(), "same.toml", &format!("# reformatted\n{}", std::fs::read_to_string(QUICK).unwrap()));
    let (ok, stdout, stderr) = sweep(&same, &dir, &[]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("0 rows solved") && stdout.contains("610 already done"), "{stdout}");
}

#[test]
fn foreign_and_corrupt_files_are_reported_and_left_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir, &[]).0);
    let shards = dir.join("shards");

    // A stray file in the dataset folder.
    std::fs::write(shards.join("notes.txt"), "mine").unwrap();
    let before = snapshot(&dir);
    let (ok, _, stderr) = run_cmd_status(&dir);
    assert!(!ok && stderr.contains("notes.txt") && stderr.contains("not written by cablemap"), "{stderr}");
    let (ok, _, stderr) = sweep(Path::new(QUICK), &dir, &[]);
    assert!(!ok && stderr.contains("notes.txt"), "{stderr}");
    assert_eq!(snapshot(&dir), before);
    std::fs::remove_file(shards.join("notes.txt")).unwrap();

    // A chunk file cut short: status and readers name it; the sweep moves it
    // to DIR/damaged and recomputes exactly that chunk.
    let victim = shards.join("chunk-000003.parquet");
    let good = std::fs::read(&victim).unwrap();
    std::fs::write(&victim, &good[..good.len() / 2]).unwrap();
    let (ok, stdout, _) = run_cmd_status(&dir);
    assert!(ok && stdout.contains("chunk-000003.parquet") && stdout.contains("damaged") && stdout.contains("partial"), "{stdout}");
    let err = open_run(&dir, Completeness::AllowPartial).unwrap_err().to_string();
    assert!(err.contains("chunk-000003.parquet") && err.contains("damaged"), "{err}");
    let (ok, stdout, stderr) = sweep(Path::new(QUICK), &dir, &[]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("chunk-000003.parquet") && stderr.contains("moved to"), "{stderr}");
    assert!(stdout.contains("80 rows solved") && stdout.contains("1 damaged chunks redone"), "{stdout}");
    assert_eq!(std::fs::read(&victim).unwrap(), good);
    let aside: Vec<_> = std::fs::read_dir(dir.join("damaged")).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(aside.len(), 1);
    assert_eq!(std::fs::read(&aside[0]).unwrap(), &good[..good.len() / 2]);

    // A chunk of another job under a valid chunk name.
    let other_dir = tmp.path().join("other");
    let other = write_spec(tmp.path(), "other.toml", &std::fs::read_to_string(QUICK).unwrap().replace("max_n = 2.0", "max_n = 1.5"));
    assert!(sweep(&other, &other_dir, &[]).0);
    std::fs::copy(other_dir.join("shards/chunk-000002.parquet"), shards.join("chunk-000002.parquet")).unwrap();
    let before = snapshot(&dir);
    let (ok, _, stderr) = sweep(Path::new(QUICK), &dir, &[]);
    assert!(!ok && stderr.contains("does not belong to this sweep"), "{stderr}");
    assert_eq!(snapshot(&dir), before);

    std::fs::remove_file(shards.join("chunk-000002.parquet")).unwrap();

    // A stray file beside the manifest.
    std::fs::write(dir.join("extra.csv"), "a,b").unwrap();
    let (ok, _, stderr) = sweep(Path::new(QUICK), &dir, &[]);
    assert!(!ok && stderr.contains("extra.csv") && stderr.contains("not written by cablemap"), "{stderr}");
    std::fs::remove_file(dir.join("extra.csv")).unwrap();
    let (ok, stdout, stderr) = sweep(Path::new(QUICK), &dir, &[]);
    assert!(ok && stdout.contains("80 rows solved"), "{stdout}{stderr}");
    assert_eq!(read_rows(&dir, Completeness::Complete).len(), 610);

    // A damaged manifest.
    let dir2 = tmp.path().join("run2");
    assert!(sweep(Path::new(QUICK), &dir2, &[]).0);
    std::fs::write(dir2.join("manifest.json"), "{ not json").unwrap();
    let (ok, _, stderr) = run(&["status", dir2.to_str().unwrap()]);
    assert!(!ok && stderr.contains("manifest") && stderr.contains("damaged"), "{stderr}");
}

#[test]
fn unusable_output_directories_get_clear_errors() {
    let tmp = tempfile::tempdir().unwrap();
    // Under a regular file: cannot be created (whoever runs the test).
    let file = tmp.path().join("plain-file");
    std::fs::write(&file, "x").unwrap();
    let (ok, _, stderr) = sweep(Path::new(QUICK), &file.join("run"), &[]);
    assert!(!ok && stderr.contains("creating output directory"), "{stderr}");
    // An existing directory with someone else's files.
    let busy = tmp.path().join("busy");
    std::fs::create_dir(&busy).unwrap();
    std::fs::write(busy.join("thesis.pdf"), "pdf").unwrap();
    let (ok, _, stderr) = sweep(Path::new(QUICK), &busy, &[]);
    assert!(!ok && stderr.contains("not a cablemap sweep directory") && stderr.contains("thesis.pdf"), "{stderr}");
    assert_eq!(std::fs::read_dir(&busy).unwrap().count(), 1);
    // Status of a directory without a sweep.
    let (ok, _, stderr) = run(&["status", busy.to_str().unwrap()]);
    assert!(!ok && stderr.contains("holds no sweep"), "{stderr}");
}

#[test]
fn bad_specs_are_rejected_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        ("[grid]\nlevels = 9\nspacing = 2\n", "unknown field `spacing`"),
        ("[grid]\nextent_r = 1.0\n", "beyond ±r"),
        ("[tension]\nmin_n = -0.5\n", "min_n = -0.5"),
        ("[tension]\ncount = 0\n", "count = 0"),
        ("[actuator]\nradius_mm = 0.0\n", "radius_mm"),
        ("[solver]\nsteps_per_span = 3\n", "steps_per_span"),
        ("[grid\nlevels = 3\n", "TOML"),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let spec = write_spec(tmp.path(), &format!("bad{i}.toml"), text);
        let dir = tmp.path().join(format!("out{i}"));
        let (ok, _, stderr) = sweep(&spec, &dir, &[]);
        assert!(!ok, "{text} accepted");
        assert!(stderr.contains(needle) && stderr.contains(&format!("bad{i}.toml")), "{text}: {stderr}");
        assert!(!dir.exists(), "{text}: output created for a bad spec");
    }
    let (ok, _, stderr) = sweep(&tmp.path().join("missing.toml"), &tmp.path().join("o"), &[]);
    assert!(!ok && stderr.contains("missing.toml"), "{stderr}");
}

#[test]
fn failed_solves_keep_their_inputs_and_have_null_outputs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let spec = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/python/failures.toml");
    let (ok, stdout, stderr) = sweep(Path::new(spec), &dir, &[]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("shooting_not_converged"), "{stdout}");
    let run = open_run(&dir, Completeness::Complete).unwrap();
    let counts = run.status_counts();
    let failed = counts.get("shooting_not_converged").copied().unwrap_or(0);
    assert!(failed > 0 && counts.get("ok").copied().unwrap_or(0) > 0, "{counts:?}");
    let mut seen_failed = 0;
    for batch in run.batches() {
        let batch = batch.unwrap();
        let status = batch.column_by_name("status").unwrap().as_string::<i32>();
        let iterations = batch.column_by_name("iterations").unwrap().as_primitive::<Int32Type>();
        assert_eq!(iterations.null_count(), 0);
        for r in 0..batch.num_rows() {
            let ok = status.value(r) == "ok";
            for name in ["tip_x_mm", "tip_y_mm", "tip_angle_rad", "base_angle_rad", "length_mm", "a0", "a3", "centreline_x_mm"] {
                assert_eq!(batch.column_by_name(name).unwrap().is_null(r), !ok, "{name} row {r} ({})", status.value(r));
            }
            for name in ["routing_id", "y0_mm", "y4_mm", "tension_n"] {
                assert!(!batch.column_by_name(name).unwrap().is_null(r));
            }
            if ok {
                assert!(iterations.value(r) >= 1);
            } else {
                assert_eq!(iterations.value(r), 0);
                seen_failed += 1;
            }
        }
    }
    assert_eq!(seen_failed, failed);
    let (ok, status, _) = run_cmd_status(&dir);
    assert!(ok && status.contains(&format!("shooting_not_converged {failed}")), "{status}");
}

fn run_cmd_status(dir: &Path) -> (bool, String, String) {
    run(&["status", dir.to_str().unwrap()])
}

/// The contract between the stages: the reducer reads a sweep through
/// `open_run` (mirror de-duplication undone there: 2·122 − 1 routings).
#[test]
fn the_reducer_reads_a_sweep_through_open_run() {
    use cablemap::reduce::{reduce_run, ReduceOptions};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir, &[]).0);
    let (map, grid, solver) = reduce_run(&dir, false, &ReduceOptions::default()).unwrap();
    let run = open_run(&dir, Completeness::Complete).unwrap();
    assert_eq!((Some(&grid), &solver), (run.spec().planar(), &run.spec().solver));
    assert_eq!(map.summary.rows_total, (2 * 122 - 1) * 5);
    assert_eq!(map.summary.rows_converged, map.summary.rows_total);
}

/// Ctrl-C (SIGINT) says what is kept and how to resume, ends like the
/// signal (exit 130), and the resume completes the run.
#[cfg(unix)]
#[test]
fn an_interrupted_sweep_says_how_to_resume() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), "kill.toml", KILL_SPEC);
    let dir = tmp.path().join("run");
    let mut child = cablemap()
        .args(["sweep", spec.to_str().unwrap(), "--out", dir.to_str().unwrap(), "--threads", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // After the first committed chunk (not after a time).
    let deadline = Instant::now() + Duration::from_secs(300);
    while committed_chunks(&dir) == 0 && Instant::now() < deadline && child.try_wait().unwrap().is_none() {
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted: every chunk already written is kept; resume with the same command:"), "{stderr}");
    assert!(stderr.contains(&format!("sweep {} --out {}", spec.display(), dir.display())), "{stderr}");
    let (ok, stdout, stderr) = sweep(&spec, &dir, &[]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("complete") && !stdout.contains(" 0 already done"), "{stdout}");
}
