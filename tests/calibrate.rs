//! `synth`, `calibrate` and `diagnose` as a user runs them.

use std::path::Path;
use std::process::Command;

fn cablemap(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cablemap")).args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn synth(path: &Path, extra: &[&str]) {
    let mut args = vec!["synth", "--out", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    let (ok, _, stderr) = cablemap(&args);
    assert!(ok, "synth failed: {stderr}");
}

fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.trim()).unwrap_or_else(|e| panic!("not JSON ({e}): {stdout}"))
}

/// The true rigidities the synthetic data are made with (not the defaults,
/// so the fit has to move).
const TRUTH: [(&str, &str, f64); 3] = [("--ea-n", "ea_n", 30.0), ("--ga-n", "ga_n", 1.5), ("--ei-n-mm2", "ei_n_mm2", 100.0)];

fn truth_args() -> Vec<String> {
    TRUTH.iter().flat_map(|(flag, _, v)| [flag.to_string(), v.to_string()]).collect()
}

#[test]
fn calibrate_recovers_rigidities_from_noise_free_data() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("clean.csv");
    let t = truth_args();
    let mut extra: Vec<&str> = vec!["--noise-mm", "0", "--noise-deg", "0", "--routings", "a:3,2.5,2,1.5,1;s:-2,-3,0,3,3.5;st:2,2,2,2,2"];
    extra.extend(t.iter().map(|s| s.as_str()));
    synth(&data, &extra);
    let (ok, stdout, stderr) = cablemap(&["calibrate", data.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    let params = v["parameters"].as_array().unwrap();
    for ((_, name, want), p) in TRUTH.iter().zip(params) {
        assert_eq!(p["name"], *name);
        let got = p["value"].as_f64().unwrap();
        assert!(((got - want) / want).abs() < 1e-6, "{name}: {got} vs {want}");
    }
    assert_eq!(v["per_routing"].as_array().unwrap().len(), 3);
    // The human-readable form names every parameter with its SE.
    let (ok, stdout, _) = cablemap(&["calibrate", data.to_str().unwrap(), "--holdout", "st"]);
    assert!(ok);
    assert!(stdout.contains("ei_n_mm2") && stdout.contains("±") && stdout.contains("(held out)"), "{stdout}");
}

#[test]
fn bad_files_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let head = "measurement,routing,y0_mm,y1_mm,y2_mm,y3_mm,y4_mm,tension_n,direction,step,dwell_s,tip_x_mm,tip_y_mm,tip_angle_rad";
    let good = "1,a,1,1,1,1,1,0,rest,0,5,65,0,0";
    let cases: &[(&str, String, &[&str])] = &[
        ("missing column", "measurement,routing,y0_mm\n1,a,1\n".to_string(), &["y1_mm", "missing column"]),
        ("bad number", format!("{head}\n{good}\n2,a,1,1,1,1,1,abc,load,1,5,60,1,0.1\n"), &["row 2", "tension_n", "abc"]),
        ("bad direction", format!("{head}\n{good}\n2,a,1,1,1,1,1,1,up,1,5,60,1,0.1\n"), &["row 2", "direction"]),
        ("negative dwell", format!("{head}\n{good}\n2,a,1,1,1,1,1,1,load,1,-5,60,1,0.1\n"), &["row 2", "dwell_s"]),
        ("short row", format!("{head}\n{good}\n2,a,1,1\n"), &["row 2", "fields"]),
        ("outside the body", format!("{head}\n1,a,1,1,9,1,1,0,rest,0,5,65,0,0\n2,a,1,1,9,1,1,1,load,1,5,60,1,0.1\n"), &["routing 'a'", "row 1", "y2"]),
        ("empty", String::new(), &["no data rows"]),
    ];
    for (what, text, needles) in cases {
        let path = dir.path().join("bad.csv");
        std::fs::write(&path, text).unwrap();
        let (ok, _, stderr) = cablemap(&["calibrate", path.to_str().unwrap()]);
        assert!(!ok, "{what}: should fail");
        for n in *needles {
            assert!(stderr.contains(n), "{what}: '{n}' not in: {stderr}");
        }
    }
    let (ok, _, stderr) = cablemap(&["calibrate", dir.path().join("nope.csv").to_str().unwrap()]);
    assert!(!ok && stderr.contains("nope.csv"), "{stderr}");
    // A holdout that does not exist, and one that leaves nothing to fit.
    let path = dir.path().join("one.csv");
    synth(&path, &["--routings", "only:1,1,1,1,1", "--load-steps", "2"]);
    let (ok, _, stderr) = cablemap(&["diagnose", path.to_str().unwrap(), "--holdout", "other", "--no-report"]);
    assert!(!ok && stderr.contains("no routing 'other'") && stderr.contains("only"), "{stderr}");
    let (ok, _, stderr) = cablemap(&["diagnose", path.to_str().unwrap(), "--holdout", "only", "--no-report"]);
    assert!(!ok && stderr.contains("only routing"), "{stderr}");
    let (ok, _, stderr) = cablemap(&["synth", "--out", path.to_str().unwrap(), "--effect", "magic", "--magnitude", "1"]);
    assert!(!ok && stderr.contains("unknown effect"), "{stderr}");
}

#[test]
fn diagnose_writes_a_report_with_plots() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("d.csv");
    let lines = dir.path().join("c.csv");
    let mut args = vec!["--effect", "channel_offset", "--magnitude", "0.4", "--seed", "5", "--centreline-out", lines.to_str().unwrap()];
    args.extend(DIAGNOSIS_SOLVER);
    synth(&data, &args);
    let out = dir.path().join("report");
    let (data_arg, lines_arg, out_arg) = (data.to_str().unwrap(), lines.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec!["diagnose", data_arg, "--holdout", "arc", "--centrelines", lines_arg, "--out", out_arg, "--json"];
    args.extend(DIAGNOSIS_SOLVER);
    let (ok, stdout, stderr) = cablemap(&args);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    assert_eq!(v["verdict"], "channel_offset");
    for key in ["parameter", "parameter_se", "holdout_rms_before", "holdout_rms_after"] {
        assert!(v[key].is_f64(), "{key}: {v}");
    }
    assert_eq!(v["candidates"].as_array().unwrap().len(), 7, "one per candidate effect");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("channel_offset") && md.contains("| rank |") && md.contains("Criterion"), "{md}");
    // Measured and simulated shape coefficients side by side, in the thesis basis.
    assert!(md.contains("| measured |") && md.contains("per unit rest length"), "{md}");
    assert!(md.contains("χ²/dof") && md.contains("× smaller"), "{md}");
    for png in ["residuals.png", "loops.png", "shapes.png"] {
        let bytes = std::fs::read(out.join(png)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000, "{png}");
    }
}

/// Solver resolution of the diagnosis tests, for synthesis and fits alike: 8
/// collocation intervals per span instead of the default 10 (6 is refused by
/// the solver's own error estimate on the s-curve routing at 0.4 N). The tip
/// is then well within 2.7e-4 mm of the converged solve (docs/performance.md,
/// "Accuracy"), far below the 0.4 mm noise, so verdicts, parameters and
/// held-out errors are the default resolution's for less CPU. Stiffening
/// solves use at least 16 intervals either way. Not for the glue joint: see
/// [`solver_for`].
const DIAGNOSIS_SOLVER: [&str; 2] = ["--nodes-per-span", "8"];

/// The solver flags for data with `effect` hidden: [`DIAGNOSIS_SOLVER`],
/// except for the glue joint, a stiff 5 mm at the clamp, which 6 intervals
/// per span resolve visibly less finely (χ²/dof of the thesis model 6.75
/// instead of 7.10 on seed 11), so it keeps the default resolution.
fn solver_for(effect: &str) -> &'static [&'static str] {
    if effect == "glue_joint" {
        &[]
    } else {
        &DIAGNOSIS_SOLVER
    }
}

/// One diagnosis job: hidden effect, magnitude, seed, and whether the
/// centreline file enters the fit.
type Job = (&'static str, f64, u64, bool);

/// Synthesises and diagnoses each job on two worker threads (the machine
/// has two cores); returns the JSON answers in job order. With
/// `same_data`, centreline points are generated for every job (the noise
/// stream then matches), so tip-only and tip+shape jobs see the same tips.
fn diagnose_jobs(dir: &Path, jobs: &[Job], same_data: bool) -> Vec<serde_json::Value> {
    let t = truth_args();
    let mut out: Vec<(usize, serde_json::Value)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..2)
            .map(|w| {
                let t = &t;
                scope.spawn(move || {
                    jobs.iter()
                        .enumerate()
                        .skip(w)
                        .step_by(2)
                        .map(|(k, &(effect, magnitude, seed, shapes))| {
                            let path = dir.join(format!("{effect}-{magnitude}-{seed}-{shapes}.csv"));
                            let lines = dir.join(format!("{effect}-{magnitude}-{seed}-{shapes}-c.csv"));
                            let (m, s) = (magnitude.to_string(), seed.to_string());
                            let mut args: Vec<&str> = vec!["--seed", &s, "--effect", effect];
                            if effect != "none" {
                                args.extend(["--magnitude", &m]);
                            }
                            if shapes || same_data {
                                args.extend(["--centreline-out", lines.to_str().unwrap()]);
                            }
                            args.extend(t.iter().map(|s| s.as_str()));
                            args.extend(solver_for(effect));
                            synth(&path, &args);
                            let mut d = vec!["diagnose", path.to_str().unwrap(), "--holdout", "arc", "--no-report", "--json"];
                            d.extend(solver_for(effect));
                            if shapes {
                                d.extend(["--centrelines", lines.to_str().unwrap()]);
                            }
                            let (ok, stdout, stderr) = cablemap(&d);
                            assert!(ok, "{effect} seed {seed}: {stderr}");
                            (k, json(&stdout))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    out.sort_by_key(|(k, _)| *k);
    out.into_iter().map(|(_, v)| v).collect()
}

/// For every effect and the null case, over several seeds, at magnitudes a
/// few times the detection limit: the verdict names the hidden effect (none
/// for the null case), the parameter is within ±25 % and the held-out error
/// shrinks at least 1.5×. Effects outside the candidate list (a rod cured
/// pre-curved, a stiff glue joint at the clamp), with and without centreline
/// data, get `unexplained`: not `none`, not a wrong name (except that the
/// glue joint, a stiffness varying along s, may be named
/// `stiffness_gradient` from tip data alone, never with centrelines).
/// Prints the confusion matrix.
#[test]
fn diagnose_names_the_hidden_effect_and_admits_what_it_cannot_name() {
    // (effect, magnitude): about five times the probes near the detection
    // limit listed in docs/measurements.md (default protocol and noise).
    let library: [(&str, f64); 8] = [
        ("none", 0.0),
        ("friction", 0.08),
        ("gravity", 2.0),
        ("stiffening", 3.0),
        ("clamp_compliance", 20.0),
        ("channel_offset", 0.4),
        ("creep", 0.2),
        // β = ln 0.5: EI halves from clamp to tip.
        ("stiffness_gradient", std::f64::consts::LN_2 * -1.0),
    ];
    // Out of the library: rest curvature 0.004 /mm over the whole rod, and
    // EI × 5 over the first 5 mm.
    let outside: [(&str, f64); 2] = [("rest_curvature", 0.004), ("glue_joint", 5.0)];
    let verdicts =
        ["none", "friction", "gravity", "stiffening", "clamp_compliance", "channel_offset", "creep", "stiffness_gradient", "ambiguous", "unexplained", "inconclusive"];
    let seeds = [11u64, 12, 13];
    let mut jobs: Vec<Job> = library.iter().flat_map(|&(e, m)| seeds.iter().map(move |&s| (e, m, s, false))).collect();
    for &(e, m) in &outside {
        for &s in &seeds[..2] {
            jobs.push((e, m, s, false));
            jobs.push((e, m, s, true));
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let results = diagnose_jobs(dir.path(), &jobs, false);
    let mut rows: Vec<String> = library.iter().map(|c| c.0.to_string()).collect();
    for &(e, _) in &outside {
        rows.push(format!("{e} (tip)"));
        rows.push(format!("{e} (shapes)"));
    }
    let mut matrix = vec![vec![0usize; verdicts.len()]; rows.len()];
    let mut failures = Vec::new();
    for (&(effect, magnitude, seed, shapes), v) in jobs.iter().zip(&results) {
        let verdict = v["verdict"].as_str().unwrap();
        let label = if library.iter().any(|c| c.0 == effect) {
            effect.to_string()
        } else {
            format!("{effect} ({})", if shapes { "shapes" } else { "tip" })
        };
        let r = rows.iter().position(|x| *x == label).unwrap();
        matrix[r][verdicts.iter().position(|x| *x == verdict).unwrap()] += 1;
        for c in v["candidates"].as_array().unwrap() {
            assert!(c["converged"].is_boolean() && c.get("reduced_chi2").is_some(), "{c}");
        }
        let before = v["holdout_rms_before"].as_f64().unwrap();
        let after = v["holdout_rms_after"].as_f64().unwrap();
        let p = v["parameter"].as_f64();
        println!(
            "{label:>24} = {magnitude:<6} seed {seed}: verdict {verdict:<17} parameter {:<22} χ²/dof {:.2} → {:.2}, holdout RMS {before:.3} → {after:.3} mm",
            p.map_or("—".into(), |p| format!("{p:.5} ± {:.2e}", v["parameter_se"].as_f64().unwrap_or(f64::NAN))),
            v["baseline"]["reduced_chi2"].as_f64().unwrap_or(f64::NAN),
            v["best"]["reduced_chi2"].as_f64().unwrap_or(f64::NAN),
        );
        let want = if library.iter().any(|c| c.0 == effect) { effect } else { "unexplained" };
        // A stiff glue joint at the clamp is a stiffness varying along s:
        // from the tips alone it is indistinguishable from a stiffness
        // gradient (stiffer base, β < 0), which may name it; the centreline
        // shows that the stiffening is local, and must leave it unexplained.
        if effect == "glue_joint" && !shapes && verdict == "stiffness_gradient" {
            let beta = p.unwrap();
            assert!(beta < 0.0, "a stiff base is a negative gradient: {v}");
            continue;
        }
        if verdict != want {
            failures.push(format!("{label} seed {seed}: verdict {verdict}, expected {want}"));
            continue;
        }
        if want == "unexplained" {
            assert!(v["signature"]["summary"].as_array().is_some_and(|s| !s.is_empty()), "{v}");
            assert!(v["reason"].as_str().unwrap().contains("χ²/dof") && v["reason"].as_str().unwrap().contains("1e-3"), "{v}");
        }
        if effect == "none" || want == "unexplained" {
            continue;
        }
        let p = p.unwrap();
        if ((p - magnitude) / magnitude).abs() > 0.25 {
            failures.push(format!("{effect} seed {seed}: parameter {p} not within 25 % of {magnitude}"));
        }
        if before < 1.5 * after {
            failures.push(format!("{effect} seed {seed}: held-out RMS {before} → {after} shrank less than 1.5×"));
        }
    }
    println!("\nconfusion matrix (rows: hidden effect, columns: verdict)");
    print!("{:>24} |", "");
    for v in verdicts {
        print!(" {:>9}", &v[..v.len().min(9)]);
    }
    println!();
    for (label, row) in rows.iter().zip(&matrix) {
        print!("{label:>24} |");
        for n in row {
            print!(" {n:>9}");
        }
        println!();
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Centreline data sharpen the diagnosis. At half the magnitudes of the
/// confusion-matrix test, every library effect is named correctly with
/// centreline data; near the detection limit of clamp compliance (k_θ = 150
/// N·mm/rad) the centreline names it where the tip data alone (the same
/// tips) do not. (The other tip-only diagnoses at half magnitude are not
/// run: the test asserted nothing of them.)
#[test]
fn centrelines_name_effects_at_half_the_magnitude() {
    let half: [(&str, f64); 7] = [
        ("friction", 0.04),
        ("gravity", 1.5),
        ("stiffening", 1.5),
        ("clamp_compliance", 40.0),
        ("channel_offset", 0.2),
        ("creep", 0.1),
        ("stiffness_gradient", -0.5 * std::f64::consts::LN_2),
    ];
    let mut jobs: Vec<Job> = half.iter().map(|&(e, m)| (e, m, 11, true)).collect();
    jobs.push(("clamp_compliance", 150.0, 11, false));
    jobs.push(("clamp_compliance", 150.0, 11, true));
    let dir = tempfile::tempdir().unwrap();
    let results = diagnose_jobs(dir.path(), &jobs, true);
    let mut failures = Vec::new();
    for (&(effect, magnitude, _, shapes), v) in jobs.iter().zip(&results) {
        let verdict = v["verdict"].as_str().unwrap();
        let p = v["parameter"].as_f64();
        println!(
            "{effect:>17} = {magnitude:<6} {:<11} verdict {verdict:<17} parameter {}",
            if shapes { "tip+shapes" } else { "tip only" },
            p.map_or("—".into(), |p| format!("{p:.5} ± {:.2e}", v["parameter_se"].as_f64().unwrap_or(f64::NAN)))
        );
        if shapes && (verdict != effect || p.is_none_or(|p| ((p - magnitude) / magnitude).abs() > 0.25)) {
            failures.push(format!("{effect} = {magnitude} with centrelines: verdict {verdict}, parameter {p:?}"));
        }
        if !shapes && magnitude == 150.0 && verdict == effect {
            failures.push("clamp_compliance = 150 from tip data alone: named (the test no longer shows what centrelines add; lower k_θ)".into());
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Writes `path` again with two readings spoiled: a marker swap on one
/// (tip y off by `dy_mm`) and a wrong tension on another (× 1.6).
fn spoil_two_readings(path: &Path, swap_id: i64, tension_id: i64, dy_mm: f64) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(|l| l.to_string()).collect();
    let head: Vec<&str> = lines[0].split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (id, tension, tip_y) = (col("measurement"), col("tension_n"), col("tip_y_mm"));
    for line in lines.iter_mut().skip(1) {
        let mut cells: Vec<String> = line.split(',').map(|c| c.to_string()).collect();
        let this: i64 = cells[id].parse().unwrap();
        if this == swap_id {
            cells[tip_y] = (cells[tip_y].parse::<f64>().unwrap() + dy_mm).to_string();
        }
        if this == tension_id {
            cells[tension] = (cells[tension].parse::<f64>().unwrap() * 1.6).to_string();
        }
        *line = cells.join(",");
    }
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

/// Two bad readings (a swapped marker, a wrong tension) in a null and in a
/// friction dataset do not flip the verdicts, and the swapped one is
/// reported by its measurement id.
#[test]
fn two_outliers_do_not_flip_the_verdict() {
    let dir = tempfile::tempdir().unwrap();
    let t = truth_args();
    let cases: [(&str, &str); 2] = [("none", "none"), ("friction", "friction")];
    let results: Vec<(String, serde_json::Value)> = std::thread::scope(|scope| {
        let handles: Vec<_> = cases
            .iter()
            .map(|&(effect, want)| {
                let (dir, t) = (dir.path(), &t);
                scope.spawn(move || {
                    let path = dir.join(format!("{effect}.csv"));
                    let mut args: Vec<&str> = vec!["--seed", "12", "--effect", effect];
                    if effect != "none" {
                        args.extend(["--magnitude", "0.08"]);
                    }
                    args.extend(t.iter().map(|s| s.as_str()));
                    args.extend(DIAGNOSIS_SOLVER);
                    synth(&path, &args);
                    // Reading 4 (base_offset, loading) and reading 19 (s_curve, loading).
                    spoil_two_readings(&path, 4, 19, 15.0);
                    let mut d = vec!["diagnose", path.to_str().unwrap(), "--holdout", "arc", "--no-report", "--json"];
                    d.extend(DIAGNOSIS_SOLVER);
                    let (ok, stdout, stderr) = cablemap(&d);
                    assert!(ok, "{stderr}");
                    (want.to_string(), json(&stdout))
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (want, v) in results {
        assert_eq!(v["verdict"], want.as_str(), "{}", v["reason"]);
        let outliers: Vec<i64> = v["baseline"]["outliers"].as_array().unwrap().iter().map(|o| o.as_i64().unwrap()).collect();
        let named_fit = if want == "none" { &v["baseline"] } else { &v["extended"] };
        let final_outliers: Vec<i64> = named_fit["outliers"].as_array().unwrap().iter().map(|o| o.as_i64().unwrap()).collect();
        assert!(final_outliers.contains(&4), "{want}: the swapped marker is flagged ({outliers:?}, {final_outliers:?})");
    }
}

/// When no fit converges (here: one iteration allowed), the verdict is
/// never `none`, and the report says why each candidate does not count.
#[test]
fn a_dataset_where_every_fit_fails_never_yields_none() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("d.csv");
    synth(&data, &["--seed", "4", "--routings", "a:3,2.5,2,1.5,1;s:-2,-3,0,3,3.5", "--load-steps", "3"]);
    let out = dir.path().join("report");
    let (ok, stdout, stderr) = cablemap(&["diagnose", data.to_str().unwrap(), "--max-iterations", "1", "--out", out.to_str().unwrap(), "--json"]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    assert_ne!(v["verdict"], "none", "{v}");
    assert_eq!(v["verdict"], "inconclusive", "{}", v["reason"]);
    assert_eq!(v["baseline"]["converged"], false);
    assert!(v["candidates"].as_array().unwrap().iter().all(|c| c["converged"] == false));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("**inconclusive**") && md.contains("no: did not converge"), "{md}");
    assert!(!md.contains("within its noise") && !md.contains("within the stated noise"), "{md}");
}

/// `--fix` holds a rigidity (and an effect), and every fit reports χ²,
/// its degrees of freedom and χ²/dof; bad `--fix` and noise values are
/// refused with a clear message.
#[test]
fn calibrate_holds_fixed_parameters_and_reports_chi_square() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("d.csv");
    let t = truth_args();
    let mut extra: Vec<&str> = vec!["--seed", "2", "--routings", "a:3,2.5,2,1.5,1;s:-2,-3,0,3,3.5;st:2,2,2,2,2"];
    extra.extend(t.iter().map(|s| s.as_str()));
    synth(&data, &extra);
    let (ok, stdout, stderr) = cablemap(&["calibrate", data.to_str().unwrap(), "--fix", "GA=1.5", "--fix", "friction_mu=0.01", "--json"]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    let ga = &v["parameters"][1];
    assert_eq!(ga["name"], "ga_n");
    assert_eq!(ga["value"].as_f64().unwrap(), 1.5);
    assert_eq!(ga["fixed"], true);
    assert_eq!(v["held_effects"]["friction_mu"].as_f64().unwrap(), 0.01);
    let (chi2, dof) = (v["chi2"].as_f64().unwrap(), v["dof"].as_u64().unwrap());
    // 33 readings × 3 residuals − 2 fitted parameters.
    assert_eq!(dof, 97);
    assert!((v["reduced_chi2"].as_f64().unwrap() - chi2 / dof as f64).abs() < 1e-9);
    assert!(v["converged"].as_bool().unwrap());
    let (ok, stdout, _) = cablemap(&["calibrate", data.to_str().unwrap(), "--fix", "GA=1.5"]);
    assert!(ok && stdout.contains("(held)") && stdout.contains("χ²"), "{stdout}");
    for (args, needle) in [
        (vec!["--fix", "GA"], "NAME=VALUE"),
        (vec!["--fix", "shear=1"], "unknown parameter 'shear'"),
        (vec!["--fix", "EI=abc"], "not a number"),
        (vec!["--fix", "EI=-3"], "ei_n_mm2"),
        (vec!["--noise-mm", "0"], "--noise-mm"),
        (vec!["--effect", "friction", "--fix", "friction_mu=0.1"], "either fitted or held"),
    ] {
        let mut a = vec!["calibrate", data.to_str().unwrap()];
        a.extend(args.iter());
        let (ok, _, stderr) = cablemap(&a);
        assert!(!ok && stderr.contains(needle), "{args:?}: {stderr}");
    }
}

/// Markers off the centreline (known s and lateral offset) and centreline
/// points enter the fit: on noise-free data the rigidities come back exactly.
#[test]
fn markers_and_centrelines_enter_the_fit() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("d.csv");
    let markers = dir.path().join("m.csv");
    let lines = dir.path().join("c.csv");
    let t = truth_args();
    let mut extra: Vec<&str> = vec![
        "--noise-mm", "0", "--noise-deg", "0", "--routings", "a:3,2.5,2,1.5,1;s:-2,-3,0,3,3.5;st:2,2,2,2,2",
        "--markers-out", markers.to_str().unwrap(), "--centreline-out", lines.to_str().unwrap(),
    ];
    extra.extend(t.iter().map(|s| s.as_str()));
    synth(&data, &extra);
    let (ok, stdout, stderr) = cablemap(&[
        "calibrate", data.to_str().unwrap(), "--markers", markers.to_str().unwrap(), "--centrelines", lines.to_str().unwrap(), "--json",
    ]);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    // 33 readings × (3 tip + 21 centreline points + 4 markers × 2).
    assert_eq!(v["n_residuals"].as_u64().unwrap(), 33 * (3 + 21 + 8));
    for ((_, name, want), p) in TRUTH.iter().zip(v["parameters"].as_array().unwrap()) {
        let got = p["value"].as_f64().unwrap();
        assert!(((got - want) / want).abs() < 1e-6, "{name}: {got} vs {want}");
    }
    // A marker off the rod is refused with its row.
    std::fs::write(&markers, "measurement,s_mm,offset_mm,x_mm,y_mm\n1,80,0,1,1\n").unwrap();
    let (ok, _, stderr) = cablemap(&["calibrate", data.to_str().unwrap(), "--markers", markers.to_str().unwrap()]);
    assert!(!ok && stderr.contains("row 1") && stderr.contains("s_mm"), "{stderr}");
}

#[test]
fn simulate_uses_the_new_effects() {
    let base = ["simulate", "--routing", "1,2,3,3,2", "--tension", "1.5", "--json"];
    let tip = |extra: &[&str]| -> f64 {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = cablemap(&args);
        assert!(ok, "{stderr}");
        json(&stdout)["tip_angle_rad"].as_f64().unwrap()
    };
    let plain = tip(&[]);
    let load = tip(&["--friction-mu", "0.1"]);
    let unload = tip(&["--friction-mu", "0.1", "--direction", "unload"]);
    assert!(load < plain && plain < unload, "{load} {plain} {unload}");
    let instant = tip(&["--creep-fraction", "0.3"]);
    let held = tip(&["--creep-fraction", "0.3", "--dwell-s", "20"]);
    let held_default = tip(&["--creep-fraction", "0.3", "--creep-hold-s", "20"]);
    assert!((instant - plain).abs() < 1e-12 && held > plain + 0.05, "{instant} {held}");
    // Equal to within the shooting tolerance (the warm starts differ).
    assert!((held - held_default).abs() < 1e-7, "{held} {held_default}");
    let (ok, _, stderr) = cablemap(&["simulate", "--routing", "1,2,3,3,2", "--tension", "1", "--creep-fraction", "1.5"]);
    assert!(!ok && stderr.contains("creep_fraction"), "{stderr}");
}

#[test]
fn diagnose_adds_a_second_effect_stepwise() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("two.csv");
    let t = truth_args();
    let mut extra: Vec<&str> = vec!["--seed", "3", "--effect", "friction", "--magnitude", "0.08", "--channel-offset-mm", "0.4"];
    extra.extend(t.iter().map(|s| s.as_str()));
    extra.extend(DIAGNOSIS_SOLVER);
    synth(&data, &extra);
    let mut d = vec!["diagnose", data.to_str().unwrap(), "--holdout", "arc", "--no-report", "--json"];
    d.extend(DIAGNOSIS_SOLVER);
    let (ok, stdout, stderr) = cablemap(&d);
    assert!(ok, "{stderr}");
    let v = json(&stdout);
    let effects = v["effects"].as_array().unwrap();
    let names: Vec<&str> = effects.iter().map(|e| e["effect"].as_str().unwrap()).collect();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(sorted, ["channel_offset", "friction"], "{v}");
    assert_eq!(v["verdict"], names[0]);
    for (e, want) in effects.iter().map(|e| (e, if e["effect"] == "friction" { 0.08 } else { 0.4 })) {
        let got = e["parameter"].as_f64().unwrap();
        assert!(((got - want) / want).abs() < 0.25, "{e}");
    }
    let (before, after) = (v["holdout_rms_before"].as_f64().unwrap(), v["holdout_rms_after"].as_f64().unwrap());
    assert!(before > 1.5 * after, "{before} → {after}");
}
