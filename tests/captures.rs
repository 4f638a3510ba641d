//! Several-cable captures with 3-D markers (issue 26): `predict` and
//! `calibrate --actuator` as a user runs them on the real SoRoMoX tentacle
//! (tests/data/soromox, MIT), and the 3-D fit's round trip on synthetic
//! captures whose truth is known.

use cablemap::calibrate::synth::captures::{default_plan, load_unload_plan, one_cable_at_a_time, synth_captures, MarkerSpec};
use cablemap::calibrate::diagnose::captures::diagnose_captures;
use cablemap::calibrate::diagnose::{DiagnoseSpec, Diagnosis};
use cablemap::calibrate::observations::captures::CapturesReport;
use cablemap::calibrate::observations::captures::files::{Capture, CaptureSet};
use cablemap::calibrate::fit::{fit, FitSpec, Loss, Status};
use cablemap::calibrate::observations::captures::Captures;
use cablemap::calibrate::Parameter;
use cablemap::calibrate::Effect;
use cablemap::solver::SolverOptions;
use cablemap::model::Actuator;
use std::path::PathBuf;
use std::process::Command;

fn cablemap(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cablemap")).args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn soromox(file: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/soromox").join(file).display().to_string()
}

fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("not JSON ({e}): {stdout}"))
}

/// `predict --json` on the real captures with `actuator`.
fn predict(actuator: &str) -> serde_json::Value {
    let (ok, stdout, stderr) = cablemap(&["predict", &soromox("captures.csv"), "--actuator", actuator, "--markers", &soromox("markers.csv"), "--json"]);
    assert!(ok, "{stderr}");
    json(&stdout)
}

fn by_marker(v: &serde_json::Value) -> Vec<(String, f64)> {
    v["rms_by_marker_mm"].as_object().unwrap().iter().map(|(k, x)| (k.clone(), x.as_f64().unwrap())).collect()
}

fn by_marker_text(v: &[(String, f64)]) -> String {
    v.iter().map(|(k, x)| format!("{k} {x:.2}")).collect::<Vec<_>>().join(", ")
}

#[test]
fn predict_reports_every_capture_and_marker_in_3d() {
    let v = predict(&soromox("actuator.toml"));
    let captures = v["captures"].as_array().unwrap();
    assert_eq!(captures.len(), 14);
    for c in captures {
        let markers = c["markers"].as_array().unwrap();
        assert_eq!(markers.len(), 4);
        let errors: Vec<f64> = markers.iter().map(|m| m["error_mm"].as_f64().unwrap()).collect();
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / 4.0).sqrt();
        assert!((c["rms_mm"].as_f64().unwrap() - rms).abs() < 1e-9, "{c}");
        assert!(c["measurement"].as_i64().is_some() && markers[3]["marker"] == "p4");
    }
    let markers = by_marker(&v);
    assert_eq!(markers.iter().map(|(k, _)| k.as_str()).collect::<Vec<_>>(), ["p1", "p2", "p3", "p4"]);
    println!("predict with the nominal materials: per-marker RMS {} mm, overall {:.2} mm", by_marker_text(&markers), v["rms_mm"].as_f64().unwrap());
    // The text form prints the same per-marker RMS.
    let (ok, stdout, _) = cablemap(&["predict", &soromox("captures.csv"), "--actuator", &soromox("actuator.toml"), "--markers", &soromox("markers.csv")]);
    assert!(ok && stdout.contains("RMS per marker: p1") && stdout.contains("capture   14"), "{stdout}");
}

#[test]
fn calibrate_fits_the_real_tentacle_and_its_actuator_predicts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("all");
    let (ok, stdout, stderr) = cablemap(&[
        "calibrate",
        &soromox("captures.csv"),
        "--actuator",
        &soromox("actuator.toml"),
        "--markers",
        &soromox("markers.csv"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("RMS per marker") && stdout.contains("calibrated.toml"), "{stdout}");
    let fit = json(&std::fs::read_to_string(out.join("fit.json")).unwrap());
    assert_eq!(fit["converged"], true, "{fit}");
    let params = fit["parameters"].as_array().unwrap();
    let param = |name: &str| params.iter().find(|p| p["name"] == name).unwrap_or_else(|| panic!("{name} in {fit}"));
    // EI and the weight are determined by the markers (at full weight).
    for name in ["ei_n_mm2", "density_g_cm3"] {
        let p = param(name);
        assert_eq!(p["status"], "fitted", "{p}");
        let (value, se) = (p["value"].as_f64().unwrap(), p["se"].as_f64().unwrap());
        assert!(value > 0.0 && se > 0.0 && se < 0.2 * value, "{p}");
    }
    // A parameter is fitted with a finite SE or reported undetermined at its start.
    for p in params {
        match p["status"].as_str().unwrap() {
            "fitted" => assert!(p["se"].as_f64().is_some_and(f64::is_finite), "{p}"),
            "undetermined" => assert_eq!(p["value"], p["start"], "{p}"),
            other => panic!("status {other}"),
        }
    }
    let fitted = by_marker(&fit);
    let nominal = by_marker(&predict(&soromox("actuator.toml")));
    println!("calibrate on all 14 captures: per-marker RMS {} mm (nominal materials {}; the authors' fit about 11 / 16 / 16 / 33 mm)", by_marker_text(&fitted), by_marker_text(&nominal));
    let rms = fit["rms_mm"].as_f64().unwrap();
    let nominal_rms = predict(&soromox("actuator.toml"))["rms_mm"].as_f64().unwrap();
    assert!(rms < 0.5 * nominal_rms, "the fit lowers the error: {rms} vs {nominal_rms}");
    // The calibrated actuator is an actuator file every command reads:
    // predict reproduces the fit's errors with it.
    let calibrated = out.join("calibrated.toml");
    let again = predict(calibrated.to_str().unwrap());
    assert!((again["rms_mm"].as_f64().unwrap() - rms).abs() < 1e-6, "{} vs {rms}", again["rms_mm"]);
    let (ok, _, stderr) = cablemap(&["simulate", "--actuator", calibrated.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    // The fit's residuals per capture and marker.
    let first = &fit["captures"][0]["markers"][0];
    assert!(first["residual_mm"].as_array().unwrap().len() == 3 && first["error_mm"].as_f64().is_some(), "{first}");
    assert!(fit["chi2"].as_f64().unwrap() > 0.0 && fit["dof"].as_u64().unwrap() > 0);
}

#[test]
fn calibrate_on_one_tendon_predicts_the_other() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t1");
    let (ok, stdout, stderr) = cablemap(&[
        "calibrate",
        &soromox("captures.csv"),
        "--actuator",
        &soromox("actuator.toml"),
        "--markers",
        &soromox("markers.csv"),
        "--holdout-cable",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(ok, "{stderr}");
    let fit = json(&stdout);
    assert_eq!(fit["converged"], true);
    assert_eq!(fit["captures_fitted"], 7);
    assert_eq!(fit["captures"].as_array().unwrap().len(), 7);
    let held = &fit["holdout"];
    assert_eq!(held["captures"].as_array().unwrap().len(), 7);
    let fitted = by_marker(&fit);
    let predicted = by_marker(held);
    println!("calibrate on tendon 1's 7 captures: fitted per-marker RMS {} mm; tendon 2's 7 predicted: {} mm", by_marker_text(&fitted), by_marker_text(&predicted));
    // predict with the calibrated actuator gives the same held-out errors.
    let all = predict(out.join("calibrated.toml").to_str().unwrap());
    for c in held["captures"].as_array().unwrap() {
        let same = all["captures"].as_array().unwrap().iter().find(|a| a["measurement"] == c["measurement"]).unwrap();
        assert!((same["rms_mm"].as_f64().unwrap() - c["rms_mm"].as_f64().unwrap()).abs() < 1e-6, "{same} vs {c}");
    }
    // A cable the actuator does not have is refused.
    let (ok, _, stderr) = cablemap(&["calibrate", &soromox("captures.csv"), "--actuator", &soromox("actuator.toml"), "--markers", &soromox("markers.csv"), "--holdout-cable", "3"]);
    assert!(!ok && stderr.contains("cable 3"), "{stderr}");
}

#[test]
fn bad_captures_and_markers_name_file_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let markers = dir.path().join("markers.csv");
    let mut text = std::fs::read_to_string(soromox("markers.csv")).unwrap();
    text = text.replacen("1,p2,219.5,0.0,-21.0,217.334", "1,p2,219.5,0.0,-21.0,abc", 1);
    std::fs::write(&markers, text).unwrap();
    let (ok, _, stderr) = cablemap(&["predict", &soromox("captures.csv"), "--actuator", &soromox("actuator.toml"), "--markers", markers.to_str().unwrap()]);
    assert!(!ok && stderr.contains("markers.csv") && stderr.contains("row 2") && stderr.contains("'x_mm'"), "{stderr}");
    // Rod flags are refused: the rod is the actuator file's.
    let (ok, _, stderr) = cablemap(&["predict", &soromox("captures.csv"), "--actuator", &soromox("actuator.toml"), "--markers", &soromox("markers.csv"), "--ei-n-mm2", "100"]);
    assert!(!ok && stderr.contains("[rod]"), "{stderr}");
}

/// The tentacle with the authors' identified materials: the truth of the
/// synthetic round trip (not the file's start, so the fit has to move).
fn tentacle_truth() -> Actuator {
    let mut a = Actuator::read(std::path::Path::new(&soromox("actuator.toml"))).unwrap();
    a.rod.ei_n_mm2 = 13955.3;
    a.rod.ea_n = 235.07;
    a.rod.ga_n = 81.06;
    a.gj_n_mm2 = Some(9624.4);
    a.rod.density_g_cm3 = 1.3177;
    a
}

#[test]
fn the_3d_fit_recovers_the_rigidities_within_their_standard_errors() {
    let truth = tentacle_truth();
    let options = SolverOptions::default();
    let markers = soromox_markers();
    let captures = one_cable_at_a_time(2, &[1.5, 3.0, 4.5, 6.0, 7.5], 5.0);
    let set = synth_captures(&truth, &options, captures, &markers, 1.0, 7, false).unwrap();
    let start = Actuator::read(std::path::Path::new(&soromox("actuator.toml"))).unwrap();
    let spec = FitSpec { params: Parameter::BODY.to_vec(), held: Vec::new(), loss: Loss::Squared, max_iterations: 40 };
    let fit = fit(&start, &Captures::new(&set, 1.0, &options), &spec, &mut |_| {}).unwrap();
    assert!(fit.converged, "{}", fit.report.termination);
    for f in &fit.parameters {
        let want = f.param.get(&truth);
        println!("{}: {:?} {} ± {} (truth {want}, start {})", f.name, f.status, f.value, f.se, f.start);
    }
    for p in Parameter::BODY {
        let f = fit.parameter(p).unwrap();
        let want = p.get(&truth);
        match f.status {
            Status::Fitted => assert!((f.value - want).abs() <= 2.0 * f.se, "{}: {} ± {} vs truth {want}", f.name, f.value, f.se),
            Status::Undetermined => assert_eq!(f.value, f.start),
            Status::AtBound | Status::Held => panic!("{} is no effect and was not held", f.name),
        }
    }
    for p in [Parameter::Ei, Parameter::Density] {
        let f = fit.parameter(p).unwrap();
        assert!(f.status == Status::Fitted && f.se < 0.05 * p.get(&truth), "{f:?}");
    }
    // 1 mm noise: χ²/dof near 1 and the marker RMS near √3 mm.
    assert!((0.6..1.5).contains(&fit.reduced_chi2), "{}", fit.reduced_chi2);
    assert!((1.2..2.3).contains(&fit.errors.rms_mm), "{}", fit.errors.rms_mm);
}

/// The SoRoMoX markers: three on stalks, one 8 mm beyond the tip.
fn soromox_markers() -> Vec<MarkerSpec> {
    vec![MarkerSpec::new("p1", 129.1, 0.0, 25.0), MarkerSpec::new("p2", 219.5, 0.0, -21.0), MarkerSpec::new("p3", 280.0, 0.0, 20.0), MarkerSpec::new("p4", 368.0, 0.0, 0.0)]
}

/// Synthetic captures of the tentacle (the file's materials) with `hidden`
/// applied to the truth: each tendon alone at three levels, both at three
/// pairs and one capture at rest, the four SoRoMoX markers, 1 mm noise.
fn hidden(effect: impl Fn(&mut Actuator)) -> (Actuator, CaptureSet) {
    // Each tendon alone at 2, 4.5, 7 N, at rest, and both at (4, 4), (7, 3),
    // (3, 7) N: the pairs bend the body out of either tendon's plane, which
    // separates effects on the cables' tension from effects on the body
    // (stiffening, a gradient).
    let captures = default_plan(2, 7.0, 5.0);
    assert_eq!(captures.len(), 10);
    hidden_in(effect, captures, &soromox_markers())
}

/// As [`hidden`], with the given captures and markers.
fn hidden_in(effect: impl Fn(&mut Actuator), captures: Vec<Capture>, markers: &[MarkerSpec]) -> (Actuator, CaptureSet) {
    let start = Actuator::read(std::path::Path::new(&soromox("actuator.toml"))).unwrap();
    let mut truth = start.clone();
    effect(&mut truth);
    let set = synth_captures(&truth, &SolverOptions::default(), captures, markers, 1.0, 3, false).unwrap();
    (start, set)
}

fn diagnosis(start: &Actuator, set: &CaptureSet) -> Diagnosis<CapturesReport> {
    let spec = DiagnoseSpec { settings: 1.0, ..DiagnoseSpec::default() };
    let d = diagnose_captures(start, set, &spec).unwrap();
    println!("{d}");
    d
}

#[test]
fn diagnose_names_a_hidden_clamp_compliance_in_3d() {
    // How precisely captures determine a clamp spring depends on how soft it
    // is: the tendons' moment at the clamp is partly cancelled by the curled
    // body's weight at high tension, so a stiff spring barely turns the base
    // (800 N·mm/rad: 0.7° more tip angle at 7 N; from these ten captures,
    // fitted 1127 ± 346, SE 30 %). At 400 N·mm/rad (a grip as soft as 56 mm
    // of the base section) the SE is about 20 % and it is named within
    // ±25 % (492 ± 100 with this seed: the noise's offset, not a bias —
    // noise-free captures give back 400.000).
    let k = 400.0;
    let (start, set) = hidden(|a| Effect::ClampCompliance.apply(&mut a.rod, k));
    let d = diagnosis(&start, &set);
    assert_eq!(d.verdict.label(), "clamp_compliance", "{}", d.reason);
    let (got, se) = (d.named[0].parameter, d.named[0].parameter_se);
    println!("hidden clamp stiffness {k} N·mm/rad: named at {got:.1} ± {se:.1}");
    assert!((got - k).abs() <= 0.25 * k, "{got} ± {se} vs {k}: not within ±25 %");
    assert!((got - k).abs() <= 2.0 * se, "{got} ± {se} vs {k}: not within 2 SE");
}

#[test]
fn diagnose_names_a_hidden_friction_in_3d() {
    let mu = 0.15;
    // Static captures alone leave friction's BIC lead over stiffening below
    // the margin (both make the bend sublinear in tension); a load/unload
    // protocol, the diagnosis's separating measurement, shows the loop
    // only friction opens.
    let (start, set) = hidden_in(|a| Effect::Friction.apply(&mut a.rod, mu), load_unload_plan(2, 7.0, 5.0), &soromox_markers());
    let d = diagnosis(&start, &set);
    assert_eq!(d.verdict.label(), "friction", "{}", d.reason);
    let (got, se) = (d.named[0].parameter, d.named[0].parameter_se);
    println!("hidden friction μ {mu}: named at {got:.4} ± {se:.4}");
    assert!((got - mu).abs() <= 0.25 * mu, "{got} ± {se} vs {mu}: not within ±25 %");
}

#[test]
fn diagnose_finds_nothing_in_null_data_and_no_library_effect_in_a_curved_rod() {
    let (start, set) = hidden(|_| {});
    let d = diagnosis(&start, &set);
    assert_eq!(d.verdict.label(), "none", "{}", d.reason);
    let (start, set) = hidden(|a| a.rod.rest_curvature_per_mm = 1.0 / 1500.0);
    let d = diagnosis(&start, &set);
    assert_eq!(d.verdict.label(), "unexplained", "{}", d.reason);
    assert!(d.signature.is_some());
}

#[test]
fn diagnose_cli_on_the_real_tentacle_prints_a_verdict_and_writes_its_report() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report");
    let (ok, stdout, stderr) = cablemap(&[
        "diagnose",
        &soromox("captures.csv"),
        "--actuator",
        &soromox("actuator.toml"),
        "--markers",
        &soromox("markers.csv"),
        "--holdout-cable",
        "2",
        "--out",
        report.to_str().unwrap(),
        "--json",
    ]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    // The report: the verdict, the candidates, the fits' values, the per-marker RMS.
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    for part in ["## Verdict: ", "## Candidates", "| rank | effect |", "### Body fit", "`ei_n_mm2`", "## Per-marker RMS", "| p4 |", "## Held out"] {
        assert!(md.contains(part), "{part} in {md}");
    }
    assert!(md.contains(&format!("## Verdict: {}", v["verdict"].as_str().unwrap())), "{md}");
    // A picture per capture, of the captures of every cable (held out or fitted), each its own.
    let captures = std::fs::read_to_string(soromox("captures.csv")).unwrap();
    let mut pictures = Vec::new();
    for line in captures.lines().skip(1) {
        let id: i64 = line.split(',').next().unwrap().parse().unwrap();
        let picture = report.join(format!("capture_{id}.png"));
        let bytes = std::fs::read(&picture).unwrap_or_else(|e| panic!("{}: {e}", picture.display()));
        assert!(bytes.starts_with(b"\x89PNG") && md.contains(&format!("](capture_{id}.png)")), "capture {id}");
        pictures.push(bytes);
    }
    assert_eq!(pictures.len(), 14);
    for cable in ["cables pulling: 1)", "cables pulling: 2)"] {
        assert_eq!(md.matches(cable).count(), 7, "{cable} in {md}");
    }
    assert!(pictures[0] != pictures[7] && pictures[0] != pictures[6], "each capture's picture draws its own body");
    // What the verdict is on real data is the tool's to say; the fit is asserted.
    assert!(["none", "unexplained", "inconclusive", "ambiguous"].contains(&v["verdict"].as_str().unwrap()) || v["parameter_name"].is_string(), "{v}");
    assert_eq!(v["baseline"]["converged"], true);
    assert!(v["holdout_rms_before"].as_f64().is_some() && v["candidates"].as_array().unwrap().len() >= 5, "{v}");
    println!("diagnose on the real tentacle (fit on tendon 1, tendon 2 held out): verdict {}: {}", v["verdict"], v["reason"]);
}

/// The SoRoMoX actuator file with the authors' identified materials (the
/// truth of the round trip through the binary), as text.
fn truth_toml() -> String {
    let text = std::fs::read_to_string(soromox("actuator.toml")).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        let replaced = match line.split(" = ").next().unwrap() {
            "gj_n_mm2" => "gj_n_mm2 = 9624.4",
            "ei_n_mm2" => "ei_n_mm2 = 13955.3",
            "ea_n" => "ea_n = 235.07",
            "ga_n" => "ga_n = 81.06",
            "density_g_cm3" => "density_g_cm3 = 1.3177",
            _ => line,
        };
        out.push_str(replaced);
        out.push('\n');
    }
    out
}

#[test]
fn synth_captures_then_calibrate_recovers_the_rigidities_through_the_binary() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).display().to_string();
    std::fs::write(path("truth.toml"), truth_toml()).unwrap();
    let synth = |extra: &[&str], out: &str, markers: &str| {
        let (truth, out, markers) = (path("truth.toml"), path(out), path(markers));
        let mut args = vec!["synth", "--actuator", &truth];
        args.extend(["--out", &out, "--markers-out", &markers, "--noise-mm", "1", "--seed", "7", "--tension-max-n", "7"]);
        args.extend(extra);
        cablemap(&args)
    };
    let (ok, _, stderr) = synth(&[], "captures.csv", "markers.csv");
    assert!(ok, "{stderr}");
    assert!(stderr.contains("wrote 10 captures") && stderr.contains("4 markers each"), "{stderr}");
    // The documented format: both tendons' columns, the four default markers.
    let captures = std::fs::read_to_string(path("captures.csv")).unwrap();
    assert!(captures.starts_with("measurement,tension_1_n,tension_2_n,direction,step,dwell_s\n"), "{captures}");
    assert!(captures.contains(",4,4,static,") && captures.contains(",0,0,static,"), "pairs and rest: {captures}");
    let markers = std::fs::read_to_string(path("markers.csv")).unwrap();
    assert_eq!(markers.lines().count(), 1 + 10 * 4, "{markers}");
    assert!(markers.starts_with("measurement,marker,s_mm,offset_y_mm,offset_z_mm,x_mm,y_mm,z_mm"), "{markers}");
    // An existing file is kept.
    let (ok, _, stderr) = synth(&[], "captures.csv", "markers.csv");
    assert!(!ok && stderr.contains("exists"), "{stderr}");
    // Calibrate from the file's nominal materials: the truth within two standard errors.
    let (ok, stdout, stderr) = cablemap(&["calibrate", &path("captures.csv"), "--actuator", &soromox("actuator.toml"), "--markers", &path("markers.csv"), "--noise-mm", "1", "--json"]);
    assert!(ok, "{stderr}");
    let fit = json(&stdout);
    assert_eq!(fit["converged"], true, "{fit}");
    let truth = [("ei_n_mm2", 13955.3), ("ea_n", 235.07), ("ga_n", 81.06), ("gj_n_mm2", 9624.4), ("density_g_cm3", 1.3177)];
    let mut fitted = 0;
    for p in fit["parameters"].as_array().unwrap() {
        let want = truth.iter().find(|(n, _)| p["name"] == *n).unwrap().1;
        println!("synth → calibrate: {} = {} ± {} (truth {want}, {})", p["name"], p["value"], p["se"], p["status"]);
        if p["status"] == "fitted" {
            let (value, se) = (p["value"].as_f64().unwrap(), p["se"].as_f64().unwrap());
            assert!((value - want).abs() <= 2.0 * se, "{p} vs truth {want}");
            fitted += 1;
        }
    }
    assert!(fitted >= 3, "EI, EA and the weight at least: {fit}");
    assert!((0.6..1.5).contains(&fit["reduced_chi2"].as_f64().unwrap()), "{}", fit["reduced_chi2"]);
    // A hidden effect by NAME=VALUE, and markers where asked.
    let (ok, _, stderr) = synth(&["--effect", "clamp_compliance=800", "--markers-at", "a:100:0:20;tip:360:0:0"], "c2.csv", "m2.csv");
    assert!(ok && stderr.contains("hidden effect: clamp_compliance = 800") && stderr.contains("2 markers each"), "{stderr}");
    let (ok, _, stderr) = synth(&["--routings", "a:1,1,1,1,1"], "c3.csv", "m3.csv");
    assert!(!ok && stderr.contains("--routings"), "{stderr}");
}

/// The planar projection of the tentacle (`tests/data/soromox/planar/`,
/// written by `scripts/soromox-planar.py`: each capture in its tendon's
/// bending plane) is what the planar `calibrate` and `diagnose` read; the
/// committed files are the script's output, and the planar fit converges
/// at full weight on the tapered, anchored body its header gives.
#[test]
fn the_planar_projection_of_the_tentacle_is_the_scripts_output_and_calibrates() {
    let dir = tempfile::tempdir().unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scripts/soromox-planar.py");
    let out = Command::new("python3").arg(&script).arg(soromox("")).arg(dir.path()).output().expect("python3 runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for file in ["readings.csv", "markers.csv"] {
        let committed = std::fs::read_to_string(soromox(&format!("planar/{file}"))).unwrap();
        let made = std::fs::read_to_string(dir.path().join(file)).unwrap();
        assert_eq!(committed, made, "planar/{file} is not scripts/soromox-planar.py's output: run the script again");
    }
    let (ok, stdout, stderr) = cablemap(&["calibrate", &soromox("planar/readings.csv"), "--markers", &soromox("planar/markers.csv"), "--noise-mm", "5", "--fix", "ga_n=129.9118", "--json"]);
    assert!(ok, "{stderr}");
    let fit = json(&stdout);
    assert_eq!(fit["converged"], true, "{fit}");
    let routing = &fit["per_routing"][0];
    assert_eq!(routing["rows"], 14, "{routing}");
    let ei = fit["parameters"].as_array().unwrap().iter().find(|p| p["name"] == "ei_n_mm2").unwrap();
    let (value, se) = (ei["value"].as_f64().unwrap(), ei["se"].as_f64().unwrap());
    println!("planar projection: EI {value:.0} ± {se:.0} N·mm², tip RMS {:.2} mm, angle RMS {:.2}°", routing["rms_position_mm"], routing["rms_angle_deg"]);
    // Softer than the nominal 22 366 N·mm² (the captures bend more than the
    // nominal model), as the 3-D fit finds.
    assert!(value > 0.0 && se < 0.1 * value && value < 22366.18, "{ei}");
    assert!(routing["rms_position_mm"].as_f64().unwrap() < 40.0, "{routing}");
}
