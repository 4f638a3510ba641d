//! `cablemap design --actuator A.toml --targets T.toml` as a user runs it:
//! several cables with free spatial channels reaching a sequence of
//! simulated shapes (re-simulated independently of the optimiser), the
//! thesis's Table 5.1 through the same request, unreachable targets refused
//! with the reason, a trajectory's reported path against a re-simulation,
//! and determinism across thread counts.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn run_env(args: &[&str], env: &[(&str, &str)]) -> (bool, String, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_cablemap"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn run(args: &[&str]) -> (bool, String, String) {
    run_env(args, &[])
}

fn json(args: &[&str]) -> Value {
    let (ok, stdout, stderr) = run(args);
    assert!(ok, "{args:?} failed: {stderr}");
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("{e}: {stdout}"))
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not a list: {v}")).iter().map(|x| x.as_f64().unwrap()).collect()
}

fn angle_deg(a: &[f64], b: &[f64]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let n = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (dot / (n(a) * n(b))).clamp(-1.0, 1.0).acos().to_degrees()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

/// Two spatial cables at a tension pair, as `simulate --actuator` reads them.
fn spatial_pair(t1: f64, t2: f64) -> String {
    format!(
        "[[cable]]\ny_mm = [2.0, 2.5, 1.5, 2.0, 2.5]\nz_mm = [1.0, 0.5, 1.5, 1.0, 0.0]\ntension_n = {t1}\n\n\
         [[cable]]\ny_mm = [-2.0, -1.5, -2.5, -2.0, -1.0]\nz_mm = [-1.0, 0.0, 1.0, 1.5, 2.0]\ntension_n = {t2}\n"
    )
}

#[test]
fn a_sequence_of_two_simulated_spatial_shapes_is_reached_and_resimulated() {
    let dir = tempfile::tempdir().unwrap();
    let mut targets = String::new();
    let mut asked = Vec::new();
    for (i, (t1, t2)) in [(1.0, 0.3), (0.2, 1.2)].into_iter().enumerate() {
        let file = write(dir.path(), &format!("pair{i}.toml"), &spatial_pair(t1, t2));
        let v = json(&["simulate", "--actuator", &file, "--json"]);
        let tip = [v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap(), v["tip_z_mm"].as_f64().unwrap()];
        let tangent = floats(&v["tip_tangent"]);
        targets += &format!(
            "[[target]]\ntip_mm = {tip:?}\ntip_tangent = {tangent:?}\na_bend_z = {:?}\na_bend_y = {:?}\na_twist = {:?}\n\n",
            floats(&v["a_bend_z"]),
            floats(&v["a_bend_y"]),
            floats(&v["a_twist"])
        );
        asked.push((tip.to_vec(), tangent));
    }
    let targets = write(dir.path(), "targets.toml", &targets);
    // Both channels free (no y_mm/z_mm), tensions within the default 0 … 2 N.
    let actuator = write(dir.path(), "free.toml", "[[cable]]\n\n[[cable]]\n");
    let out = dir.path().join("design");
    let d = json(&["design", "--actuator", &actuator, "--targets", &targets, "--out", out.to_str().unwrap(), "--json"]);
    let cables = d["cables"].as_array().unwrap();
    assert_eq!(cables.len(), 2);
    for c in cables {
        assert_eq!(floats(&c["y_mm"]).len(), 5);
        assert_eq!(floats(&c["z_mm"]).len(), 5);
        assert_eq!(c["free"], serde_json::json!(["y", "z"]));
    }
    let file: Value = serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap();
    assert_eq!(file["cables"], d["cables"], "--json prints design.json's object");
    for name in ["channel_1.csv", "channel_2.csv", "target_1.png", "target_2.png", "target_1.toml", "target_2.toml"] {
        assert!(out.join(name).exists(), "{name} not written");
    }
    let targets = d["targets"].as_array().unwrap();
    assert_eq!(targets.len(), 2);
    for (k, (t, (tip, tangent))) in targets.iter().zip(&asked).enumerate() {
        assert_eq!(floats(&t["tensions_n"]).len(), 2);
        assert!(distance(&floats(&t["tip_mm"]), tip) < 0.1, "{t}");
        assert!(angle_deg(&floats(&t["tip_tangent"]), tangent) < 0.1, "{t}");
        // Re-simulated independently of the optimiser: the actuator file the design wrote.
        let again = json(&["simulate", "--actuator", out.join(format!("target_{}.toml", k + 1)).to_str().unwrap(), "--json"]);
        let tip_again = [again["tip_x_mm"].as_f64().unwrap(), again["tip_y_mm"].as_f64().unwrap(), again["tip_z_mm"].as_f64().unwrap()];
        assert!(distance(&tip_again, tip) < 0.1, "target {}: re-simulated tip {tip_again:?} vs {tip:?}", k + 1);
        assert!(angle_deg(&floats(&again["tip_tangent"]), tangent) < 0.1, "target {}: {again}", k + 1);
        // The same channels at both targets: only the tensions differ.
        let cables_again = again["cables"].as_array().unwrap();
        for (c, designed) in cables_again.iter().zip(cables) {
            assert_eq!(c["y_mm"], designed["y_mm"]);
            assert_eq!(c["z_mm"], designed["z_mm"]);
        }
        assert_eq!(floats(&again["tension_n"]), floats(&t["tensions_n"]));
    }
}

/// Table 5.1's targets through the several-cable request (one planar cable
/// free in y, the default bounds: one cable's are the thesis's 1 … 2 N of
/// `design --target`) give the answers of `design --target`, with the
/// actuator file and without one (the rod of the flags, one cable).
#[test]
fn table_5_1_through_the_cable_request_gives_todays_answers() {
    let dir = tempfile::tempdir().unwrap();
    let actuator = write(dir.path(), "one.toml", "[[cable]]\ny_mm = [0, 0, 0, 0, 0]\nfree = [\"y\"]\n");
    let cases = [
        ("x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015", "{ x = 50, y = 5 }", "[-0.025, -0.06, 0.015]", true),
        ("x=10,y=50,a0=0.015,a1=-0.07,a2=-0.03", "{ x = 10, y = 50 }", "[0.015, -0.07, -0.03]", true),
        ("x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015", "{ x = 50, y = 5 }", "[-0.025, -0.06, 0.015]", false),
    ];
    for (target, tip, a, with_file) in cases {
        let today = json(&["design", "--target", target, "--json"]);
        let targets = write(dir.path(), "t.toml", &format!("[[target]]\ntip_mm = {tip}\na_bend_z = {a}\n"));
        let v = if with_file { json(&["design", "--actuator", &actuator, "--targets", &targets, "--json"]) } else { json(&["design", "--targets", &targets, "--json"]) };
        assert_eq!(v["method"], "planar", "{v}");
        assert_eq!(v["cables"][0]["actuation"], serde_json::json!({"kind": "tension", "min_n": 1.0, "max_n": 2.0}));
        let y = floats(&v["cables"][0]["y_mm"]);
        for (got, want) in y.iter().zip(floats(&today["routing_mm"])) {
            assert!((got - want).abs() < 1e-9, "{target}: {y:?} vs {}", today["routing_mm"]);
        }
        assert_eq!(floats(&v["cables"][0]["z_mm"]), vec![0.0; 5]);
        let t = &v["targets"][0];
        assert!((floats(&t["tensions_n"])[0] - today["tension_n"].as_f64().unwrap()).abs() < 1e-9);
        for (key, old) in [("tip_x_mm", "x"), ("tip_y_mm", "y"), ("a_bend_z0", "a0"), ("a_bend_z1", "a1"), ("a_bend_z2", "a2")] {
            let (new, old) = (t["error_pct"][key].as_f64().unwrap(), today["error_pct"][old].as_f64().unwrap());
            assert!((new - old).abs() < 1e-9, "{target} {key}: {new} vs {old}");
        }
        assert_eq!(t["met"], today["met"]);
    }
}

#[test]
fn unreachable_targets_are_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let one = write(dir.path(), "one.toml", "[[cable]]\ny_mm = [0, 0, 0, 0, 0]\nfree = [\"y\"]\n");
    // A tip beyond the rod's length: refused before any search.
    let far = write(dir.path(), "far.toml", "[[target]]\ntip_mm = { x = 80, y = 0 }\n");
    let (ok, _, stderr) = run(&["design", "--actuator", &one, "--targets", &far]);
    assert!(!ok);
    assert!(stderr.contains("unreachable") && stderr.contains("target 1") && stderr.contains("beyond the rod's length L = 65 mm") && stderr.contains("misses by at least 15"), "{stderr}");
    // Opposite bends in one sequence with one cable: one channel cannot bend both ways.
    let both = write(dir.path(), "both.toml", "[[target]]\ntip_mm = { x = 50, y = 20 }\n\n[[target]]\ntip_mm = { x = 50, y = -20 }\n");
    let v = json(&["design", "--actuator", &one, "--targets", &both, "--json"]);
    assert_eq!(v["met"], false, "{v}");
    let unmet: Vec<&str> = v["unmet"].as_array().unwrap().iter().map(|s| s.as_str().unwrap()).collect();
    assert!(unmet.iter().any(|u| u.contains("tip_y_mm misses by")), "{unmet:?}");
    // Which target misses, and by as much as the achieved values say.
    for t in v["targets"].as_array().unwrap() {
        for miss in t["unmet"].as_array().unwrap() {
            assert!(miss.as_str().unwrap().starts_with(t["name"].as_str().unwrap()), "{miss}");
        }
    }
    let worst = v["targets"].as_array().unwrap().iter().map(|t| (t["achieved"]["tip_y_mm"].as_f64().unwrap() - t["target"]["tip_mm"]["y"].as_f64().unwrap()).abs()).fold(0.0, f64::max);
    assert!(worst > 10.0, "{v}");
    let (ok, stdout, _) = run(&["design", "--actuator", &one, "--targets", &both]);
    assert!(ok && stdout.contains("NOT REACHABLE") && stdout.contains("tip_y_mm misses by"), "{stdout}");
}

#[test]
fn the_same_design_on_every_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let two = write(dir.path(), "two.toml", "[[cable]]\nfree = [\"y\"]\ny_mm = [1, 1, 1, 1, 1]\n\n[[cable]]\nfree = [\"y\"]\ny_mm = [-1, -1, -1, -1, -1]\n");
    let t = write(dir.path(), "t.toml", "[[target]]\ntip_mm = { x = 55, y = 15 }\n\n[[target]]\ntip_mm = { x = 57, y = -12 }\n");
    let args = ["design", "--actuator", two.as_str(), "--targets", t.as_str(), "--json", "--starts", "2"];
    let strip = |text: &str| {
        let mut v: Value = serde_json::from_str(text.trim()).unwrap();
        v.as_object_mut().unwrap().remove("seconds");
        v
    };
    let (ok1, one, e1) = run_env(&args, &[("RAYON_NUM_THREADS", "1")]);
    let (ok2, many, e2) = run_env(&args, &[("RAYON_NUM_THREADS", "3")]);
    assert!(ok1 && ok2, "{e1}{e2}");
    assert_eq!(strip(&one), strip(&many));
}

#[test]
fn bad_design_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let one = write(dir.path(), "one.toml", "[[cable]]\nfree = [\"x\"]\n");
    let t = write(dir.path(), "t.toml", "[[target]]\ntip_mm = [50, 5, 0]\n");
    let (ok, _, stderr) = run(&["design", "--actuator", &one, "--targets", &t]);
    assert!(!ok && stderr.contains("--actuator") && stderr.contains("free"), "{stderr}");
    let ok_actuator = write(dir.path(), "ok.toml", "[[cable]]\n");
    let bad_t = write(dir.path(), "bad.toml", "[[target]]\ntip_mm = [50, 5]\n");
    let (ok, _, stderr) = run(&["design", "--actuator", &ok_actuator, "--targets", &bad_t]);
    assert!(!ok && stderr.contains("--targets") && stderr.contains("tip_mm has 2 numbers"), "{stderr}");
    let (ok, _, stderr) = run(&["design", "--actuator", &ok_actuator, "--targets", &t, "--weights", "x=2"]);
    assert!(!ok && stderr.contains("--weights does not apply to --targets"), "{stderr}");
}

/// Distance of `p` from the segment a–b.
fn segment_distance(p: &[f64], a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = (0..3).map(|i| b[i] - a[i]).collect();
    let w: Vec<f64> = (0..3).map(|i| p[i] - a[i]).collect();
    let dd: f64 = d.iter().map(|v| v * v).sum();
    let t = (w.iter().zip(&d).map(|(x, y)| x * y).sum::<f64>() / dd).clamp(0.0, 1.0);
    (0..3).map(|i| (w[i] - t * d[i]).powi(2)).sum::<f64>().sqrt()
}

/// A trajectory of 4 waypoints for the antagonistic pair (channels as
/// given, tensions designed): the reported path deviation is that of a
/// re-simulation of every sample, by `simulate`, to 1e-6 mm.
#[test]
fn a_trajectory_reports_the_path_a_resimulation_follows() {
    let dir = tempfile::tempdir().unwrap();
    let pair = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/spatial/antagonistic.toml");
    let pair = pair.to_str().unwrap();
    let cables = |t1: f64, t2: f64| {
        [format!("y=2.4,3.1,1.8,2.6,2.8 tension={t1}"), format!("y=-1.7,-2.4,-1.6,-3.2,-3.1 tension={t2}")]
    };
    let tip_of = |v: &Value| vec![v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap(), v["tip_z_mm"].as_f64().unwrap()];
    let simulate = |t1: f64, t2: f64| {
        let [c1, c2] = cables(t1, t2);
        json(&["simulate", "--actuator", pair, "--cable", &c1, "--cable", &c2, "--json"])
    };
    let waypoints: Vec<Vec<f64>> = [(0.2, 1.2), (0.8, 0.6), (1.4, 0.3), (1.8, 1.0)].iter().map(|&(a, b)| tip_of(&simulate(a, b))).collect();
    let targets = write(dir.path(), "path.toml", &format!("[trajectory]\nwaypoints = {waypoints:?}\nsmooth = true\n"));
    let out = dir.path().join("d");
    let d = json(&["design", "--actuator", pair, "--targets", &targets, "--out", out.to_str().unwrap(), "--json"]);
    // The trajectory's picture: the target pictures' two views, the sampled path drawn in red.
    let png = image::open(out.join("trajectory.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (1400, 760));
    let red = png.pixels().filter(|p| p.0 == [255, 0, 0]).count();
    assert!(red > 1000, "{red} pixels of the tip path");
    assert_eq!(std::fs::read_to_string(out.join("trajectory.csv")).unwrap().lines().count(), 1 + 3 * 21 * 2);
    assert_eq!(d["met"], true, "{d}");
    let path = &d["trajectory"];
    assert_eq!(path["steps_per_leg"], 20);
    let legs = path["legs"].as_array().unwrap();
    assert_eq!(legs.len(), 3);
    let mut largest = 0.0f64;
    for (k, leg) in legs.iter().enumerate() {
        let samples = leg["samples"].as_array().unwrap();
        assert_eq!(samples.len(), 21);
        let mut worst = 0.0f64;
        for s in samples {
            let a = floats(&s["actuation"]);
            let tip = tip_of(&simulate(a[0], a[1]));
            worst = worst.max(segment_distance(&tip, &waypoints[k], &waypoints[k + 1]));
        }
        let reported = leg["max_deviation_mm"].as_f64().unwrap();
        assert!((reported - worst).abs() < 1e-6, "leg {}: reported {reported} mm, re-simulated {worst} mm", k + 1);
        assert!(leg["reversals"].as_array().unwrap().is_empty());
        largest = largest.max(worst);
    }
    assert!((path["max_deviation_mm"].as_f64().unwrap() - largest).abs() < 1e-6);
    assert!(largest > 0.1, "the path leaves the straight legs: the check is not empty ({largest} mm)");
    assert_eq!(path["failed_samples"], 0);
}

/// The antagonistic pair's map (jobs/antagonistic-pair.toml): `feasible
/// --targets` says which target tips the sweep reached (voxels, plane
/// cells), gives the planar verdict with the nearest designs showing every
/// cable, and `design --targets --map` starts from the map's designs.
#[test]
fn feasible_and_design_with_a_cable_sweeps_map() {
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs/antagonistic-pair.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pair");
    let (ok, _, stderr) = run(&["map", spec.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let map = out.join("map");
    // A design of the sweep's grid: its tip is one of the map's.
    let v = json(&["simulate", "--cable", "y=3,2.5,2.5,2.5,3 tension=1", "--cable", "y=-3,-3,-4,-3,-3 tension=0.4", "--json"]);
    let tip = [v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap(), v["tip_z_mm"].as_f64().unwrap()];
    let targets = write(
        dir.path(),
        "t.toml",
        &format!("[[target]]\nname = \"grid tip\"\ntip_mm = {tip:?}\n\n[[target]]\nname = \"sideways\"\ntip_mm = [5, 60, 0]\n\n[[target]]\nname = \"plane\"\ntip_mm = {{ x = {}, y = {} }}\n", tip[0], tip[1]),
    );
    let f = json(&["feasible", "--map", map.to_str().unwrap(), "--targets", &targets, "--nearest", "3", "--json"]);
    assert_eq!(f["cables"], 2, "{f}");
    let t = f["targets"].as_array().unwrap();
    assert_eq!(t[0]["tip"]["verdict"], "reached", "{f}");
    assert_eq!(t[0]["tip"]["table"], "3d");
    assert!(t[0]["tip"]["count"].as_i64().unwrap() >= 1);
    assert_eq!(t[1]["tip"]["verdict"], "not_reached", "{f}");
    assert_eq!((t[2]["tip"]["verdict"].as_str(), t[2]["tip"]["table"].as_str()), (Some("reached"), Some("xy")), "{f}");
    let nearest = t[0]["planar"]["nearest"].as_array().unwrap();
    assert_eq!(nearest.len(), 3);
    for near in nearest {
        assert_eq!(near["cables"].as_array().unwrap().len(), 2, "every cable of a nearest design: {near}");
        assert!(near["command"].as_str().unwrap().starts_with("cablemap simulate"));
    }
    let (ok, text, stderr) = run(&["feasible", "--map", map.to_str().unwrap(), "--targets", &targets]);
    assert!(ok && text.contains("grid tip   reached") && text.contains("sideways   not reached by the sweep"), "{text}{stderr}");
    // The map's designs seed a design of the pair (channels free in y).
    let pair = write(dir.path(), "pair.toml", "[[cable]]\ny_mm = [3, 3, 3, 3, 3]\nfree = [\"y\"]\n\n[[cable]]\ny_mm = [-3, -3, -3, -3, -3]\nfree = [\"y\"]\n");
    let one = write(dir.path(), "one.toml", &format!("[[target]]\ntip_mm = {tip:?}\n"));
    let d = json(&["design", "--actuator", &pair, "--targets", &one, "--map", map.to_str().unwrap(), "--json"]);
    assert!(d["starts"].as_array().unwrap().iter().any(|s| s["source"] == "map"), "{d}");
    assert_eq!(d["met"], true, "{d}");
    assert!(d["targets"][0]["tip_error_mm"].as_f64().unwrap() < 1e-3, "{d}");
}

/// `design --targets --out DIR --moulds` writes every channel's moulds
/// (the moulds' own request, `mould::for_actuator`) beside the design.
#[test]
fn a_sequence_design_writes_the_moulds_of_every_channel() {
    let dir = tempfile::tempdir().unwrap();
    let pair = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/spatial/antagonistic.toml");
    let t = write(dir.path(), "t.toml", "[[target]]\ntip_mm = { x = 45, y = 30 }\n\n[[target]]\ntip_mm = { x = 45, y = -30 }\n");
    let out = dir.path().join("d");
    let (ok, stdout, stderr) = run(&["design", "--actuator", pair.to_str().unwrap(), "--targets", &t, "--out", out.to_str().unwrap(), "--moulds"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("moulds for 2 channels"), "{stdout}");
    for name in ["mould1.stl", "mould2.stl", "mould.json", "design.json"] {
        assert!(out.join(name).exists(), "{name} not written: {stdout}");
    }
    let v: Value = serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap();
    assert!(v["moulds"].is_object(), "{v}");
    // One owner of the channel files: the moulds list the design's
    // channel_K.csv, and `mould --actuator` of the designed actuator writes
    // the same bytes.
    assert_eq!(v["moulds"]["channel_files"], serde_json::json!(["channel_1.csv", "channel_2.csv"]), "{v}");
    let again = dir.path().join("m");
    let (ok, _, stderr) = run(&["mould", "--actuator", out.join("target_1.toml").to_str().unwrap(), "--out", again.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    for name in ["channel_1.csv", "channel_2.csv"] {
        let (design, mould) = (std::fs::read_to_string(out.join(name)).unwrap(), std::fs::read_to_string(again.join(name)).unwrap());
        assert!(design.starts_with("s_mm,y_mm,z_mm,dy_ds,dz_ds\n"), "{name}: {}", &design[..60]);
        assert_eq!(design, mould, "{name}: the design's and the mould's channel files differ");
    }
}

/// `smooth = true` is enforced by the search. The antagonistic pair's
/// channels, both cables displacement-driven: two waypoints simulated at
/// displacements A = (0.5, 2.5) mm and B = (2.0, d) mm with d chosen so
/// cable 2's tension is the same at both, so along the straight leg A → B
/// it dips (by about 0.4 mN) and comes back: the exact fit reverses. With
/// `smooth = true` the design moves the waypoints' actuation (within the
/// tolerance) until no sample of the leg reverses.
#[test]
fn a_smooth_trajectory_has_no_tension_reversal_where_the_exact_fit_has_one() {
    let dir = tempfile::tempdir().unwrap();
    // The pair's rod and gravity (across the rod, as in the x–y plane), its cables displacement-driven.
    let rod = "gj_n_mm2 = 76.74\ngravity_direction = [0, -1, 0]\n\n[rod]\nei_n_mm2 = 115.117\n\n";
    let pair = write(
        dir.path(),
        "pair.toml",
        &format!("{rod}[[cable]]\ny_mm = [2.4, 3.1, 1.8, 2.6, 2.8]\ndisplacement_max_mm = 5\n\n[[cable]]\ny_mm = [-1.7, -2.4, -1.6, -3.2, -3.1]\ndisplacement_max_mm = 5\n"),
    );
    // `simulate` reads the same rod, its cables given by --cable.
    let rod_only = write(dir.path(), "rod.toml", &format!("{rod}[[cable]]\ny_mm = [0, 0, 0, 0, 0]\ntension_n = 0\n"));
    let channels = ["y=2.4,3.1,1.8,2.6,2.8", "y=-1.7,-2.4,-1.6,-3.2,-3.1"];
    let simulate = |d1: f64, d2: f64| {
        let (c1, c2) = (format!("{} displacement={d1}", channels[0]), format!("{} displacement={d2}", channels[1]));
        json(&["simulate", "--actuator", &rod_only, "--cable", &c1, "--cable", &c2, "--json"])
    };
    let tension2 = |v: &Value| floats(&v["tension_n"])[1];
    let a = simulate(0.5, 2.5);
    // Bisection on d: cable 2's tension rises with its displacement.
    let (mut lo, mut hi) = (0.5, 4.0);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if tension2(&simulate(2.0, mid)) < tension2(&a) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let b = simulate(2.0, 0.5 * (lo + hi));
    let tip = |v: &Value| vec![v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap(), v["tip_z_mm"].as_f64().unwrap()];
    let design = |smooth: bool| {
        let t = write(dir.path(), "leg.toml", &format!("[trajectory]\nwaypoints = [{:?}, {:?}]\nsteps_per_leg = 10\nsmooth = {smooth}\n", tip(&a), tip(&b)));
        json(&["design", "--actuator", &pair, "--targets", &t, "--json"])
    };
    let exact = design(false);
    assert_eq!(exact["met"], true, "{exact}");
    let leg = &exact["trajectory"]["legs"][0];
    assert_eq!(leg["reversals"], serde_json::json!([2]), "the exact fit dips: {leg}");
    let smooth = design(true);
    assert_eq!(smooth["met"], true, "{smooth}");
    assert_eq!(smooth["unmet"], serde_json::json!([]), "{smooth}");
    let leg = &smooth["trajectory"]["legs"][0];
    assert_eq!(leg["reversals"], serde_json::json!([]), "{leg}");
    // Cable 2's tension along the leg, as reported, never moves against its
    // direction (beyond the report's rounding, 1e-9 of the tension).
    let t2: Vec<f64> = leg["samples"].as_array().unwrap().iter().map(|s| floats(&s["tensions_n"])[1]).collect();
    let steps: Vec<f64> = t2.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(steps.iter().all(|d| *d >= -1e-9) || steps.iter().all(|d| *d <= 1e-9), "{t2:?}");
    assert!(t2[0] - t2[10] > 1e-4 || t2[10] - t2[0] > 1e-4, "the ends now differ: {t2:?}");
    // It paid for that with waypoints off by a little, within the tolerance.
    let off = smooth["targets"].as_array().unwrap().iter().map(|t| t["tip_error_mm"].as_f64().unwrap()).fold(0.0, f64::max);
    assert!(off > 1e-4 && off < 0.5, "{off} mm");
}
