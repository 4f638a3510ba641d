//! Non-uniform actuators as a user runs them: tapered and segmented bodies,
//! a cable knotted before the tip, actuator files, measurement files that
//! carry their geometry, and the errors for bad bodies.

use std::path::Path;
use std::process::Command;

fn cablemap(args: &[&str]) -> (bool, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cablemap"));
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "SLURM_CPUS_PER_TASK"] {
        c.env_remove(v);
    }
    let out = c.args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.lines().last().unwrap_or("").trim()).unwrap_or_else(|e| panic!("not JSON ({e}): {stdout}"))
}

/// The real tentacle of the real-measurements issue: 360 mm, r 15.4 → 6.4 →
/// 4.8 mm (the thesis silicone: its rigidities are those of r = 5 mm),
/// tendon knotted at 305 mm, full gravity.
const TENTACLE: [&str; 6] = ["--length-mm", "360", "--radius-profile-mm", "0:15.4,305:6.4,360:4.8", "--cable-anchor-mm", "305"];

#[test]
fn the_real_tentacle_solves_at_every_measured_tension_and_draws_its_taper() {
    let dir = tempfile::tempdir().unwrap();
    for tension in ["1.5", "4", "7.7"] {
        let png = dir.path().join(format!("t{tension}.png"));
        let mut args = vec!["simulate", "--routing", "4,4,4,4,4", "--tension", tension, "--json", "--png", png.to_str().unwrap()];
        args.extend(TENTACLE);
        let (ok, stdout, stderr) = cablemap(&args);
        assert!(ok, "{tension} N: {stderr}");
        let v = json(&stdout);
        assert_eq!(v["status"], "ok", "{v}");
        assert!(v["tip_angle_rad"].as_f64().unwrap() > 0.2, "{v}");
        let bytes = std::fs::read(&png).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{tension} N: no picture");
    }
}

#[test]
fn bad_bodies_get_errors_naming_where_and_what_to_do() {
    let cases: [(&[&str], &[&str]); 5] = [
        (&["--radius-profile-mm", "0:6,40:5,30:4"], &["point 2", "s = 30 mm", "increasing s"]),
        (&["--radius-profile-mm", "0:6,30:0,65:4"], &["s = 30 mm", "r = 0 mm", "> 0 mm"]),
        (&["--radius-profile-mm", "0:6,60:4"], &["L = 65 mm", "add points at 0 and L"]),
        (&["--cable-anchor-mm", "80"], &["anchor", "80", "0 < s_k ≤ L = 65 mm"]),
        (&["--radius-profile-mm", "0:6,65:1.5", "--routing", "0,2,2,2,2"], &["channel at s =", "outside the body", "r(s) ="]),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["simulate", "--routing", "0,1,1,1,1", "--tension", "1"];
        if extra.contains(&"--routing") {
            args.truncate(1);
            args.extend(["--tension", "1"]);
        }
        args.extend(extra);
        let (ok, _, stderr) = cablemap(&args);
        assert!(!ok, "{extra:?} accepted");
        for n in needles {
            assert!(stderr.contains(n), "{extra:?}: '{n}' not in {stderr}");
        }
    }
    let (ok, _, stderr) = cablemap(&["simulate", "--routing", "0,1,1,1,1", "--tension", "1", "--radius-profile-mm", "0:6,65"]);
    assert!(!ok && stderr.contains("--radius-profile-mm") && stderr.contains("s:r"), "{stderr}");
    // RK4 knots the cable at the tip only.
    let (ok, _, stderr) = cablemap(&["simulate", "--routing", "0,1,1,1,1", "--tension", "1", "--cable-anchor-mm", "50", "--method", "rk4"]);
    assert!(!ok && stderr.contains("collocation"), "{stderr}");
    // The two-part moulds are for uniform cylinders: a tapered body asked for them is refused;
    // left to choose, it gets the printed body with lumens, as any actuator.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let (ok, _, stderr) = cablemap(&[
        "mould", "--routing", "0,1,1,1,1", "--radius-profile-mm", "0:6,65:4", "--style", "two-part", "--out", out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("uniform cylinders") && stderr.contains("radius profile"), "{stderr}");
    assert!(!out.exists());
    let (ok, stdout, stderr) =
        cablemap(&["mould", "--routing", "0,1,1,1,1", "--radius-profile-mm", "0:6,65:4", "--json", "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let report: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(report["style"], "lumens", "{stdout}");
}

#[test]
fn an_actuator_file_gives_segments_and_the_flags_override_it() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("finger.toml");
    std::fs::write(
        &file,
        "length_mm = 65.0\nradius_profile_mm = [[0.0, 6.0], [65.0, 4.0]]\ncable_anchor_mm = 60.0\n\
         [[segments]]\nend_mm = 20.0\nei_n_mm2 = 400.0\ndensity_g_cm3 = 1.3\n[[segments]]\nend_mm = 65.0\n",
    )
    .unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["simulate", "--routing", "0,2,2,2,2", "--tension", "1.5", "--json", "--actuator-file", file.to_str().unwrap()];
        args.extend(extra);
        let (ok, stdout, stderr) = cablemap(&args);
        assert!(ok, "{stderr}");
        json(&stdout)
    };
    let segmented = run(&[]);
    let (ok, stdout, stderr) =
        cablemap(&["simulate", "--routing", "0,2,2,2,2", "--tension", "1.5", "--json", "--radius-profile-mm", "0:6,65:4", "--cable-anchor-mm", "60"]);
    assert!(ok, "{stderr}");
    let one_material = json(&stdout);
    // The stiff base segment bends less.
    assert!(segmented["tip_angle_rad"].as_f64().unwrap() < one_material["tip_angle_rad"].as_f64().unwrap() - 0.01, "{segmented} {one_material}");
    // A flag overrides the file.
    let softer = run(&["--ei-n-mm2", "60"]);
    assert!(softer["tip_angle_rad"].as_f64().unwrap() > segmented["tip_angle_rad"].as_f64().unwrap());
    std::fs::write(&file, "radius_profile_mm = [[0.0, 6.0], [40.0, 5.0], [30.0, 4.0]]\n").unwrap();
    let (ok, _, stderr) = cablemap(&["simulate", "--routing", "0,1,1,1,1", "--tension", "1", "--actuator-file", file.to_str().unwrap()]);
    assert!(!ok && stderr.contains("finger.toml") && stderr.contains("increasing s"), "{stderr}");
}

#[test]
fn a_tapered_finger_gets_its_own_feasibility_map() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("finger.toml");
    std::fs::write(
        &spec,
        "[grid]\nlevels = 3\nextent_r = 0.8\nmirror_dedup = true\n[tension]\nmin_n = 1.0\nmax_n = 2.0\ncount = 3\n\
         [output]\norder = 3\ncentreline = false\nchunk_routings = 32\n\
         [actuator]\nradius_profile_mm = [[0.0, 6.0], [65.0, 4.0]]\ncable_anchor_mm = 60.0\n",
    )
    .unwrap();
    let out = dir.path().join("finger");
    let (ok, stdout, stderr) = cablemap(&["map", spec.to_str().unwrap(), "--out", out.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    assert!(v["summary"]["rows_converged"].as_i64().unwrap() > 0, "{v}");
    // The levels are fractions of the narrowest radius along the cable
    // (4.15 mm at s = 60 mm), so every routing fits inside the taper.
    assert_eq!(v["summary"]["rows_failed"].as_i64(), Some(0), "{v}");
    // The run's manifest keeps the body with the spec.
    let manifest = std::fs::read_to_string(out.join("run").join("manifest.json")).unwrap();
    assert!(manifest.contains("radius_profile_mm") && manifest.contains("cable_anchor_mm"), "{manifest}");
    // The design on that map is for the tapered finger.
    let (ok, stdout, stderr) = cablemap(&[
        "design",
        "--target",
        "x=45,y=20",
        "--radius-profile-mm",
        "0:6,65:4",
        "--cable-anchor-mm",
        "60",
        "--map",
        out.join("map").to_str().unwrap(),
        "--json",
    ]);
    assert!(ok, "{stderr}");
    let d = json(&stdout);
    let y = d["routing_mm"].as_array().or_else(|| d["best"]["routing_mm"].as_array()).expect("routing in the design answer");
    assert!(y.iter().all(|v| v.as_f64().unwrap().abs() < 4.2), "{d}");
}

fn synth(path: &Path, extra: &[&str]) {
    let mut args = vec!["synth", "--out", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    let (ok, _, stderr) = cablemap(&args);
    assert!(ok, "synth failed: {stderr}");
}

#[test]
fn diagnose_reads_the_body_from_the_measurement_file() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("tapered.csv");
    synth(&data, &["--radius-profile-mm", "0:6,65:4.5", "--cable-anchor-mm", "60", "--effect", "stiffness_gradient", "--magnitude", "-0.6931", "--seed", "4"]);
    let text = std::fs::read_to_string(&data).unwrap();
    assert!(text.starts_with("# length_mm = 65.0\n") && text.contains("# radius_profile_mm = [[0.0, 6.0], [65.0, 4.5]]"), "{text}");
    assert!(!text.contains("stiffness_gradient"), "the hidden effect must not leak into the file");
    let (ok, stdout, stderr) = cablemap(&["diagnose", data.to_str().unwrap(), "--no-report", "--json"]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    assert_eq!(v["verdict"], "stiffness_gradient", "{v}");
    let beta = v["parameter"].as_f64().unwrap();
    assert!((beta - 0.5f64.ln()).abs() < 0.25 * 0.5f64.ln().abs(), "{beta}");
    // The same file read as a uniform rod (header removed) fits worse.
    let bare: String = text.lines().filter(|l| !l.starts_with('#')).map(|l| format!("{l}\n")).collect();
    let uniform = dir.path().join("bare.csv");
    std::fs::write(&uniform, bare).unwrap();
    let (ok, stdout, stderr) = cablemap(&["calibrate", uniform.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let bare_fit = json(&stdout);
    let (ok, stdout, stderr) = cablemap(&["calibrate", data.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let body_fit = json(&stdout);
    let chi = |v: &serde_json::Value| v["reduced_chi2"].as_f64().or_else(|| v["fit"]["reduced_chi2"].as_f64()).unwrap_or(f64::NAN);
    assert!(chi(&body_fit) < chi(&bare_fit), "{body_fit} {bare_fit}");
    // An actuator file named in the header, relative to the data file.
    std::fs::write(dir.path().join("act.toml"), "radius_profile_mm = [[0.0, 6.0], [65.0, 4.5]]\ncable_anchor_mm = 60.0\n").unwrap();
    let named = dir.path().join("named.csv");
    let body: String = text.lines().filter(|l| !l.starts_with('#')).map(|l| format!("{l}\n")).collect();
    std::fs::write(&named, format!("# actuator_file = \"act.toml\"\n{body}")).unwrap();
    let (ok, stdout, stderr) = cablemap(&["calibrate", named.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    assert!((chi(&json(&stdout)) - chi(&body_fit)).abs() < 1e-9 * chi(&body_fit), "{stdout}");
    std::fs::write(&named, format!("# actuator_file = \"missing.toml\"\n{body}")).unwrap();
    let (ok, _, stderr) = cablemap(&["calibrate", named.to_str().unwrap()]);
    assert!(!ok && stderr.contains("geometry header") && stderr.contains("missing.toml"), "{stderr}");
}
