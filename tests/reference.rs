//! Physics checks against the independent reference solver (full 3-D
//! Rucker–Webster ODE by shooting; the values are copied into
//! `tests/data/reference/`, see its README) and against the straight-routing
//! analytic solution (model-notes §3).

use cablemap::model::{Rod, Routing};
use cablemap::solver::{simulate, SolverOptions};
use cablemap::shape::LengthBasis;
use proptest::prelude::*;
use serde_json::Value;
use std::path::PathBuf;

fn load(name: &str) -> Vec<Value> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference").join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("reference file {} missing ({e})", path.display()));
    let v: Value = serde_json::from_str(&text).unwrap();
    v["cases"].as_array().unwrap().clone()
}

fn actuator_for(case: &Value) -> Rod {
    let mut a = Rod::default();
    let w = case["gravity_N_per_mm"].as_f64().unwrap();
    a.gravity.enabled = w > 0.0;
    if w > 0.0 {
        // The reference uses exactly ρ π r² g; check we agree before comparing shapes.
        assert!((a.weight_n_per_mm() - w).abs() < 1e-15);
    }
    a
}

fn check_file(name: &str) {
    let cases = load(name);
    assert!(!cases.is_empty());
    let mut worst = [0.0f64; 4];
    for case in &cases {
        let a = actuator_for(case);
        let y: Vec<f64> = case["routing_mm"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let tension = case["tension_N"].as_f64().unwrap();
        let routing = Routing::new(&y, a.length_mm, a.radius_mm).unwrap();
        let sim = simulate(&a, &SolverOptions::default(), &routing, tension, 3, LengthBasis::Rest).unwrap();
        let deformed = simulate(&a, &SolverOptions::default(), &routing, tension, 3, LengthBasis::Deformed).unwrap();
        let p = sim.pose;
        let f = |k: &str| case[k].as_f64().unwrap();
        let tip_err = (p.tip_x_mm - f("tip_x_mm")).hypot(p.tip_y_mm - f("tip_y_mm"));
        let angle_err = (p.tip_angle_rad - f("tip_tangent_angle_rad"))
            .abs()
            .max((p.tip_frame_angle_rad - f("tip_frame_angle_rad")).abs())
            .max((p.base_angle_rad - f("base_tangent_angle_rad")).abs());
        let len_err = (p.length_mm - f("deformed_length_mm")).abs();
        let list = |k: &str| -> Vec<f64> { case[k].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect() };
        // The default basis is the thesis's (per unit rest length); the
        // deformed basis is the option.
        let (a_thesis, a_deformed) = (list("a_thesis_per_mm"), list("a_per_mm"));
        let a_err = (0..4)
            .map(|i| (sim.a_bend_z[i] - a_thesis[i]).abs().max((deformed.a_bend_z[i] - a_deformed[i]).abs()))
            .fold(0.0, f64::max);
        worst = [worst[0].max(tip_err), worst[1].max(angle_err), worst[2].max(a_err), worst[3].max(len_err)];
        let ctx = format!("{name}: routing {y:?}, tension {tension}");
        assert!(tip_err < 1e-3, "{ctx}: tip off by {tip_err} mm");
        assert!(angle_err < 1e-5, "{ctx}: angle off by {angle_err} rad");
        assert!(a_err < 1e-5, "{ctx}: a_i off by {a_err}");
        assert!(len_err < 1e-3, "{ctx}: length off by {len_err}");
    }
    eprintln!("{name}: worst tip {:.2e} mm, angle {:.2e} rad, a_i {:.2e} /mm, length {:.2e} mm", worst[0], worst[1], worst[2], worst[3]);
}

#[test]
fn reference_without_gravity() {
    check_file("no-gravity.json");
}

#[test]
fn reference_with_gravity() {
    check_file("gravity.json");
}

#[test]
fn reference_large_deformation() {
    check_file("large-deformation.json");
}

fn no_gravity() -> Rod {
    let mut a = Rod::default();
    a.gravity.enabled = false;
    a
}

#[test]
fn straight_routing_matches_the_analytic_arc() {
    let a = no_gravity();
    for (d, tau) in [(4.0, 2.0), (-2.5, 1.3), (1.0, 0.4)] {
        let routing = Routing::new(&[d; 5], a.length_mm, a.radius_mm).unwrap();
        let sim = simulate(&a, &SolverOptions::default(), &routing, tau, 3, LengthBasis::Deformed).unwrap();
        let kappa = tau * d / a.ei_n_mm2;
        let v1 = 1.0 - tau / a.ea_n;
        let l = a.length_mm;
        let (x, y) = (v1 * (kappa * l).sin() / kappa, v1 * (1.0 - (kappa * l).cos()) / kappa);
        assert!((sim.pose.tip_x_mm - x).abs() < 1e-6 && (sim.pose.tip_y_mm - y).abs() < 1e-6, "d={d}: {:?} vs ({x},{y})", sim.pose);
        // Constant curvature per deformed length, κ/v1: a_0 has it, the rest vanish.
        assert!((sim.a_bend_z[0] - kappa / v1).abs() < 1e-9, "a0 {} vs {}", sim.a_bend_z[0], kappa / v1);
        assert!(sim.a_bend_z[1..].iter().all(|v| v.abs() < 1e-9), "{:?}", sim.a_bend_z);
        // Per unit rest length (the thesis's basis): the turning angle κL over L.
        let rest = simulate(&a, &SolverOptions::default(), &routing, tau, 3, LengthBasis::Rest).unwrap();
        assert!((rest.a_bend_z[0] - kappa).abs() < 1e-9, "rest a0 {} vs {kappa}", rest.a_bend_z[0]);
        assert!(rest.a_bend_z[1..].iter().all(|v| v.abs() < 1e-9), "{:?}", rest.a_bend_z);
    }
    // The number model-notes §3 quotes.
    let routing = Routing::new(&[4.0; 5], 65.0, 5.0).unwrap();
    let sim = simulate(&a, &SolverOptions::default(), &routing, 2.0, 1, LengthBasis::Deformed).unwrap();
    assert!((sim.pose.tip_x_mm + 13.058685).abs() < 1e-6 && (sim.pose.tip_y_mm - 15.894155).abs() < 1e-6);
}

#[test]
fn zero_tension_gives_the_straight_rod() {
    let a = no_gravity();
    let routing = Routing::new(&[1.0, -3.0, 2.0, 4.0, -4.0], 65.0, 5.0).unwrap();
    let sim = simulate(&a, &SolverOptions::default(), &routing, 0.0, 3, LengthBasis::Deformed).unwrap();
    assert!((sim.pose.tip_x_mm - 65.0).abs() < 1e-12 && sim.pose.tip_y_mm.abs() < 1e-12);
    assert!(sim.a_bend_z.iter().all(|v| v.abs() < 1e-12));
    // With gravity the hanging rod only stretches under its own weight.
    let sim = simulate(&Rod::default(), &SolverOptions::default(), &routing, 0.0, 3, LengthBasis::Rest).unwrap();
    let w = Rod::default().weight_n_per_mm();
    let stretch = w * 65.0 * 65.0 / 2.0 / Rod::default().ea_n;
    assert!((sim.pose.tip_x_mm - 65.0 - stretch).abs() < 1e-9 && sim.pose.tip_y_mm.abs() < 1e-12);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Negating every y_i mirrors the solution: (x, y, angles, a_i) → (x, −y, −angles, −a_i).
    #[test]
    fn mirrored_routing_gives_the_mirrored_result(
        y in proptest::array::uniform5(-4.9f64..4.9),
        tension in 0.0f64..2.0,
        gravity in any::<bool>(),
    ) {
        let mut a = Rod::default();
        a.gravity.enabled = gravity;
        let opts = SolverOptions::default();
        let r = Routing::new(&y, 65.0, 5.0).unwrap();
        let m = simulate(&a, &opts, &r, tension, 3, LengthBasis::Rest).unwrap();
        let n = simulate(&a, &opts, &r.mirrored(), tension, 3, LengthBasis::Rest).unwrap();
        prop_assert!((m.pose.tip_x_mm - n.pose.tip_x_mm).abs() < 1e-9);
        prop_assert!((m.pose.tip_y_mm + n.pose.tip_y_mm).abs() < 1e-9);
        prop_assert!((m.pose.tip_angle_rad + n.pose.tip_angle_rad).abs() < 1e-9);
        prop_assert!((m.pose.base_angle_rad + n.pose.base_angle_rad).abs() < 1e-9);
        for i in 0..4 {
            prop_assert!((m.a_bend_z[i] + n.a_bend_z[i]).abs() < 1e-10);
        }
    }
}
