//! Simulating captures with the 3-D solver and evaluating their markers on
//! the simulated body.
//!
//! Captures that are independent (`static`) and pull the same cables are
//! solved as one chain, in order of their actuation, by one
//! [`SpatialCollocation`]: each solve is warm-started by the solver's
//! extrapolation from the chain's previous ones (a few Newton steps instead
//! of a ladder from the straight rod). A protocol (load, unload, rest rows)
//! is one chain in step order, its hold (friction's direction, creep's
//! dwell) following the rows. Static captures are each held from a virgin
//! rod (creep's history does not carry over; only the warm start does), as
//! their independence demands. Chains run in parallel.

use super::files::{Actuation, Capture, CaptureSet, MarkerReading};
use crate::calibrate::data::Direction;
use crate::calibrate::CalibrateError;
use crate::solver::Solver;
use crate::solver::spatial::{SpatialError, SpatialCollocation};
use crate::solver::{SolveFailure, SolverOptions};
use crate::model::{Actuator, LoadDirection};
use crate::solver::{CentrelinePoint, Hold, TipPose};
use rayon::prelude::*;

/// The model's answer for one capture.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureSolution {
    /// Tip pose (with every cable's tension and displacement).
    pub pose: TipPose,
    /// Each of the capture's markers, simulated, clamp frame, mm (in the
    /// order of [`CaptureSet::markers`]).
    pub markers_mm: Vec<[f64; 3]>,
}

/// Where a body-fixed point is on a solved body: `node` is the centreline
/// point at min(s, L) (`length_mm` = L); beyond the tip the point rides on
/// the tip cross-section's rigid extension, p(L) + R(L) (s − L, y, z).
pub fn body_point_mm(node: &CentrelinePoint, marker: &MarkerReading, length_mm: f64) -> [f64; 3] {
    let p = node.body_point_mm(marker.offset_y_mm, marker.offset_z_mm);
    let beyond = (marker.s_mm - length_mm).max(0.0);
    std::array::from_fn(|i| p[i] + node.rotation[i][0] * beyond)
}

/// The markers of `markers` on the last solve of `solver`.
fn markers_on(solver: &SpatialCollocation, markers: &[MarkerReading], length_mm: f64) -> Vec<[f64; 3]> {
    let s: Vec<f64> = markers.iter().map(|m| m.s_mm).collect();
    solver.points_at(&s).iter().zip(markers).map(|(node, m)| body_point_mm(node, m, length_mm)).collect()
}

/// The chains: lists of capture indices solved in order by one solver.
fn chains(captures: &[Capture]) -> Vec<Vec<usize>> {
    let protocol = captures.iter().any(|c| c.direction != Direction::Static);
    if protocol {
        let mut order: Vec<usize> = (0..captures.len()).collect();
        order.sort_by_key(|&i| captures[i].step);
        return vec![order];
    }
    let mut groups: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
    for (i, c) in captures.iter().enumerate() {
        let key = c.pulling_cables();
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, list)) => list.push(i),
            None => groups.push((key, vec![i])),
        }
    }
    groups
        .into_iter()
        .map(|(_, mut list)| {
            list.sort_by(|&a, &b| captures[a].magnitude().total_cmp(&captures[b].magnitude()));
            // From the smallest, each next capture the nearest in actuation
            // (one cable's ladder stays in order; pairs of cables are not
            // crossed in long jumps).
            let mut ordered = vec![list.remove(0)];
            while !list.is_empty() {
                let last = &captures[*ordered.last().expect("not empty")];
                let distance = |i: usize| {
                    let c = &captures[i];
                    c.actuation.iter().zip(&last.actuation).map(|(a, b)| {
                        let (Actuation::Tension(x) | Actuation::Displacement(x)) = a;
                        let (Actuation::Tension(y) | Actuation::Displacement(y)) = b;
                        (x - y).abs()
                    }).fold(0.0, f64::max)
                };
                let k = (0..list.len()).min_by(|&a, &b| distance(list[a]).total_cmp(&distance(list[b]))).expect("not empty");
                ordered.push(list.remove(k));
            }
            ordered
        })
        .collect()
}

/// Largest change of any cable's tension from one solve of a chain to the
/// next, N: beyond it the chain steps in rungs (a failed jump would cost a
/// ladder from the straight rod).
const MAX_JUMP_N: f64 = 2.0;

/// The hold a capture is read at.
fn hold_of(c: &Capture) -> Hold {
    // A static capture is taken as reached by loading (as in the plane).
    let direction = if c.direction == Direction::Unload { LoadDirection::Unload } else { LoadDirection::Load };
    Hold { direction, dwell_s: c.dwell_s }
}

/// One solve at `fraction` of the capture's actuation (displacement-driven
/// cables by Newton on their tensions).
fn solve_at(solver: &mut SpatialCollocation, c: &Capture, fraction: f64, tensions: &mut [f64]) -> Result<TipPose, SpatialError> {
    if c.actuation.iter().all(|a| matches!(a, Actuation::Tension(_))) {
        let t: Vec<f64> = c.tensions_n().iter().map(|t| t * fraction).collect();
        return solver.solve(&t);
    }
    let rung: Vec<Actuation> = c.actuation.iter().map(|a| a.scaled(fraction)).collect();
    Solver::solve(solver, &rung, tensions)
}


/// Solves one chain with one solver at `options`.
fn solve_chain(actuator: &Actuator, options: &SolverOptions, set: &CaptureSet, chain: &[usize]) -> Result<Vec<(usize, CaptureSolution)>, CalibrateError> {
    let length = actuator.rod.length_mm;
    let mut solver = SpatialCollocation::new(actuator, options).map_err(CalibrateError::Actuator)?;
    let protocol = chain.iter().any(|&i| set.captures[i].direction != Direction::Static);
    let mut tensions = vec![0.0; actuator.cables.len()];
    let mut out = Vec::with_capacity(chain.len());
    let no_markers = Vec::new();
    let mut previous: Option<Vec<f64>> = None;
    for &i in chain {
        let c = &set.captures[i];
        let fail = |failure: SpatialError| CalibrateError::Capture { measurement: c.measurement, row: c.row, failure };
        // Friction's direction and creep's dwell matter only with those effects on.
        let hold = hold_of(c);
        let set_hold = |solver: &mut SpatialCollocation, hold: Hold| if protocol { solver.set_hold(hold) } else { solver.set_independent_hold(hold) };
        set_hold(&mut solver, hold).map_err(fail)?;
        // A long jump from the previous capture's tensions leaves the warm
        // start's basin: cross it in rungs of at most MAX_JUMP_N (static
        // captures only: in a protocol every solve is part of the history).
        let target = c.tensions_n();
        let all_tension = c.actuation.iter().all(|a| matches!(a, Actuation::Tension(_)));
        if let (false, true, Some(prev)) = (protocol, all_tension, previous.as_ref()) {
            let jump = target.iter().zip(prev).map(|(a, b): (&f64, &f64)| (a - b).abs()).fold(0.0, f64::max);
            let rungs = (jump / MAX_JUMP_N).ceil() as usize;
            if rungs > 1 {
                set_hold(&mut solver, Hold { direction: hold.direction, dwell_s: 0.0 }).map_err(fail)?;
                for k in 1..rungs {
                    let f = k as f64 / rungs as f64;
                    let t: Vec<f64> = prev.iter().zip(&target).map(|(a, b)| a + (b - a) * f).collect();
                    if solver.solve(&t).is_err() {
                        break;
                    }
                }
                set_hold(&mut solver, hold).map_err(fail)?;
            }
        }
        previous = Some(target);
        let pose = match solve_at(&mut solver, c, 1.0, &mut tensions) {
            Ok(p) => p,
            Err(_) => {
                // Out of the warm start's basin: climb from the straight rod
                // in small rungs without dwell (which leaves creep's history alone).
                let n = crate::solver::ladder::rungs(&c.actuation);
                set_hold(&mut solver, Hold { direction: hold.direction, dwell_s: 0.0 }).map_err(fail)?;
                for k in 1..n {
                    solve_at(&mut solver, c, k as f64 / n as f64, &mut tensions).map_err(fail)?;
                }
                set_hold(&mut solver, hold).map_err(fail)?;
                solve_at(&mut solver, c, 1.0, &mut tensions).map_err(fail)?
            }
        };
        let markers = set.markers.get(&c.measurement).unwrap_or(&no_markers);
        out.push((i, CaptureSolution { pose, markers_mm: markers_on(&solver, markers, length) }));
    }
    Ok(out)
}

/// Solves every capture of `set` with `actuator` (its cables' actuation
/// set per capture), indexed like `set.captures`. A chain the
/// discretisation does not resolve is solved again at twice the collocation
/// intervals (up to the most there are), as single solves are.
pub fn solve_captures(actuator: &Actuator, options: &SolverOptions, set: &CaptureSet) -> Result<Vec<CaptureSolution>, CalibrateError> {
    let chains = chains(&set.captures);
    let solved: Vec<Vec<(usize, CaptureSolution)>> = chains
        .par_iter()
        .map(|chain| {
            let mut options = options.clone();
            loop {
                match solve_chain(actuator, &options, set, chain) {
                    Err(CalibrateError::Capture { failure: SpatialError::Solve(SolveFailure::Unresolved(_)), .. })
                        if options.nodes_per_span < crate::solver::MAX_NODES_PER_SPAN =>
                    {
                        options.nodes_per_span = (2 * options.nodes_per_span).min(crate::solver::MAX_NODES_PER_SPAN);
                    }
                    result => return result,
                }
            }
        })
        .collect::<Result<_, _>>()?;
    let mut out: Vec<Option<CaptureSolution>> = vec![None; set.captures.len()];
    for (i, s) in solved.into_iter().flatten() {
        out[i] = Some(s);
    }
    Ok(out.into_iter().map(|s| s.expect("every capture is in one chain")).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Cable;

    #[test]
    fn markers_ride_on_the_body_and_beyond_the_tip() {
        // A straight, weightless rod: markers sit at (s, y, z), and a point
        // 10 mm past the tip at (L + 10, y, z).
        let mut rod = crate::model::Rod::default();
        rod.gravity.enabled = false;
        let a = Actuator::with_cables(rod, vec![Cable::spatial([2.0; 5], [1.0; 5], 0.0)]);
        let mut solver = SpatialCollocation::new(&a, &SolverOptions::default()).unwrap();
        solver.solve(&[0.0]).unwrap();
        let m = |s: f64| MarkerReading { marker: "m".into(), s_mm: s, offset_y_mm: 3.0, offset_z_mm: -4.0, measured_mm: [0.0; 3], sd_mm: None, row: 1 };
        let p = markers_on(&solver, &[m(20.0), m(75.0)], 65.0);
        for (got, want) in p.iter().zip([[20.0, 3.0, -4.0], [75.0, 3.0, -4.0]]) {
            assert!(got.iter().zip(&want).all(|(g, w)| (g - w).abs() < 1e-9), "{got:?} vs {want:?}");
        }
        // Bent: the marker is the centreline point plus the rotated offset.
        solver.solve(&[1.0]).unwrap();
        // 39 mm = 12 of the centreline's 20 intervals of 3.25 mm.
        let node = solver.points_at(&[39.0])[0];
        let got = markers_on(&solver, &[m(39.0)], 65.0)[0];
        let want = node.body_point_mm(3.0, -4.0);
        assert!(got.iter().zip(&want).all(|(g, w)| (g - w).abs() < 1e-12));
        let line = solver.centreline();
        let near = line.iter().min_by(|a, b| (a.s_mm - 39.0).abs().total_cmp(&(b.s_mm - 39.0).abs())).unwrap();
        assert!((near.s_mm - 39.0).abs() < 1e-9 && (near.x_mm - node.x_mm).abs() < 1e-9, "points_at agrees with the centreline's nodes");
    }
}
