//! Least-squares fit of EA, GA, EI (thesis eq. 2.14), optionally together
//! with effect parameters, against the measurements' noise.
//!
//! Every residual is simulated minus measured, divided by its noise (σ in mm
//! for tip x, y, centreline points and markers, σ in degrees for the tip
//! angle): tip x, y and angle of each reading; for each measured centreline
//! point, its signed distance to the closest point of the simulated
//! centreline; for each marker (a point at known rest arc length s and
//! lateral body-frame offset), its x and y. The fit minimises Σ ρ(z) with
//! Huber's ρ (quadratic up to `k` σ, linear beyond: a couple of bad readings
//! cannot pull the fit over) or plain squares.
//!
//! Parameters are fitted in unconstrained coordinates (logs of the
//! rigidities, boxed to 1e-3…1e3 times their start, see
//! [`Effect::to_internal`]) by Levenberg–Marquardt with a central
//! finite-difference Jacobian; a difference the model cannot solve falls
//! back to a one-sided or smaller step rather than aborting the fit. Any
//! rigidity can be held fixed. Standard errors come from (JᵀJ)⁻¹ with one
//! variance per kind of residual in a sandwich, mapped to the parameters by
//! the delta method; correlations from the same matrix.
//!
//! Adequacy: χ² of the whitened residuals over the readings that are not
//! flagged as outliers (|z| > [`OUTLIER_Z`] on some residual, at most
//! [`max_outliers`] readings), its degrees of freedom and the chance that
//! noise alone gives a χ² as large ([`stats::chi2_p_value`]).
//!
//! The optimiser is the library's one bounded Levenberg–Marquardt
//! ([`crate::numerics::lm`], shared with design): a trial step whose solve
//! fails (a rod that collapses at absurd rigidities) is simply rejected, and
//! the stopping rule runs down to rounding for the noise-free tests.

use super::data::{CentrelinePoints, Dataset, Marker, MarkerPoints, Measurement, RoutingGroup};
use super::effect::Effect;
use super::predict::{predict, Prediction};
use super::stats;
use super::{CalibrateError, HeldError, InvalidRequest, NoiseError, Parameter};
use crate::model::Rod;
use crate::solver::{CentrelinePoint, SolverOptions};
use crate::numerics::lm;
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::Arc;

/// A residual beyond this many σ marks its reading as a possible outlier.
pub const OUTLIER_Z: f64 = 6.0;

/// Most readings set aside as outliers in the χ² test: two, or 5 % of the
/// readings if that is more. When more readings are that far off, the model
/// is wrong, not the readings, and none is set aside.
pub fn max_outliers(readings: usize) -> usize {
    2usize.max((0.05 * readings as f64).ceil() as usize)
}

/// Measurement noise (standard deviations) for rows that do not give their own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Tip x, y, centreline points and markers, mm.
    pub mm: f64,
    /// Tip angle, degrees.
    pub deg: f64,
}

impl Default for Noise {
    /// The noise `cablemap synth` adds by default: 0.4 mm and 1°.
    fn default() -> Self {
        Self { mm: 0.4, deg: 1.0 }
    }
}

impl Noise {
    /// Checks that both levels are positive and finite.
    pub fn validate(&self) -> Result<(), CalibrateError> {
        for (name, v) in [("noise_mm", self.mm), ("noise_deg", self.deg)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(NoiseError::Measurement { name, value: v }.into());
            }
        }
        Ok(())
    }

    /// The noise of row `m`, mm and degrees.
    pub fn of(&self, m: &Measurement) -> (f64, f64) {
        (m.noise_mm.unwrap_or(self.mm), m.noise_deg.unwrap_or(self.deg))
    }
}

/// The loss on whitened residuals z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Loss {
    /// Σ z²: ordinary least squares.
    Squared,
    /// Huber: z² up to `k`, 2k|z| − k² beyond (`k` in σ).
    Huber {
        /// Where the loss turns linear, in σ.
        k: f64,
    },
}

impl Default for Loss {
    fn default() -> Self {
        Loss::Huber { k: 3.0 }
    }
}

impl Loss {
    /// The residual whose square is the loss of `z` (sign kept), so that a
    /// least-squares solver minimises Σ ρ.
    pub(crate) fn transform(self, z: f64) -> f64 {
        match self {
            Loss::Squared => z,
            Loss::Huber { k } if z.abs() > k => z.signum() * (2.0 * k * z.abs() - k * k).sqrt(),
            Loss::Huber { .. } => z,
        }
    }

    /// A short description for reports.
    pub fn describe(self) -> String {
        match self {
            Loss::Squared => "least squares".into(),
            Loss::Huber { k } => format!("Huber loss (quadratic up to {k} σ, linear beyond)"),
        }
    }
}

/// Measured shapes that enter the fit besides the tip readings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShapeData {
    /// Measured centreline points by measurement id.
    pub centrelines: CentrelinePoints,
    /// Markers by measurement id.
    pub markers: MarkerPoints,
}

impl ShapeData {
    /// Whether there is nothing besides the tips.
    pub fn is_empty(&self) -> bool {
        self.centrelines.values().all(|v| v.is_empty()) && self.markers.values().all(|v| v.is_empty())
    }
}

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSpec {
    /// Effects fitted together with EA, GA, EI (empty: the thesis model).
    pub effects: Vec<Effect>,
    /// Weight of the tip angle in the reported mm-equivalent RMS: mm per
    /// degree (the fit itself weights every residual by its noise).
    pub angle_weight_mm_per_deg: f64,
    /// Noise of rows that do not give their own.
    pub noise: Noise,
    /// Loss on the whitened residuals.
    pub loss: Loss,
    /// EA, GA, EI held at the starting actuator's values instead of fitted.
    pub fixed_rigidities: [bool; 3],
    /// Most Levenberg–Marquardt iterations.
    pub max_iterations: usize,
    /// Centreline points and markers.
    pub shapes: Arc<ShapeData>,
}

impl Default for FitSpec {
    fn default() -> Self {
        Self {
            effects: Vec::new(),
            angle_weight_mm_per_deg: 1.0,
            noise: Noise::default(),
            loss: Loss::default(),
            fixed_rigidities: [false; 3],
            max_iterations: 200,
            shapes: Arc::new(ShapeData::default()),
        }
    }
}

/// Names of the rigidities, as in [`FittedParameter::name`].
pub const RIGIDITY_NAMES: [&str; 3] = ["ea_n", "ga_n", "ei_n_mm2"];

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedParameter {
    /// Name with unit (`ea_n`, an effect's parameter, …).
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// Standard error (same unit; 0 when held fixed).
    pub se: f64,
    /// Held at its given value, not fitted.
    pub fixed: bool,
}

/// RMS residual of one routing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoutingRms {
    /// Routing id.
    pub routing: String,
    /// Rows used.
    pub rows: usize,
    /// RMS over x, y (mm) and weighted angle, mm.
    pub rms_mm: f64,
    /// RMS of the tip position error |Δp|, mm.
    pub rms_position_mm: f64,
    /// RMS of the tip angle error, degrees.
    pub rms_angle_deg: f64,
}

/// The result of a fit. It serialises to the fit's JSON object (without
/// the actuator and the predictions).
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// Effects that were fitted.
    pub effects: Vec<Effect>,
    /// The base actuator with the fitted values.
    #[serde(skip)]
    pub actuator: Rod,
    /// EA, GA, EI, then each effect's parameter.
    pub parameters: Vec<FittedParameter>,
    /// Correlation matrix of the parameters (same order).
    pub correlation: Vec<Vec<f64>>,
    /// The minimised loss Σ ρ(z) of the whitened residuals.
    #[serde(rename = "loss")]
    pub rss: f64,
    /// Number of residuals (3 per reading, 1 per centreline point, 2 per marker).
    pub n_residuals: usize,
    /// Bayesian information criterion n ln(Σρ/n) + p ln n (p: fitted parameters).
    pub bic: f64,
    /// χ² = Σ z² over the readings not flagged as outliers.
    pub chi2: f64,
    /// Degrees of freedom of `chi2`: its residuals minus fitted parameters.
    pub dof: usize,
    /// χ² / dof (1 when the model explains the data to within the noise).
    pub reduced_chi2: f64,
    /// P(χ²_dof ≥ chi2): the chance of a χ² this large from noise alone.
    pub p_value: f64,
    /// Measurement ids of readings set aside as outliers in the χ² test.
    pub outliers: Vec<i64>,
    /// Physically implausible or undetermined values, in words.
    pub flags: Vec<String>,
    /// Whether some fitted value is physically implausible (axial strain,
    /// GA → 0, a rigidity at its bound, an effect outside its range).
    pub implausible: bool,
    /// RMS over all tip residuals (x, y and weighted θ), mm.
    pub rms_mm: f64,
    /// RMS per routing.
    pub per_routing: Vec<RoutingRms>,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Whether the stopping rule was met (not the iteration cap, and the
    /// Jacobian could be evaluated at the optimum).
    pub converged: bool,
    /// Predictions at the optimum, indexed like the data's rows.
    #[serde(skip)]
    pub predictions: Vec<Option<Prediction>>,
}

impl FitResult {
    /// The fitted value and SE of `effect`, if it was fitted.
    pub fn effect_parameter(&self, effect: Effect) -> Option<&FittedParameter> {
        let i = self.effects.iter().position(|&e| e == effect)?;
        self.parameters.get(3 + i)
    }

    /// Whether the model is consistent with the noise at level `alpha`
    /// (p ≥ alpha).
    pub fn consistent_with_noise(&self, alpha: f64) -> bool {
        self.p_value >= alpha
    }
}

/// Weighted tip residuals of the rows of `groups`, 3 per row in group order
/// (mm, mm, mm-equivalent), for reports.
pub fn residuals(
    data: &Dataset,
    groups: &[RoutingGroup],
    predictions: &[Option<Prediction>],
    angle_weight_mm_per_deg: f64,
) -> Vec<f64> {
    let mut r = Vec::new();
    for g in groups {
        for &i in &g.rows {
            let (m, p) = (&data.rows[i], &predictions[i].as_ref().expect("predicted").pose);
            r.extend(row_residual(m, p, angle_weight_mm_per_deg));
        }
    }
    r
}

/// Residual of one row: Δx, Δy (mm) and weighted Δθ (mm-equivalent).
pub fn row_residual(m: &super::Measurement, p: &crate::solver::TipPose, angle_weight_mm_per_deg: f64) -> [f64; 3] {
    [
        p.tip_x_mm - m.tip_x_mm,
        p.tip_y_mm - m.tip_y_mm,
        (p.tip_angle_rad - m.tip_angle_rad).to_degrees() * angle_weight_mm_per_deg,
    ]
}

/// RMS of the residuals of `groups`' rows, per routing.
pub fn rms_per_routing(
    data: &Dataset,
    groups: &[RoutingGroup],
    predictions: &[Option<Prediction>],
    angle_weight_mm_per_deg: f64,
) -> Vec<RoutingRms> {
    groups
        .iter()
        .map(|g| {
            let (mut all, mut pos, mut ang) = (0.0, 0.0, 0.0);
            for &i in &g.rows {
                let m = &data.rows[i];
                let p = &predictions[i].as_ref().expect("predicted").pose;
                let r = row_residual(m, p, angle_weight_mm_per_deg);
                all += r.iter().map(|v| v * v).sum::<f64>();
                pos += r[0] * r[0] + r[1] * r[1];
                ang += (p.tip_angle_rad - m.tip_angle_rad).to_degrees().powi(2);
            }
            let n = g.rows.len() as f64;
            RoutingRms {
                routing: g.routing.clone(),
                rows: g.rows.len(),
                rms_mm: (all / (3.0 * n)).sqrt(),
                rms_position_mm: (pos / n).sqrt(),
                rms_angle_deg: (ang / n).sqrt(),
            }
        })
        .collect()
}

/// Signed distance (mm) from `p` to the polyline `line` (clamp first):
/// the closest point on it, positive to the left of the direction of
/// travel. The last segment is extended beyond the tip, so a measured
/// point past a shorter simulated rod is judged by its side distance (the
/// tip reading judges the length).
pub fn signed_distance_to_centreline(p: [f64; 2], line: &[CentrelinePoint]) -> f64 {
    closest_on_centreline(p, line).0
}

/// [`signed_distance_to_centreline`] and the rest arc length s (mm) of the
/// closest point.
pub fn closest_on_centreline(p: [f64; 2], line: &[CentrelinePoint]) -> (f64, f64) {
    let mut best = f64::INFINITY;
    let mut signed = 0.0;
    let mut s_mm = 0.0;
    let last = line.len().saturating_sub(2);
    for (k, w) in line.windows(2).enumerate() {
        let (ax, ay) = (w[0].x_mm, w[0].y_mm);
        let (dx, dy) = (w[1].x_mm - ax, w[1].y_mm - ay);
        let len2 = dx * dx + dy * dy;
        if len2 == 0.0 {
            continue;
        }
        let mut t = ((p[0] - ax) * dx + (p[1] - ay) * dy) / len2;
        t = if k == last { t.max(0.0) } else { t.clamp(0.0, 1.0) };
        let (qx, qy) = (ax + t * dx, ay + t * dy);
        let d = (p[0] - qx).hypot(p[1] - qy);
        if d < best {
            best = d;
            let cross = dx * (p[1] - ay) - dy * (p[0] - ax);
            signed = if cross < 0.0 { -d } else { d };
            s_mm = (w[0].s_mm + t.min(1.0) * (w[1].s_mm - w[0].s_mm)).max(0.0);
        }
    }
    if best.is_finite() {
        (signed, s_mm)
    } else {
        (line.first().map_or(0.0, |c| (p[0] - c.x_mm).hypot(p[1] - c.y_mm)), 0.0)
    }
}

/// Where the simulated rod puts `marker`: the centreline point at its rest
/// arc length (linear between nodes) plus its offset along the body frame's
/// second axis (−sin φ, cos φ).
pub fn simulated_marker(marker: &Marker, line: &[CentrelinePoint]) -> [f64; 2] {
    let k = line.partition_point(|c| c.s_mm < marker.s_mm).clamp(1, line.len() - 1);
    let (a, b) = (&line[k - 1], &line[k]);
    let f = if b.s_mm > a.s_mm { ((marker.s_mm - a.s_mm) / (b.s_mm - a.s_mm)).clamp(0.0, 1.0) } else { 0.0 };
    let lerp = |u: f64, v: f64| u + f * (v - u);
    let (x, y, phi) = (lerp(a.x_mm, b.x_mm), lerp(a.y_mm, b.y_mm), lerp(a.frame_angle_rad, b.frame_angle_rad));
    [x - phi.sin() * marker.offset_mm, y + phi.cos() * marker.offset_mm]
}

/// What a residual measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResidualKind {
    /// Tip x.
    TipX,
    /// Tip y.
    TipY,
    /// Tip angle.
    TipAngle,
    /// A centreline point's distance to the simulated centreline (point index).
    Centreline(usize),
    /// A marker's x (marker index).
    MarkerX(usize),
    /// A marker's y (marker index).
    MarkerY(usize),
}

impl ResidualKind {
    /// Kind index for per-kind variances: x, y, θ, centreline, marker.
    fn channel(self) -> usize {
        match self {
            ResidualKind::TipX => 0,
            ResidualKind::TipY => 1,
            ResidualKind::TipAngle => 2,
            ResidualKind::Centreline(_) => 3,
            ResidualKind::MarkerX(_) | ResidualKind::MarkerY(_) => 4,
        }
    }
}

/// One residual: its reading (index into the data's rows) and what it measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slot {
    /// Index into [`Dataset::rows`].
    pub row: usize,
    /// What it measures.
    pub kind: ResidualKind,
}

/// The residuals of `groups`' rows in order: tip x, y, θ, then the row's
/// centreline points and markers.
pub fn layout(data: &Dataset, groups: &[RoutingGroup], shapes: &ShapeData) -> Vec<Slot> {
    let mut out = Vec::new();
    for g in groups {
        for &row in &g.rows {
            out.extend([ResidualKind::TipX, ResidualKind::TipY, ResidualKind::TipAngle].map(|kind| Slot { row, kind }));
            let id = data.rows[row].measurement;
            let points = shapes.centrelines.get(&id).map_or(0, |v| v.len());
            out.extend((0..points).map(|k| Slot { row, kind: ResidualKind::Centreline(k) }));
            let markers = shapes.markers.get(&id).map_or(0, |v| v.len());
            out.extend((0..markers).flat_map(|k| [ResidualKind::MarkerX(k), ResidualKind::MarkerY(k)]).map(|kind| Slot { row, kind }));
        }
    }
    out
}

/// Whitened residuals z (simulated − measured over noise) of `slots`.
pub fn whitened(data: &Dataset, slots: &[Slot], predictions: &[Option<Prediction>], shapes: &ShapeData, noise: &Noise) -> Vec<f64> {
    slots
        .iter()
        .map(|slot| {
            let m = &data.rows[slot.row];
            let pred = predictions[slot.row].as_ref().expect("predicted");
            let (s_mm, s_deg) = noise.of(m);
            let line = || pred.centreline.as_deref().expect("centreline kept for shape data");
            match slot.kind {
                ResidualKind::TipX => (pred.pose.tip_x_mm - m.tip_x_mm) / s_mm,
                ResidualKind::TipY => (pred.pose.tip_y_mm - m.tip_y_mm) / s_mm,
                ResidualKind::TipAngle => (pred.pose.tip_angle_rad - m.tip_angle_rad).to_degrees() / s_deg,
                ResidualKind::Centreline(k) => {
                    // The measured point's offset from the model, so simulated − measured is its negative.
                    -signed_distance_to_centreline(shapes.centrelines[&m.measurement][k], line()) / s_mm
                }
                ResidualKind::MarkerX(k) => (simulated_marker(&shapes.markers[&m.measurement][k], line())[0] - shapes.markers[&m.measurement][k].x_mm) / s_mm,
                ResidualKind::MarkerY(k) => (simulated_marker(&shapes.markers[&m.measurement][k], line())[1] - shapes.markers[&m.measurement][k].y_mm) / s_mm,
            }
        })
        .collect()
}

/// χ² of whitened residuals `z` with `fitted` parameters: readings with a
/// residual beyond [`OUTLIER_Z`] are set aside (at most [`max_outliers`]),
/// the rest give χ², its degrees of freedom and p-value.
pub fn chi_square(data: &Dataset, slots: &[Slot], z: &[f64], fitted: usize) -> (f64, usize, f64, Vec<i64>) {
    let mut worst: std::collections::BTreeMap<usize, f64> = Default::default();
    for (slot, v) in slots.iter().zip(z) {
        let e = worst.entry(slot.row).or_insert(0.0);
        *e = e.max(v.abs());
    }
    let mut far: Vec<(usize, f64)> = worst.into_iter().filter(|&(_, v)| v > OUTLIER_Z).collect();
    let readings = slots.iter().filter(|s| s.kind == ResidualKind::TipX).count();
    if far.len() > max_outliers(readings) {
        far.clear();
    }
    far.sort_by(|a, b| b.1.total_cmp(&a.1));
    let out_rows: Vec<usize> = far.iter().map(|f| f.0).collect();
    let (mut chi2, mut n) = (0.0, 0usize);
    for (slot, v) in slots.iter().zip(z) {
        if !out_rows.contains(&slot.row) {
            chi2 += v * v;
            n += 1;
        }
    }
    let dof = n.saturating_sub(fitted);
    let p = stats::chi2_p_value(chi2, dof);
    (chi2, dof, p, out_rows.iter().map(|&r| data.rows[r].measurement).collect())
}

/// Pseudo-inverse of the symmetric matrix `a` by eigen-decomposition,
/// ignoring directions with eigenvalue below 1e-12 of the largest, and
/// which parameters lean on those ignored directions.
fn pseudo_inverse(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<bool>) {
    let p = a.nrows();
    let eig = a.clone().symmetric_eigen();
    let top = eig.eigenvalues.amax();
    let mut inv = DMatrix::<f64>::zeros(p, p);
    let mut unidentified = vec![false; p];
    for (i, &l) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(i);
        if l > 1e-12 * top && l > 0.0 {
            inv += v * v.transpose() / l;
        } else {
            for k in 0..p {
                if v[k].abs() > 1e-3 {
                    unidentified[k] = true;
                }
            }
        }
    }
    (inv, unidentified)
}

/// Rigidities may move this factor either way from their start.
const RIGIDITY_RANGE: f64 = 1e3;

/// The fit problem: maps the unconstrained coordinates to an actuator.
struct Problem<'a> {
    base: &'a Rod,
    options: &'a SolverOptions,
    data: &'a Dataset,
    groups: &'a [RoutingGroup],
    spec: &'a FitSpec,
    slots: Vec<Slot>,
    /// Indices of the fitted coordinates.
    free: Vec<usize>,
}

impl Problem<'_> {
    fn actuator(&self, x: &[f64]) -> Rod {
        let mut a = self.base.clone();
        a.ea_n = x[0].exp();
        a.ga_n = x[1].exp();
        a.ei_n_mm2 = x[2].exp();
        for (e, &xi) in self.spec.effects.iter().zip(&x[3..]) {
            e.apply(&mut a, e.from_internal(xi));
        }
        a
    }

    /// Whitened residuals and predictions at `x`.
    fn evaluate(&self, x: &[f64]) -> Result<(Vec<f64>, Vec<Option<Prediction>>), CalibrateError> {
        let a = self.actuator(x);
        let keep = !self.spec.shapes.is_empty();
        let preds = predict(&a, self.options, self.data, self.groups, keep)?;
        let z = whitened(self.data, &self.slots, &preds, &self.spec.shapes, &self.spec.noise);
        Ok((z, preds))
    }

    /// The residuals the solver squares: the loss's transform of z.
    fn transformed_residuals(&self, x: &[f64]) -> Result<Vec<f64>, CalibrateError> {
        self.evaluate(x).map(|(z, _)| z.into_iter().map(|v| self.spec.loss.transform(v)).collect())
    }

    /// Finite-difference Jacobian over the free coordinates, columns in
    /// parallel; `r` are the residuals at `x`. A column whose central
    /// difference cannot be solved falls back to a one-sided difference,
    /// then to smaller steps; a column that fails every way is zero and
    /// reported by index.
    fn differences(&self, x: &[f64], r: &[f64]) -> (DMatrix<f64>, Vec<usize>) {
        let n = r.len();
        let columns: Vec<Option<Vec<f64>>> = self
            .free
            .par_iter()
            .map(|&j| {
                let at = |h: f64| {
                    let mut xh = x.to_vec();
                    xh[j] += h;
                    self.transformed_residuals(&xh).ok()
                };
                let diff = |a: &[f64], b: &[f64], span: f64| a.iter().zip(b).map(|(p, m)| (p - m) / span).collect::<Vec<f64>>();
                // One-sided differences: half the solves of central ones (the
                // Jacobian is most of a fit's cost), and an O(h) = 1e-6
                // relative error in the internal (log) parameters is far
                // below what Levenberg–Marquardt's steps or the standard
                // errors notice. A step the solver cannot take is tried the
                // other way, then smaller.
                for h in [1e-6, 1e-7, 1e-8] {
                    if let Some(rp) = at(h) {
                        return Some(diff(&rp, r, h));
                    }
                    if let Some(rm) = at(-h) {
                        return Some(diff(r, &rm, h));
                    }
                }
                None
            })
            .collect();
        let failed: Vec<usize> = self.free.iter().zip(&columns).filter(|(_, c)| c.is_none()).map(|(&j, _)| j).collect();
        let j = DMatrix::from_fn(n, self.free.len(), |i, k| columns[k].as_ref().map_or(0.0, |c| c[i]));
        (j, failed)
    }
}

impl lm::Problem for Problem<'_> {
    fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
        self.transformed_residuals(x).ok()
    }

    fn jacobian(&mut self, x: &[f64], r: &[f64], _free: &[usize]) -> Option<DMatrix<f64>> {
        // Columns that cannot be differenced are zero here; at the optimum
        // they are reported (see `fit_observed`).
        Some(self.differences(x, r).0)
    }
}

/// Fits the rigidities (and `spec.effects`) of `base` to the rows of
/// `groups`, starting from `base`'s values (an effect switched off on `base`
/// starts from [`Effect::start`]). Effects set on `base` but not fitted stay
/// as they are.
pub fn fit(
    base: &Rod,
    options: &SolverOptions,
    data: &Dataset,
    groups: &[RoutingGroup],
    spec: &FitSpec,
) -> Result<FitResult, CalibrateError> {
    fit_observed(base, options, data, groups, spec, &mut |_| {})
}

/// How much farther than the rod is long a measured tip may lie from the
/// clamp: the rod stretches by a few per cent at most, and a camera's error
/// is a fraction of its length.
const MAX_TIP_REACH_PER_LENGTH: f64 = 1.5;

/// Refuses data whose tips lie farther from the clamp than the rod could
/// reach: no parameter of the model can fit them, so the fit would
/// "converge" on nonsense. The likely cause is the unit (µm for mm).
fn check_tips_within_reach(data: &Dataset, base: &Rod) -> Result<(), CalibrateError> {
    let Some(far) = data.rows.iter().max_by(|a, b| a.tip_x_mm.hypot(a.tip_y_mm).total_cmp(&b.tip_x_mm.hypot(b.tip_y_mm))) else {
        return Ok(());
    };
    let reach = far.tip_x_mm.hypot(far.tip_y_mm);
    let length = base.length_mm;
    if reach <= MAX_TIP_REACH_PER_LENGTH * length {
        return Ok(());
    }
    Err(InvalidRequest::TipsOutOfReach { ratio: reach / length, tip_x_mm: far.tip_x_mm, tip_y_mm: far.tip_y_mm, row: far.row, length_mm: length }.into())
}

/// Where a running fit is: reported after every accepted step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitProgress {
    /// Iterations done (of at most 200).
    pub iteration: usize,
    /// Weighted RMS residual after this iteration, mm.
    pub rms_mm: f64,
}

/// [`fit`], calling `observe` after every accepted step, so that a long fit
/// (10⁵ readings) can show progress.
pub fn fit_observed(
    base: &Rod,
    options: &SolverOptions,
    data: &Dataset,
    groups: &[RoutingGroup],
    spec: &FitSpec,
    observe: &mut dyn FnMut(FitProgress),
) -> Result<FitResult, CalibrateError> {
    if !(spec.angle_weight_mm_per_deg.is_finite() && spec.angle_weight_mm_per_deg >= 0.0) {
        return Err(InvalidRequest::AngleWeight { value: spec.angle_weight_mm_per_deg }.into());
    }
    spec.noise.validate()?;
    base.validate()?;
    check_tips_within_reach(data, base)?;
    let slots = layout(data, groups, &spec.shapes);
    let mut x: Vec<f64> = vec![base.ea_n.ln(), base.ga_n.ln(), base.ei_n_mm2.ln()];
    x.extend(spec.effects.iter().map(|e| e.to_internal(e.current(base).unwrap_or_else(|| e.start()))));
    let free: Vec<usize> = (0..x.len()).filter(|&k| k >= 3 || !spec.fixed_rigidities[k]).collect();
    let bounds: Vec<(f64, f64)> = x
        .iter()
        .enumerate()
        .map(|(k, &v)| if k < 3 { (v - RIGIDITY_RANGE.ln(), v + RIGIDITY_RANGE.ln()) } else { (-50.0, 50.0) })
        .collect();
    let mut problem = Problem { base, options, data, groups, spec, slots, free };
    let p = problem.free.len();
    let r = problem.transformed_residuals(&x)?;
    let n = r.len();
    if n <= p {
        return Err(InvalidRequest::TooFewResiduals { residuals: n, readings: data.rows.len(), parameters: p }.into());
    }
    let cost: f64 = r.iter().map(|v| v * v).sum();
    // Residuals are in units of the noise (and the robust loss compresses
    // large ones): a trillion noise widths, or squares that overflow, is no
    // measurement of this actuator. No step can lower such a cost, and "no
    // step lowers the cost" must not read as a converged fit.
    const ABSURD_RESIDUAL: f64 = 1e12;
    let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !cost.is_finite() || !(worst < ABSURD_RESIDUAL) {
        let farthest = data.rows.iter().map(|m| m.tip_x_mm.abs().max(m.tip_y_mm.abs())).fold(0.0, f64::max);
        return Err(InvalidRequest::AbsurdResiduals { farthest_mm: farthest, worst_noise_widths: worst }.into());
    }
    let settings = lm::Settings { bounds: bounds.clone(), free: problem.free.clone(), max_iterations: spec.max_iterations };
    let outcome = lm::minimise(&mut problem, x, r, &settings, &mut |step| {
        observe(FitProgress { iteration: step.iteration, rms_mm: (step.cost / step.residuals as f64).sqrt() })
    });
    let (x, r, cost, iterations) = (outcome.x, outcome.r, outcome.cost, outcome.iterations);
    let mut converged = outcome.termination.converged();
    // Uncertainties from the Jacobian at the optimum.
    let (j, failed_columns) = problem.differences(&x, &r);
    let jtj = j.transpose() * &j;
    // Residual kinds are measured by different means: each gets its own
    // variance from its residuals, and the covariance is the sandwich
    // (JᵀJ)⁻¹ Jᵀ Σ J (JᵀJ)⁻¹ (σ² (JᵀJ)⁻¹ when they agree).
    let dof_share = (n - p) as f64 / n as f64;
    let kind_var: [f64; 5] = std::array::from_fn(|c| {
        let (sum, count) = problem
            .slots
            .iter()
            .zip(&r)
            .filter(|(s, _)| s.kind.channel() == c)
            .fold((0.0, 0usize), |(s, k), (_, v)| (s + v * v, k + 1));
        if count == 0 {
            0.0
        } else {
            sum / (count as f64 * dof_share)
        }
    });
    let (inv, unidentified) = pseudo_inverse(&jtj);
    let mut meat = DMatrix::<f64>::zeros(p, p);
    for (i, row) in j.row_iter().enumerate() {
        meat += row.transpose() * row * kind_var[problem.slots[i].kind.channel()];
    }
    let mut cov_free = &inv * meat * &inv;
    // A parameter the data cannot determine (a rigidity run off to where it
    // no longer matters) has no finite standard error.
    for (k, &bad) in unidentified.iter().enumerate() {
        if bad {
            cov_free[(k, k)] = f64::INFINITY;
        }
    }
    for (k, idx) in problem.free.iter().enumerate() {
        if failed_columns.contains(idx) {
            cov_free[(k, k)] = f64::INFINITY;
        }
    }
    // Full covariance, zero for held parameters.
    let total = x.len();
    let mut cov = DMatrix::<f64>::zeros(total, total);
    for (a, &ia) in problem.free.iter().enumerate() {
        for (b, &ib) in problem.free.iter().enumerate() {
            cov[(ia, ib)] = cov_free[(a, b)];
        }
    }
    let (z, predictions) = problem.evaluate(&x)?;
    let actuator = problem.actuator(&x);
    let mut names: Vec<String> = RIGIDITY_NAMES.iter().map(|s| s.to_string()).collect();
    names.extend(spec.effects.iter().map(|e| e.parameter_name().to_string()));
    let mut values = vec![actuator.ea_n, actuator.ga_n, actuator.ei_n_mm2];
    let mut derivs = values.clone(); // d value / d log value
    for (e, &xi) in spec.effects.iter().zip(&x[3..]) {
        values.push(e.from_internal(xi));
        derivs.push(e.derivative(xi));
    }
    let is_free = |k: usize| problem.free.contains(&k);
    let parameters: Vec<FittedParameter> = (0..total)
        .map(|k| FittedParameter {
            name: names[k].clone(),
            value: values[k],
            se: if !is_free(k) {
                0.0
            } else {
                match cov[(k, k)] {
                    v if v.is_finite() => derivs[k].abs() * v.max(0.0).sqrt(),
                    _ => f64::INFINITY,
                }
            },
            fixed: !is_free(k),
        })
        .collect();
    let correlation = (0..total)
        .map(|a| {
            (0..total)
                .map(|b| {
                    let (va, vb) = (cov[(a, a)], cov[(b, b)]);
                    // No correlation is defined with an undetermined or held parameter.
                    if va.is_finite() && vb.is_finite() && va > 0.0 && vb > 0.0 {
                        cov[(a, b)] / (va * vb).sqrt()
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect();
    let (chi2, dof, p_value, outliers) = chi_square(data, &problem.slots, &z, p);
    let (mut flags, implausible) = plausibility_flags(data, groups, &parameters, &spec.effects, &x, &bounds, &problem.free);
    if !failed_columns.is_empty() {
        converged = false;
        let names: Vec<&str> = failed_columns.iter().map(|&k| parameters[k].name.as_str()).collect();
        flags.push(format!("the model could not be solved near the optimum to differentiate by {}", names.join(", ")));
    }
    let nf = n as f64;
    let tip = residuals(data, groups, &predictions, spec.angle_weight_mm_per_deg);
    let tip_rms = (tip.iter().map(|v| v * v).sum::<f64>() / tip.len().max(1) as f64).sqrt();
    Ok(FitResult {
        effects: spec.effects.clone(),
        per_routing: rms_per_routing(data, groups, &predictions, spec.angle_weight_mm_per_deg),
        actuator,
        parameters,
        correlation,
        rss: cost,
        n_residuals: n,
        bic: nf * (cost / nf).max(1e-300).ln() + p as f64 * nf.ln(),
        chi2,
        dof,
        reduced_chi2: if dof > 0 { chi2 / dof as f64 } else { f64::NAN },
        p_value,
        outliers,
        flags,
        implausible,
        rms_mm: tip_rms,
        iterations,
        converged,
        predictions,
    })
}

/// Applies `--fix` values to the starting actuator: returns it with the
/// values set, which rigidities are held, and which effects are held.
pub fn apply_held(base: &Rod, held: &[(Parameter, f64)]) -> Result<(Rod, [bool; 3], Vec<Effect>), CalibrateError> {
    let mut a = base.clone();
    let mut fixed = [false; 3];
    let mut effects = Vec::new();
    for &(h, v) in held {
        if !v.is_finite() {
            return Err(CalibrateError::Held(HeldError::NotFinite { value: v }));
        }
        let rigidity = match h {
            Parameter::Ea => 0,
            Parameter::Ga => 1,
            Parameter::Ei => 2,
            Parameter::Effect(e) => {
                e.apply(&mut a, v);
                effects.push(e);
                continue;
            }
            Parameter::Gj | Parameter::Density => return Err(CalibrateError::Held(HeldError::NotPlanar { name: h.name() })),
        };
        *[&mut a.ea_n, &mut a.ga_n, &mut a.ei_n_mm2][rigidity] = v;
        fixed[rigidity] = true;
    }
    a.validate().map_err(|e| CalibrateError::Held(e.into()))?;
    Ok((a, fixed, effects))
}

/// Largest axial strain τ/EA accepted as plausible at the measured tensions.
pub const MAX_AXIAL_STRAIN: f64 = 0.2;
/// GA below this share of EA reads as a shear rigidity run to zero.
pub const MIN_GA_SHARE_OF_EA: f64 = 0.01;

/// Physically implausible fitted values in words: axial strain beyond
/// [`MAX_AXIAL_STRAIN`] at the top measured tension, GA → 0, a rigidity at
/// its bound, an effect outside its plausible range, an undetermined value.
#[allow(clippy::too_many_arguments)]
fn plausibility_flags(
    data: &Dataset,
    groups: &[RoutingGroup],
    parameters: &[FittedParameter],
    effects: &[Effect],
    x: &[f64],
    bounds: &[(f64, f64)],
    free: &[usize],
) -> (Vec<String>, bool) {
    let mut flags = Vec::new();
    let (ea, ga) = (parameters[0].value, parameters[1].value);
    let top = groups.iter().flat_map(|g| g.rows.iter()).map(|&i| data.rows[i].tension_n).fold(0.0, f64::max);
    if top / ea > MAX_AXIAL_STRAIN {
        flags.push(format!(
            "EA = {ea:.4} N implies {:.0} % axial strain at {top} N (more than {:.0} %): not a plausible rod",
            100.0 * top / ea,
            100.0 * MAX_AXIAL_STRAIN
        ));
    }
    if free.contains(&1) && ga < MIN_GA_SHARE_OF_EA * ea {
        flags.push(format!(
            "GA = {ga:.3e} N ran toward 0 (below {:.0} % of EA): shear is probably not identifiable here; hold it (--fix GA=VALUE)",
            100.0 * MIN_GA_SHARE_OF_EA
        ));
    }
    for &k in free {
        let (lo, hi) = bounds[k];
        if k < 3 && (x[k] - lo < 1e-6 || hi - x[k] < 1e-6) {
            flags.push(format!("{} = {:.4e} is at the bound of the search (1e3 × its start either way)", parameters[k].name, parameters[k].value));
        }
    }
    for (i, e) in effects.iter().enumerate() {
        let v = parameters[3 + i].value;
        if !e.plausible(v) {
            flags.push(format!("{} = {v:.4e} is outside the plausible range {}", e.parameter_name(), e.plausible_text()));
        }
    }
    let implausible = !flags.is_empty();
    for &k in free {
        if !parameters[k].se.is_finite() {
            flags.push(format!("{} is not determined by these data (no finite standard error)", parameters[k].name));
        }
    }
    (flags, implausible)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::synth::{default_routings, synthesize, SynthSpec};

    fn truth() -> Rod {
        Rod { ea_n: 30.0, ga_n: 1.5, ei_n_mm2: 100.0, ..Rod::default() }
    }

    #[test]
    fn recovers_the_rigidities_from_noise_free_data() {
        let spec = SynthSpec {
            actuator: truth(),
            noise_mm: 0.0,
            noise_deg: 0.0,
            routings: default_routings()[..3].to_vec(),
            load_steps: 4,
            ..SynthSpec::default()
        };
        let (data, _) = synthesize(&spec, 0).unwrap();
        let t0 = std::time::Instant::now();
        let mut seen = Vec::new();
        let result = fit_observed(&Rod::default(), &SolverOptions::default(), &data, &data.groups(), &FitSpec::default(), &mut |p| {
            seen.push(p)
        })
        .unwrap();
        eprintln!("noise-free fit: {:?}, {} iterations", t0.elapsed(), result.iterations);
        assert!(result.converged);
        // Progress: one report per accepted step, iterations rising, RMS falling.
        assert!(!seen.is_empty() && seen.len() <= result.iterations);
        assert!(seen.windows(2).all(|w| w[0].iteration < w[1].iteration && w[0].rms_mm >= w[1].rms_mm));
        let t = truth();
        for (p, want) in result.parameters.iter().zip([t.ea_n, t.ga_n, t.ei_n_mm2]) {
            assert!(((p.value - want) / want).abs() < 1e-6, "{}: {} vs {want}", p.name, p.value);
        }
        assert!(result.rms_mm < 1e-6, "{}", result.rms_mm);
    }

    #[test]
    fn a_jacobian_step_the_model_cannot_solve_does_not_abort_the_fit() {
        // A straight, centred channel without gravity: v1 = 1 − τ/EA along
        // the whole rod, so the rod collapses exactly when EA ≤ τ. Starting
        // EA just above the top tension puts the Jacobian's minus step past
        // the collapse; the fit must fall back to a one-sided difference.
        let mut t = truth();
        t.gravity.enabled = false;
        let spec = SynthSpec {
            actuator: t.clone(),
            noise_mm: 0.0,
            noise_deg: 0.0,
            routings: vec![("z".into(), [0.0; 5])],
            load_steps: 2,
            max_tension_n: 2.0,
            ..SynthSpec::default()
        };
        let (data, _) = synthesize(&spec, 0).unwrap();
        let mut start = t.clone();
        start.ea_n = 2.0 * (1.0 + 5e-7);
        // GA and EI do nothing on a straight, unbent rod: hold them.
        let fs = FitSpec { fixed_rigidities: [false, true, true], ..FitSpec::default() };
        let r = fit(&start, &SolverOptions::default(), &data, &data.groups(), &fs).unwrap();
        assert!(r.converged, "{:?}", r.flags);
        assert!((r.parameters[0].value - 30.0).abs() < 1e-6 * 30.0, "{:?}", r.parameters[0]);
        assert!(r.parameters[1].fixed && r.parameters[1].se == 0.0 && r.parameters[1].value == t.ga_n);
    }

    #[test]
    fn centreline_distances_and_markers_follow_the_geometry() {
        // A straight centreline along +x from the clamp to 65 mm, frame angle 0.
        let mut a = Rod::default();
        a.gravity.enabled = false;
        let mut sim = crate::solver::Simulator::new(&a, &SolverOptions::default()).unwrap();
        sim.set_routing_mm(&[0.0; 5]).unwrap();
        sim.solve(0.0).unwrap();
        let template = sim.centreline()[0];
        let line: Vec<CentrelinePoint> =
            (0..=13).map(|k| 5.0 * k as f64).map(|s| CentrelinePoint { s_mm: s, x_mm: s, y_mm: 0.0, frame_angle_rad: 0.0, ..template }).collect();
        assert!((signed_distance_to_centreline([10.0, 2.0], &line) - 2.0).abs() < 1e-12);
        assert!((signed_distance_to_centreline([12.5, -1.5], &line) + 1.5).abs() < 1e-12);
        // Past the tip the last segment is extended: only the side distance counts.
        let (d, s) = closest_on_centreline([70.0, -1.0], &line);
        assert!((d + 1.0).abs() < 1e-12 && (s - 65.0).abs() < 1e-12, "{d} {s}");
        let m = simulated_marker(&Marker { s_mm: 32.5, offset_mm: 5.0, x_mm: 0.0, y_mm: 0.0 }, &line);
        assert!((m[0] - 32.5).abs() < 1e-12 && (m[1] - 5.0).abs() < 1e-12, "{m:?}");
        // Turned by a quarter turn, the offset points along −x.
        let turned: Vec<CentrelinePoint> = line.iter().map(|p| CentrelinePoint { x_mm: 0.0, y_mm: p.s_mm, frame_angle_rad: std::f64::consts::FRAC_PI_2, ..*p }).collect();
        let m = simulated_marker(&Marker { s_mm: 20.0, offset_mm: 5.0, x_mm: 0.0, y_mm: 0.0 }, &turned);
        assert!((m[0] + 5.0).abs() < 1e-12 && (m[1] - 20.0).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn huber_keeps_small_residuals_and_tames_large_ones() {
        let l = Loss::Huber { k: 3.0 };
        assert_eq!(l.transform(2.0), 2.0);
        assert!((l.transform(-50.0).powi(2) - (2.0 * 3.0 * 50.0 - 9.0)).abs() < 1e-9);
        assert!(l.transform(-50.0) < 0.0);
        assert_eq!(max_outliers(44), 3);
        assert_eq!(max_outliers(10), 2);
    }

    #[test]
    fn noisy_fit_lands_within_its_uncertainty() {
        let t = truth();
        for seed in 1..=3 {
            let spec = SynthSpec { actuator: t.clone(), seed, routings: default_routings()[..4].to_vec(), ..SynthSpec::default() };
            let (data, _) = synthesize(&spec, 0).unwrap();
            let r = fit(&Rod::default(), &SolverOptions::default(), &data, &data.groups(), &FitSpec::default()).unwrap();
            for (p, want) in r.parameters.iter().zip([t.ea_n, t.ga_n, t.ei_n_mm2]) {
                assert!(p.se > 0.0 && p.se.is_finite());
                // 3.5 standard errors: a failure here is a real error, not bad luck (p < 5e-4).
                assert!((p.value - want).abs() < 3.5 * p.se, "seed {seed} {}: {} ± {} vs {want}", p.name, p.value, p.se);
            }
            // The noise is 0.4 mm on x, y and 1° (1 mm) on θ: RMS ≈ sqrt((0.16+0.16+1)/3).
            assert!((0.5..0.8).contains(&r.rms_mm), "{}", r.rms_mm);
            for row in &r.correlation {
                assert!(row.iter().all(|c| c.abs() <= 1.0 + 1e-9));
            }
        }
    }
}
