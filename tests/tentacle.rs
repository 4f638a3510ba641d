//! A heavy, tapered rod in 3-D at full weight: the SoRoMoX tendon-driven
//! tentacle (`tests/data/soromox/`, MIT; 360 mm, radius 15.4 → 6.4 → 4.8 mm,
//! two tendons at 30° and 150° about the axis knotted at 305 mm, hanging
//! along gravity). Every tension pair of its captures and a grid up to 8 N
//! per tendon converge, and converged shapes are in equilibrium, checked
//! from the output centreline alone.

use cablemap::solver::spatial::{simulate_spatial, Actuator};
use cablemap::solver::SolverOptions;
use cablemap::solver::Simulation;
use cablemap::shape::LengthBasis;
use std::path::PathBuf;

fn data(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/soromox").join(file)
}

fn tentacle(t1: f64, t2: f64) -> Actuator {
    let mut a = Actuator::read(&data("actuator.toml")).unwrap();
    a.cables[0].tension_n = t1;
    a.cables[1].tension_n = t2;
    a
}

/// The tension pairs of `captures.csv` (columns tension_1_n, tension_2_n).
fn capture_tensions() -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(data("captures.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (c1, c2) = (col("tension_1_n"), col("tension_2_n"));
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[c1].parse().unwrap(), f[c2].parse().unwrap())
        })
        .collect()
}

fn solve(a: &Actuator, options: &SolverOptions) -> Simulation {
    let t: Vec<f64> = a.cables.iter().map(|c| c.tension_n).collect();
    simulate_spatial(a, options, 3, LengthBasis::Rest).unwrap_or_else(|e| panic!("tensions {t:?} N: {e}"))
}

#[test]
fn every_capture_and_a_grid_to_8_n_converge_at_full_weight() {
    let captures = capture_tensions();
    assert_eq!(captures.len(), 14);
    let mut pairs = captures.clone();
    for t1 in [0.0, 2.0, 4.0, 6.0, 8.0] {
        for t2 in [0.0, 2.0, 4.0, 6.0, 8.0] {
            pairs.push((t1, t2));
        }
    }
    for (t1, t2) in pairs {
        let sim = solve(&tentacle(t1, t2), &SolverOptions::default());
        let [x, y, z] = sim.pose.tip_mm();
        assert!([x, y, z].iter().all(|v| v.is_finite()), "{t1} {t2}: {:?}", sim.pose.tip_mm());
        // Both tendons sit on the +z side: pulling bends the tip toward +z,
        // tendon 1 (at 30°) toward +y and tendon 2 (at 150°) toward −y.
        if t1 + t2 > 0.0 {
            assert!(z > 0.0, "{t1} {t2}: tip {:?}", sim.pose.tip_mm());
        }
        if t1 > t2 {
            assert!(y > 0.0, "{t1} {t2}: tip {:?}", sim.pose.tip_mm());
        } else if t2 > t1 {
            assert!(y < 0.0, "{t1} {t2}: tip {:?}", sim.pose.tip_mm());
        }
    }
    // Mirror images: tendon 1 alone and tendon 2 alone at the same tension.
    let (a, b) = (solve(&tentacle(7.692308, 0.0), &SolverOptions::default()), solve(&tentacle(0.0, 7.692308), &SolverOptions::default()));
    let (p, q) = (a.pose.tip_mm(), b.pose.tip_mm());
    assert!((p[0] - q[0]).abs() < 1e-7 && (p[1] + q[1]).abs() < 1e-7 && (p[2] - q[2]).abs() < 1e-7, "{p:?} vs {q:?}");
}

/// Equilibrium of the distal part (s, L] at every cut, from the output
/// centreline alone (positions, frames, the cables' paths; finite
/// differences and Simpson quadrature, nothing from the solver's own
/// integrals): the internal moment R K_bt u(s), u from the frames'
/// finite differences, equals the cables' moment −Σ τ_i (p_i − p) × t_i plus
/// the distal weight's moment ∫ (p(σ) − p(s)) × w(σ) ĝ dσ; the internal
/// force R K_se (v − e₁), v = Rᵀ p', equals −Σ τ_i t_i + W(s).
#[test]
fn the_tentacles_shape_is_in_equilibrium() {
    let options = SolverOptions { spatial_steps_per_span: 360, ..SolverOptions::default() };
    let base = tentacle(0.0, 0.0);
    let rod = &base.rod;
    let body = rod.body().unwrap().expect("a tapered body");
    let gj0 = base.torsional_rigidity_n_mm2();
    let g = base.gravity_unit().unwrap();
    let weight_factor = rod.gravity.scale * 1e-6 * std::f64::consts::PI * rod.gravity.g_m_s2;
    for (t1, t2) in [(7.692308, 0.0), (6.0, 3.0)] {
        let sim = solve(&tentacle(t1, t2), &options);
        // Equally spaced points only (the boundary points sit in between).
        let line: Vec<_> = sim.centreline.iter().filter(|p| ((p.s_mm / 0.5).round() * 0.5 - p.s_mm).abs() < 1e-9).copied().collect();
        let n = line.len();
        let h = line[1].s_mm - line[0].s_mm;
        assert!((h - 0.5).abs() < 1e-12, "{h}");
        let tensions = [t1, t2];
        let (mut worst_m, mut scale_m, mut worst_f) = (0.0f64, 0.0f64, 0.0f64);
        for k in 2..n - 2 {
            let p = &line[k];
            let s = p.s_mm;
            // Away from the anchor at 305 mm and the profile's breakpoints,
            // where the strains jump and finite differences straddle it.
            if (s - 305.0).abs() < 2.0 {
                continue;
            }
            let d = |f: &dyn Fn(usize) -> f64| (f(k + 1) - f(k - 1)) / (2.0 * h);
            let r = |i: usize, a: usize, b: usize| line[i].rotation[a][b];
            // û = Rᵀ R': u from the skew part.
            let mut rd = [[0.0; 3]; 3];
            for a in 0..3 {
                for b in 0..3 {
                    rd[a][b] = d(&|i| r(i, a, b));
                }
            }
            let rt_rd = |a: usize, b: usize| (0..3).map(|c| p.rotation[c][a] * rd[c][b]).sum::<f64>();
            let u = [0.5 * (rt_rd(2, 1) - rt_rd(1, 2)), 0.5 * (rt_rd(0, 2) - rt_rd(2, 0)), 0.5 * (rt_rd(1, 0) - rt_rd(0, 1))];
            let dp = [d(&|i| line[i].x_mm), d(&|i| line[i].y_mm), d(&|i| line[i].z_mm)];
            let v: [f64; 3] = std::array::from_fn(|a| (0..3).map(|c| p.rotation[c][a] * dp[c]).sum());
            let sec = body.section_at(s);
            let gj = gj0 * (sec.radius_mm / rod.radius_mm).powi(4);
            let m_body = [gj * u[0], sec.ei_n_mm2 * u[1], sec.ei_n_mm2 * u[2]];
            let n_body = [sec.ea_n * (v[0] - 1.0), sec.ga_n * v[1], sec.ga_n * v[2]];
            let to_global = |x: [f64; 3]| -> [f64; 3] { std::array::from_fn(|a| (0..3).map(|b| p.rotation[a][b] * x[b]).sum()) };
            let (m_int, n_int) = (to_global(m_body), to_global(n_body));
            // The cables at the cut.
            let mut m_ext = [0.0; 3];
            let mut f_ext = [0.0; 3];
            for (c, &tau) in tensions.iter().enumerate() {
                if !p.cables[c].is_present() || !line[k + 1].cables[c].is_present() || tau == 0.0 {
                    continue;
                }
                let dc: [f64; 3] = std::array::from_fn(|a| d(&|i| line[i].cables[c].position_mm[a]));
                let norm = (dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]).sqrt();
                let t: [f64; 3] = dc.map(|x| x / norm);
                let arm: [f64; 3] = std::array::from_fn(|a| p.cables[c].position_mm[a] - p.position_mm()[a]);
                let cross = [arm[1] * t[2] - arm[2] * t[1], arm[2] * t[0] - arm[0] * t[2], arm[0] * t[1] - arm[1] * t[0]];
                for a in 0..3 {
                    m_ext[a] -= tau * cross[a];
                    f_ext[a] -= tau * t[a];
                }
            }
            // The distal weight: W(s) along g, its moment about p(s) by Simpson.
            let w = |i: usize| weight_factor * body.density_at(line[i].s_mm) * body.radius_at(line[i].s_mm).powi(2);
            let mut moment_w = [0.0; 3];
            let intervals = n - 1 - k;
            let arm = |i: usize, a: usize| line[i].position_mm()[a] - p.position_mm()[a];
            let integrand = |i: usize| -> [f64; 3] {
                let (x, y, z) = (arm(i, 0), arm(i, 1), arm(i, 2));
                let wi = w(i);
                [wi * (y * g[2] - z * g[1]), wi * (z * g[0] - x * g[2]), wi * (x * g[1] - y * g[0])]
            };
            let mut j = k;
            if intervals % 2 == 1 {
                let (a, b) = (integrand(j), integrand(j + 1));
                for c in 0..3 {
                    moment_w[c] += 0.5 * h * (a[c] + b[c]);
                }
                j += 1;
            }
            while j + 2 <= n - 1 {
                let (a, b, c3) = (integrand(j), integrand(j + 1), integrand(j + 2));
                for c in 0..3 {
                    moment_w[c] += h / 3.0 * (a[c] + 4.0 * b[c] + c3[c]);
                }
                j += 2;
            }
            let distal_weight = weight_factor * body.distal_density_area(s);
            for a in 0..3 {
                let expected_m = m_ext[a] + moment_w[a];
                worst_m = worst_m.max((m_int[a] - expected_m).abs());
                scale_m = scale_m.max(m_int[a].abs());
                let expected_f = f_ext[a] + distal_weight * g[a];
                worst_f = worst_f.max((n_int[a] - expected_f).abs());
            }
        }
        eprintln!("tentacle at ({t1}, {t2}) N: moment residual {worst_m:.2e} of {scale_m:.0} N·mm, force residual {worst_f:.2e} N");
        assert!(worst_m < 2e-3 * scale_m, "({t1}, {t2}) N: moment residual {worst_m} N·mm of {scale_m}");
        assert!(worst_f < 2e-3 * (t1 + t2), "({t1}, {t2}) N: force residual {worst_f} N");
    }
}
