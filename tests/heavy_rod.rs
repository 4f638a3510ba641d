//! Heavy, long rods under full gravity (issue 15): a lab-sized actuator
//! (L = 360 mm, r = 12 mm, ρ = 1.16 g/cm³, EI 6,000–10,000 N·mm², EA 20–60 N,
//! a straight channel from 11.4 mm to 0.8 mm, 1.5–7.7 N) converges, and the
//! converged shapes are checked by computations independent of the solver's
//! own: refinement, the equilibrium of the distal free body evaluated from
//! the output shape alone, and the previous RK4 method where it converges.

use cablemap::model::{Rod, Routing};
use cablemap::solver::{simulate, Simulation, SolverMethod, SolverOptions};
use cablemap::shape::LengthBasis;
use std::process::Command;

const CHANNEL_MM: [f64; 5] = [11.4, 8.75, 6.1, 3.45, 0.8];
const TENSIONS_N: [f64; 4] = [1.5, 3.0, 5.0, 7.7];

fn heavy(ei_n_mm2: f64, ea_n: f64) -> Rod {
    let mut a = Rod::default();
    a.length_mm = 360.0;
    a.radius_mm = 12.0;
    a.density_g_cm3 = 1.16;
    a.ei_n_mm2 = ei_n_mm2;
    a.ea_n = ea_n;
    // Incompressible rubber: G = E/3.
    a.ga_n = ea_n / 3.0;
    a
}

fn solve(a: &Rod, options: &SolverOptions, tension_n: f64) -> Simulation {
    let routing = Routing::new(&CHANNEL_MM, a.length_mm, a.radius_mm).unwrap();
    simulate(a, options, &routing, tension_n, 3, LengthBasis::Rest)
        .unwrap_or_else(|e| panic!("EI {} EA {} at {tension_n} N: {e}", a.ei_n_mm2, a.ea_n))
}

#[test]
fn heavy_rods_converge_and_refinement_agrees() {
    let fine = SolverOptions { nodes_per_span: 24, ..SolverOptions::default() };
    let mut worst: f64 = 0.0;
    for ei in [6000.0, 8000.0, 10000.0] {
        for ea in [20.0, 40.0, 60.0] {
            let a = heavy(ei, ea);
            for t in TENSIONS_N {
                let coarse = solve(&a, &SolverOptions::default(), t);
                let refined = solve(&a, &fine, t);
                let (p, q) = (coarse.pose, refined.pose);
                let tip = (p.tip_x_mm - q.tip_x_mm).hypot(p.tip_y_mm - q.tip_y_mm);
                let angle = (p.tip_angle_rad - q.tip_angle_rad).abs();
                let a_err = (0..4).map(|i| (coarse.a_bend_z[i] - refined.a_bend_z[i]).abs()).fold(0.0, f64::max);
                worst = worst.max(tip);
                assert!(tip < 1e-6 && angle < 1e-8 && a_err < 1e-8, "EI {ei} EA {ea} {t} N: tip {tip} angle {angle} a {a_err}");
                // The weight bends the rod down toward the clamp axis: the
                // tip sits lower than without gravity.
                assert!(p.tip_y_mm > 0.0);
            }
        }
    }
    eprintln!("heavy rods: worst tip change from 10 to 24 intervals per span {worst:.2e} mm");
}

/// Equilibrium of the distal part (s, L] at every cut, from the output
/// centreline alone (positions, frame angle, cable path; finite differences
/// and Simpson quadrature, nothing from the solver's internal integrals):
/// bending moment EI φ' = τ y_c t_c1 + M_W(s) with M_W the weight's moment
/// about the cut, and axial force EA (v1 − 1) = −τ t_c1 + (Rᵀ W)_1.
#[test]
fn heavy_rod_shape_is_in_equilibrium() {
    let options = SolverOptions { planar_steps_per_span: 400, ..SolverOptions::default() };
    for (ei, ea) in [(6000.0, 20.0), (6000.0, 60.0), (10000.0, 40.0)] {
        let a = heavy(ei, ea);
        let w = a.weight_n_per_mm();
        for t in [1.5, 7.7] {
            let line = solve(&a, &options, t).centreline;
            let n = line.len();
            let h = line[1].s_mm - line[0].s_mm;
            // ∫_{s_k}^{L} f by Simpson where the count of intervals is even, else one trapezoid first.
            let distal = |k: usize, f: &dyn Fn(usize) -> f64| -> f64 {
                let intervals = n - 1 - k;
                let mut start = k;
                let mut sum = 0.0;
                if intervals % 2 == 1 {
                    sum += 0.5 * h * (f(k) + f(k + 1));
                    start += 1;
                }
                let mut j = start;
                while j + 2 <= n - 1 {
                    sum += h / 3.0 * (f(j) + 4.0 * f(j + 1) + f(j + 2));
                    j += 2;
                }
                sum
            };
            let (mut worst_m, mut worst_f, mut scale_m) = (0.0f64, 0.0f64, 0.0f64);
            for k in 2..n - 2 {
                let p = &line[k];
                let d = |f: &dyn Fn(usize) -> f64| (f(k + 1) - f(k - 1)) / (2.0 * h);
                let u = d(&|i| line[i].frame_angle_rad);
                let (dx, dy) = (d(&|i| line[i].x_mm), d(&|i| line[i].y_mm));
                let (cx, cy) = (d(&|i| line[i].cables[0].position_mm[0]), d(&|i| line[i].cables[0].position_mm[1]));
                let (sp, cp) = p.frame_angle_rad.sin_cos();
                // Cable direction in the body frame, from the cable's path.
                let norm = cx.hypot(cy);
                let tc1 = (cx * cp + cy * sp) / norm;
                // Gravity along +x: moment of the distal weight about the cut.
                let m_w = -w * distal(k, &|i| line[i].y_mm - p.y_mm);
                let moment = ei * u;
                let expected = t * p.cables[0].channel_mm[0] * tc1 + m_w;
                worst_m = worst_m.max((moment - expected).abs());
                scale_m = scale_m.max(moment.abs());
                let v1 = dx * cp + dy * sp;
                let axial = ea * (v1 - 1.0);
                let expected_axial = -t * tc1 + w * (a.length_mm - p.s_mm) * cp;
                worst_f = worst_f.max((axial - expected_axial).abs());
            }
            // Finite differences at h = 0.45 mm leave ~1e-5 relative.
            assert!(worst_m < 2e-4 * scale_m, "EI {ei} EA {ea} {t} N: moment residual {worst_m} N·mm of {scale_m}");
            assert!(worst_f < 2e-4 * t, "EI {ei} EA {ea} {t} N: axial residual {worst_f} N");
            eprintln!("EI {ei} EA {ea} {t} N: moment residual {worst_m:.2e} of {scale_m:.1} N·mm, axial {worst_f:.2e} N");
        }
    }
}

#[test]
fn heavy_rod_agrees_with_rk4_where_rk4_converges() {
    let rk4 = SolverOptions { method: SolverMethod::Rk4, planar_steps_per_span: 96, ..SolverOptions::default() };
    let a = heavy(10000.0, 40.0);
    for t in TENSIONS_N {
        let (p, q) = (solve(&a, &SolverOptions::default(), t).pose, solve(&a, &rk4, t).pose);
        let tip = (p.tip_x_mm - q.tip_x_mm).hypot(p.tip_y_mm - q.tip_y_mm);
        eprintln!("rk4-96 vs collocation at {t} N: {tip:.2e} mm");
        assert!(tip < 1e-6, "{t} N: {tip} mm");
    }
}

#[test]
fn heavy_rod_simulates_from_the_command_line() {
    let out = Command::new(env!("CARGO_BIN_EXE_cablemap"))
        .args(["simulate", "--routing=11.4,8.75,6.1,3.45,0.8", "--tension", "7.7", "--json"])
        .args(["--length-mm", "360", "--radius-mm", "12", "--density-g-cm3", "1.16"])
        .args(["--ei-n-mm2", "6000", "--ea-n", "20", "--ga-n", "6.6667"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let v: serde_json::Value = serde_json::from_str(String::from_utf8_lossy(&out.stdout).trim()).unwrap();
    assert_eq!(v["status"], "ok");
}
