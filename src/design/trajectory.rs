//! The tip path of a trajectory design: between consecutive waypoints the
//! actuation moves linearly from one waypoint's to the next one's; the path
//! is sampled `steps_per_leg` times per leg, each sample solved on its own
//! (from zero, by the path `simulate` takes), and reported with its distance
//! from the straight leg between the waypoints as asked, the samples whose
//! solve fails, and (with `smooth = true`) any cable whose tension reverses
//! inside a leg.

use super::sequence::{Channel, Setup};
use super::targets::Trajectory;
use super::targets::ShapeTarget;
use super::DesignError;
use serde::Serialize;
use std::fmt;

/// One sample of a leg.
#[derive(Debug, Clone, Serialize)]
pub struct PathSample {
    /// Step 0 … steps_per_leg.
    pub step: usize,
    /// Each cable's actuation (tension N, or displacement mm).
    pub actuation: Vec<f64>,
    /// Each cable's tension, N (none when the solve failed).
    pub tensions_n: Option<Vec<f64>>,
    /// The tip, mm (none when the solve failed).
    pub tip_mm: Option<[f64; 3]>,
    /// Distance of the tip from the straight leg, mm.
    pub deviation_mm: Option<f64>,
    /// Why the solve failed.
    pub failure: Option<String>,
}

/// One leg, from waypoint `from` to `to` (numbered from 1).
#[derive(Debug, Clone, Serialize)]
pub struct Leg {
    /// First waypoint.
    pub from: usize,
    /// Second waypoint.
    pub to: usize,
    /// The samples, both waypoints included.
    pub samples: Vec<PathSample>,
    /// The largest distance of a sample's tip from the straight leg, mm.
    pub max_deviation_mm: f64,
    /// Cables (numbered from 1) whose tension reverses inside the leg.
    pub reversals: Vec<usize>,
}

/// The path report of a trajectory design.
#[derive(Debug, Clone, Serialize)]
pub struct PathReport {
    /// Samples per leg.
    pub steps_per_leg: usize,
    /// Whether tension reversals count as failures.
    pub smooth: bool,
    /// The legs in order.
    pub legs: Vec<Leg>,
    /// The largest deviation over every leg, mm.
    pub max_deviation_mm: f64,
    /// Samples whose solve failed.
    pub failed_samples: usize,
}

impl PathReport {
    /// No sample failed, and with `smooth` no tension reverses.
    pub fn ok(&self) -> bool {
        self.failed_samples == 0 && (!self.smooth || self.legs.iter().all(|l| l.reversals.is_empty()))
    }

    /// Sentences for what is not ok.
    pub fn problems(&self) -> Vec<String> {
        let mut v = Vec::new();
        for l in &self.legs {
            for s in l.samples.iter().filter(|s| s.failure.is_some()) {
                v.push(format!("leg {} → {}, step {}/{}: the solve failed ({})", l.from, l.to, s.step, self.steps_per_leg, s.failure.as_deref().unwrap_or("")));
            }
            if self.smooth {
                for c in &l.reversals {
                    v.push(format!("leg {} → {}: cable {c}'s tension reverses inside the leg (smooth = true)", l.from, l.to));
                }
            }
        }
        v
    }
}

impl fmt::Display for PathReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "trajectory   actuation linear between waypoints, {} steps per leg", self.steps_per_leg)?;
        for l in &self.legs {
            let failed = l.samples.iter().filter(|s| s.failure.is_some()).count();
            writeln!(
                f,
                "  leg {} → {}: largest distance from the straight leg {:.4} mm{}{}",
                l.from,
                l.to,
                l.max_deviation_mm,
                if failed > 0 { format!(", {failed} solve(s) failed") } else { String::new() },
                if l.reversals.is_empty() { String::new() } else { format!(", tension reverses in cable(s) {:?}", l.reversals) }
            )?;
        }
        writeln!(f, "  largest deviation {:.4} mm, {} failed solve(s)", self.max_deviation_mm, self.failed_samples)
    }
}

/// Distance of `p` from the segment `a`–`b`, mm.
pub fn distance_to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d: Vec<f64> = (0..3).map(|i| b[i] - a[i]).collect();
    let w: Vec<f64> = (0..3).map(|i| p[i] - a[i]).collect();
    let dd: f64 = d.iter().map(|v| v * v).sum();
    let t = if dd > 0.0 { (w.iter().zip(&d).map(|(x, y)| x * y).sum::<f64>() / dd).clamp(0.0, 1.0) } else { 0.0 };
    (0..3).map(|i| (w[i] - t * d[i]).powi(2)).sum::<f64>().sqrt()
}

/// Whether `values` both rise and fall (beyond rounding).
fn reverses(values: &[f64]) -> bool {
    let scale = values.iter().fold(1e-9_f64, |m, v| m.max(v.abs()));
    let tol = 1e-9 * scale;
    let steps: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
    steps.iter().any(|d| *d > tol) && steps.iter().any(|d| *d < -tol)
}

/// Samples the path of the designed `channels` through the waypoints' `targets`.
pub fn path(setup: &Setup, channels: &[Channel], targets: &[(&ShapeTarget, &[f64])], trajectory: &Trajectory) -> Result<PathReport, DesignError> {
    use rayon::prelude::*;
    let n = trajectory.steps_per_leg;
    let waypoint = |t: &(&ShapeTarget, &[f64])| -> [f64; 3] {
        let tip = t.0.tip_mm();
        [tip[0].unwrap_or(f64::NAN), tip[1].unwrap_or(f64::NAN), tip[2].unwrap_or(f64::NAN)]
    };
    let legs: Vec<Leg> = targets
        .windows(2)
        .enumerate()
        .map(|(k, w)| {
            let (a, b) = (waypoint(&w[0]), waypoint(&w[1]));
            let samples: Vec<PathSample> = (0..=n)
                .into_par_iter()
                .map(|j| {
                    let f = j as f64 / n as f64;
                    let actuation: Vec<f64> = w[0].1.iter().zip(w[1].1).map(|(p, q)| p + f * (q - p)).collect();
                    match setup.simulate(&setup.actuator(channels, &actuation)) {
                        Ok(sim) => {
                            let tip = sim.pose.tip_mm();
                            PathSample { step: j, tensions_n: Some(sim.pose.tensions_n.to_vec()), tip_mm: Some(tip), deviation_mm: Some(distance_to_segment(tip, a, b)), failure: None, actuation }
                        }
                        Err(e) => PathSample { step: j, actuation, tensions_n: None, tip_mm: None, deviation_mm: None, failure: Some(e.to_string()) },
                    }
                })
                .collect();
            let max_deviation_mm = samples.iter().filter_map(|s| s.deviation_mm).fold(0.0, f64::max);
            let reversals = (0..setup.cables())
                .filter(|&c| {
                    let series: Vec<f64> = samples.iter().filter_map(|s| s.tensions_n.as_ref().map(|t| t[c])).collect();
                    reverses(&series)
                })
                .map(|c| c + 1)
                .collect();
            Leg { from: k + 1, to: k + 2, samples, max_deviation_mm, reversals }
        })
        .collect();
    let max_deviation_mm = legs.iter().map(|l| l.max_deviation_mm).fold(0.0, f64::max);
    let failed_samples = legs.iter().flat_map(|l| &l.samples).filter(|s| s.failure.is_some()).count();
    Ok(PathReport { steps_per_leg: n, smooth: trajectory.smooth, legs, max_deviation_mm, failed_samples })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_and_reversal() {
        assert!((distance_to_segment([1.0, 1.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]) - 1.0).abs() < 1e-15);
        assert!((distance_to_segment([3.0, 0.0, 0.0], [0.0; 3], [2.0, 0.0, 0.0]) - 1.0).abs() < 1e-15);
        assert!(!reverses(&[0.0, 0.5, 1.0, 1.0]));
        assert!(reverses(&[0.0, 0.5, 0.4]));
        assert!(!reverses(&[1.0, 1.0 + 1e-13, 1.0]));
    }
}
