//! Tests of the spatial collocation backend.

use super::*;
use crate::solver::spatial::Cable;

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A one-cable in-plane actuator (`rod`, routing `y`, tension `tau`,
/// anchor `anchor`) by the planar collocation solver and by this one:
/// tip distance (mm), tip angle difference (rad) and largest a_k
/// difference (1/mm).
fn planar_against_spatial(rod: &Rod, y: [f64; 5], tau: f64, anchor: Option<f64>) -> (f64, f64, f64) {
    let mut planar_rod = rod.clone();
    planar_rod.cable_anchor_mm = anchor;
    let routing = crate::model::Routing::for_actuator(y, &planar_rod).unwrap();
    let options = crate::solver::SolverOptions { nodes_per_span: 24, ..Default::default() };
    let p = crate::solver::simulate(&planar_rod, &options, &routing, tau, 3, LengthBasis::Rest).unwrap();
    let mut cable = Cable::planar(y, tau);
    cable.anchor_mm = anchor;
    let a = Actuator::with_cables(rod.clone(), vec![cable]);
    let options = SolverOptions { nodes_per_span: 24, ..Default::default() };
    let sp = crate::solver::spatial::simulate_spatial(&a, &options, 3, LengthBasis::Rest).unwrap();
    let tip = dist(sp.pose.tip_mm(), [p.pose.tip_x_mm, p.pose.tip_y_mm, 0.0]);
    let angle = (sp.pose.tip_angle_rad - p.pose.tip_angle_rad).abs();
    let da = sp.a_bend_z.iter().zip(&p.a_bend_z).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    (tip, angle, da)
}

#[test]
fn in_plane_it_agrees_with_the_planar_solver_for_every_body_and_effect() {
    let y = [3.0, -1.0, 2.5, 1.0, -2.0];
    let taper = |r: &mut Rod| r.radius_profile_mm = vec![(0.0, 5.0), (40.0, 4.5), (65.0, 4.0)];
    let segments = |r: &mut Rod| {
        r.segments = vec![
            crate::model::Segment { end_mm: 30.0, ea_n: None, ga_n: None, ei_n_mm2: Some(160.0), density_g_cm3: Some(1.2) },
            crate::model::Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
        ]
    };
    type Case = (&'static str, fn(&mut Rod), Option<f64>);
    let cases: Vec<Case> = vec![
        ("uniform", |_| {}, None),
        ("sideways gravity", |r| r.gravity.direction_rad = 1.2, None),
        ("tapered", |r| r.radius_profile_mm = vec![(0.0, 5.0), (40.0, 4.5), (65.0, 4.0)], None),
        ("segments", |r| {
            r.segments = vec![
                crate::model::Segment { end_mm: 30.0, ea_n: None, ga_n: None, ei_n_mm2: Some(160.0), density_g_cm3: Some(1.2) },
                crate::model::Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
            ]
        }, None),
        ("anchored", |_| {}, Some(45.0)),
        ("tapered and anchored", |r| r.radius_profile_mm = vec![(0.0, 5.0), (40.0, 4.5), (65.0, 4.0)], Some(50.0)),
        ("friction, loading", |r| r.effects.friction_mu = 0.2, None),
        ("friction, unloading", |r| {
            r.effects.friction_mu = 0.2;
            r.effects.load_direction = crate::model::LoadDirection::Unload;
        }, None),
        ("clamp compliance", |r| r.effects.clamp_stiffness_n_mm_per_rad = Some(300.0), None),
        ("channel offset", |r| r.effects.channel_offset_mm = 0.4, None),
        ("stiffening", |r| r.effects.stiffening_alpha = 2.0, None),
        ("stiffness gradient", |r| r.effects.stiffness_gradient_beta = -0.8, None),
        ("creep", |r| {
            r.effects.creep_fraction = 0.3;
            r.effects.creep_hold_s = 20.0;
        }, None),
    ];
    let _ = (taper, segments);
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for (name, set, anchor) in cases {
        let mut rod = Rod::default();
        set(&mut rod);
        let (tip, angle, da) = planar_against_spatial(&rod, y, 1.6, anchor);
        eprintln!("{name}: tip {tip:.1e} mm, angle {angle:.1e} rad, a {da:.1e} /mm");
        assert!(tip < 1e-6 && angle < 1e-7 && da < 1e-7, "{name}: tip {tip:e} mm, angle {angle:e} rad, a_k {da:e} /mm");
        worst = (worst.0.max(tip), worst.1.max(angle), worst.2.max(da));
    }
    eprintln!("worst: {worst:?}");
}

fn simulate(a: &Actuator) -> crate::solver::Simulation {
    let options = crate::solver::SolverOptions::default();
    crate::solver::simulate_actuator(a, &options, Default::default(), None, 3, LengthBasis::Rest).unwrap()
}

fn same_shape(p: &crate::solver::Simulation, q: &crate::solver::Simulation) -> f64 {
    p.centreline.iter().zip(&q.centreline).map(|(a, b)| dist(a.position_mm(), b.position_mm())).fold(0.0, f64::max)
}

#[test]
fn exp_so3_is_the_rotation_about_its_vector() {
    for w in [V3::new(1e-9, -2e-9, 0.5e-9), V3::new(0.01, -0.02, 0.03), V3::new(0.3, 0.2, -0.1), V3::new(-0.9, 1.2, 0.4)] {
        let r = exp_so3(&w);
        let expected = Rotation3::new(w);
        assert!((r - expected.matrix()).amax() < 1e-15, "{w:?}: {r} against {}", expected.matrix());
        assert!((r.transpose() * r - M3::identity()).amax() < 1e-15);
    }
}

#[test]
fn a_displacement_gives_back_the_shape_of_the_tension_that_produced_it() {
    // Planar fast path, spatial pair, and a pair with one cable of each kind;
    // gravity on, a stretchy cable for the second.
    let mut rod = Rod::default();
    rod.gravity.enabled = true;
    let y = [3.0, -1.0, 2.5, 1.0, -2.0];
    let one = Actuator::with_cables(rod.clone(), vec![Cable::planar(y, 1.6)]);
    let mut second = Cable::spatial([-1.0, 1.0, 2.0, 0.5, -1.0], [1.0, -1.5, 0.5, 2.0, 1.0], 0.9);
    second.cable_ea_n = Some(40.0);
    let pair = Actuator::with_cables(rod.clone(), vec![Cable::spatial(y, [0.5, 1.0, -1.0, 0.0, 0.5], 1.3), second]);
    for (name, a, driven) in [("planar", &one, vec![0]), ("pair", &pair, vec![0, 1]), ("mixed", &pair, vec![1])] {
        let by_tension = simulate(a);
        let mut b = a.clone();
        for &i in &driven {
            b.cables[i].displacement_mm = Some(by_tension.pose.displacements_mm[i]);
            b.cables[i].tension_n = 0.0;
        }
        let by_displacement = simulate(&b);
        let shape = same_shape(&by_tension, &by_displacement);
        let tension = by_tension.pose.tensions_n.iter().zip(by_displacement.pose.tensions_n.iter()).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
        eprintln!("{name}: displacements {:?} mm, shape {shape:.1e} mm, tensions {tension:.1e} N", &by_tension.pose.displacements_mm[..]);
        assert!(shape < 1e-9 && tension < 1e-9, "{name}: shape {shape:e} mm, tension {tension:e} N");
        assert!(by_tension.pose.displacements_mm.iter().all(|d| d.is_finite() && *d > 0.0));
        for &i in &driven {
            assert!((by_displacement.actuator.cables[i].tension_n - by_tension.pose.tensions_n[i]).abs() < 1e-9);
        }
    }
}

#[test]
fn a_cable_pulled_in_less_than_its_path_needs_is_slack() {
    // Gravity across the rod sags it toward +y: a cable at +y is on the
    // inside of the bend and its path shortens, so a cable pulled in by
    // nothing is slack, and the shape is the weight's alone.
    let mut rod = Rod::default();
    rod.gravity.enabled = true;
    rod.gravity.direction_rad = std::f64::consts::FRAC_PI_2;
    let y = [3.0; 5];
    let weight = simulate(&Actuator::with_cables(rod.clone(), vec![Cable::planar(y, 0.0)]));
    assert!(weight.pose.displacements_mm[0] > 0.0, "the sagging rod's inner path shortens: {:?}", weight.pose.displacements_mm);
    let slack = Cable { displacement_mm: Some(0.0), ..Cable::planar(y, 0.0) };
    for cables in [vec![slack.clone()], vec![Cable { z_mm: [0.0, 1.0, 1.0, 1.0, 0.0], ..slack.clone() }, Cable::planar([-3.0; 5], 0.0)]] {
        let sim = simulate(&Actuator::with_cables(rod.clone(), cables.clone()));
        assert_eq!(sim.pose.tensions_n[0], 0.0, "{cables:?}");
        if cables.len() == 1 {
            assert!(same_shape(&sim, &weight) < 1e-12);
        }
    }
    // Pulled in a little more than the sag gives: taut, with a small tension.
    let taut = Cable { displacement_mm: Some(weight.pose.displacements_mm[0] + 0.05), ..Cable::planar(y, 0.0) };
    let sim = simulate(&Actuator::with_cables(rod, vec![taut]));
    assert!(sim.pose.tensions_n[0] > 0.0 && sim.pose.tensions_n[0] < 0.2, "{:?}", &sim.pose.tensions_n[..]);
}

#[test]
fn bad_displacements_and_stiffnesses_are_refused_by_name() {
    let y = [1.0; 5];
    for (d, ea, needle) in [(-1.0, None, "negative"), (f64::NAN, None, "finite"), (80.0, None, "cannot be pulled in"), (1.0, Some(0.0), "cable_ea_n")] {
        let cable = Cable { displacement_mm: Some(d), cable_ea_n: ea, ..Cable::planar(y, 0.0) };
        let a = Actuator::with_cables(Rod::default(), vec![cable]);
        let e = crate::solver::simulate_actuator(&a, &Default::default(), Default::default(), None, 3, LengthBasis::Rest).unwrap_err();
        assert!(e.to_string().contains(needle) && e.to_string().contains("cable 1"), "{e}");
    }
    // The RK4 references do not integrate the cables' paths.
    let cable = Cable { displacement_mm: Some(1.0), ..Cable::planar(y, 0.0) };
    let a = Actuator::with_cables(Rod::default(), vec![cable]);
    let rk4 = crate::solver::SolverOptions { method: crate::solver::SolverMethod::Rk4, ..Default::default() };
    let e = crate::solver::simulate_actuator(&a, &rk4, Default::default(), None, 3, LengthBasis::Rest).unwrap_err();
    assert!(e.to_string().contains("displacement"), "{e}");
    // A file gives one actuation.
    let both = "[[cable]]\ny_mm = [1, 1, 1, 1, 1]\ntension_n = 1\ndisplacement_mm = 1\n";
    assert!(Actuator::from_toml(both, "a.toml").unwrap_err().to_string().contains("not both"));
    let none = "[[cable]]\ny_mm = [1, 1, 1, 1, 1]\n";
    assert!(Actuator::from_toml(none, "a.toml").unwrap_err().to_string().contains("displacement_mm"));
}
