//! Synthetic measurements from the model, with a hidden effect and noise:
//! how users and tests get data in which an effect is known to be hidden.
//!
//! Protocol per routing (model-notes §6): rest; load in equal steps to the
//! top tension; unload in the same steps; rest again. Each step is held for
//! the step dwell, the two rest states for the rest dwell.


pub mod captures;

use crate::model::ControlPoints;
use crate::calibrate::data::{CentrelinePoints, Dataset, Direction, Marker, MarkerPoints, Measurement, RoutingGroup};
use crate::calibrate::predict::predict_group;
use crate::calibrate::rng::Rng;
use crate::calibrate::{CalibrateError, InvalidRequest};
use crate::model::routing::CONTROL_POINTS;
use crate::model::{Rod, Segment};
use crate::solver::SolverOptions;
use crate::calibrate::Effect;

/// Effects `synth` can hide that are deliberately not diagnosis candidates
/// (nor registry entries), so that tests can check the diagnosis answers
/// `unexplained` for them.
pub const OUT_OF_LIBRARY: [&str; 2] = ["rest_curvature", "glue_joint"];

/// Every effect `synth --effect` hides besides `none`: the calibration
/// candidates (the registry's fittable entries), then [`OUT_OF_LIBRARY`].
pub fn effect_names() -> Vec<&'static str> {
    Effect::ALL.iter().map(|e| e.name()).chain(OUT_OF_LIBRARY).collect()
}

/// The effect hidden in synthetic data (planar readings and 3-D captures
/// alike): the data's model, which the fit does not know of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HiddenEffect {
    /// The thesis model.
    None,
    /// A calibration candidate at a value of its parameter.
    Candidate {
        /// The effect.
        effect: Effect,
        /// Its parameter's value ([`Effect::parameter_name`]).
        magnitude: f64,
    },
    /// A rod cured bent (outside the library: no candidate names it).
    RestCurvature {
        /// The rest curvature, 1/mm.
        per_mm: f64,
    },
    /// A stiff glue joint at the clamp (outside the library).
    GlueJoint {
        /// The joint's bending-rigidity factor.
        ei_factor: f64,
        /// Its length from the clamp, mm.
        length_mm: f64,
    },
}

/// Why the effect to hide was not understood.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HiddenEffectError {
    /// No effect of that name.
    #[error("--effect {name}: unknown effect; use none or one of {}", effect_names().join(", "))]
    Unknown {
        /// The name given.
        name: String,
    },
    /// An effect without its size.
    #[error("--effect {name} needs --magnitude ({})", .size.describe())]
    NoMagnitude {
        /// The effect.
        name: String,
        /// What the magnitude is.
        size: MagnitudeOf,
    },
    /// A size without an effect.
    #[error("--magnitude needs --effect")]
    NoEffect,
}

/// What an effect's magnitude measures (for the message asking for it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MagnitudeOf {
    /// A candidate's parameter.
    Parameter(Effect),
    /// A rest curvature.
    RestCurvature,
    /// A glue joint's EI factor.
    GlueJoint,
}

impl MagnitudeOf {
    fn describe(self) -> String {
        match self {
            MagnitudeOf::Parameter(e) => format!("its parameter {}", e.parameter_name()),
            MagnitudeOf::RestCurvature => "the rest curvature in 1/mm, e.g. 0.004".into(),
            MagnitudeOf::GlueJoint => "the joint's EI factor, e.g. 5".into(),
        }
    }
}

impl HiddenEffect {
    /// The effect named `name` (`none`, a candidate or one of
    /// [`OUT_OF_LIBRARY`]) of size `magnitude`; a glue joint is
    /// `glue_length_mm` long.
    pub fn parse(name: &str, magnitude: Option<f64>, glue_length_mm: f64) -> Result<HiddenEffect, HiddenEffectError> {
        let needs = |size: MagnitudeOf| HiddenEffectError::NoMagnitude { name: name.to_string(), size };
        match name {
            "none" => magnitude.map_or(Ok(HiddenEffect::None), |_| Err(HiddenEffectError::NoEffect)),
            "rest_curvature" => {
                let per_mm = magnitude.ok_or_else(|| needs(MagnitudeOf::RestCurvature))?;
                Ok(HiddenEffect::RestCurvature { per_mm })
            }
            "glue_joint" => {
                let ei_factor = magnitude.ok_or_else(|| needs(MagnitudeOf::GlueJoint))?;
                Ok(HiddenEffect::GlueJoint { ei_factor, length_mm: glue_length_mm })
            }
            _ => {
                let effect = Effect::parse(name).ok_or_else(|| HiddenEffectError::Unknown { name: name.to_string() })?;
                let magnitude = magnitude.ok_or_else(|| needs(MagnitudeOf::Parameter(effect)))?;
                Ok(HiddenEffect::Candidate { effect, magnitude })
            }
        }
    }

    /// Its name, as `--effect` takes it.
    pub fn name(&self) -> &'static str {
        match self {
            HiddenEffect::None => "none",
            HiddenEffect::Candidate { effect, .. } => effect.name(),
            HiddenEffect::RestCurvature { .. } => OUT_OF_LIBRARY[0],
            HiddenEffect::GlueJoint { .. } => OUT_OF_LIBRARY[1],
        }
    }

    /// Its parameter, as `--magnitude` takes it; `None` for no effect.
    pub fn magnitude(&self) -> Option<f64> {
        match *self {
            HiddenEffect::None => None,
            HiddenEffect::Candidate { magnitude, .. } => Some(magnitude),
            HiddenEffect::RestCurvature { per_mm } => Some(per_mm),
            HiddenEffect::GlueJoint { ei_factor, .. } => Some(ei_factor),
        }
    }

    /// Hides the effect in `rod`. The ones outside the library are built
    /// into the body: a rest curvature, or a segment of stiffer material
    /// at the clamp. The measurement file's header takes the geometry of
    /// the rod without the effect, so that no file carries them.
    pub fn plant(&self, rod: &mut Rod) {
        match *self {
            HiddenEffect::None => {}
            HiddenEffect::Candidate { effect, magnitude } => effect.apply(rod, magnitude),
            HiddenEffect::RestCurvature { per_mm } => rod.rest_curvature_per_mm = per_mm,
            HiddenEffect::GlueJoint { ei_factor, length_mm } => stiffen_base(rod, ei_factor, length_mm),
        }
    }

    /// `rod` with the effect in it ([`HiddenEffect::plant`]).
    pub fn apply(&self, rod: &Rod) -> Rod {
        let mut with = rod.clone();
        self.plant(&mut with);
        with
    }
}

/// Makes the bending rigidity of `rod` `ei_factor` times stiffer over
/// [0, `length_mm`] (a glue joint at the clamp): its segments there take
/// the factor, the segment across `length_mm` is split there.
fn stiffen_base(rod: &mut Rod, ei_factor: f64, length_mm: f64) {
    let whole = Segment { end_mm: rod.length_mm, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None };
    let mut segments = if rod.segments.is_empty() { vec![whole] } else { rod.segments.clone() };
    if let Some(k) = segments.iter().position(|g| g.end_mm > length_mm) {
        if length_mm > 0.0 && (k == 0 || segments[k - 1].end_mm < length_mm) {
            let first = Segment { end_mm: length_mm, ..segments[k].clone() };
            segments.insert(k, first);
        }
    }
    for g in segments.iter_mut().filter(|g| g.end_mm <= length_mm) {
        g.ei_n_mm2 = Some(g.ei_n_mm2.unwrap_or(rod.ei_n_mm2) * ei_factor);
    }
    rod.segments = segments;
}

/// What to generate.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthSpec {
    /// The true actuator, hidden effects included.
    pub actuator: Rod,
    /// Solver settings.
    pub options: SolverOptions,
    /// Routings: (id, y0..y4 in mm).
    pub routings: Vec<(String, [f64; CONTROL_POINTS])>,
    /// Top tension τ_u, N.
    pub max_tension_n: f64,
    /// Loading steps from rest to τ_u (the unloading uses the same levels).
    pub load_steps: usize,
    /// Dwell before each loaded reading, s.
    pub step_dwell_s: f64,
    /// Dwell before each rest reading, s.
    pub rest_dwell_s: f64,
    /// Clamp axis from the vertical, rad.
    pub clamp_tilt_rad: f64,
    /// Per-routing clamp tilt overriding `clamp_tilt_rad`, rad (routing id →
    /// tilt): a tilted repeat is how gravity is told apart from other effects.
    pub routing_tilts_rad: std::collections::BTreeMap<String, f64>,
    /// Standard deviation of the noise on tip x and y, mm.
    pub noise_mm: f64,
    /// Standard deviation of the noise on the tip angle, degrees.
    pub noise_deg: f64,
    /// Noise seed.
    pub seed: u64,
    /// Markers on every reading: (rest arc length s, lateral body-frame
    /// offset), mm. Their noise is `noise_mm` per axis, from a stream of
    /// its own so that adding markers leaves the other data unchanged.
    pub markers: Vec<(f64, f64)>,
}

/// Default routings: one with y_c(0) ≠ 0, an S-curve, a straight one, one
/// with y_c(0) = 0 and an arc (a good held-out routing).
pub fn default_routings() -> Vec<(String, [f64; CONTROL_POINTS])> {
    vec![
        ("base_offset".into(), [3.0, 2.5, 2.0, 1.5, 1.0]),
        ("s_curve".into(), [-2.0, -3.0, 0.0, 3.0, 3.5]),
        ("straight".into(), [2.0; 5]),
        ("tip_bend".into(), [0.0, 0.5, 1.5, 3.0, 4.0]),
        ("arc".into(), [1.5, 3.0, 2.5, 2.0, 3.0]),
    ]
}

impl Default for SynthSpec {
    fn default() -> Self {
        Self {
            actuator: Rod::default(),
            options: SolverOptions::default(),
            routings: default_routings(),
            max_tension_n: 2.0,
            load_steps: 5,
            step_dwell_s: 5.0,
            rest_dwell_s: 30.0,
            clamp_tilt_rad: 0.0,
            routing_tilts_rad: Default::default(),
            noise_mm: 0.4,
            noise_deg: 1.0,
            seed: 1,
            markers: Vec::new(),
        }
    }
}

/// The protocol of one routing: (tension N, direction, dwell s) in order.
pub fn protocol(spec: &SynthSpec) -> Vec<(f64, Direction, f64)> {
    let n = spec.load_steps;
    let level = |k: usize| spec.max_tension_n * k as f64 / n as f64;
    let mut steps = vec![(0.0, Direction::Rest, spec.rest_dwell_s)];
    steps.extend((1..=n).map(|k| (level(k), Direction::Load, spec.step_dwell_s)));
    steps.extend((1..n).rev().map(|k| (level(k), Direction::Unload, spec.step_dwell_s)));
    steps.push((0.0, Direction::Rest, spec.rest_dwell_s));
    steps
}

/// Most load steps of a synthetic protocol.
pub const MAX_LOAD_STEPS: usize = 1000;
/// Most centreline points per synthetic reading.
pub const MAX_CENTRELINE_POINTS: usize = 10_000;

/// Generates the measurements (and noisy centreline points of every
/// reading, `points` per reading, when `points > 0`).
pub fn synthesize(spec: &SynthSpec, points: usize) -> Result<(Dataset, CentrelinePoints), CalibrateError> {
    synthesize_with_markers(spec, points).map(|(d, c, _)| (d, c))
}

/// [`synthesize`], and the markers of `spec.markers` on every reading.
pub fn synthesize_with_markers(spec: &SynthSpec, points: usize) -> Result<(Dataset, CentrelinePoints, MarkerPoints), CalibrateError> {
    for &(s_mm, offset_mm) in &spec.markers {
        if !(s_mm.is_finite() && offset_mm.is_finite() && (0.0..=spec.actuator.length_mm).contains(&s_mm)) {
            return Err(InvalidRequest::MarkerOffRod { s_mm, offset_mm, length_mm: spec.actuator.length_mm }.into());
        }
    }
    if !(spec.max_tension_n.is_finite() && spec.max_tension_n > 0.0) || spec.load_steps == 0 {
        return Err(InvalidRequest::Protocol { max_tension_n: spec.max_tension_n, load_steps: spec.load_steps }.into());
    }
    for (name, v) in [("noise_mm", spec.noise_mm), ("noise_deg", spec.noise_deg), ("step_dwell_s", spec.step_dwell_s), ("rest_dwell_s", spec.rest_dwell_s)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(InvalidRequest::Negative { name, value: v }.into());
        }
    }
    if spec.routings.is_empty() {
        return Err(InvalidRequest::NoRoutings.into());
    }
    // Sizes are checked up front: a typo like 1000000 steps would otherwise
    // run for hours (every step is a chain of solves) before writing anything.
    if spec.load_steps > MAX_LOAD_STEPS {
        return Err(InvalidRequest::TooManyLoadSteps { load_steps: spec.load_steps, max: MAX_LOAD_STEPS }.into());
    }
    if points > MAX_CENTRELINE_POINTS {
        return Err(InvalidRequest::TooManyCentrelinePoints { points, max: MAX_CENTRELINE_POINTS }.into());
    }
    spec.actuator.validate()?;
    // Noise-free rows first (the measured fields are filled below).
    let mut data = protocol_rows(spec)?;
    let mut rng = Rng::new(spec.seed);
    let mut marker_rng = Rng::new(spec.seed ^ 0x6d61_726b_6572);
    let mut centrelines = CentrelinePoints::new();
    let mut markers = MarkerPoints::new();
    let groups: Vec<RoutingGroup> = data.groups();
    for g in &groups {
        let preds = predict_group(&spec.actuator, &spec.options, &data, g, points > 0 || !spec.markers.is_empty())?;
        for (&i, p) in g.rows.iter().zip(preds) {
            let m = &mut data.rows[i];
            m.tip_x_mm = p.pose.tip_x_mm + spec.noise_mm * rng.normal();
            m.tip_y_mm = p.pose.tip_y_mm + spec.noise_mm * rng.normal();
            m.tip_angle_rad = p.pose.tip_angle_rad + spec.noise_deg.to_radians() * rng.normal();
            if let Some(line) = p.centreline {
                if points > 0 {
                    let pts = resample(&line.iter().map(|c| [c.x_mm, c.y_mm]).collect::<Vec<_>>(), points);
                    let noisy = pts.into_iter().map(|[x, y]| [x + spec.noise_mm * rng.normal(), y + spec.noise_mm * rng.normal()]);
                    centrelines.insert(m.measurement, noisy.collect());
                }
                if !spec.markers.is_empty() {
                    let on_body = spec.markers.iter().map(|&(s_mm, offset_mm)| {
                        let exact = crate::calibrate::observations::measurements::simulated_marker(&Marker { s_mm, offset_mm, x_mm: 0.0, y_mm: 0.0 }, &line);
                        Marker {
                            s_mm,
                            offset_mm,
                            x_mm: exact[0] + spec.noise_mm * marker_rng.normal(),
                            y_mm: exact[1] + spec.noise_mm * marker_rng.normal(),
                        }
                    });
                    markers.insert(m.measurement, on_body.collect());
                }
            }
        }
    }
    Ok((data, centrelines, markers))
}

/// The protocol's readings of every routing with the measured fields
/// still zero: what [`synthesize_with_markers`] fills with noisy model
/// values and [`hidden_effect_size`] predicts twice.
fn protocol_rows(spec: &SynthSpec) -> Result<Dataset, CalibrateError> {
    let steps = protocol(spec);
    let mut data = Dataset::default();
    for (id, y) in &spec.routings {
        let clamp_tilt_rad = spec.routing_tilts_rad.get(id).copied().unwrap_or(spec.clamp_tilt_rad);
        if !clamp_tilt_rad.is_finite() {
            return Err(InvalidRequest::ClampTilt { routing: id.clone(), tilt_rad: clamp_tilt_rad }.into());
        }
        for (k, &(tension_n, direction, dwell_s)) in steps.iter().enumerate() {
            let measurement = data.rows.len() as i64 + 1;
            data.rows.push(Measurement {
                measurement,
                routing: id.clone(),
                routing_mm: ControlPoints(*y),
                tension_n,
                direction,
                step: k as i64,
                dwell_s,
                tip_x_mm: 0.0,
                tip_y_mm: 0.0,
                tip_angle_rad: 0.0,
                clamp_tilt_rad,
                noise_mm: None,
                noise_deg: None,
                row: measurement as usize,
            });
        }
    }
    Ok(data)
}

/// How far a hidden effect moves the simulated, noise-free readings: the
/// largest change of tip position and of tip angle over the protocol.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectSize {
    /// Largest change of tip x or of tip y between the two models, mm (per
    /// coordinate, as the noise `noise_mm` is).
    pub max_tip_shift_mm: f64,
    /// Largest tip angle change between the two models, degrees.
    pub max_angle_shift_deg: f64,
}

/// An effect is taken as visible in the data when some reading moves by at
/// least this many noise standard deviations.
pub const VISIBLE_NOISE_SDS: f64 = 2.0;

impl EffectSize {
    /// Whether no reading moves by [`VISIBLE_NOISE_SDS`] noise standard
    /// deviations, in position or in angle: the noise then hides the effect
    /// and a diagnosis will rightly answer `none`.
    pub fn hidden_by_noise(&self, noise_mm: f64, noise_deg: f64) -> bool {
        self.max_tip_shift_mm < VISIBLE_NOISE_SDS * noise_mm && self.max_angle_shift_deg < VISIBLE_NOISE_SDS * noise_deg
    }
}

/// The size of the effect hidden in `spec.actuator`: its noise-free readings
/// against those of `without` (the same actuator without the effect) on the
/// same protocol.
pub fn hidden_effect_size(spec: &SynthSpec, without: &Rod) -> Result<EffectSize, CalibrateError> {
    let data = protocol_rows(spec)?;
    let mut size = EffectSize { max_tip_shift_mm: 0.0, max_angle_shift_deg: 0.0 };
    for g in &data.groups() {
        let with_effect = predict_group(&spec.actuator, &spec.options, &data, g, false)?;
        let plain = predict_group(without, &spec.options, &data, g, false)?;
        for (a, b) in with_effect.iter().zip(&plain) {
            let shift = (a.pose.tip_x_mm - b.pose.tip_x_mm).abs().max((a.pose.tip_y_mm - b.pose.tip_y_mm).abs());
            size.max_tip_shift_mm = size.max_tip_shift_mm.max(shift);
            size.max_angle_shift_deg = size.max_angle_shift_deg.max((a.pose.tip_angle_rad - b.pose.tip_angle_rad).abs().to_degrees());
        }
    }
    Ok(size)
}


/// `count` points at equal index spacing along a polyline (clamp and tip included).
pub fn resample(line: &[[f64; 2]], count: usize) -> Vec<[f64; 2]> {
    if count < 2 || line.len() < 2 {
        return line.iter().take(count).copied().collect();
    }
    (0..count)
        .map(|k| {
            let t = k as f64 * (line.len() - 1) as f64 / (count - 1) as f64;
            let i = (t.floor() as usize).min(line.len() - 2);
            let f = t - i as f64;
            [line[i][0] * (1.0 - f) + line[i + 1][0] * f, line[i][1] * (1.0 - f) + line[i + 1][1] * f]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_candidate_and_unmodelled_effect_can_be_planted() {
        for name in effect_names() {
            let planted = HiddenEffect::parse(name, Some(0.3), 5.0).unwrap();
            let mut rod = Rod::default();
            planted.plant(&mut rod);
            assert_ne!(rod, Rod::default(), "{name} changes the rod");
            assert!(HiddenEffect::parse(name, None, 5.0).unwrap_err().to_string().contains("needs --magnitude"));
        }
        assert_eq!(HiddenEffect::parse("none", None, 5.0).unwrap(), HiddenEffect::None);
        assert!(HiddenEffect::parse("bogus", Some(1.0), 5.0).unwrap_err().to_string().contains("stiffness_gradient, rest_curvature, glue_joint"));
    }

    #[test]
    fn protocol_rests_loads_unloads_and_rests() {
        let spec = SynthSpec { load_steps: 3, ..SynthSpec::default() };
        let p = protocol(&spec);
        let dirs: Vec<_> = p.iter().map(|s| s.1).collect();
        use Direction::*;
        assert_eq!(dirs, vec![Rest, Load, Load, Load, Unload, Unload, Rest]);
        assert!((p[3].0 - 2.0).abs() < 1e-15 && p[4].0 < p[3].0);
    }

    #[test]
    fn noise_free_data_is_the_model_and_noise_has_its_size() {
        let clean = SynthSpec { noise_mm: 0.0, noise_deg: 0.0, routings: default_routings()[..2].to_vec(), ..SynthSpec::default() };
        let (d0, _) = synthesize(&clean, 0).unwrap();
        let noisy = SynthSpec { noise_mm: 0.4, noise_deg: 1.0, ..clean.clone() };
        let (d1, _) = synthesize(&noisy, 0).unwrap();
        let dx: Vec<f64> = d0.rows.iter().zip(&d1.rows).map(|(a, b)| b.tip_x_mm - a.tip_x_mm).collect();
        let rms = (dx.iter().map(|v| v * v).sum::<f64>() / dx.len() as f64).sqrt();
        assert!((0.2..0.7).contains(&rms), "{rms}");
        // Same seed, same data.
        assert_eq!(synthesize(&noisy, 0).unwrap().0, d1);
    }

    #[test]
    fn an_effect_below_the_noise_is_told_from_one_above_it() {
        let spec = |alpha: f64| {
            let mut actuator = Rod::default();
            actuator.effects.stiffening_alpha = alpha;
            SynthSpec { actuator, routings: default_routings()[..2].to_vec(), ..SynthSpec::default() }
        };
        let weak = hidden_effect_size(&spec(0.01), &Rod::default()).unwrap();
        assert!(weak.max_tip_shift_mm > 0.0 && weak.hidden_by_noise(0.4, 1.0), "{weak:?}");
        let strong = hidden_effect_size(&spec(30.0), &Rod::default()).unwrap();
        assert!(!strong.hidden_by_noise(0.4, 1.0), "{strong:?}");
        // The same effect shows once the noise is small enough.
        assert!(!weak.hidden_by_noise(weak.max_tip_shift_mm / 4.0, weak.max_angle_shift_deg / 4.0), "{weak:?}");
        assert_eq!(hidden_effect_size(&spec(0.0), &Rod::default()).unwrap().max_tip_shift_mm, 0.0);
    }
}
