//! One request for any actuator's moulds (`cablemap mould --actuator`,
//! `design --moulds`): the style its channels need, checked, built and
//! written.
//!
//! Channels all in the bending plane (every z_i = 0) on a uniform cylinder
//! get the thesis's two-part mould (tray, lid with a protrusion per channel,
//! cover; [`MouldSet`]); channels in space, or a tapered body, get a printed
//! body with lumens and its castable cores ([`Lumens`]).

use super::{BodyFeature, Lumens, LumenSummary, MouldError, MouldParams, MouldSet, MouldSummary};
use crate::model::{Actuator, Routing};
use serde::Serialize;
use std::path::Path;

/// Which moulds to make.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MouldStyle {
    /// Two-part moulds when every channel lies in the bending plane and the
    /// body is a uniform cylinder, else the printed body with lumens.
    #[default]
    Auto,
    /// The thesis's tray, lid and cover (planar channels, uniform cylinder).
    TwoPart,
    /// A printable body with lumens and the lumens' castable cores.
    Lumens,
}

impl MouldStyle {
    /// Name used in files, reports and flags.
    pub fn name(self) -> &'static str {
        match self {
            MouldStyle::Auto => "auto",
            MouldStyle::TwoPart => "two_part",
            MouldStyle::Lumens => "lumens",
        }
    }
}

/// The options of a mould request.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct MouldOptions {
    /// Wall, tube, clearance, clamp block, skin.
    pub params: MouldParams,
    /// Which moulds.
    pub style: MouldStyle,
}

/// An actuator's moulds, checked and built (the two-part meshes) or ready
/// to mesh (the lumens').
#[derive(Debug, Clone)]
pub enum ActuatorMoulds {
    /// Tray, lid, cover.
    TwoPart(MouldSet),
    /// Body with lumens and cores.
    Lumens(Lumens),
}

/// What was written (also saved as mould.json, with its `style`).
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum MouldReport {
    /// Tray, lid, cover.
    TwoPart(MouldSummary),
    /// Body with lumens and cores.
    Lumens(LumenSummary),
}

impl MouldReport {
    /// The style made (never [`MouldStyle::Auto`]).
    pub fn style(&self) -> MouldStyle {
        match self {
            MouldReport::TwoPart(_) => MouldStyle::TwoPart,
            MouldReport::Lumens(_) => MouldStyle::Lumens,
        }
    }

    /// The text `mould` prints once the files are written into `dir`.
    pub fn report(&self, dir: &Path) -> String {
        match self {
            MouldReport::TwoPart(s) => s.report(dir),
            MouldReport::Lumens(s) => s.report(dir),
        }
    }
}

/// Refuses a body `style` cannot make: segments of their own material (one
/// pour, one print), a cable knotted before the tip (its tube or lumen
/// must run out of the tip), and for the two-part moulds a radius profile
/// ([`MouldError::NonUniformBody`]).
pub fn check_body(actuator: &Actuator, style: MouldStyle) -> Result<(), MouldError> {
    let rod = &actuator.rod;
    let mut features = Vec::new();
    if style == MouldStyle::TwoPart && !rod.radius_profile_mm.is_empty() {
        features.push(BodyFeature::RadiusProfile { lumens: true });
    }
    if !rod.segments.is_empty() {
        features.push(BodyFeature::Segments);
    }
    if rod.cable_length_mm() < rod.length_mm {
        features.push(BodyFeature::CableAnchored);
    }
    for (k, c) in actuator.cables.iter().enumerate() {
        let anchor_mm = c.anchor_or_tip_mm(rod.length_mm);
        if anchor_mm < rod.length_mm {
            features.push(BodyFeature::CableKnotted { cable: k + 1, anchor_mm });
        }
    }
    if features.is_empty() {
        Ok(())
    } else {
        Err(MouldError::NonUniformBody { features })
    }
}

/// The style `options` ask for, resolved for `actuator`: `Auto` is
/// two-part when every cable is planar and the body has no radius profile.
pub fn resolve_style(actuator: &Actuator, options: &MouldOptions) -> MouldStyle {
    match options.style {
        MouldStyle::Auto if actuator.cables.iter().all(|c| c.is_planar()) && actuator.rod.radius_profile_mm.is_empty() => MouldStyle::TwoPart,
        MouldStyle::Auto => MouldStyle::Lumens,
        style => style,
    }
}

/// The two-part moulds' channels: every cable's y_c(s), refusing one out
/// of the bending plane.
fn planar_channels(actuator: &Actuator) -> Result<Vec<Routing>, MouldError> {
    let rod = &actuator.rod;
    actuator
        .cables
        .iter()
        .enumerate()
        .map(|(k, c)| {
            if !c.is_planar() {
                return Err(MouldError::CableOutOfPlane { cable: k + 1, z_mm: c.z_mm });
            }
            Routing::new(c.y_mm, rod.length_mm, rod.radius_mm).map_err(|source| MouldError::CableRouting { cable: k + 1, source })
        })
        .collect()
}

/// Checks and builds the moulds of `actuator` (every cable's channel) in
/// the style `options` ask for; nothing is written.
pub fn build(actuator: &Actuator, options: &MouldOptions) -> Result<ActuatorMoulds, MouldError> {
    if actuator.cables.is_empty() {
        return Err(MouldError::NoCables);
    }
    match resolve_style(actuator, options) {
        MouldStyle::Lumens => Ok(ActuatorMoulds::Lumens(Lumens::new(actuator, &options.params)?)),
        _ => {
            check_body(actuator, MouldStyle::TwoPart)?;
            actuator.rod.validate()?;
            let channels = planar_channels(actuator)?;
            Ok(ActuatorMoulds::TwoPart(MouldSet::planar(&channels, actuator.rod.radius_mm, &options.params)?))
        }
    }
}

/// Checks, without meshing, that [`build`] would make the moulds of
/// `actuator`; the style it would make. For a search that wants to know
/// before it starts (`design --moulds`).
pub fn check(actuator: &Actuator, options: &MouldOptions) -> Result<MouldStyle, MouldError> {
    if actuator.cables.is_empty() {
        return Err(MouldError::NoCables);
    }
    let style = resolve_style(actuator, options);
    match style {
        MouldStyle::Lumens => {
            Lumens::new(actuator, &options.params)?;
        }
        _ => {
            check_body(actuator, MouldStyle::TwoPart)?;
            actuator.rod.validate()?;
            super::Moulds::planar(&planar_channels(actuator)?, actuator.rod.radius_mm, &options.params)?;
        }
    }
    Ok(style)
}

/// The moulds of any actuator, written into `dir` (created if missing; the
/// files are written in place, among others there, as `design --moulds`
/// does): [`build`], then [`ActuatorMoulds::write_all`].
pub fn for_actuator(actuator: &Actuator, options: &MouldOptions, dir: &Path) -> Result<MouldReport, MouldError> {
    build(actuator, options)?.write_all(dir)
}

impl ActuatorMoulds {
    /// The style built.
    pub fn style(&self) -> MouldStyle {
        match self {
            ActuatorMoulds::TwoPart(_) => MouldStyle::TwoPart,
            ActuatorMoulds::Lumens(_) => MouldStyle::Lumens,
        }
    }

    /// Writes the files into `dir` in place (created if missing).
    pub fn write_all(&self, dir: &Path) -> Result<MouldReport, MouldError> {
        Ok(match self {
            ActuatorMoulds::TwoPart(set) => MouldReport::TwoPart(set.write_all(dir)?),
            ActuatorMoulds::Lumens(l) => MouldReport::Lumens(l.write_all(dir)?),
        })
    }

    /// Writes the mould directory `dir` as a whole (new, empty or an
    /// earlier mould directory; a killed run leaves nothing partial).
    pub fn write_dir(&self, dir: &Path) -> Result<MouldReport, MouldError> {
        super::write::write_mould_dir(dir, |staging| self.write_all(staging))
    }
}
