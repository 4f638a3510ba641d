//! Captures with body-fixed 3-D markers as a fit's observations: each
//! marker coordinate's error, simulated minus measured, over the marker's
//! noise σ = √(sd² + σ₀²) (its frame-to-frame s.d. from the file and the
//! system's error σ₀, which a frame-to-frame s.d. does not contain).
//!
//! The rules: the rigidities and the density move a factor 100 either way
//! in logs, an effect in its registry coordinate within bounds near where
//! it stops mattering; one variance for every coordinate; a parameter the
//! data do not determine is held at its start and the others fitted again;
//! an accepted step that lowers the cost by less than 1e-6 of it ends the
//! fit (each further step re-solves every capture several times for a
//! change far below the standard errors).

use super::Observations;
pub mod errors;
pub mod files;
pub mod simulate;

use errors::ErrorReport;
use files::CaptureSet;
use simulate::{solve_captures, CaptureSolution};
use crate::calibrate::fit::{Adequacy, Covariance, EffectBounds, FailedColumn, FitReport, FitRules, FitSpec, Fitted, FittedParameter, Status};
use crate::calibrate::{stats, CalibrateError, InvalidRequest, NoiseError, Parameter};
use crate::model::Actuator;
use crate::numerics::lm;
use crate::solver::SolverOptions;
use serde::ser::SerializeSeq;
use serde::Serialize;

/// An accepted step that lowers the cost by less than this share ends the
/// fit as converged: near the optimum the cost is quadratic, and a 1e-6
/// share of χ² ≈ dof is a hundredth of σ.
pub const ENOUGH_REDUCTION: f64 = 1e-6;

/// The fit's rules for 3-D markers.
pub const RULES: FitRules = FitRules {
    steps: &[1e-5, 1e-6],
    failed_column: FailedColumn::NoJacobian,
    body_factor: 100.0,
    effect_bounds: EffectBounds::ByDomain { signed: 10.0, logit: 15.0, factor: 1e4 },
    enough_reduction: Some(ENOUGH_REDUCTION),
    hold_undetermined: true,
    covariance: Covariance::Pooled,
};

/// Captures and their markers, with the system's noise and the 3-D
/// solver's settings.
#[derive(Debug, Clone)]
pub struct Captures<'a> {
    /// The captures and markers fitted.
    pub set: &'a CaptureSet,
    /// The system's noise σ₀ per coordinate, mm, added in quadrature to a
    /// marker's own `sd_mm`.
    pub noise_mm: f64,
    /// The 3-D solver's settings.
    pub options: &'a SolverOptions,
    sigma: Vec<f64>,
}

impl<'a> Captures<'a> {
    /// The observations of `set` with the system's noise `noise_mm`.
    pub fn new(set: &'a CaptureSet, noise_mm: f64, options: &'a SolverOptions) -> Self {
        let sigma = set
            .readings()
            .flat_map(|(_, m)| {
                let s = (m.sd_mm.unwrap_or(0.0).powi(2) + noise_mm.powi(2)).sqrt();
                [s; 3]
            })
            .collect();
        Self { set, noise_mm, options, sigma }
    }
}

/// What a fit to 3-D markers reports besides the common fields.
#[derive(Debug, Clone, Serialize)]
pub struct CapturesReport {
    /// Why it stopped, in words.
    pub termination: String,
    /// The noise σ₀ added to each marker's own, mm.
    pub noise_mm: f64,
    /// The marker errors at the fitted values.
    #[serde(flatten)]
    pub errors: ErrorReport,
    /// The solutions at the fitted values.
    #[serde(skip)]
    pub solutions: Vec<CaptureSolution>,
}

/// A parameter as a fit to 3-D markers writes it.
#[derive(Serialize)]
struct ParameterJson<'a> {
    name: &'a str,
    value: f64,
    start: f64,
    se: f64,
    status: Status,
}

impl FitReport for CapturesReport {
    fn serialize_parameters<S: serde::Serializer>(parameters: &[FittedParameter], serializer: S) -> Result<S::Ok, S::Error> {
        let mut seq = serializer.serialize_seq(Some(parameters.len()))?;
        for p in parameters {
            seq.serialize_element(&ParameterJson { name: &p.name, value: p.value, start: p.start, se: p.se, status: p.status })?;
        }
        seq.end()
    }
}

impl Observations for Captures<'_> {
    type Solution = Vec<CaptureSolution>;
    type Report = CapturesReport;

    fn rules(&self) -> FitRules {
        RULES
    }

    fn check(&self, base: &Actuator, spec: &FitSpec) -> Result<(), CalibrateError> {
        if !(self.noise_mm.is_finite() && self.noise_mm > 0.0) {
            return Err(NoiseError::Markers { value: self.noise_mm }.into());
        }
        base.channels().map_err(|e| CalibrateError::Actuator(e.into()))?;
        if spec.params.contains(&Parameter::Density) && !base.rod.gravity.enabled {
            return Err(InvalidRequest::DensityWithoutGravity.into());
        }
        Ok(())
    }

    fn whitened(&self, actuator: &Actuator) -> Result<(Vec<f64>, Vec<CaptureSolution>), CalibrateError> {
        actuator.rod.validate().map_err(CalibrateError::from)?;
        let solutions = solve_captures(actuator, self.options, self.set)?;
        let mut z = Vec::with_capacity(self.sigma.len());
        for (i, c) in self.set.captures.iter().enumerate() {
            if let Some(ms) = self.set.markers.get(&c.measurement) {
                for (m, sim) in ms.iter().zip(&solutions[i].markers_mm) {
                    for k in 0..3 {
                        z.push(sim[k] - m.measured_mm[k]);
                    }
                }
            }
        }
        for (v, s) in z.iter_mut().zip(&self.sigma) {
            *v /= s;
        }
        Ok((z, solutions))
    }

    fn check_start(&self, r: &[f64], fitted: usize) -> Result<(), CalibrateError> {
        if r.len() <= fitted {
            return Err(InvalidRequest::TooFewMarkerCoordinates { coordinates: r.len(), parameters: fitted }.into());
        }
        Ok(())
    }

    fn channels(&self) -> Vec<usize> {
        vec![0; self.sigma.len()]
    }

    fn adequacy(&self, z: &[f64], fitted: usize) -> Adequacy {
        let chi2: f64 = z.iter().map(|v| v * v).sum();
        let dof = z.len() - fitted;
        Adequacy { chi2, dof, p_value: stats::chi2_p_value(chi2, dof), outliers: Vec::new() }
    }

    fn report(&self, fitted: &Fitted<'_>, solutions: Vec<CaptureSolution>) -> CapturesReport {
        let termination = if fitted.termination == lm::Termination::Stopped {
            format!("converged: the last step lowered the cost by less than {ENOUGH_REDUCTION:e} of it")
        } else {
            fitted.termination.to_string()
        };
        CapturesReport { termination, noise_mm: self.noise_mm, errors: ErrorReport::of(self.set, &solutions), solutions }
    }
}
