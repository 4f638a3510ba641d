//! The `cablemap` binary as a user runs it.

use std::process::Command;

fn cablemap() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cablemap"))
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = cablemap().args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

#[test]
fn simulate_json_has_the_documented_fields() {
    let (ok, stdout, stderr) = run(&["simulate", "--routing", "1,-2,4,4,-4", "--tension", "0.77", "--json", "--order", "4"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(v["status"], "ok");
    for key in ["tip_x_mm", "tip_y_mm", "tip_angle_rad", "base_angle_rad", "length_mm"] {
        assert!(v[key].is_f64(), "{key} missing in {v}");
    }
    assert_eq!(v["a"].as_array().unwrap().len(), 5);
    // Reference case (gravity.json, first case).
    assert!((v["tip_x_mm"].as_f64().unwrap() - 60.5535722675456).abs() < 1e-3);
}

#[test]
fn simulate_no_gravity_changes_the_result() {
    let (_, with, _) = run(&["simulate", "--routing", "1,-2,4,4,-4", "--tension", "0.77", "--json"]);
    let (_, without, _) = run(&["simulate", "--routing", "1,-2,4,4,-4", "--tension", "0.77", "--json", "--no-gravity"]);
    let a: serde_json::Value = serde_json::from_str(with.trim()).unwrap();
    let b: serde_json::Value = serde_json::from_str(without.trim()).unwrap();
    assert!((a["tip_x_mm"].as_f64().unwrap() - b["tip_x_mm"].as_f64().unwrap()).abs() > 1e-3);
}

#[test]
fn simulate_writes_csv_and_png() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("c.csv");
    let png = dir.path().join("c.png");
    let (ok, stdout, stderr) = run(&[
        "simulate", "--routing", "0,4,1,2,-2", "--tension", "1.7", "--csv", csv.to_str().unwrap(), "--png", png.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("tip"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert!(lines.next().unwrap().starts_with("s_mm,x_mm,y_mm"));
    assert_eq!(lines.count(), 49, "one row per solver node");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    assert!(bytes.len() > 10_000, "picture has content");
    // The picture is named where it went: after the report, or on stderr
    // with --json, whose stdout stays one JSON object.
    assert!(stdout.lines().last().unwrap().starts_with(&format!("wrote {}", png.display())), "{stdout}");
    let (ok, stdout, stderr) = run(&["simulate", "--routing", "0,4,1,2,-2", "--tension", "1.7", "--json", "--png", png.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("stdout is the JSON object alone");
    assert_eq!(v["status"], "ok");
    assert!(stderr.contains(&format!("wrote {}", png.display())), "{stderr}");
}

#[test]
fn bad_input_gets_a_clear_message_and_a_failure_exit() {
    let cases: &[(&[&str], &str)] = &[
        (&["simulate", "--routing", "1,2,3", "--tension", "1"], "exactly 5 control points"),
        (&["simulate", "--routing", "1,2,3,4,5", "--tension", "1"], "outside the body"),
        (&["simulate", "--routing", "1,2,x,4,1", "--tension", "1"], "'x' is not a number"),
        (&["simulate", "--routing", "1,2,3,4,1", "--tension", "-1"], "tension -1 N is invalid"),
        (&["simulate", "--routing", "1,2,3,4,1", "--tension", "1", "--ei-n-mm2", "0"], "ei_n_mm2"),
        (&["simulate", "--routing", "1,2,3,4,1", "--tension", "1", "--steps-per-span", "3"], "steps_per_span"),
        (&["simulate", "--routing", "1,2,3,4,1"], "--tension"),
    ];
    for (args, needle) in cases {
        let (ok, _, stderr) = run(args);
        assert!(!ok, "{args:?} should fail");
        assert!(stderr.contains(needle), "{args:?}: stderr {stderr:?} lacks {needle:?}");
    }
}

#[test]
fn bench_prints_figures() {
    let (ok, stdout, stderr) = run(&["bench", "--routings", "5", "--json"]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v.as_array().unwrap().len(), 2);
    assert!(v[0]["median_us_per_solve"].as_f64().unwrap() > 0.0);
}

/// a_0..a_2 of one simulated shape by the thesis route at a given order.
fn coefficients(order: &str, route: &str) -> Vec<f64> {
    let (ok, out, stderr) = run(&[
        "simulate", "--routing", "1,-2,4,4,-4", "--tension", "1.5", "--json", "--order", order, "--coefficients", route,
    ]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    (0..3).map(|i| v["a"][i].as_f64().unwrap()).collect()
}

/// The thesis route (§3.3) truncates eq. (3.12) at the requested order, so
/// on a real shape (whose a_3, a_4 are not small) its a_0..a_2 at order 2
/// are off by up to ~0.02 mm⁻¹; asking for a higher order removes the
/// truncation and leaves only the n_d = 40 resampling error.
#[test]
fn thesis_coefficient_route_converges_to_the_exact_one_with_order() {
    let exact = coefficients("2", "exact");
    assert_eq!(exact, coefficients("5", "exact")[..3].to_vec(), "exact route does not depend on the order");
    let worst = |route: &[f64]| (0..3).map(|i| (route[i] - exact[i]).abs()).fold(0.0, f64::max);
    let at2 = worst(&coefficients("2", "thesis"));
    let at8 = worst(&coefficients("8", "thesis"));
    eprintln!("thesis route vs exact, max |Δa_0..2|: order 2 {at2:.2e}, order 8 {at8:.2e} mm⁻¹");
    assert!(at2 < 3e-2, "order 2: {at2}");
    assert!(at8 < 5e-4, "order 8: {at8}");
    assert!(at8 < at2 / 10.0);
}

/// `simulate --json` as a user runs it, on every single-cable reference case
/// (tests/data/reference): by default the a_i are the thesis's (per unit rest
/// length, `a_thesis_per_mm`); with `--length-basis deformed`, `a_per_mm`.
#[test]
fn simulate_json_coefficients_match_the_reference_in_both_bases() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference");
    let mut checked = 0;
    for file in ["no-gravity.json", "gravity.json", "large-deformation.json"] {
        let doc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join(file)).unwrap()).unwrap();
        for case in doc["cases"].as_array().unwrap() {
            let routing: Vec<String> = case["routing_mm"].as_array().unwrap().iter().map(|v| v.to_string()).collect();
            let routing = routing.join(",");
            let tension = case["tension_N"].to_string();
            let mut args = vec!["simulate", "--routing", &routing, "--tension", &tension, "--json"];
            if case["gravity_N_per_mm"].as_f64().unwrap() == 0.0 {
                args.push("--no-gravity");
            }
            for (basis, key) in [(None, "a_thesis_per_mm"), (Some("deformed"), "a_per_mm")] {
                let mut all = args.clone();
                if let Some(b) = basis {
                    all.extend(["--length-basis", b]);
                }
                let (ok, stdout, stderr) = run(&all);
                assert!(ok, "{file} {routing} @ {tension}: {stderr}");
                let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
                assert_eq!(v["length_basis"], basis.unwrap_or("rest"));
                let want = case[key].as_array().unwrap();
                for (i, w) in want.iter().enumerate() {
                    let got = v["a"][i].as_f64().unwrap();
                    let w = w.as_f64().unwrap();
                    assert!((got - w).abs() < 1e-5, "{file} {routing} @ {tension}, {key}[{i}]: {got} vs {w}");
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 32, "only {checked} reference checks");
}

/// `diagnose` ends with the lines to paste: flags with the fitted rigidities
/// and effect, which `simulate` accepts as they are.
#[test]
fn diagnose_prints_pasteable_next_steps() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("friction.csv");
    let (ok, _, err) = run(&["synth", "--effect", "friction", "--magnitude", "0.1", "--out", data.to_str().unwrap()]);
    assert!(ok, "{err}");
    let (ok, out, err) = run(&["diagnose", data.to_str().unwrap(), "--no-report"]);
    assert!(ok, "{err}");
    assert!(out.starts_with("verdict: friction"), "{out}");
    let flags = out.lines().find_map(|l| l.trim().strip_prefix("simulate / design / calibrate flags: ")).unwrap_or_else(|| panic!("{out}"));
    assert!(flags.contains("--ei-n-mm2 ") && flags.contains("--friction-mu 0.0"), "{flags}");
    assert!(out.contains("[actuator.effects]") && out.contains("friction_mu = "), "{out}");
    let mut args = vec!["simulate", "--routing", "1,-2,3,0.5,-3", "--tension", "1.5", "--json"];
    args.extend(flags.split_whitespace());
    let (ok, out, err) = run(&args);
    assert!(ok, "{flags}: {err}");
    assert!(out.contains("\"tip_x_mm\""));
}

/// Without `--out`, the diagnosis report lands beside the data file, not in
/// the current directory.
#[test]
fn diagnose_report_goes_beside_the_data_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("lab.csv");
    let (ok, _, err) = run(&["synth", "--out", data.to_str().unwrap()]);
    assert!(ok, "{err}");
    let cwd = tempfile::tempdir().unwrap();
    let out = cablemap().current_dir(cwd.path()).args(["diagnose", data.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(dir.path().join("lab-diagnosis").join("report.md").exists());
    assert_eq!(std::fs::read_dir(cwd.path()).unwrap().count(), 0, "the current directory was written to");
}
