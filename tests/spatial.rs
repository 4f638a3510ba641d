//! The 3-D several-cable solver (issue 16): the independent reference cases
//! (`tests/data/reference/multi-cable.json`, an N-cable Rucker–Webster
//! shooting solver), analytic solutions, symmetries and agreement with the
//! planar solver.

use cablemap::solver::spatial::{simulate_spatial, Cable, Actuator, SpatialError};
use cablemap::solver::Simulation;
use cablemap::model::{ActuatorError, Rod, Routing};
use cablemap::solver::{simulate, SolverOptions};
use cablemap::shape::LengthBasis;
use serde_json::Value;
use std::path::PathBuf;

fn cases() -> Vec<Value> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference/multi-cable.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("reference file {} missing ({e})", path.display()));
    let v: Value = serde_json::from_str(&text).unwrap();
    v["cases"].as_array().unwrap().clone()
}

fn vec_of(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn arr5(v: &Value) -> [f64; 5] {
    vec_of(v).try_into().unwrap()
}

fn arr3(v: &Value) -> [f64; 3] {
    vec_of(v).try_into().unwrap()
}

fn actuator_for(case: &Value) -> Actuator {
    let mut rod = Rod::default();
    let g = arr3(&case["gravity_N_per_mm"]);
    let w = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    rod.gravity.enabled = w > 0.0;
    let cables = case["cables"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| Cable::spatial(arr5(&c["routing_y_mm"]), arr5(&c["routing_z_mm"]), c["tension_N"].as_f64().unwrap()))
        .collect();
    let mut a = Actuator::with_cables(rod, cables);
    if w > 0.0 {
        // The reference's weight is exactly ρ π r² g: only the direction is an input.
        assert!((a.rod.weight_n_per_mm() - w).abs() < 1e-12, "{w}");
        a.gravity_direction = Some(g);
    }
    a
}

fn run(a: &Actuator) -> Simulation {
    simulate_spatial(a, &SolverOptions::default(), 3, LengthBasis::Rest).unwrap()
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    (cross[0].hypot(cross[1]).hypot(cross[2])).atan2(dot)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The 3-D collocation (the default) against the independent reference
/// within 1e-6 mm and 1e-7 rad (the issue asks 1e-4 mm and 1e-6 rad; at 10
/// intervals per span it is within 2.1e-7 mm), and its RK4 reference within
/// 1e-3 mm and 1e-5 rad.
#[test]
fn every_reference_case_agrees() {
    let rk4 = SolverOptions { method: cablemap::solver::SolverMethod::Rk4, ..SolverOptions::default() };
    for (options, tip_mm, angle_rad) in [(SolverOptions::default(), 1e-6, 1e-7), (rk4, 1e-3, 1e-5)] {
        reference_cases_agree(&options, tip_mm, angle_rad);
    }
}

fn reference_cases_agree(options: &SolverOptions, tip_mm: f64, angle_rad: f64) {
    let cases = cases();
    assert_eq!(cases.len(), 8);
    let mut worst = [0.0f64; 4];
    for case in &cases {
        let name = case["name"].as_str().unwrap();
        let sim = simulate_spatial(&actuator_for(case), options, 3, LengthBasis::Rest).unwrap();
        let p = sim.pose;
        let tip = dist(p.tip_mm(), arr3(&case["tip_mm"]));
        let tangent = angle(p.tip_tangent(), arr3(&case["tip_tangent"]));
        let body_y = angle(p.tip_body_y_axis(), arr3(&case["tip_body_y_axis"]));
        let length = (p.length_mm - case["deformed_length_mm"].as_f64().unwrap()).abs();
        eprintln!("{name}: tip {tip:.2e} mm, tangent {tangent:.2e} rad, body y {body_y:.2e} rad, length {length:.2e} mm, {} passes", p.iterations);
        assert!(tip < tip_mm, "{name}: tip {:?} vs {}", p.tip_mm(), case["tip_mm"]);
        assert!(tangent < angle_rad, "{name}: tangent off by {tangent} rad");
        assert!(body_y < angle_rad, "{name}: body y-axis off by {body_y} rad");
        assert!(length < tip_mm, "{name}: length off by {length} mm");
        // The centreline at the reference's 65 stations (s = 0 … L): our
        // nodes are on a different grid, so compare the clamp and tip only,
        // plus the curvature at the clamp (the shooting unknown there).
        let u0 = arr3(&case["base_u_per_mm"]);
        let node0 = sim.centreline[0];
        for i in 0..3 {
            assert!((node0.u_per_mm[i] - u0[i]).abs() < 1e-6, "{name}: clamp curvature {:?} vs {u0:?}", node0.u_per_mm);
        }
        for (w, x) in worst.iter_mut().zip([tip, tangent, body_y, length]) {
            *w = w.max(x);
        }
    }
    eprintln!("{:?}: worst tip {:.2e} mm, tangent {:.2e} rad, body y {:.2e} rad, length {:.2e} mm", options.method, worst[0], worst[1], worst[2], worst[3]);
}

fn no_gravity() -> Rod {
    let mut a = Rod::default();
    a.gravity.enabled = false;
    a
}

#[test]
fn constant_offset_bends_at_constant_curvature_about_the_perpendicular_axis() {
    // Offset (d_y, d_z) = (2.4, −3.2), |d| = 4 mm, τ = 1.5 N.
    let (dy, dz, tau) = (2.4, -3.2, 1.5);
    let a = Actuator::with_cables(no_gravity(), vec![Cable::spatial([dy; 5], [dz; 5], tau)]);
    // Fine steps: this checks the model, not RK4's error (≈ 6e-6 mm at the default).
    let sim = simulate_spatial(&a, &SolverOptions { spatial_steps_per_span: 128, ..SolverOptions::default() }, 3, LengthBasis::Rest).unwrap();
    let rod = &a.rod;
    let d = dy.hypot(dz);
    let kappa = tau * d / rod.ei_n_mm2;
    let stretch = 1.0 - tau / rod.ea_n;
    // The rod bends toward the cable: in the plane spanned by x and the
    // offset direction e = (0, dy, dz)/|d|, about the axis x × e.
    let e = [0.0, dy / d, dz / d];
    let l = rod.length_mm;
    let along = stretch * (kappa * l).sin() / kappa;
    let side = stretch * (1.0 - (kappa * l).cos()) / kappa;
    let expect = [along, side * e[1], side * e[2]];
    assert!(dist(sim.pose.tip_mm(), expect) < 1e-6, "{:?} vs {expect:?}", sim.pose.tip_mm());
    assert!((sim.pose.length_mm - stretch * l).abs() < 1e-9);
    for n in &sim.centreline {
        // K_bt u = −τ r × e_x = τ (0, −d_z, d_y): about the axis ⟂ the offset.
        let u = n.u_per_mm;
        assert!(u[0].abs() < 1e-12, "no twist");
        assert!((u[1] + tau * dz / rod.ei_n_mm2).abs() < 1e-10 && (u[2] - tau * dy / rod.ei_n_mm2).abs() < 1e-10, "{u:?}");
        assert!((n.v[0] - stretch).abs() < 1e-12 && n.v[1].abs() < 1e-12 && n.v[2].abs() < 1e-12);
    }
    // Coefficients: constant curvature is a_0 only (per unit rest length),
    // split between the two bending series by the offset direction.
    assert!((sim.a_bend_z[0] - tau * dy / rod.ei_n_mm2).abs() < 1e-9, "{:?}", sim.a_bend_z);
    assert!((sim.a_bend_y[0] + tau * dz / rod.ei_n_mm2).abs() < 1e-9, "{:?}", sim.a_bend_y);
    for i in 1..4 {
        assert!(sim.a_bend_z[i].abs() < 1e-9 && sim.a_bend_y[i].abs() < 1e-9 && sim.a_twist[i].abs() < 1e-9);
    }
}

#[test]
fn two_opposed_equal_cables_only_compress() {
    for (dy, dz) in [(3.0, 0.0), (1.2, -2.5)] {
        let tau = 1.7;
        let a = Actuator::with_cables(
            no_gravity(),
            vec![Cable::spatial([dy; 5], [dz; 5], tau), Cable::spatial([-dy; 5], [-dz; 5], tau)],
        );
        let sim = run(&a);
        let expect = [a.rod.length_mm * (1.0 - 2.0 * tau / a.rod.ea_n), 0.0, 0.0];
        assert!(dist(sim.pose.tip_mm(), expect) < 1e-9, "{:?} vs {expect:?}", sim.pose.tip_mm());
        assert!(angle(sim.pose.tip_tangent(), [1.0, 0.0, 0.0]) < 1e-12);
    }
}

/// A spatial two-cable actuator without gravity, for the symmetry checks.
fn pair() -> Vec<Cable> {
    vec![
        Cable::spatial([1.5, 3.0, -0.5, 2.0, 2.5], [0.5, -1.0, 2.0, 1.5, -2.0], 1.2),
        Cable::spatial([-2.0, -1.0, 0.5, -3.0, -1.5], [1.0, 2.5, -2.0, 0.0, 1.0], 0.7),
    ]
}

#[test]
fn rotating_every_routing_by_90_degrees_rotates_the_solution() {
    let a = Actuator::with_cables(no_gravity(), pair());
    // Rotation by +90° about x: (y, z) → (−z, y).
    let turned: Vec<Cable> = pair().into_iter().map(|c| Cable::spatial(c.z_mm.map(|z| -z), c.y_mm, c.tension_n)).collect();
    let b = Actuator::with_cables(no_gravity(), turned);
    let (s, t) = (run(&a), run(&b));
    let rot = |p: [f64; 3]| [p[0], -p[2], p[1]];
    assert!(dist(rot(s.pose.tip_mm()), t.pose.tip_mm()) < 1e-9, "{:?} {:?}", s.pose.tip_mm(), t.pose.tip_mm());
    assert!(angle(rot(s.pose.tip_tangent()), t.pose.tip_tangent()) < 1e-10);
    // R' = Rx R Rxᵀ and Rxᵀ e_y = −e_z: the turned rod's body y-axis is the
    // original's body z-axis, turned and reversed.
    let r = s.centreline.last().unwrap().rotation;
    assert!(angle(rot([-r[0][2], -r[1][2], -r[2][2]]), t.pose.tip_body_y_axis()) < 1e-10);
    // Body-frame curvatures rotate the same way: about-z becomes about-y… (u_y, u_z) → (−u_z, u_y).
    for i in 0..4 {
        assert!((t.a_bend_y[i] + s.a_bend_z[i]).abs() < 1e-10 && (t.a_bend_z[i] - s.a_bend_y[i]).abs() < 1e-10);
        assert!((t.a_twist[i] - s.a_twist[i]).abs() < 1e-10);
    }
}

#[test]
fn swapping_cables_changes_nothing() {
    let mut cables = pair();
    let a = Actuator::with_cables(Rod::default(), cables.clone());
    cables.reverse();
    let b = Actuator::with_cables(Rod::default(), cables);
    let (s, t) = (run(&a), run(&b));
    assert!(dist(s.pose.tip_mm(), t.pose.tip_mm()) < 1e-10);
    assert!(angle(s.pose.tip_tangent(), t.pose.tip_tangent()) < 1e-12);
    assert_eq!(s.a_bend_z.len(), t.a_bend_z.len());
    for i in 0..4 {
        assert!((s.a_bend_z[i] - t.a_bend_z[i]).abs() < 1e-12 && (s.a_bend_y[i] - t.a_bend_y[i]).abs() < 1e-12);
    }
}

#[test]
fn mirroring_y_mirrors_the_solution() {
    let a = Actuator::with_cables(no_gravity(), pair());
    let mirrored: Vec<Cable> = pair().into_iter().map(|c| Cable::spatial(c.y_mm.map(|y| -y), c.z_mm, c.tension_n)).collect();
    let b = Actuator::with_cables(no_gravity(), mirrored);
    let (s, t) = (run(&a), run(&b));
    let m = |p: [f64; 3]| [p[0], -p[1], p[2]];
    assert!(dist(m(s.pose.tip_mm()), t.pose.tip_mm()) < 1e-9);
    assert!(angle(m(s.pose.tip_tangent()), t.pose.tip_tangent()) < 1e-10);
    // R' = M R M: the body y-axis is mirrored and reversed.
    let y = m(s.pose.tip_body_y_axis());
    assert!(angle([-y[0], -y[1], -y[2]], t.pose.tip_body_y_axis()) < 1e-10);
    // A reflection turns axial vectors: bending about z and twist flip sign,
    // bending about y keeps it.
    for i in 0..4 {
        assert!((t.a_bend_z[i] + s.a_bend_z[i]).abs() < 1e-10);
        assert!((t.a_bend_y[i] - s.a_bend_y[i]).abs() < 1e-10);
        assert!((t.a_twist[i] + s.a_twist[i]).abs() < 1e-10);
    }
    // A spatial pair twists the rod (a check that the twist series is not trivially zero).
    assert!(s.a_twist.iter().any(|a| a.abs() > 1e-6), "{:?}", s.a_twist);
}

#[test]
fn planar_cases_agree_with_the_planar_solver() {
    let routings = [[2.0, 3.0, -1.0, -4.0, 4.5], [4.0, -0.95, 0.16, -4.91 + 0.5, -2.7], [0.0, 1.0, 2.0, 3.0, 4.0], [-3.5, -3.5, -3.5, -3.5, -3.5]];
    for gravity in [false, true] {
        for (k, y) in routings.iter().enumerate() {
            let tension = 0.6 + 0.45 * k as f64;
            let mut rod = Rod::default();
            rod.gravity.enabled = gravity;
            rod.gravity.direction_rad = 0.3 * k as f64; // tilted clamps too
            let routing = Routing::new(y, rod.length_mm, rod.radius_mm).unwrap();
            let fine = SolverOptions { nodes_per_span: 32, ..SolverOptions::default() };
            let planar = simulate(&rod, &fine, &routing, tension, 3, LengthBasis::Rest).unwrap();
            let a = Actuator::with_cables(rod.clone(), vec![Cable::planar(*y, tension)]);
            let opts = SolverOptions { spatial_steps_per_span: 256, ..SolverOptions::default() };
            let s = simulate_spatial(&a, &opts, 3, LengthBasis::Rest).unwrap();
            let tip = [planar.pose.tip_x_mm, planar.pose.tip_y_mm, 0.0];
            let d = dist(s.pose.tip_mm(), tip);
            assert!(d < 1e-6, "gravity {gravity}, routing {y:?}: tip {:?} vs {tip:?} ({d:.2e} mm)", s.pose.tip_mm());
            let theta = s.pose.tip_tangent()[1].atan2(s.pose.tip_tangent()[0]);
            let turn = (theta - planar.pose.tip_angle_rad) / std::f64::consts::TAU;
            assert!((turn - turn.round()).abs() * std::f64::consts::TAU < 1e-8, "{theta} vs {}", planar.pose.tip_angle_rad);
            assert!((s.pose.length_mm - planar.pose.length_mm).abs() < 1e-6);
            for i in 0..4 {
                assert!((s.a_bend_z[i] - planar.a_bend_z[i]).abs() < 1e-7, "a_{i}: {} vs {}", s.a_bend_z[i], planar.a_bend_z[i]);
                assert!(s.a_bend_y[i].abs() < 1e-12 && s.a_twist[i].abs() < 1e-12);
            }
            assert!(s.pose.tip_mm()[2].abs() < 1e-12);
            // Same in the deformed-length basis.
            let sd = simulate_spatial(&a, &opts, 3, LengthBasis::Deformed).unwrap();
            let pd = simulate(&rod, &fine, &routing, tension, 3, LengthBasis::Deformed).unwrap();
            assert!((sd.a_bend_z[1] - pd.a_bend_z[1]).abs() < 1e-7);
        }
    }
}

#[test]
fn default_resolution_is_close_to_a_fine_one_on_planar_cases() {
    // The default (10 steps per span) on a strongly curved S at the thesis's
    // top tension, against the planar solver: within the reference tolerance.
    let y = [4.0, -3.0, 2.0, -4.0, 4.0];
    let rod = Rod::default();
    let routing = Routing::new(&y, rod.length_mm, rod.radius_mm).unwrap();
    let planar = simulate(&rod, &SolverOptions { nodes_per_span: 32, ..SolverOptions::default() }, &routing, 2.0, 3, LengthBasis::Rest).unwrap();
    let s = run(&Actuator::with_cables(rod, vec![Cable::planar(y, 2.0)]));
    let d = dist(s.pose.tip_mm(), [planar.pose.tip_x_mm, planar.pose.tip_y_mm, 0.0]);
    eprintln!("default resolution: tip off by {d:.2e} mm");
    assert!(d < 5e-4, "{d}");
}

#[test]
fn bad_input_gets_clear_errors() {
    let rod = Rod::default();
    let err = |cables: Vec<Cable>| simulate_spatial(&Actuator::with_cables(rod.clone(), cables), &SolverOptions::default(), 3, LengthBasis::Rest).unwrap_err();
    // Each coordinate below r, the distance √2·3.6 = 5.09 mm above it.
    let e = err(vec![Cable::spatial([3.6; 5], [3.6; 5], 1.0)]);
    assert!(matches!(e, SpatialError::Actuator(ActuatorError::OutsideBody { cable: 1, .. })), "{e}");
    let e = err(vec![Cable::planar([1.0; 5], 1.0), Cable::planar([1.0; 5], 0.5)]);
    assert!(matches!(e, SpatialError::Actuator(ActuatorError::SamePath { first: 1, second: 2 })), "{e}");
    let e = err(vec![Cable::planar([1.0; 5], 1.0), Cable::planar([-1.0; 5], -0.5)]);
    assert!(e.to_string().contains("cable 2") && e.to_string().contains("-0.5"), "{e}");
    let mut a = Actuator::with_cables(rod.clone(), vec![Cable::planar([1.0; 5], 1.0)]);
    a.gravity_direction = Some([0.0, 0.0, 0.0]);
    assert!(matches!(simulate_spatial(&a, &SolverOptions::default(), 3, LengthBasis::Rest), Err(SpatialError::Actuator(ActuatorError::GravityDirection(_)))));
    a.gravity_direction = None;
    a.rod.effects.friction_mu = 0.1;
    // The RK4 reference models the thesis's rod without effects; the default collocation models friction.
    let rk4 = SolverOptions { method: cablemap::solver::SolverMethod::Rk4, ..SolverOptions::default() };
    let e = simulate_spatial(&a, &rk4, 3, LengthBasis::Rest).unwrap_err();
    assert!(e.to_string().contains("friction_mu") && e.to_string().contains("spatial RK4"), "{e}");
    assert!(simulate_spatial(&a, &SolverOptions::default(), 3, LengthBasis::Rest).is_ok());
}

#[test]
fn gravity_along_z_bends_the_rod_out_of_plane() {
    // A planar cable with gravity along +z: the planar solver cannot do this.
    let mut a = Actuator::with_cables(Rod::default(), vec![Cable::planar([2.0; 5], 1.0)]);
    a.gravity_direction = Some([0.0, 0.0, 1.0]);
    let s = run(&a);
    assert!(s.pose.tip_mm()[2] > 0.1, "{:?}", s.pose.tip_mm());
    // Torsional rigidity matters only when the rod twists: GJ default is EI/1.5.
    assert!((a.torsional_rigidity_n_mm2() - a.rod.ei_n_mm2 / 1.5).abs() < 1e-12);
}

#[test]
fn an_anchor_before_the_tip_leaves_the_distal_part_straight() {
    let mut cable = Cable::planar([2.0; 5], 1.0);
    cable.anchor_mm = Some(40.0);
    let s = run(&Actuator::with_cables(no_gravity(), vec![cable]));
    for n in s.centreline.iter().filter(|n| n.s_mm > 40.0 + 1e-9) {
        assert!(n.u_per_mm.iter().all(|u| u.abs() < 1e-12), "{n:?}");
    }
    // Up to the anchor: constant curvature τ d/EI as for a tip anchor.
    let rod = Rod::default();
    for n in s.centreline.iter().filter(|n| n.s_mm < 40.0 - 1e-9) {
        assert!((n.u_per_mm[2] - 2.0 / rod.ei_n_mm2).abs() < 1e-10);
    }
}

/// The spatial solve of a planar actuator against the planar one (fine on
/// both): tip, in-plane series and no out-of-plane or twist series.
fn assert_planar_agreement(rod: &Rod, cable: Cable, what: &str) {
    let mut planar_rod = rod.clone();
    planar_rod.cable_anchor_mm = cable.anchor_mm;
    let routing = Routing::for_actuator(cable.y_mm, &planar_rod).unwrap();
    let fine = SolverOptions { nodes_per_span: 32, ..SolverOptions::default() };
    let planar = simulate(&planar_rod, &fine, &routing, cable.tension_n, 3, LengthBasis::Rest).unwrap();
    let a = Actuator::with_cables(rod.clone(), vec![cable]);
    let s = simulate_spatial(&a, &SolverOptions { spatial_steps_per_span: 128, ..SolverOptions::default() }, 3, LengthBasis::Rest).unwrap();
    let d = dist(s.pose.tip_mm(), [planar.pose.tip_x_mm, planar.pose.tip_y_mm, 0.0]);
    assert!(d < 1e-6, "{what}: tip off by {d:.2e} mm");
    for i in 0..4 {
        let (p, q) = (planar.a_bend_z[i], s.a_bend_z[i]);
        assert!((p - q).abs() < 1e-7, "{what}: a_{i} planar {p} vs spatial {q}");
        assert!(s.a_bend_y[i].abs() < 1e-12 && s.a_twist[i].abs() < 1e-12, "{what}");
    }
}

#[test]
fn an_anchored_cable_turns_the_tangent_where_it_ends_in_both_solvers() {
    // The tension stops at the anchor, so the shear and stretch jump and the
    // tangent turns there: both series include the turn.
    for gravity in [false, true] {
        let mut rod = Rod::default();
        rod.gravity.enabled = gravity;
        let cable = Cable { anchor_mm: Some(40.0), ..Cable::planar([0.0, 1.0, 2.0, 3.0, 4.0], 1.2) };
        assert_planar_agreement(&rod, cable, &format!("anchored, gravity {gravity}"));
    }
}

#[test]
fn a_rod_cured_bent_bends_alike_in_both_solvers() {
    for (gravity, tension) in [(false, 0.0), (true, 0.8), (false, 1.5)] {
        let mut rod = Rod::default();
        rod.gravity.enabled = gravity;
        rod.rest_curvature_per_mm = 0.004;
        assert_planar_agreement(&rod, Cable::planar([1.0, -2.0, 3.0, 1.5, -1.0], tension), &format!("rest curvature, {tension} N"));
    }
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Control points within 3.5 mm in y and z: |r_c| ≤ 4.95 mm < r.
    fn cable() -> impl Strategy<Value = Cable> {
        (proptest::array::uniform5(-3.5f64..3.5), proptest::array::uniform5(-3.5f64..3.5), 0.0f64..2.0)
            .prop_map(|(y, z, t)| Cable::spatial(y, z, t))
    }

    fn solve(cables: Vec<Cable>, gravity: Option<[f64; 3]>) -> Simulation {
        let mut rod = Rod::default();
        rod.gravity.enabled = gravity.is_some();
        let mut a = Actuator::with_cables(rod, cables);
        a.gravity_direction = gravity;
        run(&a)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Rotating the routings and the gravity direction together by 90°
        /// about the axis rotates the solution (without gravity the issue's
        /// symmetry; with gravity turned along, the same statement).
        #[test]
        fn a_quarter_turn_of_everything_turns_the_solution(c1 in cable(), c2 in cable(), g in proptest::option::of(proptest::array::uniform3(-1.0f64..1.0))) {
            prop_assume!(c1.y_mm != c2.y_mm || c1.z_mm != c2.z_mm);
            prop_assume!(g.is_none_or(|g| g.iter().map(|v| v * v).sum::<f64>() > 0.01));
            let turn = |c: &Cable| Cable::spatial(c.z_mm.map(|z| -z), c.y_mm, c.tension_n);
            let rot = |p: [f64; 3]| [p[0], -p[2], p[1]];
            let s = solve(vec![c1.clone(), c2.clone()], g);
            let t = solve(vec![turn(&c1), turn(&c2)], g.map(rot));
            prop_assert!(dist(rot(s.pose.tip_mm()), t.pose.tip_mm()) < 1e-8, "{:?} {:?}", s.pose.tip_mm(), t.pose.tip_mm());
            prop_assert!(angle(rot(s.pose.tip_tangent()), t.pose.tip_tangent()) < 1e-9);
            for i in 0..4 {
                prop_assert!((t.a_bend_y[i] + s.a_bend_z[i]).abs() < 1e-9 && (t.a_bend_z[i] - s.a_bend_y[i]).abs() < 1e-9);
            }
        }

        /// Mirroring y (routings and gravity) mirrors the solution; swapping
        /// the cables changes nothing.
        #[test]
        fn mirror_and_swap(c1 in cable(), c2 in cable(), g in proptest::option::of(proptest::array::uniform3(-1.0f64..1.0))) {
            prop_assume!(c1.y_mm != c2.y_mm || c1.z_mm != c2.z_mm);
            prop_assume!(g.is_none_or(|g| g.iter().map(|v| v * v).sum::<f64>() > 0.01));
            let m = |p: [f64; 3]| [p[0], -p[1], p[2]];
            let flip = |c: &Cable| Cable::spatial(c.y_mm.map(|y| -y), c.z_mm, c.tension_n);
            let s = solve(vec![c1.clone(), c2.clone()], g);
            let mirrored = solve(vec![flip(&c1), flip(&c2)], g.map(m));
            prop_assert!(dist(m(s.pose.tip_mm()), mirrored.pose.tip_mm()) < 1e-8);
            prop_assert!(angle(m(s.pose.tip_tangent()), mirrored.pose.tip_tangent()) < 1e-9);
            for i in 0..4 {
                prop_assert!((mirrored.a_twist[i] + s.a_twist[i]).abs() < 1e-9);
            }
            // Swapping changes the order of the cables' sums (rounding), as
            // mirroring does: the same bound as above, the solver's tolerance.
            let swapped = solve(vec![c2, c1], g);
            prop_assert!(dist(s.pose.tip_mm(), swapped.pose.tip_mm()) < 1e-8);
        }
    }
}
