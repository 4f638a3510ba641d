//! The solver interface as a user meets it: `cablemap simulate` given one
//! in-plane cable as `--cable` takes the planar fast path and agrees with
//! `--routing … --tension-n …`; settings a backend does not read are refused
//! by name, not ignored; and an anchored cable's control points span
//! [0, anchor] whichever backend solves it.

mod process;

use serde_json::Value;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = process::cablemap().args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn json(args: &[&str]) -> Value {
    let (ok, out, err) = run(args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(out.trim()).unwrap_or_else(|e| panic!("{args:?}: not JSON ({e}): {out}"))
}

fn num(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key} missing in {v}"))
}

fn series(v: &Value) -> Vec<f64> {
    v["a"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// `planar` (the `--routing` record) and `actuator` (the `--cable` record)
/// have the same tip, angle and a_i to `tolerance`. The actuator record's
/// angle is unsigned from +x (the routings here bend by less than π);
/// its tangent is (cos θ, sin θ, 0).
fn assert_same(planar: &Value, actuator: &Value, tolerance: f64, what: &str) {
    let close = |a: f64, b: f64, name: &str| assert!((a - b).abs() <= tolerance, "{what}: {name} {a} vs {b}\n{planar}\n{actuator}");
    close(num(planar, "tip_x_mm"), num(actuator, "tip_x_mm"), "tip_x_mm");
    close(num(planar, "tip_y_mm"), num(actuator, "tip_y_mm"), "tip_y_mm");
    close(0.0, num(actuator, "tip_z_mm"), "tip_z_mm");
    let theta = num(planar, "tip_angle_rad");
    close(theta.abs(), num(actuator, "tip_angle_rad"), "tip_angle_rad");
    let t = &actuator["tip_tangent"];
    close(theta.cos(), t[0].as_f64().unwrap(), "tip tangent x");
    close(theta.sin(), t[1].as_f64().unwrap(), "tip tangent y");
    let (a, b) = (series(planar), series(actuator));
    assert_eq!(a.len(), b.len(), "{what}: orders");
    for (i, (p, q)) in a.iter().zip(&b).enumerate() {
        close(*p, *q, &format!("a_{i}"));
    }
}

const Y: &str = "0.5,-2,3,1.5,-1";

#[test]
fn one_in_plane_cable_takes_the_planar_fast_path() {
    let dir = tempfile::tempdir().unwrap();
    let tapered = dir.path().join("tapered.toml");
    std::fs::write(&tapered, "length_mm = 65.0\nradius_profile_mm = [[0.0, 6.0], [65.0, 4.0]]\n").unwrap();
    let tapered = tapered.to_str().unwrap();
    let cable = format!("y={Y} tension=1.3");
    let anchored = format!("y={Y} tension=1.3 anchor=45");
    let cases: Vec<(&str, Vec<&str>, Vec<&str>)> = vec![
        ("uniform", vec!["--routing", Y, "--tension-n", "1.3"], vec!["--cable", &cable]),
        ("anchored", vec!["--routing", Y, "--tension-n", "1.3", "--cable-anchor-mm", "45"], vec!["--cable", &anchored]),
        ("tapered", vec!["--routing", Y, "--tension-n", "1.3", "--actuator-file", tapered], vec!["--cable", &cable, "--actuator-file", tapered]),
        (
            "tapered and anchored",
            vec!["--routing", Y, "--tension-n", "1.3", "--actuator-file", tapered, "--cable-anchor-mm", "45"],
            vec!["--cable", &anchored, "--actuator-file", tapered],
        ),
        // The flags of the planar backends are honoured on the fast path.
        ("rk4", vec!["--routing", Y, "--tension-n", "1.3", "--method", "rk4"], vec!["--cable", &cable, "--method", "rk4"]),
        ("nodes", vec!["--routing", Y, "--tension-n", "1.3", "--nodes-per-span", "30"], vec!["--cable", &cable, "--nodes-per-span", "30"]),
        ("friction", vec!["--routing", Y, "--tension-n", "1.3", "--friction-mu", "0.1"], vec!["--cable", &cable, "--friction-mu", "0.1"]),
    ];
    for (what, planar, actuator) in cases {
        let planar = json(&[&["simulate", "--json"][..], &planar].concat());
        let actuator = json(&[&["simulate", "--json"][..], &actuator].concat());
        assert_same(&planar, &actuator, 1e-9, what);
    }
}

#[test]
fn settings_the_serving_backend_does_not_read_are_refused_by_name() {
    let cable = format!("y={Y} tension=1.3");
    let other = "y=-1,1,1,1,1 tension=1";
    let cases: &[(&[&str], &[&str])] = &[
        // One in-plane cable: planar rk4 serves, and does not read collocation's intervals.
        (&["--cable", &cable, "--method", "rk4", "--nodes-per-span", "30"], &["planar rk4", "--nodes-per-span", "planar collocation"]),
        (&["--routing", Y, "--tension-n", "1", "--method", "rk4", "--nodes-per-span", "30"], &["planar rk4", "--nodes-per-span", "planar collocation"]),
        // Two cables: the spatial solver serves; its RK4 reference reads RK4
        // steps only and models the thesis's rod without effects.
        (&["--cable", &cable, "--cable", other, "--method", "rk4", "--nodes-per-span", "30"], &["spatial rk4", "--nodes-per-span"]),
        (&["--cable", &cable, "--cable", other, "--method", "rk4", "--friction-mu", "0.1"], &["spatial rk4", "friction_mu"]),
        (&["--cable", &cable, "--cable", other, "--method", "rk4", "--dwell-s", "5"], &["spatial rk4", "--dwell-s"]),
        (&["--cable", &cable, "--cable", other, "--coefficients", "thesis"], &["spatial", "--coefficients thesis"]),
        (&["--cable", &cable, "--cable", other, "--method", "rk4", "--radius-profile-mm", "0:5,65:3"], &["spatial rk4", "uniform rod"]),
        (&["--routing", Y, "--tension-n", "1", "--cable-anchor-mm", "40", "--method", "rk4"], &["planar rk4", "anchored", "planar collocation"]),
    ];
    for (args, needles) in cases {
        let (ok, _, err) = run(&[&["simulate"][..], args].concat());
        assert!(!ok, "{args:?} was accepted");
        for n in *needles {
            assert!(err.to_lowercase().contains(&n.to_lowercase()), "{args:?}: stderr {err:?} lacks {n:?}");
        }
    }
    // What the spatial solvers read is honoured: --method rk4 picks the RK4
    // reference, whose resolution is --steps-per-span; the collocation's is
    // --nodes-per-span. Both agree within the RK4 reference's accuracy.
    let two = ["simulate", "--json", "--cable", &cable, "--cable", other];
    let plain = json(&two);
    let rk4 = json(&[&two[..], &["--method", "rk4"]].concat());
    let (a, b) = (plain["tip_x_mm"].as_f64().unwrap(), rk4["tip_x_mm"].as_f64().unwrap());
    assert!(a != b && (a - b).abs() < 1e-3, "collocation {a} mm, rk4 {b} mm");
    let rk4_fine = json(&[&two[..], &["--method", "rk4", "--steps-per-span", "40"]].concat());
    assert_ne!(rk4["tip_x_mm"], rk4_fine["tip_x_mm"], "--steps-per-span is the RK4 reference's resolution");
    let fine = json(&[&two[..], &["--nodes-per-span", "20"]].concat());
    let c = fine["tip_x_mm"].as_f64().unwrap();
    assert!(c != a && (c - a).abs() < 1e-7, "--nodes-per-span is the collocation's resolution: {a} vs {c}");
}

#[test]
fn an_anchored_cable_spans_its_control_points_over_zero_to_the_anchor_in_every_solver() {
    // A second, slack cable sends the request to the spatial solver; the
    // planar solver spans the routing over [0, anchor]. With a routing that
    // varies along s, spanning it over [0, L] instead moves the tip by mm.
    let y = "0,1,2,3,4";
    let planar = json(&["simulate", "--json", "--routing", y, "--tension-n", "1.2", "--cable-anchor-mm", "40"]);
    let spatial = json(&[
        "simulate",
        "--json",
        "--cable",
        &format!("y={y} tension=1.2 anchor=40"),
        "--cable",
        "y=-1,-1,-1,-1,-1 tension=0",
        "--steps-per-span",
        "80",
    ]);
    let tip = (num(&planar, "tip_x_mm") - num(&spatial, "tip_x_mm")).hypot(num(&planar, "tip_y_mm") - num(&spatial, "tip_y_mm"));
    assert!(tip < 2e-3, "tips {tip} mm apart:\n{planar}\n{spatial}");
    let angle = (num(&planar, "tip_angle_rad") - num(&spatial, "tip_angle_rad")).abs();
    assert!(angle < 1e-4, "tip angles {angle} rad apart:\n{planar}\n{spatial}");
    // The a_i agree too: both series count the tangent's jump where the
    // cable ends (the tension stops, the shear and stretch jump), to the
    // spatial solver's accuracy (its resolution check holds every a_i to
    // 5e-5 mm⁻¹ against half the steps).
    let (a, b) = (series(&planar), series(&spatial));
    for (i, (p, q)) in a.iter().zip(&b).enumerate() {
        assert!((p - q).abs() < 5e-5, "a_{i}: planar {p} vs spatial {q}\n{planar}\n{spatial}");
    }
}
