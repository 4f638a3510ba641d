//! `cablemap design` as a user runs it: Table 5.1, recovery of simulated
//! designs, unreachable targets, exports and bad input.

use serde_json::Value;
use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cablemap")).args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn design_json(args: &[&str]) -> Value {
    let mut all = vec!["design", "--json"];
    all.extend_from_slice(args);
    let (ok, stdout, stderr) = run(&all);
    assert!(ok, "design failed: {stderr}");
    serde_json::from_str(stdout.trim()).expect("one JSON object")
}

/// Runs a Table 5.1 target with the default settings (the thesis's basis:
/// a_i per unit rest length) and checks every component's error against the
/// thesis's.
fn check_table_5_1(target: &str, thesis_error_pct: &[(&str, f64)]) -> Value {
    let v = design_json(&["--target", target]);
    assert_eq!(v["length_basis"], "rest", "{v}");
    for (key, thesis) in thesis_error_pct {
        let e = v["error_pct"][key].as_f64().unwrap_or_else(|| panic!("no error_pct.{key} in {v}"));
        assert!(e.abs() <= thesis.abs(), "{key}: error {e:.4}% exceeds the thesis's {thesis}% ({v})");
    }
    let t = v["tension_n"].as_f64().unwrap();
    assert!((1.0..=2.0).contains(&t), "tension {t}");
    assert!(v["routing_mm"].as_array().unwrap().iter().all(|y| y.as_f64().unwrap().abs() < 5.0));
    assert_eq!(v["a"].as_array().unwrap().len(), 3);
    v
}

#[test]
fn table_5_1_target_i() {
    let v = check_table_5_1(
        "x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015",
        &[("x", -0.02), ("y", -0.04), ("a0", 2.40), ("a1", 0.17), ("a2", -12.7)],
    );
    // In the thesis's basis Target I is met exactly (issue #9's evidence).
    for key in ["x", "y", "a0", "a1", "a2"] {
        assert!(v["error_pct"][key].as_f64().unwrap().abs() < 0.01, "{key}: {v}");
    }
    assert_eq!(v["met"], true);
    // The same target read per unit deformed length is out of reach.
    let d = design_json(&["--target", "x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015", "--length-basis", "deformed"]);
    assert_eq!(d["length_basis"], "deformed");
    assert_eq!(d["met"], false, "{d}");
}

#[test]
fn table_5_1_target_ii() {
    // The thesis prints 0.02 % for x (10.02 mm would be 0.2 %): hold the stricter one.
    check_table_5_1(
        "x=10,y=50,a0=0.015,a1=-0.07,a2=-0.03",
        &[("x", 0.02), ("y", -0.12), ("a0", 12.7), ("a1", -1.86), ("a2", 4.33)],
    );
}

/// Simulates a design and returns its (x, y, a0, a1, a2).
fn simulated(routing: &str, tension: &str) -> [f64; 5] {
    let (ok, stdout, stderr) = run(&["simulate", "--routing", routing, "--tension", tension, "--order", "2", "--json"]);
    assert!(ok, "{stderr}");
    let v: Value = serde_json::from_str(stdout.trim()).unwrap();
    let a = v["a"].as_array().unwrap();
    [v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap(), a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()]
}

/// Recovers `(routing, tension)` from its simulated (x, y, a0, a1, a2).
fn assert_recovered(routing: &str, tension: &str) {
    let [x, y, a0, a1, a2] = simulated(routing, tension);
    let target = format!("x={x},y={y},a0={a0},a1={a1},a2={a2}");
    let v = design_json(&["--target", &target]);
    let got = |k: &str| v[k].as_f64().unwrap();
    assert!((got("tip_x_mm") - x).abs() < 1e-3 && (got("tip_y_mm") - y).abs() < 1e-3, "{routing} @ {tension}: {v}");
    for (k, want) in [a0, a1, a2].iter().enumerate() {
        assert!((v["a"][k].as_f64().unwrap() - want).abs() < 1e-5, "{routing} @ {tension}: {v}");
    }
    assert_eq!(v["met"], true);
}

#[test]
fn recovers_simulated_designs_off_the_grid() {
    // Control points and tensions off any sweep grid (levels are multiples of 0.2 r = 1 mm).
    for (routing, tension) in [("1.3,-2.7,3.1,0.4,-1.9", "1.37"), ("-3.3,2.2,-0.7,4.1,3.6", "1.81"), ("4.45,4.45,-0.35,-4.45,2.15", "1.03")] {
        assert_recovered(routing, tension);
    }
}

#[test]
fn recovers_random_designs_including_bound_active_ones() {
    // A fixed pseudo-random sample (LCG), plus designs on the tension bounds
    // and near the body surface, where the bounds transformation is flat.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = |lo: f64, hi: f64| {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    let mut cases: Vec<(String, String)> = (0..3)
        .map(|_| {
            let y: Vec<String> = (0..5).map(|_| format!("{:.3}", uniform(-4.9, 4.9))).collect();
            (y.join(","), format!("{:.3}", uniform(1.0, 2.0)))
        })
        .collect();
    cases.push(("4.95,-4.95,4.95,-4.95,4.95".into(), "2.0".into()));
    cases.push(("-2.5,0.3,4.9,1.1,-4.9".into(), "1.0".into()));
    for (routing, tension) in &cases {
        assert_recovered(routing, tension);
    }
}

#[test]
fn recovers_a_tip_only_target_with_its_default_order() {
    let [x, y, ..] = simulated("2.2,-1.1,3.3,-0.6,1.7", "1.55");
    let v = design_json(&["--target", &format!("x={x},y={y}")]);
    assert!((v["tip_x_mm"].as_f64().unwrap() - x).abs() < 1e-3);
    assert!((v["tip_y_mm"].as_f64().unwrap() - y).abs() < 1e-3);
    assert_eq!(v["a"].as_array().unwrap().len(), 3, "tip-only targets report a_0..a_2");
}

#[test]
fn a_tip_beyond_the_rod_is_reported_unreachable_with_the_closest_design() {
    // The rod is 65 mm long: no tip can be 80 mm from the clamp.
    let v = design_json(&["--target", "x=80,y=0"]);
    assert_eq!(v["met"], false);
    let unmet: Vec<&str> = v["unmet"].as_array().unwrap().iter().map(|s| s.as_str().unwrap()).collect();
    assert!(unmet.contains(&"x"), "{v}");
    // The closest achievable tip is the straightest, least-compressed rod.
    assert!(v["tip_x_mm"].as_f64().unwrap() > 55.0 && v["tip_x_mm"].as_f64().unwrap() < 65.0, "{v}");
    let (ok, stdout, _) = run(&["design", "--target", "x=80,y=0"]);
    assert!(ok);
    assert!(stdout.contains("NOT REACHABLE") && stdout.contains("x_e"), "{stdout}");
}

#[test]
fn text_output_is_a_table_5_1() {
    let (ok, stdout, stderr) = run(&["design", "--target", "x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015"]);
    assert!(ok, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(lines[0].contains("x_e [mm]") && lines[0].contains("a_2 [1/mm]"), "{stdout}");
    assert!(lines[1].starts_with("Target") && lines[2].starts_with("Achieved") && lines[3].starts_with("Error"), "{stdout}");
    assert!(stdout.contains("every component met"), "{stdout}");
    // The routing line pastes into simulate: run it and get the same tip.
    let line = stdout.lines().find(|l| l.starts_with("routing")).unwrap();
    let args: Vec<&str> = line.split_whitespace().skip_while(|w| *w != "--routing").collect();
    let mut sim = vec!["simulate", "--json"];
    sim.extend(&args);
    let (ok, out, err) = run(&sim);
    assert!(ok, "{line}: {err}");
    let v: Value = serde_json::from_str(out.trim()).unwrap();
    assert!((v["tip_x_mm"].as_f64().unwrap() - 50.0).abs() < 0.01 && (v["tip_y_mm"].as_f64().unwrap() - 5.0).abs() < 0.01, "{v}");
}

#[test]
fn exports_json_csv_svg_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("export");
    let (ok, stdout, stderr) = run(&["design", "--target", "x=55,y=20,a0=0.01", "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert_eq!(reported_exports(&stdout, &out), files_in(&out), "{stdout}");
    let json: Value = serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap();
    assert_eq!(json["routing_mm"].as_array().unwrap().len(), 5);
    let csv = std::fs::read_to_string(out.join("channel.csv")).unwrap();
    let mut rows = csv.lines();
    assert_eq!(rows.next(), Some("s_mm,y_mm,dy_ds"));
    let first: Vec<f64> = rows.next().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    let y0 = json["routing_mm"][0].as_f64().unwrap();
    assert!((first[1] - y0).abs() < 1e-5, "the channel starts at y0");
    let svg = std::fs::read_to_string(out.join("mould.svg")).unwrap();
    assert!(svg.contains(r#"width="85mm""#) && svg.contains("id=\"channel\""));
    let png = std::fs::read(out.join("shape.png")).unwrap();
    assert_eq!(&png[..4], b"\x89PNG");
}

/// The files in `dir`, sorted.
fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// The files `design` says it exported to `dir`, sorted.
fn reported_exports(stdout: &str, dir: &std::path::Path) -> Vec<String> {
    let suffix = format!(" to {}", dir.display());
    let line = stdout.lines().find(|l| l.starts_with("exported ")).unwrap_or_else(|| panic!("no exported line: {stdout}"));
    let mut names: Vec<String> =
        line.strip_prefix("exported ").unwrap().strip_suffix(&suffix).expect("names the directory").split(", ").map(String::from).collect();
    names.sort();
    names
}

#[test]
fn the_export_line_lists_exactly_the_files_written() {
    let dir = tempfile::tempdir().unwrap();
    // A tapered body: no mould.svg (its mould drawing is of a uniform cylinder).
    let out = dir.path().join("tapered");
    let (ok, stdout, stderr) =
        run(&["design", "--target", "x=55,y=20", "--radius-profile-mm", "0:5,65:4", "--starts", "1", "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert_eq!(reported_exports(&stdout, &out), files_in(&out), "{stdout}");
    assert_eq!(files_in(&out), ["channel.csv", "design.json", "shape.png"]);
}

/// The default design → mould path: `--moulds` designs within the offset
/// the moulds cast (their own rule, 4.2 mm for the 1 mm tube and 0.3 mm skin
/// in r = 5 mm) where the thesis's bound (4.995 mm) gives Target I a channel
/// `mould` refuses; without it, the bound `mould` will need is said first.
#[test]
fn design_with_moulds_gives_a_channel_the_moulds_cast() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d");
    let target = "x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015";
    let (ok, stdout, stderr) = run(&["design", "--target", target, "--starts", "2", "--moulds", "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let design: Value = serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap();
    let y: Vec<f64> = design["routing_mm"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    // The default bound (4.995 mm) lets Target I's routing reach
    // |y_3| = 4.91 mm; with --moulds every |y_i| stays within 4.2 mm.
    assert!(y.iter().all(|y| y.abs() <= 4.2 + 1e-9), "within the moulds' bound: {y:?}");
    for file in ["mould1.stl", "mould2.stl", "mould.json", "design.json", "mould.svg"] {
        assert!(out.join(file).is_file(), "{file}: {stdout}");
    }
    assert_eq!(reported_exports(&stdout, &out), ["channel.csv", "design.json", "mould.svg", "shape.png"]);
    assert!(!stderr.contains("note:"), "{stderr}");
    // Without --moulds: one line before the search, on stderr (stdout stays JSON).
    let (ok, stdout, stderr) = run(&["design", "--target", "x=50,y=5", "--starts", "1", "--json"]);
    assert!(ok, "{stderr}");
    serde_json::from_str::<Value>(stdout.trim()).expect("stdout is one JSON object");
    let notes: Vec<&str> = stderr.lines().filter(|l| l.starts_with("note:")).collect();
    assert_eq!(notes.len(), 1, "{stderr}");
    assert!(
        notes[0].contains("needs |y_i| ≤ 4.200 mm") && notes[0].contains("allows 4.995 mm") && notes[0].contains("--moulds"),
        "{stderr}"
    );
    // A bound within the moulds' needs no note; a body mould cannot cast is refused before the search.
    let (_, _, stderr) = run(&["design", "--target", "x=50,y=5", "--starts", "1", "--max-offset-mm", "4", "--json"]);
    assert!(!stderr.contains("note:"), "{stderr}");
    let refused = dir.path().join("refused");
    let (ok, _, stderr) =
        run(&["design", "--target", "x=50,y=5", "--moulds", "--cable-anchor-mm", "50", "--out", refused.to_str().unwrap()]);
    assert!(!ok && stderr.contains("uniform cylinders only"), "{stderr}");
    assert!(!refused.exists(), "refused before anything was written");
}

#[test]
fn bad_input_is_named() {
    for (args, needle) in [
        (vec!["design", "--target", "x=abc"], "not a finite number"),
        (vec!["design", "--target", "q=1"], "unknown component"),
        (vec!["design", "--target", "x=50", "--length-basis", "rst"], "unknown length basis 'rst'"),
        (vec!["design", "--target", "x=50", "--weights", "y=3"], "does not ask for it"),
        (vec!["design", "--target", "x=50", "--tension-min-n", "3"], "τ_l ≤ τ_u"),
        (vec!["design", "--target", "x=50", "--max-offset-mm", "6"], "largest control-point offset"),
    ] {
        let (ok, _, stderr) = run(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}
