//! Synthetic several-cable captures with 3-D markers: the true actuator
//! (any hidden effect set on it) solved at every capture, its markers
//! measured with Gaussian noise. How tests get 3-D data whose truth is known.

use crate::calibrate::observations::captures::files::{Actuation, Capture, CaptureSet, MarkerReading};
use crate::calibrate::observations::captures::simulate::solve_captures;
use crate::calibrate::data::Direction;
use crate::calibrate::rng::Rng;
use crate::calibrate::CalibrateError;
use crate::solver::SolverOptions;
use crate::model::Actuator;

/// A body-fixed marker to place on every capture.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerSpec {
    /// Its name.
    pub name: String,
    /// Rest arc length, mm (beyond L: on the tip's rigid extension).
    pub s_mm: f64,
    /// Body-frame offsets (y, z), mm.
    pub offset_mm: [f64; 2],
}

impl MarkerSpec {
    /// A marker `name` at `s_mm` with offsets (y, z).
    pub fn new(name: &str, s_mm: f64, offset_y_mm: f64, offset_z_mm: f64) -> Self {
        Self { name: name.into(), s_mm, offset_mm: [offset_y_mm, offset_z_mm] }
    }
}

/// Static captures pulling each cable alone at `levels_n` (the SoRoMoX
/// protocol: one tendon at a time), numbered from 1.
pub fn one_cable_at_a_time(cables: usize, levels_n: &[f64], dwell_s: f64) -> Vec<Capture> {
    let mut out = Vec::new();
    for k in 0..cables {
        for &t in levels_n {
            let id = out.len() as i64 + 1;
            let actuation = (0..cables).map(|j| Actuation::Tension(if j == k { t } else { 0.0 })).collect();
            out.push(Capture { measurement: id, actuation, direction: Direction::Static, step: id - 1, dwell_s, row: id as usize });
        }
    }
    out
}

/// The default plan of `synth --actuator` for `cables` cables up to
/// `max_tension_n`: each cable alone at 2/7, 4.5/7 and 7/7 of it, one
/// capture at rest, and every pair of cables at (4, 4), (7, 3) and (3, 7)
/// sevenths of it (pairs bend the body out of either cable's plane, which
/// separates effects on the cables' tension from effects on the body);
/// static captures dwelling `dwell_s`, numbered from 1. At 7 N these are
/// the SoRoMoX-like captures of `tests/captures.rs`.
pub fn default_plan(cables: usize, max_tension_n: f64, dwell_s: f64) -> Vec<Capture> {
    let level = |sevenths: f64| max_tension_n * sevenths / 7.0;
    let mut out = one_cable_at_a_time(cables, &[level(2.0), level(4.5), level(7.0)], dwell_s);
    let mut push = |tensions: Vec<f64>| {
        let id = out.len() as i64 + 1;
        let actuation = tensions.into_iter().map(Actuation::Tension).collect();
        out.push(Capture { measurement: id, actuation, direction: Direction::Static, step: id - 1, dwell_s, row: id as usize });
    };
    push(vec![0.0; cables]);
    for i in 0..cables {
        for j in i + 1..cables {
            for (a, b) in [(4.0, 4.0), (7.0, 3.0), (3.0, 7.0)] {
                let mut t = vec![0.0; cables];
                t[i] = level(a);
                t[j] = level(b);
                push(t);
            }
        }
    }
    out
}

/// A load/unload protocol for `cables` cables up to `max_tension_n`, the
/// measurement that separates friction from the other effects (friction
/// opens a loop between the two directions): each cable alone is loaded
/// to 2/7, 4.5/7 and 7/7 of it, unloaded to 4.5/7 and 2/7, then released
/// (a rest capture); one chain in step order, dwelling `dwell_s`, numbered
/// from 1.
pub fn load_unload_plan(cables: usize, max_tension_n: f64, dwell_s: f64) -> Vec<Capture> {
    let mut out = Vec::new();
    for k in 0..cables {
        for (sevenths, direction) in [(2.0, Direction::Load), (4.5, Direction::Load), (7.0, Direction::Load), (4.5, Direction::Unload), (2.0, Direction::Unload), (0.0, Direction::Rest)] {
            let id = out.len() as i64 + 1;
            let actuation = (0..cables).map(|j| Actuation::Tension(if j == k { max_tension_n * sevenths / 7.0 } else { 0.0 })).collect();
            out.push(Capture { measurement: id, actuation, direction, step: id - 1, dwell_s, row: id as usize });
        }
    }
    out
}

/// The default markers of `synth --actuator`, after the SoRoMoX tentacle's:
/// `p1`, `p2`, `p3` on stalks at 0.36 L, 0.61 L and 0.78 L, off the body
/// along body z by twice the radius there (alternately +, −, +), and `p4`
/// on the axis 2 % of L beyond the tip.
pub fn default_markers(actuator: &Actuator) -> Vec<MarkerSpec> {
    let l = actuator.rod.length_mm;
    let stalk = |name: &str, f: f64, side: f64| MarkerSpec::new(name, f * l, 0.0, side * 2.0 * actuator.rod.radius_at(f * l));
    vec![stalk("p1", 0.36, 1.0), stalk("p2", 0.61, -1.0), stalk("p3", 0.78, 1.0), MarkerSpec::new("p4", 1.02 * l, 0.0, 0.0)]
}

/// Solves `captures` with `truth` and measures `markers` on each with
/// noise of standard deviation `noise_mm` per coordinate (seeded; the
/// readings carry `sd_mm` = `noise_mm` when `state_sd` is set).
pub fn synth_captures(
    truth: &Actuator,
    options: &SolverOptions,
    captures: Vec<Capture>,
    markers: &[MarkerSpec],
    noise_mm: f64,
    seed: u64,
    state_sd: bool,
) -> Result<CaptureSet, CalibrateError> {
    if !(noise_mm.is_finite() && noise_mm >= 0.0) {
        return Err(crate::calibrate::NoiseError::Synthetic { value: noise_mm }.into());
    }
    let readings = |c: &Capture| -> Vec<MarkerReading> {
        markers
            .iter()
            .map(|m| MarkerReading {
                marker: m.name.clone(),
                s_mm: m.s_mm,
                offset_y_mm: m.offset_mm[0],
                offset_z_mm: m.offset_mm[1],
                measured_mm: [0.0; 3],
                sd_mm: (state_sd && noise_mm > 0.0).then_some(noise_mm),
                row: c.row,
            })
            .collect()
    };
    let mut set = CaptureSet { markers: captures.iter().map(|c| (c.measurement, readings(c))).collect(), captures };
    let solutions = solve_captures(truth, options, &set)?;
    let mut rng = Rng::new(seed);
    for (c, sol) in set.captures.iter().zip(&solutions) {
        for (m, sim) in set.markers.get_mut(&c.measurement).expect("every capture has markers").iter_mut().zip(&sol.markers_mm) {
            m.measured_mm = std::array::from_fn(|k| sim[k] + noise_mm * rng.normal());
        }
    }
    Ok(set)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_load_unload_plan_loads_unloads_and_releases_each_cable_in_order() {
        let plan = load_unload_plan(2, 7.0, 5.0);
        assert_eq!(plan.len(), 12);
        let first: Vec<(f64, Direction)> = plan[..6].iter().map(|c| (c.magnitude(), c.direction)).collect();
        use Direction::*;
        assert_eq!(first, vec![(2.0, Load), (4.5, Load), (7.0, Load), (4.5, Unload), (2.0, Unload), (0.0, Rest)]);
        assert!(plan[6..].iter().all(|c| c.pulling_cables().iter().all(|&k| k == 2)));
        assert!(plan.iter().enumerate().all(|(i, c)| c.step == i as i64 && c.measurement == i as i64 + 1));
    }
}
