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
fn an_output_in_a_missing_folder_is_named_before_the_solve() {
    let dir = tempfile::tempdir().unwrap();
    for flag in ["--png", "--csv"] {
        let path = dir.path().join("missing").join("x.out");
        let (ok, stdout, stderr) = run(&["simulate", "--routing", "1,1,1,1,1", "--tension-n", "1", flag, path.to_str().unwrap()]);
        assert!(!ok && stdout.is_empty(), "{flag}: {stdout}");
        assert!(stderr.contains(flag) && stderr.contains("does not exist") && !stderr.contains("IoError"), "{flag}: {stderr}");
    }
}

#[test]
fn a_negative_tolerance_is_refused_for_targets_files_too() {
    let dir = tempfile::tempdir().unwrap();
    let targets = dir.path().join("t.toml");
    std::fs::write(&targets, "[[target]]\ntip_mm = { x = 50, y = 5 }\n").unwrap();
    let (ok, _, stderr) = run(&["design", "--targets", targets.to_str().unwrap(), "--tolerance-pct", "-1"]);
    assert!(!ok && stderr.contains("--tolerance-pct") && stderr.contains("≥ 0 %"), "{stderr}");
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
    assert!(ok && !err.contains("warning"), "a visible effect gets no warning: {err}");
    let (ok, out, err) = run(&["diagnose", data.to_str().unwrap(), "--no-report"]);
    assert!(ok, "{err}");
    assert!(out.starts_with("verdict: friction"), "{out}");
    // The candidate table stays aligned past `stiffness_gradient`.
    let candidates: Vec<&str> =
        out.lines().skip_while(|l| !l.starts_with("candidates")).skip(1).take_while(|l| l.starts_with("  ")).collect();
    let columns: Vec<Option<usize>> = candidates.iter().map(|l| l.find("ΔBIC").map(|i| l[..i].chars().count())).collect();
    assert!(candidates.len() == 7 && columns.iter().all(|c| c.is_some() && *c == columns[0]), "{out}");
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

// --- advice: wrong advice and formatting (issue "What a new user and a hostile probe found") ---

/// The folder `map --out DIR` writes holds the run in `DIR/run` and the map
/// in `DIR/map`: every command given the wrong one of the three says which
/// to give, and the summaries print numbers and ranges as people write them.
#[test]
fn the_map_folder_its_run_and_its_map_are_told_apart() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("thesis");
    let d = dir.to_str().unwrap();
    let (run_dir, map_dir) = (format!("{d}/run"), format!("{d}/map"));
    let quick = concat!(env!("CARGO_MANIFEST_DIR"), "/jobs/quick.toml");
    let (ok, out, err) = run(&["map", quick, "--out", d]);
    assert!(ok, "{err}");
    // `map` reduces by itself: no advice to reduce half-way.
    assert!(!out.contains("next: cablemap reduce"), "{out}");
    // Mode boundaries to a few significant digits (summary.json keeps them all).
    let modes = out.lines().find(|l| l.contains("modes by")).unwrap_or_else(|| panic!("{out}"));
    let longest_digits = modes.split(|c: char| !c.is_ascii_digit()).map(str::len).max().unwrap();
    assert!(longest_digits <= 6 && modes.contains("a0 [") && modes.contains("a1 ["), "{modes}");
    let other = tmp.path().join("other");
    let o = other.to_str().unwrap();
    let refused = |args: &[&str]| -> String {
        let (ok, out, err) = run(args);
        assert!(!ok, "{args:?} was accepted: {out}");
        err
    };
    for command in [&["reduce", d, "--out", o][..], &["status", d]] {
        let err = refused(command);
        assert!(err.contains(&format!("give {run_dir}")) && !err.contains("cablemap sweep SPEC"), "{command:?}: {err}");
    }
    for command in [&["reduce", &map_dir, "--out", o][..], &["status", &map_dir]] {
        let err = refused(command);
        let named = err.contains(&format!("{map_dir} is a map")) && err.contains(&format!("made from the run {run_dir}"));
        assert!(named, "{command:?}: {err}");
    }
    let err = refused(&["feasible", "--map", d, "--target", "x=50,y=5"]);
    assert!(err.contains(&format!("give {map_dir}")), "{err}");
    let typo = format!("{d}/rn");
    let err = refused(&["reduce", &typo, "--out", o]);
    assert!(err.contains(&format!("{typo} holds no sweep: it does not exist")) && err.contains(&run_dir), "{err}");
    assert!(!err.contains("manifest.json is missing"), "{err}");
    assert!(!other.exists());
    // `status` names the coefficients a_0…a_3, not a Rust range.
    let (ok, out, err) = run(&["status", &run_dir]);
    assert!(ok && out.contains("a_0…a_3") && !out.contains("0..="), "{out}{err}");
    // The `sweep` command itself still says what comes next.
    let (ok, out, err) = run(&["sweep", quick, "--out", &run_dir, "--quiet"]);
    assert!(ok && out.contains(&format!("next: cablemap reduce {run_dir} --out MAP_DIR")), "{out}{err}");
}

/// An unknown flag gets the flag one typo away (`--pgn` is `--png` with two
/// letters swapped), not clap's pick by Jaro similarity (`--ga-n`).
#[test]
fn a_mistyped_flag_is_answered_with_the_flag_meant() {
    let (ok, _, err) = run(&["simulate", "--routing", "1,1,1,1,1", "--tension-n", "1", "--pgn", "x.png"]);
    assert!(!ok && err.contains("'--png'") && !err.contains("ga-n"), "{err}");
    // Where clap's suggestion is already the nearest, it stays.
    let (ok, _, err) = run(&["simulate", "--routing", "1,1,1,1,1", "--tension-n", "1", "--jsn"]);
    assert!(!ok && err.contains("'--json'"), "{err}");
}

/// Standard errors print as plain decimals (`± 0.0512`), not `± 5.1200e-2`.
#[test]
fn calibrate_prints_standard_errors_as_plain_decimals() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("d.csv");
    let routings = "a:3,2.5,2,1.5,1;s:-2,-3,0,3,3.5";
    let (ok, _, err) = run(&["synth", "--out", data.to_str().unwrap(), "--routings", routings, "--load-steps", "3"]);
    assert!(ok, "{err}");
    let (ok, out, err) = run(&["calibrate", data.to_str().unwrap()]);
    assert!(ok, "{err}");
    let errors: Vec<&str> = out.lines().filter_map(|l| l.split_once(" ± ").map(|(_, se)| se.trim())).collect();
    assert_eq!(errors.len(), 3, "EA, GA, EI: {out}");
    for se in errors {
        assert!(se.parse::<f64>().is_ok_and(|v| v > 0.0) && !se.contains('e'), "'{se}' in {out}");
    }
}

/// `synth` warns when the hidden effect is smaller than the noise can show:
/// stiffening α = 3 on the 360 mm tentacle moves no tip coordinate by 0.8 mm
/// (2 × the 0.4 mm noise), so a diagnosis answers `none`.
#[test]
fn synth_warns_when_the_noise_hides_the_effect() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("t.csv");
    let tentacle = ["--length-mm", "360", "--radius-profile-mm", "0:15.4,305:6.4,360:4.8", "--cable-anchor-mm", "305"];
    let mut args = vec!["synth", "--out", data.to_str().unwrap(), "--effect", "stiffening", "--magnitude", "3"];
    args.extend(tentacle);
    let (ok, _, err) = run(&args);
    assert!(ok, "{err}");
    assert!(err.contains("warning: the hidden effect moves the simulated tips by at most 0.") && err.contains("(sd 0.4 mm, 1°)"), "{err}");
    // With less noise the same effect shows, and no warning is given.
    args.extend(["--noise-mm", "0.1", "--noise-deg", "0.2", "--force"]);
    let (ok, _, err) = run(&args);
    assert!(ok && !err.contains("warning"), "{err}");
}
