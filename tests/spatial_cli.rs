//! `cablemap simulate` with several or spatial cables, as a user runs it:
//! `--cable`, `--actuator FILE.toml`, `--gravity-direction`, and the JSON,
//! CSV and PNG outputs (docs/schema.md).

mod process;

use serde_json::Value;
use std::path::PathBuf;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = process::cablemap().args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn json(args: &[&str]) -> Value {
    let (ok, out, err) = run(args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(out.trim()).unwrap_or_else(|e| panic!("{args:?}: not JSON ({e}): {out}"))
}

fn reference(name: &str) -> Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference/multi-cable.json");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v["cases"].as_array().unwrap().iter().find(|c| c["name"] == name).unwrap().clone()
}

fn list(v: &Value) -> String {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap().to_string()).collect::<Vec<_>>().join(",")
}

fn f3(v: &Value) -> [f64; 3] {
    std::array::from_fn(|i| v[i].as_f64().unwrap())
}

fn tip(v: &Value) -> [f64; 3] {
    [v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap(), v["tip_z_mm"].as_f64().unwrap()]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn cable_flags_reproduce_a_reference_case() {
    let case = reference("public_00_planar_antagonistic");
    let cables: Vec<String> = case["cables"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| format!("y={} z={} tension={}", list(&c["routing_y_mm"]), list(&c["routing_z_mm"]), c["tension_N"]))
        .collect();
    let mut args = vec!["simulate", "--no-gravity", "--json"];
    for c in &cables {
        args.extend(["--cable", c.as_str()]);
    }
    let v = json(&args);
    assert!(dist(tip(&v), f3(&case["tip_mm"])) < 1e-3, "{v}");
    assert!(dist(f3(&v["tip_tangent"]), f3(&case["tip_tangent"])) < 1e-5);
    assert!(dist(f3(&v["tip_body_y_axis"]), f3(&case["tip_body_y_axis"])) < 1e-5);
    for key in ["a", "a_bend_z", "a_bend_y", "a_twist"] {
        assert_eq!(v[key].as_array().unwrap().len(), 4, "{key}");
    }
    assert_eq!(v["a"], v["a_bend_z"]);
    assert_eq!(v["tension_n"].as_array().unwrap().len(), 2);
    assert_eq!(v["status"], "ok");
    assert_eq!(v["length_basis"], "rest");
}

#[test]
fn an_actuator_file_reproduces_a_three_cable_case_with_gravity() {
    let case = reference("public_05_spatial_multi");
    let g = f3(&case["gravity_N_per_mm"]);
    let mut toml = format!("gravity_direction = [{}, {}, {}]\n\n[rod]\nlength_mm = 65.0\n\n", g[0], g[1], g[2]);
    for c in case["cables"].as_array().unwrap() {
        toml += &format!(
            "[[cable]]\ny_mm = [{}]\nz_mm = [{}]\ntension_n = {}\n\n",
            list(&c["routing_y_mm"]),
            list(&c["routing_z_mm"]),
            c["tension_N"]
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("three.toml");
    std::fs::write(&file, toml).unwrap();
    let v = json(&["simulate", "--actuator", file.to_str().unwrap(), "--json"]);
    assert!(dist(tip(&v), f3(&case["tip_mm"])) < 1e-3, "{v}");
    assert!(dist(f3(&v["tip_tangent"]), f3(&case["tip_tangent"])) < 1e-5);
    assert!((v["length_mm"].as_f64().unwrap() - case["deformed_length_mm"].as_f64().unwrap()).abs() < 1e-3);
    // Rod flags override the file; --cable replaces its cables.
    let off = json(&["simulate", "--actuator", file.to_str().unwrap(), "--no-gravity", "--json"]);
    assert_eq!(off["gravity"], false);
    assert!(dist(tip(&off), tip(&v)) > 0.1);
    let one = json(&["simulate", "--actuator", file.to_str().unwrap(), "--cable", "y=2,2,2,2,2 tension=1", "--json"]);
    assert_eq!(one["cables"].as_array().unwrap().len(), 1);
    // A broken file is named.
    std::fs::write(&file, "[[cable]]\ny_mm = [1, 2]\ntension_n = 1\n").unwrap();
    let (ok, _, err) = run(&["simulate", "--actuator", file.to_str().unwrap()]);
    assert!(!ok && err.contains("three.toml"), "{err}");
}

#[test]
fn planar_routing_output_is_unchanged_and_agrees_with_the_cable_form() {
    let planar = json(&["simulate", "--routing", "1,-2,4,4,-4", "--tension", "1.2", "--json"]);
    assert!(planar.get("tip_z_mm").is_none(), "the planar record keeps its fields");
    let spatial = json(&["simulate", "--cable", "y=1,-2,4,4,-4 tension=1.2", "--steps-per-span", "128", "--json"]);
    let d = dist(tip(&spatial), [planar["tip_x_mm"].as_f64().unwrap(), planar["tip_y_mm"].as_f64().unwrap(), 0.0]);
    assert!(d < 1e-5, "{d}");
    for i in 0..4 {
        assert!((spatial["a"][i].as_f64().unwrap() - planar["a"][i].as_f64().unwrap()).abs() < 1e-6);
    }
    // --gravity-direction with --routing: the same cable, gravity turned out of the plane.
    let out = json(&["simulate", "--routing", "1,-2,4,4,-4", "--tension", "1.2", "--gravity-direction", "0,0,1", "--json"]);
    assert!(out["tip_z_mm"].as_f64().unwrap() > 0.05, "{out}");
    assert_eq!(f3(&out["gravity_direction"]), [0.0, 0.0, 1.0]);
}

#[test]
fn csv_and_png_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, png) = (dir.path().join("c.csv"), dir.path().join("c.png"));
    let (ok, out, err) = run(&[
        "simulate",
        "--cable",
        "y=2,3,1,-1,2 z=1,-1,2,2,0 tension=1.4",
        "--cable",
        "y=-2,-2,-2,-2,-2 tension=0.5",
        "--csv",
        csv.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("tip tangent") && out.contains("cable 2"), "{out}");
    assert!(out.lines().last().unwrap().starts_with(&format!("wrote {}", png.display())), "the picture is named: {out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for col in ["s_mm", "x_mm", "y_mm", "z_mm", "u1_per_mm", "cable1_x_mm", "cable2_z_mm"] {
        assert!(header.contains(&col), "{col} missing from {header:?}");
    }
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert!(rows.len() > 20);
    assert!(rows.iter().all(|r| r.len() == header.len()));
    // First row at the clamp: centreline at the origin, cable 2 at (0, −2, 0).
    assert_eq!(&rows[0][1..4], &[0.0, 0.0, 0.0]);
    let c2 = header.iter().position(|&h| h == "cable2_x_mm").unwrap();
    assert_eq!(&rows[0][c2..c2 + 3], &[0.0, -2.0, 0.0]);
    // The last row is the tip (s = L).
    assert_eq!(rows.last().unwrap()[0], 65.0);
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (1400, 760));
}

#[test]
fn bad_input_is_refused_with_a_clear_message() {
    let cases: &[(&[&str], &str)] = &[
        (&["simulate", "--cable", "y=1,2,3 tension=1"], "5 control points"),
        (&["simulate", "--cable", "y=1,1,1,1,1 tension=-1"], "cable 1: tension -1 N is invalid"),
        (&["simulate", "--cable", "y=1,1,1,1,1 tension=1", "--cable", "y=1,1,1,1,1 tension=2"], "same path"),
        (&["simulate", "--cable", "y=3.6,3.6,3.6,3.6,3.6 z=3.6,3.6,3.6,3.6,3.6 tension=1"], "outside the radius"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,0,6,0,0 tension=1"], "cable 1, z control points"),
        (&["simulate", "--cable", "y=1,1,1,1,1 tension=1", "--gravity-direction", "0,0,0"], "non-zero"),
        (&["simulate", "--cable", "y=1,1,1,1,1 tension=1", "--gravity-direction", "0,1"], "3 numbers"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--coefficients", "thesis"], "--coefficients thesis"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--method", "rk4", "--friction-mu", "0.1"], "friction_mu"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--method", "rk4", "--order", "7"], "--steps-per-span"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--order", "9"], "highest order 8"),
        (&["simulate", "--actuator", "/nonexistent/a.toml"], "/nonexistent/a.toml"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--method", "rk4", "--radius-profile-mm", "0:5,65:3"], "uniform rod"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--cable-anchor-mm", "40"], "anchor=S"),
        (&["simulate", "--cable", "y=1,1,1,1,1 z=0,1,1,1,0 tension=1", "--method", "rk4", "--stiffness-gradient-beta", "-0.5"], "stiffness_gradient_beta"),
        (&["simulate"], "--cable"),
    ];
    for (args, needle) in cases {
        let (ok, _, err) = run(args);
        assert!(!ok, "{args:?} was accepted");
        assert!(err.contains(needle), "{args:?}: stderr {err:?} lacks {needle:?}");
    }
}

#[test]
fn the_documented_actuator_file_runs() {
    let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/spatial/antagonistic.toml");
    let v = json(&["simulate", "--actuator", file.to_str().unwrap(), "--json"]);
    assert_eq!(v["cables"].as_array().unwrap().len(), 2);
    assert!((v["gj_n_mm2"].as_f64().unwrap() - 76.74).abs() < 1e-12);
    assert_eq!(f3(&v["gravity_direction"]), [0.0, -1.0, 0.0]);
    assert!(v["tip_y_mm"].as_f64().unwrap() > 5.0, "the stronger cable at +y wins: {v}");
}

/// Displacement as the input, as a user drives a motor: the record carries
/// both actuations; the displacement a tension produced, given back,
/// returns that tension and shape (the round trip through the binary, its
/// JSON numbers printed exactly); a long cable is slack; a negative
/// displacement and RK4 (which does not integrate the cable's path) are
/// refused with the reason.
#[test]
fn displacement_drives_a_cable_from_the_command_line() {
    let num = |v: &Value, k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k} in {v}"));
    let by_tension = json(&["simulate", "--routing", "1,-2,4,4,-4", "--tension-n", "1.2", "--json"]);
    let d = num(&by_tension, "displacement_mm");
    assert!(d > 0.5, "a pulled cable is pulled in: {by_tension}");
    let by_displacement = json(&["simulate", "--routing", "1,-2,4,4,-4", "--displacement-mm", &format!("{d:e}"), "--json"]);
    assert!((num(&by_displacement, "tension_n") - 1.2).abs() < 1e-8, "{by_displacement}");
    for k in ["tip_x_mm", "tip_y_mm"] {
        assert!((num(&by_displacement, k) - num(&by_tension, k)).abs() < 1e-8, "{k}: {by_displacement} vs {by_tension}");
    }
    // Slack: a cable pulled in by nothing, across a rod whose weight sags
    // it toward the cable (its path shortens), carries nothing: the shape is
    // the weight's alone. (Hanging along the axis the weight stretches the
    // rod, and a cable pulled in by 0 mm holds it: taut.)
    let across = ["--routing", "3,3,3,3,3", "--gravity-direction", "0,1,0", "--json"];
    let slack = json(&[&["simulate", "--displacement-mm", "0"][..], &across[..]].concat());
    let hanging = json(&[&["simulate", "--tension-n", "0"][..], &across[..]].concat());
    assert_eq!(slack["tension_n"][0].as_f64(), Some(0.0), "{slack}");
    assert!((num(&slack, "tip_y_mm") - num(&hanging, "tip_y_mm")).abs() < 1e-12);
    assert!(num(&hanging, "tip_y_mm") > 1.0, "the weight bends the rod: {hanging}");
    // A stiffer-than-infinite cable stretches: more displacement for the same tension.
    let stretchy = json(&["simulate", "--routing", "1,-2,4,4,-4", "--tension-n", "1.2", "--cable-ea-n", "100", "--json"]);
    assert!((num(&stretchy, "displacement_mm") - d - 1.2 * 64.0 / 100.0).abs() < 0.05, "{stretchy}");
    // Several cables: each carries its tension and displacement.
    let two = json(&["simulate", "--cable", "y=3,3,3,3,3 displacement=2", "--cable", "y=-3,-3,-3,-3,-3 tension=0.5", "--json"]);
    assert!((two["displacement_mm"][0].as_f64().unwrap() - 2.0).abs() < 1e-9, "{two}");
    assert!(two["tension_n"][0].as_f64().unwrap() > 0.0 && two["tension_n"][1].as_f64().unwrap() == 0.5, "{two}");
    assert!(two["displacement_mm"][1].as_f64().unwrap().is_finite());
    let (ok, _, err) = run(&["simulate", "--routing", "1,-2,4,4,-4", "--displacement-mm", "-1"]);
    assert!(!ok && err.contains("negative displacement"), "{err}");
    let (ok, _, err) = run(&["simulate", "--routing", "1,-2,4,4,-4", "--displacement-mm", "1", "--method", "rk4"]);
    assert!(!ok && err.contains("displacement") && err.contains("collocation"), "{err}");
    let (ok, _, err) = run(&["simulate", "--routing", "1,-2,4,4,-4"]);
    assert!(!ok && err.contains("--displacement-mm"), "{err}");
    let (ok, _, err) = run(&["simulate", "--routing", "1,-2,4,4,-4", "--tension-n", "1", "--displacement-mm", "1"]);
    assert!(!ok && err.contains("cannot be used with"), "{err}");
}
