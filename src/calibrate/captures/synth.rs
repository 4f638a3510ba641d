//! Synthetic several-cable captures with 3-D markers: the true actuator
//! (any hidden effect set on it) solved at every capture, its markers
//! measured with Gaussian noise. How tests get 3-D data whose truth is known.

use super::files::{Actuation, Capture, CaptureSet, MarkerReading};
use super::simulate::solve_captures;
use crate::calibrate::data::Direction;
use crate::calibrate::rng::Rng;
use crate::calibrate::CalibrateError;
use crate::model::spatial::SpatialOptions;
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

/// Solves `captures` with `truth` and measures `markers` on each with
/// noise of standard deviation `noise_mm` per coordinate (seeded; the
/// readings carry `sd_mm` = `noise_mm` when `state_sd` is set).
pub fn synth_captures(
    truth: &Actuator,
    options: &SpatialOptions,
    captures: Vec<Capture>,
    markers: &[MarkerSpec],
    noise_mm: f64,
    seed: u64,
    state_sd: bool,
) -> Result<CaptureSet, CalibrateError> {
    if !(noise_mm.is_finite() && noise_mm >= 0.0) {
        return Err(CalibrateError::Noise(format!("noise_mm = {noise_mm}: the noise must be a standard deviation ≥ 0")));
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
