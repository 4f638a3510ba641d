//! The 3-D errors of simulated markers against measured ones: per marker,
//! per capture (RMS over its markers), per marker name (RMS over the
//! captures) and overall — what `predict` prints and `fit.json` records.

use super::files::CaptureSet;
use super::simulate::CaptureSolution;
use serde::Serialize;
use std::collections::BTreeMap;

/// One marker of one capture.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MarkerError {
    /// The marker's name.
    pub marker: String,
    /// |simulated − measured|, mm.
    pub error_mm: f64,
    /// simulated − measured (x, y, z), mm.
    pub residual_mm: [f64; 3],
    /// Measured position, mm.
    pub measured_mm: [f64; 3],
    /// Simulated position, mm.
    pub simulated_mm: [f64; 3],
}

/// One capture's errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaptureErrors {
    /// Measurement id.
    pub measurement: i64,
    /// Each cable's tension in the solve, N.
    pub tensions_n: Vec<f64>,
    /// RMS of the 3-D errors over its markers, mm.
    pub rms_mm: f64,
    /// Each marker.
    pub markers: Vec<MarkerError>,
}

/// The errors of a set of captures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ErrorReport {
    /// Per capture, in file order.
    pub captures: Vec<CaptureErrors>,
    /// Per marker name: RMS of its 3-D error over the captures, mm.
    pub rms_by_marker_mm: BTreeMap<String, f64>,
    /// RMS over every marker of every capture, mm.
    pub rms_mm: f64,
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).sqrt()
    }
}

impl ErrorReport {
    /// The errors of `solutions` (indexed like `set.captures`).
    pub fn of(set: &CaptureSet, solutions: &[CaptureSolution]) -> ErrorReport {
        let no_markers = Vec::new();
        let captures: Vec<CaptureErrors> = set
            .captures
            .iter()
            .zip(solutions)
            .map(|(c, sol)| {
                let markers: Vec<MarkerError> = set
                    .markers
                    .get(&c.measurement)
                    .unwrap_or(&no_markers)
                    .iter()
                    .zip(&sol.markers_mm)
                    .map(|(m, sim)| {
                        let residual_mm: [f64; 3] = std::array::from_fn(|i| sim[i] - m.measured_mm[i]);
                        let error_mm = residual_mm.iter().map(|v| v * v).sum::<f64>().sqrt();
                        MarkerError { marker: m.marker.clone(), error_mm, residual_mm, measured_mm: m.measured_mm, simulated_mm: *sim }
                    })
                    .collect();
                CaptureErrors { measurement: c.measurement, tensions_n: sol.pose.tensions_n.to_vec(), rms_mm: rms(markers.iter().map(|m| m.error_mm)), markers }
            })
            .collect();
        let mut by_marker: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        for c in &captures {
            for m in &c.markers {
                by_marker.entry(m.marker.clone()).or_default().push(m.error_mm);
            }
        }
        let rms_by_marker_mm = by_marker.into_iter().map(|(k, v)| (k, rms(v.into_iter()))).collect();
        let rms_mm = rms(captures.iter().flat_map(|c| c.markers.iter().map(|m| m.error_mm)));
        ErrorReport { captures, rms_by_marker_mm, rms_mm }
    }

    /// The per-marker RMS on one line: `p1 11.2, p2 15.9, … mm`.
    pub fn by_marker_text(&self) -> String {
        let parts: Vec<String> = self.rms_by_marker_mm.iter().map(|(k, v)| format!("{k} {v:.2}")).collect();
        format!("{} mm", parts.join(", "))
    }
}

impl std::fmt::Display for ErrorReport {
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(out, "3-D marker errors (|simulated − measured|, mm):")?;
        for c in &self.captures {
            let t: Vec<String> = c.tensions_n.iter().map(|t| format!("{t:.3}")).collect();
            write!(out, "  capture {:>4}  tensions [{}] N  RMS {:>8.3}:", c.measurement, t.join(", "), c.rms_mm)?;
            for m in &c.markers {
                write!(out, "  {} {:.3}", m.marker, m.error_mm)?;
            }
            writeln!(out)?;
        }
        writeln!(out, "RMS per marker: {}", self.by_marker_text())?;
        writeln!(out, "RMS over all markers and captures: {:.3} mm", self.rms_mm)
    }
}
