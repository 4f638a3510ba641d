//! Cable sweeps as a user runs them (`cablemap map`/`sweep`/`status`/`reduce`
//! with a spec of `[[cable]]` tables): rows with one tension column per cable
//! and the 3-D tip, reach maps on the three coordinate planes and in 3-D,
//! rejected routings, agreement with `simulate --cable`, and the sweep
//! engine's guarantees (kill and resume, shards, status) on cable runs.

mod process;

use arrow::array::{Array, Float64Array, Int64Array, StringArray};
use arrow::record_batch::RecordBatch;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use cablemap::sweep::SweepSpec;
use cablemap::sweep::{open_run, Completeness};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

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

/// Every row of a cable run (through the library's reader), in order.
fn rows_of(run: &Path) -> RecordBatch {
    let run = open_run(run, Completeness::Complete).unwrap();
    let batches: Vec<RecordBatch> = run.batches().map(|b| b.unwrap()).collect();
    arrow::compute::concat_batches(&run.schema(), &batches).unwrap()
}

/// The run's chunk files, by name.
fn chunks(run: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(run.join("shards"))
        .map(|d| {
            d.map(|e| e.unwrap())
                .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
                .map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap()))
                .collect()
        })
        .unwrap_or_default()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_spatial_pair_map_writes_rows_and_reach_maps() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("pair.toml");
    std::fs::write(&spec, SPEC).unwrap();
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = run(&["map", s(&spec), "--out", s(&out), "--threads", "2"]);
    assert!(ok, "{stderr}");
    // 2 × 3 routings (cable 2 with y0 = 2 is still inside and apart), 3 × 2 tension pairs.
    assert!(stdout.contains("36 rows of 2 cable(s) (36 solved"), "{stdout}");
    let rows = rows_of(&out.join("run"));
    assert_eq!(rows.num_rows(), 6 * 6);
    for name in ["tension1_n", "tension2_n", "tip_x_mm", "tip_y_mm", "tip_z_mm", "tip_tangent_z", "a0", "a2", "a_bend_y2", "a_twist0", "cable2_y0_mm", "cable1_z4_mm"] {
        assert!(rows.column_by_name(name).is_some(), "{name}");
    }
    assert!(rows.column_by_name("a3").is_none(), "order 2 stores a0…a2");
    let status = rows.column_by_name("status").unwrap().as_any().downcast_ref::<StringArray>().unwrap();
    let ok_rows = (0..rows.num_rows()).filter(|&i| status.value(i) == "ok").count();
    assert_eq!(ok_rows, 36);
    // Rows in (routing, tension grid) order: cable 1's tension slowest.
    let ids = rows.column_by_name("routing_id").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
    let t1 = f64s(&rows, "tension1_n");
    let t2 = f64s(&rows, "tension2_n");
    for i in 1..rows.num_rows() {
        let key = |i: usize| (ids.value(i), t1[i].unwrap(), t2[i].unwrap());
        assert!(key(i - 1) < key(i), "rows {} and {i} out of order", i - 1);
    }
    // Every solved tip is counted once in each map.
    for file in ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"] {
        let m = read(&out.join("map").join(file));
        let counts = m.column_by_name("count").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
        assert_eq!(counts.iter().map(|c| c.unwrap()).sum::<i64>(), 36, "{file}");
    }
    let png = image::open(out.join("map/reach.png")).unwrap();
    assert!(png.width() > 1000 && png.height() > 500);
    let m = read(&out.join("map/reach_3d.parquet"));
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
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("map/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rows"], 36);
    assert_eq!(summary["kind"], "cables");
    assert_eq!(summary["planar"], false);
    assert_eq!(summary["cell_mm"], 2.0, "the spec's output.cell_mm");
    assert!(!out.join("map/planar").exists(), "a spatial run has no planar maps");
    let (ok, _, stderr) = run(&["feasible", "--map", s(&out.join("map")), "--target", "x=50,y=5,a0=-0.02,a1=0"]);
    assert!(!ok && stderr.contains("spatial cable sweep") && stderr.contains("no feasibility map"), "{stderr}");
    // The same command again resumes: nothing is solved twice, the map is replaced.
    let before = chunks(&out.join("run"));
    let (ok, stdout, stderr) = run(&["map", s(&spec), "--out", s(&out)]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("0 rows solved and written, 36 already done"), "{stdout}");
    assert_eq!(chunks(&out.join("run")), before);
    // --cell-mm overrides the spec's cell size.
    let (ok, _, stderr) = run(&["reduce", s(&out.join("run")), "--out", s(&out.join("map")), "--cell-mm", "0.5"]);
    assert!(ok, "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("map/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["cell_mm"], 0.5);
}

#[test]
fn rejected_routings_are_rows_with_a_status_and_a_planar_run_gets_the_planar_map() {
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
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = run(&["map", s(&spec), "--out", s(&out)]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("2 of rejected routings"), "{stdout}");
    let rows = rows_of(&out.join("run"));
    let status = rows.column_by_name("status").unwrap().as_any().downcast_ref::<StringArray>().unwrap();
    let statuses: Vec<&str> = (0..rows.num_rows()).map(|i| status.value(i)).collect();
    assert_eq!(statuses, ["ok", "ok", "invalid_routing", "invalid_routing"]);
    assert_eq!(f64s(&rows, "tip_x_mm")[2], None);
    // A planar run: tips on the x–y plane, and the planar sweep's map.
    assert!(f64s(&rows, "tip_z_mm")[0].unwrap().abs() < 1e-12);
    let planar = out.join("map/planar");
    let cells = read(&planar.join("cells.parquet"));
    let counts = cells.column_by_name("count").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
    assert_eq!(counts.iter().map(|c| c.unwrap()).sum::<i64>(), 2, "the two solved rows");
    let designs = read(&planar.join("designs.parquet"));
    let ids = designs.column_by_name("routing_id").unwrap().as_any().downcast_ref::<Int64Array>().unwrap();
    let tips = f64s(&rows, "tip_x_mm");
    for (k, id) in ids.iter().enumerate() {
        // routing_id there is the row key: routing × combinations + combination,
        // the row number of a complete run.
        assert_eq!(f64s(&designs, "tip_x_mm")[k], tips[id.unwrap() as usize]);
    }
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(planar.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rows_converged"], 2);
    // The pictures and the explorer page, as for a planar sweep.
    for file in ["reach.png", "modes.png", "a0_p10.png", "a1_gap.png", "index.html", "explorer-data.js"] {
        assert!(planar.join(file).is_file(), "{file}");
    }
    let data = std::fs::read_to_string(planar.join("explorer-data.js")).unwrap();
    assert!(!data.contains("Not drawn"), "every mode representative is drawn");
    // `feasible` reads the planar map, and points there from the cable map.
    let (ok, _, stderr) = run(&["feasible", "--map", s(&out.join("map")), "--target", "x=50,y=5,a0=-0.02,a1=0"]);
    assert!(!ok && stderr.contains("map of a cable sweep") && stderr.contains("planar"), "{stderr}");
    let (ok, _, stderr) = run(&["feasible", "--map", s(&planar), "--target", "x=50,y=5,a0=-0.02,a1=0"]);
    assert!(ok, "{stderr}");
}

#[test]
fn planar_pair_mode_pictures_are_drawn_from_a_solve_of_all_cables() {
    // Two opposed cables whose tensions decide the bending direction. Each
    // representative is solved again from zero with both cables; the reducer
    // refuses (and names, "Not drawn") a drawing whose tip is more than 1 µm
    // from the row's stored tip, so none may be missing.
    let dir = tempfile::tempdir().unwrap();
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs/antagonistic-pair.toml");
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = run(&["map", s(&spec), "--out", s(&out), "--threads", "2"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("planar run: feasibility map"), "{stdout}");
    let data = std::fs::read_to_string(out.join("map/planar/explorer-data.js")).unwrap();
    assert!(!data.contains("Not drawn"), "every representative's solve from zero reaches its row's tip");
    assert_eq!(data.matches("\"further_cables\":[[[").count(), 12, "each mode's drawing has cable 2's path too");
    let png = image::open(out.join("map/planar/modes.png")).unwrap();
    assert!(png.width() > 1000);
}

/// The words of a command line as a POSIX shell splits it (the commands
/// cablemap prints quote with double quotes only).
fn shell_words(line: &str) -> Vec<String> {
    assert!(!line.contains(['\'', '\\', '$', '`']), "{line}");
    let (mut words, mut word, mut quoted, mut started) = (Vec::new(), String::new(), false, false);
    for ch in line.chars() {
        match ch {
            '"' => (quoted, started) = (!quoted, true),
            c if c.is_whitespace() && !quoted => {
                if started {
                    words.push(std::mem::take(&mut word));
                }
                started = false;
            }
            c => (word, started) = (word + &c.to_string(), true),
        }
    }
    assert!(!quoted, "unbalanced quotes: {line}");
    if started {
        words.push(word);
    }
    words
}

/// Runs a printed `cablemap simulate …` command with `--json`: its tip (x, y), mm.
fn tip_of_command(command: &str) -> (f64, f64) {
    let words = shell_words(command);
    assert_eq!(words[..2], ["cablemap", "simulate"], "{command}");
    let mut args: Vec<&str> = words[1..].iter().map(String::as_str).collect();
    args.push("--json");
    let (ok, stdout, stderr) = run(&args);
    assert!(ok, "{command}: {stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    (v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap())
}

#[test]
fn a_shown_design_of_a_two_cable_map_pasted_gives_the_maps_tip() {
    // An antagonistic pair on a rod other than the thesis's, cable 2 knotted
    // short of the tip: the commands must carry the rod and every cable.
    let spec_text = r#"
[rod]
ei_n_mm2 = 100.5
[rod.gravity]
scale = 1.5
[[cable]]
y_mm = [3, 3, 3, 3, 3]
tension_n = { min = 0.0, max = 2.0, count = 5 }
[[cable.sweep]]
axis = "y"
points = [2]
levels_mm = [1.0, 4.0]
[[cable]]
y_mm = [-3, -3, -3, -3, -3]
anchor_mm = 50
tension_n = { min = 0.0, max = 2.0, count = 5 }
"#;
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("pair.toml");
    std::fs::write(&spec, spec_text).unwrap();
    let out = dir.path().join("out");
    let (ok, _, stderr) = run(&["map", s(&spec), "--out", s(&out)]);
    assert!(ok, "{stderr}");
    let planar = out.join("map/planar");
    let designs = read(&planar.join("designs.parquet"));
    let (xs, ys) = (f64s(&designs, "tip_x_mm"), f64s(&designs, "tip_y_mm"));
    // The explorer: its header names both cables, each row shows both and a command.
    let script = std::fs::read_to_string(planar.join("explorer-data.js")).unwrap();
    let json = script.split_once("window.CABLEMAP_MAP = ").unwrap().1.trim_end().trim_end_matches(';');
    let data: serde_json::Value = serde_json::from_str(json).unwrap();
    assert_eq!(data["cables"]["count"], 2, "the page's header says the actuator has two cables");
    assert!(data["cables"]["describe"][1].as_str().unwrap().contains("knotted at s = 50 mm"), "{}", data["cables"]);
    let commands = data["designs"]["command"].as_array().expect("every design has its command");
    assert_eq!(commands.len(), designs.num_rows());
    let mut moved = 0;
    for (k, command) in commands.iter().enumerate().step_by(3) {
        let command = command.as_str().unwrap();
        assert!(command.contains("--ei-n-mm2 100.5") && command.contains("--gravity-scale 1.5"), "{command}");
        assert_eq!(command.matches("--cable ").count(), 2, "{command}");
        assert_eq!(data["designs"]["cables"][k].as_array().unwrap().len(), 2);
        let (x, y) = tip_of_command(command);
        let gap = (x - xs[k].unwrap()).hypot(y - ys[k].unwrap());
        assert!(gap < 1e-3, "design {k}: `{command}` ends at ({x}, {y}) mm, {gap} mm from the map's tip");
        moved += usize::from(data["designs"]["cables"][k][1]["tension_n"].as_f64().unwrap() > 0.0);
    }
    assert!(moved > 0, "some checked design pulls cable 2 too");
    // The modes' representatives (modes.png's captions, the page's panels) carry every cable too.
    for m in data["modes"].as_array().unwrap().iter().filter(|m| !m["rep"].is_null()) {
        assert_eq!(m["rep"]["cables"].as_array().unwrap().len(), 2, "{}", m["rep"]["command"]);
    }
    // `feasible`: each nearest design is listed with both cables and the command that solves it.
    let target = format!("x={},y={}", xs[0].unwrap(), ys[0].unwrap());
    let (ok, text, stderr) = run(&["feasible", "--map", s(&planar), "--target", &target, "--nearest", "4"]);
    assert!(ok, "{stderr}");
    let (ok, json, stderr) = run(&["feasible", "--map", s(&planar), "--target", &target, "--nearest", "4", "--json"]);
    assert!(ok, "{stderr}");
    let nearest: serde_json::Value = serde_json::from_str(&json).unwrap();
    let shown: Vec<&str> = text.lines().filter_map(|l| l.trim_start().strip_prefix("cablemap simulate").map(|_| l.trim())).collect();
    assert_eq!(shown.len(), 4, "{text}");
    assert_eq!(text.matches("cable 2 y = [").count(), 4, "{text}");
    for (command, near) in shown.iter().zip(nearest["nearest"].as_array().unwrap()) {
        let (x, y) = tip_of_command(command);
        let gap = (x - near["tip_x_mm"].as_f64().unwrap()).hypot(y - near["tip_y_mm"].as_f64().unwrap());
        assert!(gap < 1e-3, "`{command}` ends {gap} mm from the map's tip");
    }
}

/// The antagonistic pair's map (jobs/antagonistic-pair.toml): `feasible
/// --json` gives each nearest design with every cable (as an actuator file
/// writes them) and the command the text shows, which solves it again to the
/// map's tip; `design --map` refuses the map, whose designs are of a
/// two-cable actuator, instead of seeding a one-cable search with cable 1.
#[test]
fn a_two_cable_maps_nearest_designs_carry_every_cable_and_design_refuses_the_map() {
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs/antagonistic-pair.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pair");
    let (ok, _, stderr) = run(&["map", s(&spec), "--out", s(&out)]);
    assert!(ok, "{stderr}");
    let planar = out.join("map/planar");
    let target = "x=58,y=5";
    let (ok, text, stderr) = run(&["feasible", "--map", s(&planar), "--target", target, "--nearest", "3"]);
    assert!(ok, "{stderr}");
    let (ok, json, stderr) = run(&["feasible", "--map", s(&planar), "--target", target, "--nearest", "3", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let nearest = v["nearest"].as_array().unwrap();
    assert_eq!(nearest.len(), 3, "{v}");
    let shown: Vec<&str> = text.lines().map(str::trim).filter(|l| l.starts_with("cablemap simulate")).collect();
    let mut pulled_both = 0;
    for (near, shown) in nearest.iter().zip(&shown) {
        let cables = near["cables"].as_array().unwrap_or_else(|| panic!("no cables in {near}"));
        assert_eq!(cables.len(), 2, "{near}");
        // Cable 1 is the design's routing and tension; cable 2 is there too.
        assert_eq!(cables[0]["y_mm"], near["routing_mm"], "{near}");
        assert_eq!(cables[0]["tension_n"], near["tension_n"], "{near}");
        assert_eq!(cables[1]["y_mm"][0], -3.0, "{near}");
        pulled_both += usize::from(cables[1]["tension_n"].as_f64().unwrap() > 0.0);
        let command = near["command"].as_str().unwrap();
        assert_eq!(command, *shown, "the JSON's command is the one the text shows");
        for cable in cables {
            let y: Vec<String> = cable["y_mm"].as_array().unwrap().iter().map(|y| y.as_f64().unwrap().to_string()).collect();
            let tension = cable["tension_n"].as_f64().unwrap();
            assert!(command.contains(&format!("y={} tension={tension}", y.join(","))), "{command} lacks {cable}");
        }
        let (x, y) = tip_of_command(command);
        let gap = (x - near["tip_x_mm"].as_f64().unwrap()).hypot(y - near["tip_y_mm"].as_f64().unwrap());
        assert!(gap < 1e-3, "`{command}` ends {gap} mm from the map's tip");
    }
    assert!(pulled_both > 0, "some nearest design pulls both cables: {v}");
    let (ok, _, stderr) = run(&["design", "--target", target, "--map", s(&planar), "--json"]);
    assert!(!ok, "design --map on a two-cable map must be refused");
    assert!(stderr.contains("an actuator of 2 cables") && stderr.contains("cablemap feasible --map"), "{stderr}");
}

/// A cable spec of many small chunks, slow enough that kills land mid-run.
const KILL_SPEC: &str = r#"
gravity_direction = [1, 0, 0]
[output]
chunk_routings = 2
[[cable]]
y_mm = [2, 2, 2, 2, 2]
tension_n = { min = 0.0, max = 1.5, count = 6 }
[[cable.sweep]]
axis = "z"
points = [1, 2, 3]
levels_mm = [-1.0, 0.0, 1.0, 2.0]
[[cable]]
y_mm = [-2, -2, -2, -2, -2]
tension_n = { min = 0.0, max = 1.5, count = 6 }
[[cable.sweep]]
axis = "y"
points = [2]
levels_mm = [-3.0, -2.0, -1.0]
"#;

#[test]
fn a_killed_cable_sweep_resumes_to_the_uninterrupted_rows() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("kill.toml");
    std::fs::write(&spec, KILL_SPEC).unwrap();
    let reference = dir.path().join("reference");
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&reference), "--quiet"]);
    assert!(ok, "{stderr}");
    let want = chunks(&reference);
    // 4³ × 3 = 192 routings in chunks of 2.
    assert_eq!(want.len(), 96);
    let killed = dir.path().join("killed");
    let mut interrupted = 0;
    for round in 0..3u64 {
        let mut child = process::cablemap()
            .args(["sweep", s(&spec), "--out", s(&killed), "--quiet", "--threads", "1"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Killed after 1–3 more committed chunks (counted, not timed).
        let before = chunks(&killed).len();
        let ready = |d: &Path| d.join("manifest.json").exists() && chunks(d).len() > before + round as usize;
        let deadline = Instant::now() + Duration::from_secs(300);
        while !ready(&killed) && Instant::now() < deadline && child.try_wait().unwrap().is_none() {
            std::thread::sleep(Duration::from_micros(200));
        }
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
        let partial = chunks(&killed);
        // Whatever the moment, every chunk present equals the reference's.
        for (name, bytes) in &partial {
            assert_eq!(Some(bytes), want.get(name), "{name} differs after a kill in round {round}");
        }
        if partial.len() < want.len() {
            interrupted += 1;
        }
    }
    assert!(interrupted > 0, "no kill landed mid-run");
    // Status names the partial run.
    let (ok, stdout, stderr) = run(&["status", s(&killed), "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(v["format"], "cablemap-cables/1");
    assert_eq!(v["rows_total"], 192 * 36);
    assert_eq!(v["complete"], false);
    // A partial run is refused by reduce unless asked for.
    let (ok, _, stderr) = run(&["reduce", s(&killed), "--out", s(&dir.path().join("m"))]);
    assert!(!ok && stderr.contains("incomplete"), "{stderr}");
    let (ok, _, stderr) = run(&["reduce", s(&killed), "--out", s(&dir.path().join("m")), "--partial"]);
    assert!(ok, "{stderr}");
    // Resume finishes with the same bytes as the uninterrupted run.
    let (ok, stdout, stderr) = run(&["sweep", s(&spec), "--out", s(&killed), "--quiet"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("already done"), "{stdout}");
    assert_eq!(chunks(&killed), want);
}

#[test]
fn two_shards_then_reduce_equal_one_shard_and_status_reports_progress() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("pair.toml");
    std::fs::write(&spec, SPEC.replace("[output]", "[output]\nchunk_routings = 1")).unwrap();
    let one = dir.path().join("one");
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&one), "--quiet"]);
    assert!(ok, "{stderr}");
    let two = dir.path().join("two");
    let (ok, stdout, stderr) = run(&["sweep", s(&spec), "--out", s(&two), "--shard", "0", "--shards", "2", "--quiet"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("partial (other shards not done yet)"), "{stdout}");
    // Status after one shard: its chunks done, the other shard's not.
    let (ok, text, stderr) = run(&["status", s(&two)]);
    assert!(ok, "{stderr}");
    assert!(text.contains("kind       cable sweep (cablemap-cables/1)") && text.contains("6 routings x 6 tension combinations = 36 rows"), "{text}");
    assert!(text.contains("state      partial: 18/36 rows"), "{text}");
    let (_, json, _) = run(&["status", s(&two), "--json"]);
    let v: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    assert_eq!(v["shards"][0]["rows_done"], 18);
    assert_eq!(v["shards"][1]["rows_done"], 0);
    // A different shard count for the same directory is refused.
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&two), "--shard", "0", "--shards", "3"]);
    assert!(!ok && stderr.contains("--shards 2"), "{stderr}");
    // Shard 1 from the SLURM array index, as on a cluster.
    let out = process::cablemap()
        .args(["sweep", s(&spec), "--out", s(&two), "--shards", "2", "--quiet"])
        .env("SLURM_ARRAY_TASK_ID", "1")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(chunks(&two), chunks(&one), "the same chunk files, whatever the sharding");
    for run_dir in [&one, &two] {
        let map = run_dir.with_extension("map");
        let (ok, _, stderr) = run(&["reduce", s(run_dir), "--out", s(&map)]);
        assert!(ok, "{stderr}");
    }
    // The planar reduce's parts (--shard/--shards/--merge) are not for cable runs.
    let (ok, _, stderr) = run(&["reduce", s(&two), "--out", s(&dir.path().join("m")), "--shard", "0", "--shards", "2"]);
    assert!(!ok && stderr.contains("cable sweep") && stderr.contains("--shards"), "{stderr}");
    for file in ["reach_xy.parquet", "reach_xz.parquet", "reach_yz.parquet", "reach_3d.parquet"] {
        assert_eq!(std::fs::read(one.with_extension("map").join(file)).unwrap(), std::fs::read(two.with_extension("map").join(file)).unwrap(), "{file}");
    }
}

#[test]
fn runs_of_the_other_kind_and_bad_specs_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("bad.toml");
    std::fs::write(&spec, SPEC.replace("points = [4]", "points = [9]")).unwrap();
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&dir.path().join("o"))]);
    assert!(!ok && stderr.contains("bad.toml") && stderr.contains("control point 9"), "{stderr}");
    let (ok, _, stderr) = run(&["map", "/nonexistent.toml", "--out", s(&dir.path().join("o"))]);
    assert!(!ok && stderr.contains("/nonexistent.toml"), "{stderr}");
    std::fs::write(&spec, SPEC.replace("[output]", "[output]\nchunk_routings = 0")).unwrap();
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&dir.path().join("o"))]);
    assert!(!ok && stderr.contains("chunk_routings = 0"), "{stderr}");
    // A rod the 3-D solver asked for does not model is refused up front, not
    // solved into rows that are all invalid (the RK4 reference models the
    // uniform rod only; the default collocation models this one).
    std::fs::write(&spec, format!("{SPEC}\n[rod]\nradius_profile_mm = [[0, 5], [65, 4.5]]\n[solver]\nmethod = \"rk4\"\n")).unwrap();
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&dir.path().join("o"))]);
    assert!(!ok && stderr.contains("[rod]") && stderr.contains("uniform rod"), "{stderr}");
    // A cable spec into a planar run directory, and the other way round.
    let planar = dir.path().join("planar");
    let planar_spec = dir.path().join("planar.toml");
    std::fs::write(&planar_spec, "[grid]\nlevels = 2\n[tension]\ncount = 2\n").unwrap();
    assert!(run(&["sweep", s(&planar_spec), "--out", s(&planar), "--quiet"]).0);
    std::fs::write(&spec, SPEC).unwrap();
    let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&planar)]);
    assert!(!ok && stderr.contains("cablemap-sweep/2") && stderr.contains("another kind"), "{stderr}");
    let cables = dir.path().join("cables");
    assert!(run(&["sweep", s(&spec), "--out", s(&cables), "--quiet"]).0);
    let (ok, _, stderr) = run(&["sweep", s(&planar_spec), "--out", s(&cables)]);
    assert!(!ok && stderr.contains("cablemap-cables/1"), "{stderr}");
    // The library's reader opens a run of either kind; the planar map's
    // reader names the kind of a cable run.
    let run = cablemap::sweep::open_run(&cables, Completeness::Complete).unwrap();
    assert_eq!(run.spec().kind(), cablemap::sweep::RunKind::Cables);
    let e = cablemap::reduce::reduce_run(&cables, false, &Default::default()).unwrap_err().to_string();
    assert!(e.contains("cablemap-cables/1") && e.contains("another kind"), "{e}");
}

#[test]
fn the_shipped_job_specs_are_valid() {
    for name in ["antagonistic-pair.toml", "spatial-pair.toml"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs").join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let job = cablemap::job::Job::load(&path).unwrap();
        assert!(matches!(&job.spec, cablemap::job::JobSpec::Sweep(s) if s.kind() == cablemap::sweep::RunKind::Cables), "{name}");
        let spec = SweepSpec::from_toml(&text, name).unwrap();
        let grid = spec.cables().unwrap();
        assert!(grid.routings() > 1 && grid.actuation_combinations() > 1);
    }
}

/// A cable driven by its displacement in a cable sweep: its rows store the
/// commanded `displacement1_mm` exactly and the tension found; the other
/// cable's rows its commanded tension and the displacement it produced;
/// each row solves again by `simulate --cable "… displacement=D"`; the map's
/// designs carry the displacement as cable 1's command (the explorer's
/// command reproduces the tip). A spec giving both or neither is refused.
#[test]
fn a_displacement_driven_cable_sweeps_and_maps() {
    let spec_text = r#"
[[cable]]
y_mm = [3, 3, 3, 3, 3]
displacement_mm = { min = 0.5, max = 3.0, count = 3 }
cable_ea_n = 5000
[[cable.sweep]]
axis = "y"
points = [2]
levels_mm = [1.0, 4.0]
[[cable]]
y_mm = [-3, -3, -3, -3, -3]
tension_n = { min = 0.0, max = 1.0, count = 2 }
"#;
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("d.toml");
    std::fs::write(&spec, spec_text).unwrap();
    let out = dir.path().join("out");
    let (ok, _, stderr) = run(&["map", s(&spec), "--out", s(&out)]);
    assert!(ok, "{stderr}");
    let rows = rows_of(&out.join("run"));
    assert_eq!(rows.num_rows(), 2 * 3 * 2);
    let (d1, t1, t2, d2) = (f64s(&rows, "displacement1_mm"), f64s(&rows, "tension1_n"), f64s(&rows, "tension2_n"), f64s(&rows, "displacement2_mm"));
    let (x, y) = (f64s(&rows, "tip_x_mm"), f64s(&rows, "tip_y_mm"));
    let y2 = f64s(&rows, "cable1_y2_mm");
    for r in 0..rows.num_rows() {
        assert!([0.5, 1.75, 3.0].contains(&d1[r].unwrap()), "the command exactly: {:?}", d1[r]);
        assert!([0.0, 1.0].contains(&t2[r].unwrap()));
        assert!(t1[r].unwrap() >= 0.0 && d2[r].is_some(), "found and produced: {:?} {:?}", t1[r], d2[r]);
        let cable1 = format!("y=3,3,{},3,3 displacement={} ea=5000", y2[r].unwrap(), d1[r].unwrap());
        let cable2 = format!("y=-3,-3,-3,-3,-3 tension={}", t2[r].unwrap());
        let (ok, json, stderr) = run(&["simulate", "--cable", &cable1, "--cable", &cable2, "--json"]);
        assert!(ok, "{stderr}");
        let v: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
        let gap = (v["tip_x_mm"].as_f64().unwrap() - x[r].unwrap()).hypot(v["tip_y_mm"].as_f64().unwrap() - y[r].unwrap());
        assert!(gap < 1e-6, "row {r}: {gap} mm");
        assert!((v["tension_n"][0].as_f64().unwrap() - t1[r].unwrap()).abs() < 1e-7, "row {r}: {v}");
    }
    // The map: every design's command drives cable 1 by its displacement and reproduces the tip.
    let planar = out.join("map/planar");
    let designs = read(&planar.join("designs.parquet"));
    let (xs, ys) = (f64s(&designs, "tip_x_mm"), f64s(&designs, "tip_y_mm"));
    let script = std::fs::read_to_string(planar.join("explorer-data.js")).unwrap();
    let json = script.split_once("window.CABLEMAP_MAP = ").unwrap().1.trim_end().trim_end_matches(';');
    let data: serde_json::Value = serde_json::from_str(json).unwrap();
    assert!(data["cables"]["describe"][0].as_str().unwrap().contains("displacement 0.5 … 3 mm"), "{}", data["cables"]);
    for (k, command) in data["designs"]["command"].as_array().unwrap().iter().enumerate() {
        let command = command.as_str().unwrap();
        assert!(command.contains("displacement="), "{command}");
        assert!(data["designs"]["cables"][k][0]["displacement_mm"].as_f64().is_some());
        let (x, y) = tip_of_command(command);
        assert!((x - xs[k].unwrap()).hypot(y - ys[k].unwrap()) < 1e-3, "design {k}: `{command}`");
    }
    // Both, or neither, is refused.
    for (text, needle) in [
        ("[[cable]]\ny_mm = [1, 1, 1, 1, 1]\ntension_n = { min = 0.0, max = 1.0, count = 2 }\ndisplacement_mm = { min = 0.0, max = 1.0, count = 2 }\n", "only one"),
        ("[[cable]]\ny_mm = [1, 1, 1, 1, 1]\n", "give one of tension_n"),
    ] {
        std::fs::write(&spec, text).unwrap();
        let (ok, _, stderr) = run(&["sweep", s(&spec), "--out", s(&dir.path().join("bad"))]);
        assert!(!ok && stderr.contains(needle), "{text}: {stderr}");
        assert!(!dir.path().join("bad").exists());
    }
}
