//! Tests of the planar solver: solves, error estimates, bodies, anchors.

use super::*;

/// A random rod far from the thesis's (length, radius, rigidities, with or
/// without gravity), a routing within ±0.8 r and a tension bending it by
/// about 0.3–3 rad: the error estimates' test cases.
#[cfg(test)]
pub(super) fn random_case(rng: &mut crate::calibrate::rng::Rng) -> (Rod, Vec<f64>, f64) {
    let mut span = |lo: f64, hi: f64| lo * (hi / lo).powf(rng.uniform());
    let mut a = Rod::default();
    (a.length_mm, a.radius_mm, a.ei_n_mm2, a.ea_n, a.ga_n) = (span(30.0, 300.0), span(2.0, 8.0), span(20.0, 400.0), span(15.0, 60.0), span(1.0, 5.0));
    let tension = span(0.3, 3.0) * a.ei_n_mm2 / a.length_mm / a.radius_mm;
    a.gravity.enabled = rng.uniform() < 0.5;
    let y = (0..5).map(|_| (2.0 * rng.uniform() - 1.0) * 0.8 * a.radius_mm).collect();
    (a, y, tension)
}

mod tests {
    use super::super::*;
    #[allow(unused_imports)]
    use super::random_case;

    /// Thesis rod without gravity on a straight routing y_i = `d_mm`: the
    /// cable direction is α = 0 everywhere, so the effects have closed forms.
    fn straight(effects: impl FnOnce(&mut Rod), d_mm: f64) -> Simulator {
        let mut a = Rod::default();
        a.gravity.enabled = false;
        effects(&mut a);
        let mut sim = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[d_mm; 5]).unwrap();
        sim
    }

    fn ladder(sim: &mut Simulator, tension: f64) -> TipPose {
        let mut pose = None;
        for k in 1..=8 {
            pose = Some(sim.solve(tension * k as f64 / 8.0).unwrap());
        }
        pose.unwrap()
    }

    /// Every effect, collocation against the RK4 reference (at 192
    /// steps per span, well converged), on a curved routing with gravity:
    /// a tension ladder up and down, with creep holds.
    #[test]
    fn collocation_agrees_with_rk4_for_every_effect() {
        type Setup = fn(&mut Rod);
        let cases: [(&str, Setup); 9] = [
            ("thesis", |_| {}),
            ("gravity scale", |a| a.gravity.scale = 2.5),
            ("gravity direction", |a| a.gravity.direction_rad = 0.7),
            ("stiffening", |a| a.effects.stiffening_alpha = 2.0),
            ("clamp", |a| a.effects.clamp_stiffness_n_mm_per_rad = Some(40.0)),
            ("offset", |a| a.effects.channel_offset_mm = 0.5),
            ("friction", |a| a.effects.friction_mu = 0.2),
            ("creep", |a| {
                a.effects.creep_fraction = 0.3;
                a.effects.creep_time_s = 10.0;
            }),
            ("no gravity", |a| a.gravity.enabled = false),
        ];
        let rk4 = SolverOptions { method: SolverMethod::Rk4, planar_steps_per_span: 192, ..SolverOptions::default() };
        for (name, setup) in cases {
            let mut a = Rod::default();
            setup(&mut a);
            let mut sims = [Simulator::for_rod(&a, &SolverOptions::default()).unwrap(), Simulator::for_rod(&a, &rk4).unwrap()];
            for route in [[1.0, -2.0, 4.0, 4.0, -4.0], [-3.0, 1.0, -1.0, 0.0, -2.0]] {
                let mut poses = [Vec::new(), Vec::new()];
                for (sim, out) in sims.iter_mut().zip(&mut poses) {
                    sim.set_routing_mm(&route).unwrap();
                    for k in 1..=8 {
                        out.push(sim.solve(0.25 * k as f64).unwrap());
                    }
                    sim.set_hold(Hold { direction: LoadDirection::Unload, dwell_s: 5.0 }).unwrap();
                    for k in (0..8).rev() {
                        out.push(sim.solve(0.25 * k as f64).unwrap());
                    }
                    let mut coefficients = [0.0; 4];
                    sim.coefficients_into(LengthBasis::Rest, &mut coefficients);
                    out.push(TipPose { tip_x_mm: coefficients[1], tip_y_mm: coefficients[3], ..out[out.len() - 1] });
                }
                for (p, q) in poses[0].iter().zip(&poses[1]) {
                    let tip = (p.tip_x_mm - q.tip_x_mm).hypot(p.tip_y_mm - q.tip_y_mm);
                    let angle = (p.tip_angle_rad - q.tip_angle_rad).abs().max((p.base_angle_rad - q.base_angle_rad).abs());
                    // With friction τ(s) has kinks where the cable turns back
                    // (|ψ'|), so both methods converge only algebraically there:
                    // RK4 at 24 steps is itself 1.3e-4 mm off at 2 N.
                    let (tip_tol, angle_tol) = if name == "friction" { (5e-4, 3e-5) } else { (2e-5, 1e-6) };
                    assert!(tip < tip_tol && angle < angle_tol, "{name} {route:?} at {} N: tip {tip} mm, angle {angle} rad", p.tension_n());
                }
            }
        }
    }

    #[test]
    fn simulate_reports_its_own_errors_with_the_lower_layers_as_sources() {
        let (a, options) = (Rod::default(), SolverOptions::default());
        let routing = Routing::new(&[1.0, -2.0, 4.0, 4.0, -4.0], a.length_mm, a.radius_mm).unwrap();
        let err = simulate(&a, &options, &routing, -1.0, 3, LengthBasis::Rest).unwrap_err();
        assert!(matches!(err, SimulateError::Solve(SolveFailure::InvalidTension(t)) if t == -1.0), "{err:?}");
        assert_eq!(err.to_string(), SolveFailure::InvalidTension(-1.0).to_string());
        let hold = Hold { direction: LoadDirection::Load, dwell_s: f64::NAN };
        let err = simulate_held(&a, &options, &routing, 1.0, 3, LengthBasis::Rest, hold).unwrap_err();
        assert!(matches!(err, SimulateError::Parameter(ParameterError::OutOfRange { name: "dwell_s", .. })), "{err:?}");
    }

    #[test]
    fn bending_moment_adds_the_cable_moment_to_the_distal_moment() {
        assert_eq!(bending_moment(2.0, 3.0, 0.5, 0.25), 2.0 * 3.0 * 0.5 + 0.25);
    }

    #[test]
    fn friction_matches_the_capstan_closed_form() {
        // ψ' = u = τ(s) d / EI and dτ/ds = −η μ τ ψ' (slip sign η) give
        // τ(s) = τ0 / (1 + η μ τ0 d s / EI), φ(L) = η ln(1 + η μ τ0 d L / EI) / μ.
        let (mu, tau, d) = (0.1, 2.0, 4.0);
        let a = Rod::default();
        for direction in [LoadDirection::Load, LoadDirection::Unload] {
            let slip = direction.slip_sign();
            let mut sim = straight(|a| a.effects.friction_mu = mu, d);
            sim.set_hold(Hold { direction, dwell_s: 0.0 }).unwrap();
            let pose = ladder(&mut sim, tau);
            let expected = slip * (1.0 + slip * mu * tau * d * a.length_mm / a.ei_n_mm2).ln() / mu;
            assert!((pose.tip_angle_rad - expected).abs() < 2e-4, "{direction:?}: {} vs {expected}", pose.tip_angle_rad);
            let line = sim.centreline();
            let tip = line.last().unwrap();
            let tip_tension = tau / (1.0 + slip * mu * tau * d * a.length_mm / a.ei_n_mm2);
            assert!((tip.cables[0].tension_n - tip_tension).abs() < 1e-4, "{} vs {tip_tension}", tip.cables[0].tension_n);
        }
        // Without friction the profile is flat and load = unload.
        let mut sim = straight(|_| {}, d);
        let pose = ladder(&mut sim, tau);
        assert!((pose.tip_angle_rad - tau * d * a.length_mm / a.ei_n_mm2).abs() < 1e-6);
    }

    #[test]
    fn friction_makes_a_hysteresis_loop_on_a_curved_routing_with_gravity() {
        let mut a = Rod::default();
        a.effects.friction_mu = 0.2;
        let mut sim = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[1.0, -2.0, 4.0, 4.0, -4.0]).unwrap();
        let load = ladder(&mut sim, 1.5);
        sim.set_hold(Hold { direction: LoadDirection::Unload, dwell_s: 0.0 }).unwrap();
        let unload = sim.solve(1.5).unwrap();
        // Unloading, the distal tension is higher: the rod bends further.
        assert!((unload.tip_y_mm - load.tip_y_mm).abs() > 0.5, "{load:?} {unload:?}");
        let line = sim.centreline();
        assert!(line.last().unwrap().cables[0].tension_n > 1.5);
    }

    #[test]
    fn creep_follows_the_standard_linear_solid() {
        let (f, t_s, tau, d) = (0.3, 10.0, 1.0, 3.0);
        let a = Rod::default();
        let mut sim = straight(
            |a| {
                a.effects.creep_fraction = f;
                a.effects.creep_time_s = t_s;
            },
            d,
        );
        let (d1, d2) = (7.0, 4.0);
        let m = tau * d;
        let ei = a.ei_n_mm2;
        // Load step held d1 from a virgin rod (the ladder below holds 0 s).
        for k in 1..8 {
            sim.solve(tau * k as f64 / 8.0).unwrap();
        }
        sim.set_hold(Hold { direction: LoadDirection::Load, dwell_s: d1 }).unwrap();
        let held = sim.solve(tau).unwrap();
        let e1 = (-(1.0 - f) * d1 / t_s).exp();
        let u1 = m / ei * (1.0 + f * (1.0 - e1) / (1.0 - f));
        assert!((held.tip_angle_rad - u1 * a.length_mm).abs() < 1e-9, "{} vs {}", held.tip_angle_rad, u1 * a.length_mm);
        // Released and held d2: the residual bend of the recovering dashpot.
        sim.set_hold(Hold { direction: LoadDirection::Unload, dwell_s: d2 }).unwrap();
        let rest = sim.solve(0.0).unwrap();
        let q1 = m / (ei * (1.0 - f)) * (1.0 - e1);
        let e2 = (-(1.0 - f) * d2 / t_s).exp();
        assert!((rest.tip_angle_rad - f * e2 * q1 * a.length_mm).abs() < 1e-9, "{}", rest.tip_angle_rad);
        assert!(rest.tip_angle_rad > 0.01);
        // A long hold reaches the relaxed rigidity EI (1 − f).
        sim.reset_history();
        sim.set_hold(Hold { direction: LoadDirection::Load, dwell_s: 1e4 }).unwrap();
        let relaxed = sim.solve(tau).unwrap();
        assert!((relaxed.tip_angle_rad - m / (ei * (1.0 - f)) * a.length_mm).abs() < 1e-9);
        // Outside a protocol (sweeps, design) every tension is held
        // `creep_hold_s` on a fresh rod: the same as the first held step.
        let mut fresh = straight(
            |a| {
                a.effects.creep_fraction = f;
                a.effects.creep_time_s = t_s;
                a.effects.creep_hold_s = d1;
            },
            d,
        );
        for _ in 0..3 {
            let pose = ladder(&mut fresh, tau);
            assert!((pose.tip_angle_rad - u1 * a.length_mm).abs() < 1e-9);
        }
    }

    #[test]
    fn clamp_compliance_rotates_the_rod_rigidly() {
        let (k_theta, tau, d) = (40.0, 1.2, 2.5);
        let stiff = ladder(&mut straight(|_| {}, d), tau);
        let soft = ladder(&mut straight(|a| a.effects.clamp_stiffness_n_mm_per_rad = Some(k_theta), d), tau);
        let phi0 = tau * d / k_theta;
        let (s, c) = phi0.sin_cos();
        assert!((soft.tip_angle_rad - stiff.tip_angle_rad - phi0).abs() < 1e-9);
        assert!((soft.tip_x_mm - (c * stiff.tip_x_mm - s * stiff.tip_y_mm)).abs() < 1e-9);
        assert!((soft.tip_y_mm - (s * stiff.tip_x_mm + c * stiff.tip_y_mm)).abs() < 1e-9);
        // No moment at the clamp (y_c(0) = 0, no gravity): no rotation.
        let mut a = Rod::default();
        a.gravity.enabled = false;
        let route = [0.0, 2.0, 3.0, 1.0, 2.0];
        let mut rigid = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
        rigid.set_routing_mm(&route).unwrap();
        a.effects.clamp_stiffness_n_mm_per_rad = Some(k_theta);
        let mut compliant = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
        compliant.set_routing_mm(&route).unwrap();
        assert!((ladder(&mut rigid, tau).tip_y_mm - ladder(&mut compliant, tau).tip_y_mm).abs() < 1e-12);
    }

    #[test]
    fn stiffening_and_channel_offset_follow_their_laws() {
        // Straight routing: constant moment τ d, curvature solves EI (u + α r² u³) = τ d.
        let (alpha, tau, d) = (2.0, 2.0, 3.0);
        let a = Rod::default();
        let pose = ladder(&mut straight(|a| a.effects.stiffening_alpha = alpha, d), tau);
        let u = pose.tip_angle_rad / a.length_mm;
        let m = a.ei_n_mm2 * (u + alpha * a.radius_mm.powi(2) * u.powi(3));
        assert!((m - tau * d).abs() < 1e-6, "{m}");
        // Channel offset δ on y_i = d is the routing y_i = d + δ.
        let shifted = ladder(&mut straight(|a| a.effects.channel_offset_mm = 0.5, d), tau);
        let direct = ladder(&mut straight(|_| {}, d + 0.5), tau);
        assert!((shifted.tip_y_mm - direct.tip_y_mm).abs() < 1e-12);
    }

    #[test]
    fn a_rest_curvature_and_a_stiff_base_segment_follow_their_laws() {
        // Straight routing: u = τ d / EI_local + u*, so φ(L) = ∫ u ds.
        let (tau, d, u0) = (1.5, 3.0, 0.004);
        let a = Rod::default();
        let curved = ladder(&mut straight(|a| a.rest_curvature_per_mm = u0, d), tau);
        let want = tau * d * a.length_mm / a.ei_n_mm2 + u0 * a.length_mm;
        assert!((curved.tip_angle_rad - want).abs() < 1e-6, "{} vs {want}", curved.tip_angle_rad);
        // At rest the rod keeps its cured-in bend.
        let mut rest = straight(|a| a.rest_curvature_per_mm = u0, d);
        assert!((rest.solve(0.0).unwrap().tip_angle_rad - u0 * a.length_mm).abs() < 1e-9);
        // A stiff 5 mm at the clamp is a body segment of its own material.
        let glued = ladder(
            &mut straight(
                |a| {
                    a.segments = vec![
                        crate::model::Segment { end_mm: 5.0, ea_n: None, ga_n: None, ei_n_mm2: Some(5.0 * a.ei_n_mm2), density_g_cm3: None },
                        crate::model::Segment { end_mm: a.length_mm, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
                    ]
                },
                d,
            ),
            tau,
        );
        let want = tau * d / a.ei_n_mm2 * (a.length_mm - 5.0 + 5.0 / 5.0);
        assert!((glued.tip_angle_rad - want).abs() < 1e-9 * want, "{} vs {want}", glued.tip_angle_rad);
    }
}

mod body_tests {
    //! Non-uniform bodies (radius profile, segments, cable anchor) and the
    //! stiffness gradient against closed forms and equilibrium.
    use super::super::*;
    #[allow(unused_imports)]
    use super::random_case;
    use crate::model::body::Segment;

    /// Gauss–Legendre 8-point nodes and weights on [−1, 1].
    const GL8: [(f64, f64); 8] = [
        (-0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
        (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
        (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    ];

    /// ∫_a^b f by composite 8-point Gauss–Legendre on `n` panels.
    fn quad(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        let h = (b - a) / n as f64;
        (0..n)
            .map(|k| {
                let c = a + (k as f64 + 0.5) * h;
                GL8.iter().map(|&(x, w)| w * f(c + 0.5 * h * x)).sum::<f64>() * 0.5 * h
            })
            .sum()
    }

    /// The tip of a rod with curvature `kappa(s)` and stretch `v1(s)` (no
    /// shear), integrated piecewise between `cuts` (where the integrands kink).
    fn tip_by_quadrature(kappa: &dyn Fn(f64) -> f64, v1: &dyn Fn(f64) -> f64, cuts: &[f64]) -> (f64, f64, f64) {
        let phi = |s: f64| -> f64 {
            let mut total = 0.0;
            for w in cuts.windows(2) {
                if s <= w[0] {
                    break;
                }
                total += quad(kappa, w[0], s.min(w[1]), 4);
            }
            total
        };
        let (mut x, mut y) = (0.0, 0.0);
        for w in cuts.windows(2) {
            x += quad(|s| v1(s) * phi(s).cos(), w[0], w[1], 40);
            y += quad(|s| v1(s) * phi(s).sin(), w[0], w[1], 40);
        }
        (x, y, phi(cuts[cuts.len() - 1]))
    }

    fn tapered_thesis_rod() -> Rod {
        let mut a = Rod::default();
        a.radius_profile_mm = vec![(0.0, 6.0), (30.0, 5.0), (65.0, 4.0)];
        a
    }

    #[test]
    fn straight_routing_bends_as_tau_d_over_ei_of_s() {
        let (tau, d) = (1.5, 3.0);
        for beta in [0.0, -0.7] {
            let mut a = tapered_thesis_rod();
            a.gravity.enabled = false;
            a.effects.stiffness_gradient_beta = beta;
            a.segments = vec![
                Segment { end_mm: 20.0, ea_n: Some(40.0), ga_n: None, ei_n_mm2: Some(150.0), density_g_cm3: None },
                Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
            ];
            let body = a.body().unwrap().unwrap();
            let ei = |s: f64| body.section_at(s).ei_n_mm2 * (beta * (s / a.length_mm - 0.5)).exp();
            let kappa = |s: f64| tau * d / ei(s);
            let v1 = |s: f64| 1.0 - tau / body.section_at(s).ea_n;
            let (x, y, phi) = tip_by_quadrature(&kappa, &v1, &[0.0, 20.0, 30.0, 65.0]);
            let options = SolverOptions { nodes_per_span: 24, ..SolverOptions::default() };
            let mut sim = Simulator::for_rod(&a, &options).unwrap();
            sim.set_routing_mm(&[d; 5]).unwrap();
            let pose = sim.solve(tau).unwrap();
            let err = (pose.tip_x_mm - x).hypot(pose.tip_y_mm - y);
            eprintln!("angle {} vs {phi}; ell {}", pose.tip_angle_rad, pose.length_mm);
            for p in sim.centreline().iter().step_by(6) { eprintln!("{} {} {} {}", p.s_mm, p.u_per_mm[2], kappa(p.s_mm), p.v[0] - v1(p.s_mm)); }
            assert!(err < 1e-8, "β {beta}: tip ({}, {}) vs ({x}, {y}): {err:e} mm", pose.tip_x_mm, pose.tip_y_mm);
            assert!((pose.tip_angle_rad - phi).abs() < 1e-10);
            // The curvature along the centreline is τ d / EI(s).
            for p in sim.centreline().iter().step_by(7) {
                assert!((p.u_per_mm[2] - kappa(p.s_mm)).abs() < 1e-7 * kappa(p.s_mm), "s {}: {} vs {}", p.s_mm, p.u_per_mm[2], kappa(p.s_mm));
            }
        }
    }

    #[test]
    fn beyond_the_anchor_the_rod_stays_straight_without_gravity() {
        let (tau, d, anchor) = (1.2, 2.5, 45.0);
        let mut a = tapered_thesis_rod();
        a.gravity.enabled = false;
        a.cable_anchor_mm = Some(anchor);
        let mut sim = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[d; 5]).unwrap();
        let pose = sim.solve(tau).unwrap();
        let line = sim.centreline();
        let at_anchor = line.iter().find(|p| p.s_mm > anchor).unwrap();
        let body = a.body().unwrap().unwrap();
        let phi_k = quad(|s| tau * d / body.section_at(s).ei_n_mm2, 0.0, 30.0, 8) + quad(|s| tau * d / body.section_at(s).ei_n_mm2, 30.0, anchor, 8);
        assert!((pose.tip_angle_rad - phi_k).abs() < 1e-9, "{} vs {phi_k}", pose.tip_angle_rad);
        for p in line.iter().filter(|p| p.s_mm > anchor) {
            assert!(p.u_per_mm[2].abs() < 1e-12 && p.cables[0].tension_n == 0.0, "{p:?}");
            assert!((p.tangent_angle_rad - pose.tip_angle_rad).abs() < 1e-12);
            // On one straight line.
            let (dx, dy) = (p.x_mm - at_anchor.x_mm, p.y_mm - at_anchor.y_mm);
            assert!((dx * phi_k.sin() - dy * phi_k.cos()).abs() < 1e-9, "{p:?}");
        }
        // A routing spans the cable only: its control points sit on [0, s_k].
        let r = Routing::for_actuator([d; 5], &a).unwrap();
        assert_eq!(r.length_mm(), anchor);
        assert!(Simulator::for_rod(&a, &SolverOptions { method: SolverMethod::Rk4, ..SolverOptions::default() }).is_err());
    }

    #[test]
    fn a_tapered_rod_under_its_weight_balances_the_base_moment() {
        for (profile, direction) in [(vec![(0.0, 7.0), (65.0, 3.0)], 1.0), (vec![(0.0, 6.0), (30.0, 5.0), (65.0, 4.0)], 0.4)] {
            let mut a = Rod::default();
            a.radius_profile_mm = profile;
            a.gravity.direction_rad = direction;
            a.gravity.scale = 20.0;
            a.segments = vec![
                Segment { end_mm: 40.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: Some(1.5) },
                Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
            ];
            let options = SolverOptions { planar_steps_per_span: 2000, ..SolverOptions::default() };
            let mut sim = Simulator::for_rod(&a, &options).unwrap();
            sim.set_routing_mm(&[0.0; 5]).unwrap();
            let pose = sim.solve(0.0).unwrap();
            let line = sim.centreline();
            let body = a.body().unwrap().unwrap();
            let g = a.gravity.scale * a.gravity.g_m_s2 * 1e-6 * std::f64::consts::PI;
            let w = |s: f64| g * body.density_at(s) * body.radius_at(s).powi(2);
            let (c, sn) = (direction.cos(), direction.sin());
            let (x0, y0) = (line[0].x_mm, line[0].y_mm);
            // Trapezoid over the centreline (fine: 4001 points).
            let mut moment = 0.0;
            for pair in line.windows(2) {
                let f = |p: &CentrelinePoint| w(p.s_mm) * ((p.y_mm - y0) * c - (p.x_mm - x0) * sn);
                moment -= 0.5 * (f(&pair[0]) + f(&pair[1])) * (pair[1].s_mm - pair[0].s_mm);
            }
            let base = body.section_at(0.0).ei_n_mm2 * line[0].u_per_mm[2];
            assert!(pose.tip_y_mm.abs() > 5.0, "the rod should bend: {pose:?}");
            assert!((base - moment).abs() < 1e-5 * moment.abs(), "base moment {base} vs ∫ w lever {moment}");
        }
    }

    #[test]
    fn a_uniform_profile_and_one_material_match_the_uniform_rod() {
        // The same spans: agreement to the fixed point's tolerance (the
        // weight is summed differently, so rounding takes another path; the
        // sweeps stop at 1e-9 rad, about 1e-7 mm at the tip); an extra
        // breakpoint at 20 mm changes the discretisation, well below its error.
        let mut flat = Rod::default();
        flat.radius_profile_mm = vec![(0.0, 5.0), (65.0, 5.0)];
        flat.segments = vec![Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None }];
        flat.cable_anchor_mm = Some(65.0);
        let mut split = flat.clone();
        split.radius_profile_mm = vec![(0.0, 5.0), (20.0, 5.0), (65.0, 5.0)];
        let route = [1.0, -2.0, 4.0, 4.0, -4.0];
        let mut poses = Vec::new();
        for a in [Rod::default(), flat, split] {
            let mut sim = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
            sim.set_routing_mm(&route).unwrap();
            poses.push((1..=8).map(|k| sim.solve(0.25 * k as f64).unwrap()).collect::<Vec<_>>());
        }
        for (k, tol) in [(1, 1e-6), (2, 1e-6)] {
            for (p, q) in poses[0].iter().zip(&poses[k]) {
                assert!((p.tip_x_mm - q.tip_x_mm).abs() < tol && (p.tip_y_mm - q.tip_y_mm).abs() < tol, "{p:?} {q:?}");
            }
        }
    }

    #[test]
    fn rk4_agrees_with_collocation_on_a_cone_with_gravity() {
        let mut a = Rod::default();
        a.radius_profile_mm = vec![(0.0, 6.5), (65.0, 4.0)];
        a.effects.stiffness_gradient_beta = -0.5;
        let rk4 = SolverOptions { method: SolverMethod::Rk4, planar_steps_per_span: 192, ..SolverOptions::default() };
        let mut sims = [Simulator::for_rod(&a, &SolverOptions::default()).unwrap(), Simulator::for_rod(&a, &rk4).unwrap()];
        let mut poses = [Vec::new(), Vec::new()];
        for (sim, out) in sims.iter_mut().zip(&mut poses) {
            sim.set_routing_mm(&[1.0, -2.0, 3.5, 3.5, -3.5]).unwrap();
            for k in 1..=8 {
                out.push(sim.solve(0.25 * k as f64).unwrap());
            }
        }
        for (p, q) in poses[0].iter().zip(&poses[1]) {
            let tip = (p.tip_x_mm - q.tip_x_mm).hypot(p.tip_y_mm - q.tip_y_mm);
            assert!(tip < 2e-5 && (p.tip_angle_rad - q.tip_angle_rad).abs() < 1e-6, "{p:?} {q:?}");
        }
    }

    #[test]
    fn the_real_tentacle_solves_up_to_7_7_n() {
        // 360 mm, r 15.4 → 6.4 → 4.8 mm, tendon knotted at 305 mm, full gravity.
        let mut a = Rod { length_mm: 360.0, cable_anchor_mm: Some(305.0), ..Rod::default() };
        a.radius_profile_mm = vec![(0.0, 15.4), (305.0, 6.4), (360.0, 4.8)];
        let mut sim = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[4.0; 5]).unwrap();
        let mut last = None;
        for k in 1..=31 {
            last = Some(sim.solve(7.7 * k as f64 / 31.0).unwrap());
        }
        let pose = last.unwrap();
        assert!(pose.tip_angle_rad > 3.0, "{pose:?}");
    }
}

mod anchor_edge_tests {
    use super::super::*;
    #[allow(unused_imports)]
    use super::random_case;

    /// An anchor a hair above a profile point is merged with it: the span
    /// from there on carries no cable, as with the anchor exactly there.
    #[test]
    fn an_anchor_merged_into_a_breakpoint_ends_the_cable_there() {
        let mut poses = Vec::new();
        for anchor in [50.0, 50.0 + 1e-12] {
            let mut a = Rod::default();
            a.gravity.enabled = false;
            a.radius_profile_mm = vec![(0.0, 6.0), (50.0, 5.0), (65.0, 4.0)];
            a.cable_anchor_mm = Some(anchor);
            let mut sim = Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
            sim.set_routing_mm(&[2.0; 5]).unwrap();
            let pose = sim.solve(1.0).unwrap();
            assert!(sim.centreline().iter().filter(|p| p.s_mm > 50.5).all(|p| p.u_per_mm[2] == 0.0));
            poses.push(pose);
        }
        assert!((poses[0].tip_angle_rad - poses[1].tip_angle_rad).abs() < 1e-9, "{poses:?}");
    }
}
