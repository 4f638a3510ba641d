//! Planar measurement files as a fit's observations: tip readings of one
//! in-plane cable, with measured centreline points and markers.
//!
//! Every residual is simulated minus measured, divided by its noise (σ in mm
//! for tip x, y, centreline points and markers, σ in degrees for the tip
//! angle): tip x, y and angle of each reading; for each measured centreline
//! point, its signed distance to the closest point of the simulated
//! centreline; for each marker (a point at known rest arc length s and
//! lateral body-frame offset), its x and y.
//!
//! The rules: EA, GA, EI move a factor 1e3 either way in logs, an effect
//! within ±50 in its coordinate; differences by steps of 1e-6, then 1e-7
//! and 1e-8 (an O(h) = 1e-6 relative error in the coordinates is far below
//! what Levenberg–Marquardt's steps or the standard errors notice); a
//! column the model cannot difference at all is zero and reported; one
//! variance per kind of residual (tip x, y, angle, centreline, markers),
//! which are measured by different means.
//!
//! Adequacy: χ² of the whitened residuals over the readings that are not
//! flagged as outliers (|z| > [`OUTLIER_Z`] on some residual, at most
//! [`max_outliers`] readings), its degrees of freedom and the chance that
//! noise alone gives a χ² as large ([`stats::chi2_p_value`]).

use super::Observations;
use crate::calibrate::data::{CentrelinePoints, Dataset, Marker, MarkerPoints, Measurement, RoutingGroup};
use crate::calibrate::effect::Effect;
use crate::calibrate::fit::{fit, Adequacy, Covariance, EffectBounds, FailedColumn, FitReport, FitResult, FitRules, FitSpec, Fitted, FittedParameter, Status};
use crate::calibrate::predict::{predict, Prediction};
use crate::calibrate::stats;
use crate::calibrate::{CalibrateError, HeldError, InvalidRequest, NoiseError, Parameter};
use crate::model::{Actuator, Rod};
use crate::numerics::lm;
use crate::solver::{CentrelinePoint, SolverOptions};
use serde::ser::SerializeSeq;
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

/// How planar measurements are weighed: the noise of rows without their
/// own, the shapes measured besides the tips, and the angle's weight in
/// reported RMS values.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementSettings {
    /// Weight of the tip angle in the reported mm-equivalent RMS: mm per
    /// degree (the fit itself weights every residual by its noise).
    pub angle_weight_mm_per_deg: f64,
    /// Noise of rows that do not give their own.
    pub noise: Noise,
    /// Centreline points and markers.
    pub shapes: Arc<ShapeData>,
}

impl Default for MeasurementSettings {
    fn default() -> Self {
        Self { angle_weight_mm_per_deg: 1.0, noise: Noise::default(), shapes: Arc::new(ShapeData::default()) }
    }
}

/// The parameters of a planar fit: EA, GA, EI (those in `held` held at the
/// start's values), then `effects`.
pub fn planar_spec(effects: &[Effect], held: [bool; 3], loss: crate::calibrate::fit::Loss, max_iterations: usize) -> FitSpec {
    let rigidities = [Parameter::Ea, Parameter::Ga, Parameter::Ei];
    let mut params = rigidities.to_vec();
    params.extend(effects.iter().map(|&e| Parameter::Effect(e)));
    let held = rigidities.iter().zip(held).filter(|(_, h)| *h).map(|(p, _)| *p).collect();
    FitSpec { params, held, loss, max_iterations }
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

/// What a fit to planar measurements reports besides the common fields.
#[derive(Debug, Clone, Serialize)]
pub struct MeasurementsReport {
    /// Effects that were fitted.
    pub effects: Vec<Effect>,
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
    /// Predictions at the optimum, indexed like the data's rows.
    #[serde(skip)]
    pub predictions: Vec<Option<Prediction>>,
}

/// A parameter as a planar fit writes it.
#[derive(Serialize)]
struct ParameterJson<'a> {
    name: &'a str,
    value: f64,
    se: f64,
    fixed: bool,
}

impl FitReport for MeasurementsReport {
    fn serialize_parameters<S: serde::Serializer>(parameters: &[FittedParameter], serializer: S) -> Result<S::Ok, S::Error> {
        let mut seq = serializer.serialize_seq(Some(parameters.len()))?;
        for p in parameters {
            seq.serialize_element(&ParameterJson { name: &p.name, value: p.value, se: p.se, fixed: p.status == Status::Held })?;
        }
        seq.end()
    }
}

impl FitResult<MeasurementsReport> {
    /// The fitted value and SE of `effect`, if it was fitted.
    pub fn effect_parameter(&self, effect: Effect) -> Option<&FittedParameter> {
        self.parameter(Parameter::Effect(effect))
    }

    /// The fitted rod.
    pub fn rod(&self) -> &Rod {
        &self.actuator.rod
    }
}

/// The fit's rules for planar measurements.
pub const RULES: FitRules = FitRules {
    steps: &[1e-6, 1e-7, 1e-8],
    failed_column: FailedColumn::Zero,
    body_factor: 1e3,
    effect_bounds: EffectBounds::Symmetric(50.0),
    enough_reduction: None,
    hold_undetermined: false,
    covariance: Covariance::ByChannel,
};

/// Planar measurements: the rows of some routing groups of a data set,
/// how they are weighed and the planar solver's settings.
#[derive(Debug, Clone)]
pub struct Measurements<'a> {
    /// The planar solver's settings.
    pub options: &'a SolverOptions,
    /// The data set.
    pub data: &'a Dataset,
    /// The routings fitted.
    pub groups: &'a [RoutingGroup],
    /// Noise, shapes and the angle's weight.
    pub settings: &'a MeasurementSettings,
    slots: Vec<Slot>,
}

impl<'a> Measurements<'a> {
    /// The observations of `groups`' rows of `data`.
    pub fn new(options: &'a SolverOptions, data: &'a Dataset, groups: &'a [RoutingGroup], settings: &'a MeasurementSettings) -> Self {
        let slots = layout(data, groups, &settings.shapes);
        Self { options, data, groups, settings, slots }
    }
}

impl Observations for Measurements<'_> {
    type Solution = Vec<Option<Prediction>>;
    type Report = MeasurementsReport;

    fn rules(&self) -> FitRules {
        RULES
    }

    fn check(&self, base: &Actuator, _spec: &FitSpec) -> Result<(), CalibrateError> {
        let w = self.settings.angle_weight_mm_per_deg;
        if !(w.is_finite() && w >= 0.0) {
            return Err(InvalidRequest::AngleWeight { value: w }.into());
        }
        self.settings.noise.validate()?;
        base.rod.validate()?;
        check_tips_within_reach(self.data, &base.rod)
    }

    fn whitened(&self, actuator: &Actuator) -> Result<(Vec<f64>, Vec<Option<Prediction>>), CalibrateError> {
        let keep = !self.settings.shapes.is_empty();
        let preds = predict(&actuator.rod, self.options, self.data, self.groups, keep)?;
        let z = whitened(self.data, &self.slots, &preds, &self.settings.shapes, &self.settings.noise);
        Ok((z, preds))
    }

    fn check_start(&self, r: &[f64], fitted: usize) -> Result<(), CalibrateError> {
        let n = r.len();
        if n <= fitted {
            return Err(InvalidRequest::TooFewResiduals { residuals: n, readings: self.data.rows.len(), parameters: fitted }.into());
        }
        let cost: f64 = r.iter().map(|v| v * v).sum();
        // Residuals are in units of the noise (and the robust loss compresses
        // large ones): a trillion noise widths, or squares that overflow, is no
        // measurement of this actuator. No step can lower such a cost, and "no
        // step lowers the cost" must not read as a converged fit.
        const ABSURD_RESIDUAL: f64 = 1e12;
        let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !cost.is_finite() || !(worst < ABSURD_RESIDUAL) {
            let farthest = self.data.rows.iter().map(|m| m.tip_x_mm.abs().max(m.tip_y_mm.abs())).fold(0.0, f64::max);
            return Err(InvalidRequest::AbsurdResiduals { farthest_mm: farthest, worst_noise_widths: worst }.into());
        }
        Ok(())
    }

    fn channels(&self) -> Vec<usize> {
        self.slots.iter().map(|s| s.kind.channel()).collect()
    }

    fn adequacy(&self, z: &[f64], fitted: usize) -> Adequacy {
        let (chi2, dof, p_value, outliers) = chi_square(self.data, &self.slots, z, fitted);
        Adequacy { chi2, dof, p_value, outliers }
    }

    fn report(&self, fitted: &Fitted<'_>, predictions: Vec<Option<Prediction>>) -> MeasurementsReport {
        let effects: Vec<Effect> = fitted
            .parameters
            .iter()
            .filter_map(|p| match p.param {
                Parameter::Effect(e) => Some(e),
                _ => None,
            })
            .collect();
        let (mut flags, implausible) = plausibility_flags(self.data, self.groups, fitted.parameters, &effects, fitted.x, fitted.bounds, fitted.free);
        if !fitted.failed.is_empty() {
            let names: Vec<&str> = fitted.failed.iter().map(|&k| fitted.parameters[k].name.as_str()).collect();
            flags.push(format!("the model could not be solved near the optimum to differentiate by {}", names.join(", ")));
        }
        let w = self.settings.angle_weight_mm_per_deg;
        let tip = residuals(self.data, self.groups, &predictions, w);
        let rms_mm = (tip.iter().map(|v| v * v).sum::<f64>() / tip.len().max(1) as f64).sqrt();
        MeasurementsReport {
            per_routing: rms_per_routing(self.data, self.groups, &predictions, w),
            effects,
            outliers: fitted.outliers.clone(),
            flags,
            implausible,
            rms_mm,
            predictions,
        }
    }
}

/// Fits `spec` to the rows of `groups`, starting from `rod`'s values (an
/// effect switched off on `rod` starts from [`Effect::start`]); effects set
/// on `rod` but not fitted stay as they are. `observe` hears every accepted step.
#[allow(clippy::too_many_arguments)]
pub fn fit_measurements(
    rod: &Rod,
    options: &SolverOptions,
    data: &Dataset,
    groups: &[RoutingGroup],
    settings: &MeasurementSettings,
    spec: &FitSpec,
    observe: &mut dyn FnMut(lm::Step),
) -> Result<FitResult<MeasurementsReport>, CalibrateError> {
    let base = Actuator::with_cables(rod.clone(), Vec::new());
    fit(&base, &Measurements::new(options, data, groups, settings), spec, observe)
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
pub fn row_residual(m: &Measurement, p: &crate::solver::TipPose, angle_weight_mm_per_deg: f64) -> [f64; 3] {
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

impl FitProgress {
    /// The progress after an accepted step of the minimisation.
    pub fn of(step: lm::Step) -> Self {
        FitProgress { iteration: step.iteration, rms_mm: (step.cost / step.residuals as f64).sqrt() }
    }
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
    use crate::calibrate::fit::Loss;
    use crate::calibrate::synth::{default_routings, synthesize, SynthSpec};

    /// EA, GA, EI fitted, no effect: the thesis model.
    fn thesis_spec() -> FitSpec {
        planar_spec(&[], [false; 3], Loss::default(), 200)
    }

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
        let result = fit_measurements(&Rod::default(), &SolverOptions::default(), &data, &data.groups(), &MeasurementSettings::default(), &thesis_spec(), &mut |step| {
            seen.push(FitProgress::of(step))
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
        let fs = planar_spec(&[], [false, true, true], Loss::default(), 200);
        let r = fit_measurements(&start, &SolverOptions::default(), &data, &data.groups(), &MeasurementSettings::default(), &fs, &mut |_| {}).unwrap();
        assert!(r.converged, "{:?}", r.flags);
        assert!((r.parameters[0].value - 30.0).abs() < 1e-6 * 30.0, "{:?}", r.parameters[0]);
        assert!(r.parameters[1].status == Status::Held && r.parameters[1].se == 0.0 && r.parameters[1].value == t.ga_n);
    }

    #[test]
    fn centreline_distances_and_markers_follow_the_geometry() {
        // A straight centreline along +x from the clamp to 65 mm, frame angle 0.
        let mut a = Rod::default();
        a.gravity.enabled = false;
        let mut sim = crate::solver::Simulator::for_rod(&a, &SolverOptions::default()).unwrap();
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
    fn at_most_two_or_five_percent_of_the_readings_are_outliers() {
        assert_eq!(max_outliers(44), 3);
        assert_eq!(max_outliers(10), 2);
    }

    #[test]
    fn noisy_fit_lands_within_its_uncertainty() {
        let t = truth();
        for seed in 1..=3 {
            let spec = SynthSpec { actuator: t.clone(), seed, routings: default_routings()[..4].to_vec(), ..SynthSpec::default() };
            let (data, _) = synthesize(&spec, 0).unwrap();
            let r = fit_measurements(&Rod::default(), &SolverOptions::default(), &data, &data.groups(), &MeasurementSettings::default(), &thesis_spec(), &mut |_| {})
                .unwrap();
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

