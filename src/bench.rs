//! `cablemap bench`: solver speed on thesis-grid routings.
//!
//! Each sampled routing is stepped through the sweep's tension ladder
//! (21 tensions from 1.0 to 2.0 N) on one thread, exactly as the sweep does,
//! and the median time per solve over routings is reported for gravity on
//! and off. Timing is by wall clock on a shared machine: the median over
//! many routings keeps one noisy neighbour from moving the figure.
//!
//! [`bench_with_reference`] also times the reference method (RK4 with 24
//! steps per span and secant shooting, [`SolverMethod::Rk4`]) in the same
//! run, so the speed-up is measured under the same load.

use crate::model::{Rod, ControlPoints, Routing};
use crate::solver::{Simulator, SolverMethod, SolverOptions};
use serde::Serialize;
use std::time::Instant;

/// Figures of one benchmark configuration.
#[derive(Debug, Clone, Serialize)]
pub struct BenchFigures {
    /// What was measured.
    pub label: String,
    /// Routings sampled.
    pub routings: usize,
    /// Solves per routing (tension ladder).
    pub tensions: usize,
    /// Median over routings of the mean time per solve, µs.
    pub median_us_per_solve: f64,
    /// 10th and 90th percentile over routings, µs per solve.
    pub p10_us_per_solve: f64,
    /// See `p10_us_per_solve`.
    pub p90_us_per_solve: f64,
    /// Mean integration passes per solve.
    pub mean_passes: f64,
    /// Solves that failed.
    pub failures: usize,
    /// The method measured: "collocation-N" (N intervals per span) or "rk4-N" (N steps per span).
    pub method: String,
    /// The reference method measured in the same run, if asked for.
    pub reference: Option<Box<BenchFigures>>,
    /// Reference median over this median.
    pub speedup: Option<f64>,
}

/// Short name of a method and its resolution, e.g. "collocation-10", "rk4-24".
pub fn method_label(options: &SolverOptions) -> String {
    match options.method {
        SolverMethod::Collocation => format!("collocation-{}", options.nodes_per_span),
        SolverMethod::Rk4 => format!("rk4-{}", options.planar_steps_per_span),
    }
}

/// The reference method: RK4, 24 steps per span, secant shooting.
pub fn reference_options() -> SolverOptions {
    SolverOptions { method: SolverMethod::Rk4, planar_steps_per_span: 24, ..SolverOptions::default() }
}

/// The sweep's ladder (21 tensions 1.0 → 2.0 N) timed with gravity on and
/// off, each with `options` and, if `with_reference`, with
/// [`reference_options`] right after on the same routings.
pub fn bench_with_reference(
    rod: &Rod,
    options: &SolverOptions,
    routings: &[ControlPoints],
    with_reference: bool,
) -> Result<Vec<BenchFigures>, crate::Error> {
    let mut rows = Vec::new();
    for gravity in [true, false] {
        let mut a = rod.clone();
        a.gravity.enabled = gravity;
        let label = if gravity { "gravity on" } else { "gravity off" };
        let mut row = bench_solver(&a, options, routings, 1.0, 2.0, 21, label)?;
        if with_reference {
            let reference = bench_solver(&a, &reference_options(), routings, 1.0, 2.0, 21, label)?;
            row.speedup = Some(reference.median_us_per_solve / row.median_us_per_solve);
            row.reference = Some(Box::new(reference));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// Most routings `bench` samples: the thesis grid's 9⁵ (more would only
/// repeat them, and a count near `usize::MAX` cannot be allocated).
pub const MAX_ROUTINGS: usize = 59_049;

/// A deterministic sample of `count` routings from the thesis grid
/// (9 levels ±0.8 r), spread over the grid by a multiplicative walk.
pub fn sample_thesis_routings(count: usize, radius_mm: f64) -> Vec<ControlPoints> {
    let total = 9usize.pow(5);
    (0..count)
        .map(|k| {
            let mut idx = (k * 7919 + 13) % total;
            ControlPoints(std::array::from_fn(|_| {
                let level = idx % 9;
                idx /= 9;
                (level as f64 - 4.0) * 0.2 * radius_mm
            }))
        })
        .collect()
}

/// Times continuation solves: for each routing, `tensions` evenly spaced
/// from `tension_min_n` to `tension_max_n`.
pub fn bench_solver(
    rod: &Rod,
    options: &SolverOptions,
    routings: &[ControlPoints],
    tension_min_n: f64,
    tension_max_n: f64,
    tensions: usize,
    label: &str,
) -> Result<BenchFigures, crate::Error> {
    bench_ladder(rod, options, routings, &evenly(tension_min_n, tension_max_n, tensions), false, label)
}

/// Times displacement-driven solves: for each routing, `count`
/// displacements evenly spaced from `min_mm` to `max_mm` (continuation, the
/// tension found by Newton's method on the warm-started tension solves, as
/// a displacement sweep steps it), a_0 … a_3 included.
pub fn bench_displacement(
    rod: &Rod,
    options: &SolverOptions,
    routings: &[ControlPoints],
    min_mm: f64,
    max_mm: f64,
    count: usize,
    label: &str,
) -> Result<BenchFigures, crate::Error> {
    bench_ladder(rod, options, routings, &evenly(min_mm, max_mm, count), true, label)
}

/// `count` values evenly spaced from `min` to `max` (`min` alone for one).
fn evenly(min: f64, max: f64, count: usize) -> Vec<f64> {
    (0..count).map(|k| min + (max - min) * k as f64 / (count.max(2) - 1) as f64).collect()
}

/// Times each routing solved through `ladder`: tensions, N, or (when
/// `by_displacement`) displacements, mm, each tension found from the last.
fn bench_ladder(
    rod: &Rod,
    options: &SolverOptions,
    routings: &[ControlPoints],
    ladder: &[f64],
    by_displacement: bool,
    label: &str,
) -> Result<BenchFigures, crate::Error> {
    let mut sim = Simulator::for_rod(rod, options)?;
    let mut per_solve = Vec::with_capacity(routings.len());
    let mut a = [0.0; 4];
    let (mut passes, mut solves, mut failures) = (0u64, 0u64, 0usize);
    for y in routings {
        let routing = Routing::for_actuator(y, rod)?;
        let start = Instant::now();
        sim.set_routing(&routing);
        let mut tension = [0.0];
        for &v in ladder {
            let solved = if by_displacement { sim.solve_actuation(crate::model::Actuation::Displacement(v), &mut tension) } else { sim.solve(v) };
            match solved {
                Ok(pose) => {
                    sim.coefficients_into(crate::shape::LengthBasis::default(), &mut a);
                    passes += u64::from(pose.iterations);
                    solves += 1;
                }
                Err(_) => {
                    // No tension to start the next displacement from.
                    tension[0] = 0.0;
                    failures += 1;
                }
            }
        }
        per_solve.push(start.elapsed().as_secs_f64() * 1e6 / ladder.len() as f64);
    }
    std::hint::black_box(a);
    Ok(figures(label, per_solve, ladder.len(), passes as f64 / solves.max(1) as f64, failures, method_label(options)))
}

/// Figures from the mean µs per solve of each routing (any order).
fn figures(label: &str, mut per_solve: Vec<f64>, tensions: usize, mean_passes: f64, failures: usize, method: String) -> BenchFigures {
    per_solve.sort_by(f64::total_cmp);
    let q = |p: f64| per_solve[((per_solve.len() - 1) as f64 * p).round() as usize];
    BenchFigures {
        label: label.to_string(),
        routings: per_solve.len(),
        tensions,
        median_us_per_solve: q(0.5),
        p10_us_per_solve: q(0.1),
        p90_us_per_solve: q(0.9),
        mean_passes,
        failures,
        method,
        reference: None,
        speedup: None,
    }
}

/// Deterministic two-cable spatial actuators for [`bench_spatial`]: each
/// cable's y and z control points from the thesis grid scaled by 0.7, so
/// that every channel stays within 0.8 r of the axis.
pub fn sample_spatial_pairs(count: usize, radius_mm: f64) -> Vec<[crate::solver::spatial::Cable; 2]> {
    use crate::solver::spatial::Cable;
    let grid = sample_thesis_routings(4 * count + 3, radius_mm);
    let scaled = |k: usize| grid[k].map(|v| 0.7 * v);
    (0..count)
        .map(|k| {
            let mut second = Cable::spatial(scaled(4 * k + 2), scaled(4 * k + 3), 0.5);
            if second.y_mm == scaled(4 * k) && second.z_mm == scaled(4 * k + 1) {
                second.y_mm = second.y_mm.map(|v| -v);
            }
            [Cable::spatial(scaled(4 * k), scaled(4 * k + 1), 1.0), second]
        })
        .collect()
}

/// Times the 3-D backend serving two cables (`options.method`: the
/// collocation, or the RK4 reference) on two-cable spatial actuators: per actuator, a ladder of
/// `tensions` steps with τ_1 = t and τ_2 = t/2, t from 1.0 to 2.0 N
/// (continuation, as a sweep would step it), coefficients a_0 … a_3 of all
/// three series included. `gravity` is the direction (None: off).
pub fn bench_spatial(
    rod: &Rod,
    options: &SolverOptions,
    pairs: &[[crate::solver::spatial::Cable; 2]],
    tensions: usize,
    gravity: Option<[f64; 3]>,
    label: &str,
) -> Result<BenchFigures, crate::Error> {
    use crate::solver::spatial::Actuator;
    use crate::solver::Solver;
    let mut rod = rod.clone();
    rod.gravity.enabled = gravity.is_some();
    let mut per_solve = Vec::with_capacity(pairs.len());
    let (mut passes, mut solves, mut failures) = (0u64, 0u64, 0usize);
    let mut sink = 0.0;
    let basis = crate::shape::LengthBasis::default();
    for pair in pairs {
        let mut actuator = Actuator::with_cables(rod.clone(), pair.to_vec());
        actuator.gravity_direction = gravity;
        let start = Instant::now();
        let ladder = |k: usize| {
            let t = 1.0 + k as f64 / (tensions.max(2) - 1) as f64;
            [t, 0.5 * t]
        };
        let mut solver = Simulator::serving(&actuator, options, crate::solver::Given::default())?;
        for k in 0..tensions {
            match solver.solve_tensions(&ladder(k)).and_then(|pose| Ok((pose, solver.coefficients(3, basis)?))) {
                Ok((pose, a)) => {
                    sink += a[2][0];
                    passes += u64::from(pose.iterations);
                    solves += 1;
                }
                Err(_) => failures += 1,
            }
        }
        per_solve.push(start.elapsed().as_secs_f64() * 1e6 / tensions as f64);
    }
    std::hint::black_box(sink);
    let method = match options.method {
        crate::solver::SolverMethod::Collocation => format!("spatial-collocation-{}", options.nodes_per_span),
        crate::solver::SolverMethod::Rk4 => format!("spatial-rk4-{}", options.spatial_steps_per_span),
    };
    Ok(figures(label, per_solve, tensions, passes as f64 / solves.max(1) as f64, failures, method))
}
