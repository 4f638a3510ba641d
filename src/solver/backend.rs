//! The solver interface: which backend solves an [`Actuator`], what each
//! backend models, and the one check that refuses a request a backend
//! cannot serve ([`Backend::check`]).
//!
//! Three backends solve the same actuator (a rod with 1–8 cables):
//! - [`Backend::PlanarCollocation`], the fast path: spectral collocation of
//!   the planar cut equations (`collocation`), whenever every cable lies in
//!   one plane through the axis and gravity lies in it — today one cable
//!   with z ≡ 0 — with every effect, tapered and segmented bodies and anchors;
//! - [`Backend::PlanarRk4`], the planar reference: classical RK4 with
//!   shooting (`rk4`), the same model with the cable knotted at the tip;
//! - [`Backend::SpatialCollocation`], the 3-D solver (`crate::solver::spatial::collocation`):
//!   several cables, out-of-plane channels and gravity, spectral collocation
//!   with every effect, tapered and segmented bodies and anchors;
//! - [`Backend::SpatialRk4`], the 3-D reference: RK4 along s with Broyden on
//!   gravity's moment (`crate::solver::spatial::solver`), the thesis's uniform
//!   rod without effects (`--method rk4` with several or spatial cables).
//!
//! What a request needs is listed once ([`needs`]) and what a backend
//! models once ([`Backend::support`]); the check compares the two, so a
//! new feature or backend is one line in each.

use crate::model::effects::{EffectInfo, GRAVITY_DIRECTION, GRAVITY_SCALE, REGISTRY};
use crate::model::{Actuator, Cable, Rod};
use crate::solver::{Given, SolverMethod, SolverOptions};

/// A way to solve an actuator's statics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    /// Planar spectral collocation: one cable in the plane of gravity (the default).
    PlanarCollocation,
    /// Planar classical RK4 with shooting (`--method rk4`), the reference.
    PlanarRk4,
    /// The 3-D solver: several and out-of-plane cables, gravity in any
    /// direction, by spectral collocation (the default for such actuators).
    SpatialCollocation,
    /// The 3-D reference: RK4 along s (`--method rk4`), uniform rods without effects.
    SpatialRk4,
}

impl Backend {
    /// The backend's name in messages and docs.
    pub fn name(self) -> &'static str {
        match self {
            Backend::PlanarCollocation => "planar collocation",
            Backend::PlanarRk4 => "planar RK4",
            Backend::SpatialCollocation => "spatial",
            Backend::SpatialRk4 => "spatial RK4",
        }
    }
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One thing a request needs of its backend.
#[derive(Debug, Clone, Copy)]
enum Need {
    /// An effect away from its default: served where the registry says.
    SeveralCables,
    OutOfPlaneChannel,
    GravityOutOfPlane,
    NonUniformBody,
    AnchorBeforeTip,
    /// A cable driven by its displacement.
    Displacement,
    RodAnchor,
    Effect(&'static crate::model::effects::EffectInfo),
    Hold,
    ThesisCoefficients,
    Collocation,
    Rk4,
    NodesPerSpan,
    StepsPerSpan,
}

/// What a backend models: the features of [`needs`] it serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Support {
    /// More than one cable.
    pub several_cables: bool,
    /// A channel with z ≠ 0 (out of the x–y plane).
    pub out_of_plane_channels: bool,
    /// Gravity with a component out of the x–y plane.
    pub gravity_out_of_plane: bool,
    /// A tapered (radius_profile_mm) or segmented (segments) body.
    pub non_uniform_body: bool,
    /// A cable knotted before the tip.
    pub anchors: bool,
    /// The rod-level anchor `cable_anchor_mm` (the planar single cable's).
    pub rod_anchor: bool,
    /// Cables driven by their displacement (the solver integrates their paths).
    pub displacement: bool,
    /// A load direction and dwell of the final tension.
    pub hold: bool,
    /// The thesis's coefficient route (needs a planar centreline).
    pub thesis_coefficients: bool,
    /// The integration it is asked for by `method`.
    pub method: SolverMethod,
    /// Whether it reads `nodes_per_span` (collocation intervals).
    pub nodes_per_span: bool,
    /// Whether it reads `steps_per_span` (RK4 steps; collocation's centreline points).
    pub steps_per_span: bool,
    /// The effects of the registry it models.
    pub effects: EffectSupport,
}

/// Which effects of the registry ([`crate::model::effects`]) a backend models.
#[derive(Debug, Clone, Copy)]
pub enum EffectSupport {
    /// Every effect: each entry's term is in the backend.
    All,
    /// Only these (the thesis's rod: gravity's direction and scale).
    Only(&'static [&'static EffectInfo]),
}

impl PartialEq for EffectSupport {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (EffectSupport::All, EffectSupport::All) => true,
            (EffectSupport::Only(a), EffectSupport::Only(b)) => a.len() == b.len() && a.iter().zip(*b).all(|(x, y)| std::ptr::eq(*x, *y)),
            _ => false,
        }
    }
}

impl Eq for EffectSupport {}

/// The effects of the thesis's rod, which every backend models.
const THESIS_EFFECTS: &[&EffectInfo] = &[&GRAVITY_DIRECTION, &GRAVITY_SCALE];

impl Backend {
    /// Every backend, in the order a request is offered to them.
    pub const ALL: [Backend; 4] = [Backend::PlanarCollocation, Backend::PlanarRk4, Backend::SpatialCollocation, Backend::SpatialRk4];

    /// The planar backend of `method`.
    pub fn planar(method: SolverMethod) -> Backend {
        match method {
            SolverMethod::Collocation => Backend::PlanarCollocation,
            SolverMethod::Rk4 => Backend::PlanarRk4,
        }
    }

    /// The spatial backend of `method`.
    pub fn spatial(method: SolverMethod) -> Backend {
        match method {
            SolverMethod::Collocation => Backend::SpatialCollocation,
            SolverMethod::Rk4 => Backend::SpatialRk4,
        }
    }

    /// What this backend models.
    pub fn support(self) -> Support {
        let planar = Support {
            several_cables: false,
            out_of_plane_channels: false,
            gravity_out_of_plane: false,
            non_uniform_body: true,
            anchors: true,
            rod_anchor: true,
            displacement: true,
            hold: true,
            thesis_coefficients: true,
            method: SolverMethod::Collocation,
            nodes_per_span: true,
            steps_per_span: true,
            effects: EffectSupport::All,
        };
        match self {
            Backend::PlanarCollocation => planar,
            // RK4 integrates each knot span in equal steps from clamp to tip.
            Backend::PlanarRk4 => Support { anchors: false, displacement: false, method: SolverMethod::Rk4, nodes_per_span: false, ..planar },
            Backend::SpatialCollocation => Support {
                several_cables: true,
                out_of_plane_channels: true,
                gravity_out_of_plane: true,
                non_uniform_body: true,
                anchors: true,
                rod_anchor: false,
                displacement: true,
                hold: true,
                thesis_coefficients: false,
                method: SolverMethod::Collocation,
                nodes_per_span: true,
                // The centreline's points.
                steps_per_span: true,
                effects: EffectSupport::All,
            },
            Backend::SpatialRk4 => Support {
                several_cables: true,
                out_of_plane_channels: true,
                gravity_out_of_plane: true,
                non_uniform_body: false,
                anchors: true,
                rod_anchor: false,
                displacement: false,
                hold: false,
                thesis_coefficients: false,
                method: SolverMethod::Rk4,
                nodes_per_span: false,
                steps_per_span: true,
                effects: EffectSupport::Only(THESIS_EFFECTS),
            },
        }
    }

    /// Whether this backend models the registry's effect `info`.
    pub fn models(self, info: &EffectInfo) -> bool {
        match self.support().effects {
            EffectSupport::All => true,
            EffectSupport::Only(list) => list.iter().any(|e| std::ptr::eq(*e, info)),
        }
    }

    /// The first effect acting on `rod` that this backend does not model,
    /// `None` when it models all of them.
    pub fn unmodelled_effect(self, rod: &Rod) -> Option<&'static EffectInfo> {
        REGISTRY.iter().copied().find(|e| !self.models(e) && e.acts(rod))
    }

    /// Whether this backend serves `need`.
    fn serves(self, need: Need) -> bool {
        let s = self.support();
        match need {
            Need::SeveralCables => s.several_cables,
            Need::OutOfPlaneChannel => s.out_of_plane_channels,
            Need::GravityOutOfPlane => s.gravity_out_of_plane,
            Need::NonUniformBody => s.non_uniform_body,
            Need::AnchorBeforeTip => s.anchors,
            Need::RodAnchor => s.rod_anchor,
            Need::Displacement => s.displacement,
            Need::Effect(info) => self.models(info),
            Need::Hold => s.hold,
            Need::ThesisCoefficients => s.thesis_coefficients,
            Need::Collocation => s.method == SolverMethod::Collocation,
            Need::Rk4 => s.method == SolverMethod::Rk4,
            Need::NodesPerSpan => s.nodes_per_span,
            Need::StepsPerSpan => s.steps_per_span,
        }
    }

    /// The one check: `Ok` if this backend serves `actuator` with `options`
    /// (the settings in `given` asked for explicitly); otherwise what it does
    /// not model and which backend would serve the whole request, if any.
    pub fn check(self, actuator: &Actuator, options: &SolverOptions, given: Given) -> Result<(), Unsupported> {
        let request = Request { rod: &actuator.rod, cables: &actuator.cables, gravity_direction: actuator.gravity_direction };
        self.check_needs(&needs(request, options, given))
    }

    /// [`Backend::check`] of the planar backend of `options.method` for the
    /// planar solver's own input: `rod` with its one in-plane cable (the
    /// routing and tension do not matter to the check), without copying the rod.
    pub fn check_planar(rod: &Rod, options: &SolverOptions, given: Given) -> Result<(), Unsupported> {
        let one = [Cable::planar([0.0; 5], 0.0)];
        let request = Request { rod, cables: &one, gravity_direction: None };
        Backend::planar(options.method).check_needs(&needs(request, options, given))
    }

    /// `Ok` if this backend serves every one of `needs`; otherwise the first
    /// it does not, and which backend would serve them all, if any.
    fn check_needs(self, needs: &[(Need, String)]) -> Result<(), Unsupported> {
        let Some(&(need, ref what)) = needs.iter().find(|(need, _)| !self.serves(*need)) else {
            return Ok(());
        };
        let others = || Backend::ALL.into_iter().filter(move |b| *b != self);
        if let Some(b) = others().find(|b| needs.iter().all(|(n, _)| b.serves(*n))) {
            return Err(Unsupported { backend: self, what: what.clone(), served_by: Some(b), but_not: None });
        }
        // None serves it all: name the one that models this part, and what
        // else of the request it does not.
        let partial = others().find(|b| b.serves(need));
        let but_not = partial.and_then(|b| needs.iter().find(|(n, _)| !b.serves(*n)).map(|(_, w)| w.clone()));
        Err(Unsupported { backend: self, what: what.clone(), served_by: partial, but_not })
    }

    /// The backend that serves `actuator`: the planar backend of `options.method`
    /// when every cable lies in the x–y plane with gravity (the fast path),
    /// else the spatial one; refused by [`Backend::check`] if that one cannot.
    pub fn serving(actuator: &Actuator, options: &SolverOptions, given: Given) -> Result<Backend, Unsupported> {
        let backend = if is_planar(actuator) { Backend::planar(options.method) } else { Backend::spatial(options.method) };
        backend.check(actuator, options, given)?;
        Ok(backend)
    }

}

/// Whether `actuator` is planar: one cable with z ≡ 0 and gravity (if on) in
/// the x–y plane. (Several cables in one plane through the axis would be
/// planar too; the planar backends take one cable today.)
pub fn is_planar(actuator: &Actuator) -> bool {
    let gravity_in_plane = !actuator.rod.gravity.enabled || actuator.gravity_direction.is_none_or(|g| g[2] == 0.0);
    actuator.cables.len() == 1 && actuator.cables[0].is_planar() && gravity_in_plane
}

/// What the check reads of a request: the rod, the cables and the
/// direction of gravity (an [`Actuator`]'s, or the planar solver's rod with
/// its one in-plane cable).
#[derive(Clone, Copy)]
struct Request<'a> {
    rod: &'a Rod,
    cables: &'a [Cable],
    gravity_direction: Option<[f64; 3]>,
}

/// Everything `request` with `options` needs of a backend, each with the
/// words that name it in a refusal.
fn needs(request: Request<'_>, options: &SolverOptions, given: Given) -> Vec<(Need, String)> {
    let Request { rod, cables, gravity_direction } = request;
    let mut needs = Vec::new();
    let mut need = |n: Need, what: String| needs.push((n, what));
    if cables.len() > 1 {
        need(Need::SeveralCables, format!("{} cables (it takes one)", cables.len()));
    }
    if let Some(i) = cables.iter().position(|c| !c.is_planar()) {
        need(Need::OutOfPlaneChannel, format!("an out-of-plane channel (cable {}: z ≠ 0)", i + 1));
    }
    if rod.gravity.enabled && gravity_direction.is_some_and(|g| g[2] != 0.0) {
        need(Need::GravityOutOfPlane, "gravity out of the x–y plane (--gravity-direction with Z ≠ 0)".into());
    }
    if !rod.radius_profile_mm.is_empty() || !rod.segments.is_empty() {
        need(Need::NonUniformBody, "a tapered or segmented body (radius_profile_mm, segments): it models a uniform rod".into());
    }
    if let Some(i) = cables.iter().position(|c| c.is_displacement_driven()) {
        need(Need::Displacement, format!("a cable driven by its displacement (cable {}: displacement_mm; the RK4 methods do not integrate the cables' paths)", i + 1));
    }
    if rod.cable_anchor_mm.is_some() {
        need(Need::RodAnchor, "the rod-level cable_anchor_mm (--cable-anchor-mm): give each cable its own anchor (anchor=S)".into());
    }
    let length = rod.length_mm;
    let anchored = rod.cable_anchor_mm.is_some_and(|k| k < length) || cables.iter().any(|c| c.anchor_mm.is_some_and(|k| k < length));
    if anchored {
        need(Need::AnchorBeforeTip, "a cable anchored before the tip (it knots the cable at the tip only)".into());
    }
    for info in REGISTRY.iter().copied().filter(|info| info.acts(rod)) {
        need(Need::Effect(info), format!("effects.{} (leave it at its default)", info.key));
    }
    if given.hold {
        need(Need::Hold, "a load direction or dwell (--direction, --dwell-s)".into());
    }
    if given.thesis_coefficients {
        need(Need::ThesisCoefficients, "--coefficients thesis (the thesis's route from a planar centreline)".into());
    }
    if given.method {
        match options.method {
            SolverMethod::Collocation => need(Need::Collocation, "--method collocation".into()),
            SolverMethod::Rk4 => need(Need::Rk4, "--method rk4".into()),
        }
    }
    if given.nodes_per_span {
        need(Need::NodesPerSpan, "--nodes-per-span (collocation intervals; its resolution is --steps-per-span)".into());
    }
    if given.steps_per_span {
        need(Need::StepsPerSpan, "--steps-per-span".into());
    }
    needs
}

/// A request a backend cannot serve: what it does not model, and the
/// backend that would serve it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the {backend} solver does not model {what}; {}", advice(*served_by, but_not.as_deref()))]
pub struct Unsupported {
    /// The backend asked.
    pub backend: Backend,
    /// What it does not model, in the words of the flags and spec keys.
    pub what: String,
    /// The backend that serves the whole request; or, with `but_not`, the
    /// one that models `what` but not the rest; `None` if no backend models `what`.
    pub served_by: Option<Backend>,
    /// What of the request `served_by` does not model (`None`: it serves all).
    pub but_not: Option<String>,
}

/// The advice of an [`Unsupported`]: the backend to use, or why none serves.
fn advice(served_by: Option<Backend>, but_not: Option<&str>) -> String {
    let how = |b: Backend| match b {
        Backend::PlanarCollocation => "the planar collocation solver (the default --method collocation)",
        Backend::PlanarRk4 => "the planar rk4 solver (--method rk4)",
        Backend::SpatialCollocation => "the spatial (3-D) solver",
        Backend::SpatialRk4 => "the spatial rk4 solver (--method rk4 with several or spatial cables)",
    };
    match (served_by, but_not) {
        (Some(b), None) => format!("{} serves this request", how(b)),
        (Some(b), Some(rest)) => format!("{} models it, but not {rest}", how(b)),
        (None, _) => "no solver models it".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The planar solver's entry is the one check: a rod alone gets the
    /// answer an actuator of that rod and one in-plane cable gets.
    #[test]
    fn a_rod_is_checked_as_the_rod_with_its_one_planar_cable() {
        let tapered = Rod { radius_profile_mm: vec![(0.0, 5.0), (65.0, 4.0)], ..Rod::default() };
        let anchored = Rod { cable_anchor_mm: Some(40.0), ..Rod::default() };
        let mut rubbing = Rod::default();
        rubbing.effects.friction_mu = 0.2;
        let rk4 = SolverOptions { method: SolverMethod::Rk4, ..SolverOptions::default() };
        let nodes = Given { nodes_per_span: true, ..Given::default() };
        let mut refused = 0;
        for rod in [Rod::default(), tapered, anchored, rubbing] {
            for options in [SolverOptions::default(), rk4.clone()] {
                for given in [Given::default(), nodes] {
                    let actuator = Actuator::with_cables(rod.clone(), vec![Cable::planar([1.0, -2.0, 0.5, 0.0, 3.0], 1.5)]);
                    let whole = Backend::planar(options.method).check(&actuator, &options, given);
                    assert_eq!(Backend::check_planar(&rod, &options, given), whole);
                    refused += usize::from(whole.is_err());
                }
            }
        }
        assert!(refused > 0, "some of these the planar backends refuse");
    }

    #[test]
    fn the_spatial_rk4_reference_refuses_each_effect_and_a_qualifier_alone_does_not_act() {
        let mut a = Rod::default();
        assert!(Backend::ALL.iter().all(|b| b.unmodelled_effect(&a).is_none()));
        a.effects.creep_time_s = 3.0;
        a.effects.creep_hold_s = 5.0;
        assert!(Backend::SpatialRk4.unmodelled_effect(&a).is_none(), "creep's time and hold act only with a creep fraction");
        a.effects.creep_fraction = 0.2;
        assert_eq!(Backend::SpatialRk4.unmodelled_effect(&a).map(|e| e.key), Some("creep_fraction"));
        assert!(Backend::PlanarRk4.unmodelled_effect(&a).is_none());
        assert!(Backend::SpatialCollocation.unmodelled_effect(&a).is_none());
        let mut b = Rod::default();
        b.effects.clamp_stiffness_n_mm_per_rad = Some(40.0);
        assert_eq!(Backend::SpatialRk4.unmodelled_effect(&b).map(|e| e.key), Some("clamp_stiffness_n_mm_per_rad"));
        assert!(Backend::SpatialCollocation.unmodelled_effect(&b).is_none());
        b = Rod::default();
        b.gravity.scale = 2.0;
        assert!(Backend::SpatialRk4.unmodelled_effect(&b).is_none());
    }
}
