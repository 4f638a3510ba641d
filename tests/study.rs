//! `cablemap study`, `map` on a study spec and `feasible --study`, as a user
//! runs them: every variant's map is the map of its spec run alone.

use std::path::Path;
use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cablemap"));
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "SLURM_CPUS_PER_TASK"] {
        c.env_remove(v);
    }
    let out = c.args(args).output().expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// jobs/quick.toml's grid and tensions.
const QUICK_BASE: &str = "[grid]\nlevels = 3\nextent_r = 0.8\nmirror_dedup = true\n\
    [tension]\nmin_n = 1.0\nmax_n = 2.0\ncount = 5\n[output]\norder = 3\nchunk_routings = 16\n";

/// 2 × 2 variants: L ∈ {55, 75} mm × EI ∈ {92, 144} N·mm².
fn study_toml() -> String {
    format!(
        "{QUICK_BASE}[study]\nname = \"two by two\"\n[[study.axis]]\nname = \"length_mm\"\nvalues = [55.0, 75.0]\n\
         [[study.axis]]\nname = \"ei_n_mm2\"\nvalues = [92.0, 144.0]\n"
    )
}

/// A map's tables, byte for byte (summary.json without its run_dir).
fn tables(map: &Path) -> Vec<Vec<u8>> {
    let mut out: Vec<Vec<u8>> = ["cells.parquet", "modes.parquet", "designs.parquet"]
        .iter()
        .map(|f| std::fs::read(map.join(f)).unwrap())
        .collect();
    let mut summary: serde_json::Value = serde_json::from_slice(&std::fs::read(map.join("summary.json")).unwrap()).unwrap();
    summary.as_object_mut().unwrap().remove("run_dir");
    out.push(summary.to_string().into_bytes());
    out
}

#[test]
fn a_two_by_two_study_maps_each_variant_as_its_spec_alone_and_compares_them() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("study.toml");
    std::fs::write(&spec, study_toml()).unwrap();
    let dir = tmp.path().join("study");
    let (ok, stdout, stderr) = run(&["study", s(&spec), "--out", s(&dir)]);
    assert!(ok, "{stdout}{stderr}");
    assert!(stdout.contains("4 variants"), "{stdout}");
    // Each variant alone, from a spec written by hand (not the study's own copy).
    let variants = [(55.0, 92.0), (55.0, 144.0), (75.0, 92.0), (75.0, 144.0)];
    for (i, (length, ei)) in variants.iter().enumerate() {
        let alone = tmp.path().join(format!("alone{i}.toml"));
        std::fs::write(
            &alone,
            format!("[actuator]\nlength_mm = {length:?}\nei_n_mm2 = {ei:?}\n{QUICK_BASE}"),
        )
        .unwrap();
        let out = tmp.path().join(format!("alone{i}"));
        let (ok, _, stderr) = run(&["map", s(&alone), "--out", s(&out)]);
        assert!(ok, "{stderr}");
        assert_eq!(tables(&dir.join(format!("v{i}/map"))), tables(&out.join("map")), "variant {i}");
        // The study's copy of the variant's spec gives the same run.
        let (ok, stdout, stderr) = run(&["sweep", s(&dir.join(format!("v{i}/spec.toml"))), "--out", s(&out.join("run"))]);
        assert!(
            ok && stdout.contains("0 rows solved and written, 610 already done"),
            "{stdout}{stderr}"
        );
    }
    // The comparison: one row per variant, and the page shows every map.
    let csv = std::fs::read_to_string(dir.join("comparison.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    assert!(
        csv.lines().nth(2).unwrap().starts_with("1,\"length_mm=55, ei_n_mm2=144\","),
        "{csv}"
    );
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("comparison.json")).unwrap()).unwrap();
    for (i, row) in json["variants"].as_array().unwrap().iter().enumerate() {
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join(format!("v{i}/map/summary.json"))).unwrap()).unwrap();
        let cells = summary["cells"].as_f64().unwrap();
        assert_eq!(
            row["reach_area_mm2"].as_f64().unwrap(),
            cells * summary["cell_mm"].as_f64().unwrap().powi(2)
        );
        let modes: f64 = row["mode_area_mm2"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).sum();
        assert!(
            modes >= row["reach_area_mm2"].as_f64().unwrap(),
            "every cell holds at least one mode"
        );
        assert!(row["a0_range"][0].as_f64().unwrap() < row["a0_range"][1].as_f64().unwrap());
    }
    // A stiffer rod of the same length reaches less.
    let reach = |i: usize| json["variants"][i]["reach_area_mm2"].as_f64().unwrap();
    assert!(reach(1) < reach(0) && reach(3) < reach(2), "{json}");
    let page = std::fs::read_to_string(dir.join("index.html")).unwrap();
    for i in 0..4 {
        assert!(
            page.contains(&format!("v{i}/map/reach.png")) && page.contains(&format!("v{i}/map/modes.png")),
            "v{i}"
        );
    }
    // Which variants reach a target.
    let (ok, stdout, stderr) = run(&["feasible", "--study", s(&dir), "--target", "x=50,y=5", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(v["variants"].as_array().unwrap().len(), 4);
    for row in v["variants"].as_array().unwrap() {
        let i = row["variant"].as_u64().unwrap();
        let (ok, alone, _) = run(&[
            "feasible",
            "--map",
            s(&dir.join(format!("v{i}/map"))),
            "--target",
            "x=50,y=5",
            "--json",
        ]);
        assert!(ok);
        let alone: serde_json::Value = serde_json::from_str(alone.trim()).unwrap();
        assert_eq!(row["report"], alone, "variant {i}");
        let listed = v["feasible_variants"]
            .as_array()
            .unwrap()
            .contains(&serde_json::json!(format!("v{i}")));
        assert_eq!(listed, alone["verdict"] == "feasible", "variant {i}");
    }
    let (ok, stdout, _) = run(&["feasible", "--study", s(&dir), "--target", "x=50,y=5"]);
    assert!(
        ok && (stdout.contains("reach the target") || stdout.contains("no variant reaches")),
        "{stdout}"
    );
}

#[test]
fn a_study_split_into_tasks_then_compared_equals_the_study_in_one_go() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("study.toml");
    std::fs::write(&spec, study_toml()).unwrap();
    let whole = tmp.path().join("whole");
    let (ok, _, stderr) = run(&["map", s(&spec), "--out", s(&whole)]);
    assert!(ok, "`map` on a study spec runs the study: {stderr}");
    let split = tmp.path().join("split");
    let (ok, stdout, stderr) = run(&["study", s(&spec), "--out", s(&split), "--shard", "0", "--shards", "3"]);
    assert!(ok && stdout.contains("this task runs 2"), "{stdout}{stderr}");
    // Comparing before every task is done names the variants left.
    let (ok, _, stderr) = run(&["study", s(&spec), "--out", s(&split), "--compare"]);
    assert!(!ok && stderr.contains("2 of 4 variants not mapped yet (variant 1, 2)"), "{stderr}");
    for i in ["1", "2"] {
        let (ok, _, stderr) = run(&["study", s(&spec), "--out", s(&split), "--shard", i, "--shards", "3"]);
        assert!(ok, "{stderr}");
    }
    let (ok, _, stderr) = run(&["study", s(&spec), "--out", s(&split), "--compare"]);
    assert!(ok, "{stderr}");
    for i in 0..4 {
        assert_eq!(
            tables(&split.join(format!("v{i}/map"))),
            tables(&whole.join(format!("v{i}/map"))),
            "variant {i}"
        );
    }
    let strip = |p: &Path| std::fs::read_to_string(p.join("comparison.csv")).unwrap();
    assert_eq!(strip(&split), strip(&whole));
    // Run again: resumable, nothing solved anew.
    let (ok, stdout, stderr) = run(&["study", s(&spec), "--out", s(&whole)]);
    assert!(ok && stdout.contains("0 rows solved (610 already done)"), "{stdout}{stderr}");
    // With --json, stdout is the comparison alone.
    let (ok, stdout, stderr) = run(&["study", s(&spec), "--out", s(&whole), "--json"]);
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}{stderr}"));
    assert!(ok && v["variants"].as_array().unwrap().len() == 4 && stderr.contains("v3 "), "{stdout}{stderr}");
    // Another study in the same directory is refused.
    std::fs::write(&spec, study_toml().replace("[55.0, 75.0]", "[60.0, 75.0]")).unwrap();
    let (ok, _, stderr) = run(&["study", s(&spec), "--out", s(&whole)]);
    assert!(!ok && stderr.contains("holds another study"), "{stderr}");
    // A bad axis is named.
    std::fs::write(&spec, study_toml().replace("\"ei_n_mm2\"", "\"stiffness\"")).unwrap();
    let (ok, _, stderr) = run(&["study", s(&spec), "--out", s(&tmp.path().join("x"))]);
    assert!(!ok && stderr.contains("unknown axis 'stiffness'"), "{stderr}");
}
