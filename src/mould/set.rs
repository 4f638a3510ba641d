//! The three parts built once, placed on print plates and written:
//! mould1.stl, mould2.stl, previews and mould.json (`write.rs`).

use super::mesh::Mesh;
use super::{volume_below_face_mm3, MouldError, MouldParams, Moulds, Part, PartKind};
use crate::model::Routing;
use serde::Serialize;
use std::path::Path;

/// Gap between the two parts of one print plate, mm.
const PLATE_GAP_MM: f64 = 6.0;

/// The three parts of the two-part moulds of one or more planar channels, built once.
#[derive(Debug, Clone)]
pub struct MouldSet {
    /// The geometry they were built from.
    pub moulds: Moulds,
    /// Lower half trough (both castings).
    pub tray: Part,
    /// Plate with the protrusion (mould 1).
    pub lid: Part,
    /// Upper half trough (mould 2).
    pub cover: Part,
}

/// One part as placed in an STL file.
#[derive(Debug, Clone, Serialize)]
pub struct PlacedPart {
    /// Part name (tray, lid, cover).
    pub part: PartKind,
    /// Engraved letter.
    pub letter: &'static str,
    /// Translation from the part's print frame to the file, mm.
    pub offset_mm: [f64; 3],
    /// Enclosed volume (print material), mm³.
    pub volume_mm3: f64,
    /// Triangles.
    pub triangles: usize,
    /// Closed, 2-manifold, consistently oriented, positive volume.
    pub watertight: bool,
}

/// One STL file: its name and the parts on its plate.
#[derive(Debug, Clone, Serialize)]
pub struct MouldFile {
    /// File name (mould1.stl, mould2.stl).
    pub file: String,
    /// The parts, in file order.
    pub parts: Vec<PlacedPart>,
}

/// What `write_all` wrote (also saved as mould.json).
#[derive(Debug, Clone, Serialize)]
pub struct MouldSummary {
    /// "two_part": the thesis's tray, lid and cover.
    pub style: &'static str,
    /// Control points y0..y4 of the one channel, mm (absent with several).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub routing_mm: Option<crate::model::routing::ControlPoints>,
    /// Control points y0..y4 of every channel, in cable order, mm.
    pub channels_y_mm: Vec<crate::model::routing::ControlPoints>,
    /// The channels' centreline files (channel.csv for one, channel_K.csv for cable K of several).
    pub channel_files: Vec<String>,
    /// Body length L and radius r, mm.
    pub length_mm: f64,
    /// Body radius r, mm.
    pub radius_mm: f64,
    /// Mould parameters.
    pub params: MouldParams,
    /// Channel length inside the body (clamp block + arc), mm; of several, their sum.
    pub channel_length_mm: f64,
    /// The STL files with their parts.
    pub files: Vec<MouldFile>,
    /// Cavity of mould 1 measured on the meshes (half body minus half channel), mm³.
    pub mould1_cavity_mm3: f64,
    /// The half body with its groove, π r² (L + c)/2 − π ρ²/2 · channel length, mm³.
    pub mould1_body_mm3: f64,
    /// Cavity of mould 2 measured on the meshes, mm³.
    pub mould2_cavity_mm3: f64,
    /// The full body, π r² (L + c), mm³ (the tube takes π ρ² · channel length of it).
    pub mould2_body_mm3: f64,
}

impl MouldSummary {
    /// The text `mould` prints once the moulds are written into `dir`.
    pub fn report(&self, dir: &Path) -> String {
        let s = self;
        let mut out = String::new();
        let list = |c: &crate::model::routing::ControlPoints| c.iter().map(|y| format!("{y:.3}")).collect::<Vec<_>>().join(", ");
        let what = match &s.routing_mm {
            Some(r) => format!("y0..y4 = [{}] mm", list(r)),
            None => format!(
                "{} channels ({})",
                s.channels_y_mm.len(),
                s.channels_y_mm.iter().enumerate().map(|(k, c)| format!("cable {}: y0..y4 = [{}] mm", k + 1, list(c))).collect::<Vec<_>>().join("; ")
            ),
        };
        out.push_str(&format!(
            "moulds for {what}, L = {} mm, r = {} mm, clamp block {} mm, tube Ø {} mm\n",
            s.length_mm,
            s.radius_mm,
            s.params.clamp_mm,
            s.params.tube_diameter_mm
        ));
        for f in &s.files {
            let desc: Vec<String> = f
                .parts
                .iter()
                .map(|p| {
                    format!(
                        "{} '{}' {:.1} cm³{}",
                        p.part.name(),
                        p.letter,
                        p.volume_mm3 / 1000.0,
                        if p.watertight { "" } else { " NOT WATERTIGHT" }
                    )
                })
                .collect();
            out.push_str(&format!("{:<12} {}\n", f.file, desc.join(", ")));
        }
        out.push_str(&format!(
            "cavity 1     {:.1} mm³ (half body minus half channel {:.1} mm³)\ncavity 2     {:.1} mm³ (body {:.1} mm³)\n",
            s.mould1_cavity_mm3, s.mould1_body_mm3, s.mould2_cavity_mm3, s.mould2_body_mm3
        ));
        out.push_str(&format!("wrote mould1.stl, mould2.stl, mould1.png, mould2.png, {}, mould.json to {}\n", s.channel_files.join(", "), dir.display()));
        out
    }
}

impl MouldSet {
    /// Builds the tray, lid and cover.
    pub fn build(moulds: Moulds) -> Self {
        let tray = moulds.part(PartKind::Tray);
        let lid = moulds.part(PartKind::Lid);
        let cover = moulds.part(PartKind::Cover);
        Self { moulds, tray, lid, cover }
    }

    /// Checks and builds the moulds of `routing` on a body of radius `radius_mm`.
    pub fn new(routing: &Routing, radius_mm: f64, params: &MouldParams) -> Result<Self, MouldError> {
        Ok(Self::build(Moulds::new(routing, radius_mm, params)?))
    }

    /// Checks and builds the moulds of several planar channels (cable
    /// order) on a body of radius `radius_mm` ([`Moulds::planar`]).
    pub fn planar(channels: &[Routing], radius_mm: f64, params: &MouldParams) -> Result<Self, MouldError> {
        Ok(Self::build(Moulds::planar(channels, radius_mm, params)?))
    }

    /// The part of a kind.
    pub fn part(&self, kind: PartKind) -> &Part {
        match kind {
            PartKind::Tray => &self.tray,
            PartKind::Lid => &self.lid,
            PartKind::Cover => &self.cover,
        }
    }

    /// The parts of mould 1 (tray, lid) or 2 (tray, cover).
    pub fn kinds(number: u8) -> [PartKind; 2] {
        if number == 1 {
            [PartKind::Tray, PartKind::Lid]
        } else {
            [PartKind::Tray, PartKind::Cover]
        }
    }

    /// The print plate of mould `number`: both parts on z = 0, side by side in y.
    pub fn plate(&self, number: u8) -> (Mesh, Vec<PlacedPart>) {
        let mut mesh = Mesh::default();
        let mut placed = Vec::new();
        for (k, kind) in Self::kinds(number).into_iter().enumerate() {
            let m = &self.moulds;
            let offset = [0.0, k as f64 * (2.0 * m.y_half_mm() + PLATE_GAP_MM), -m.z_bottom_mm(kind)];
            let part = self.part(kind).mesh.translated(offset);
            let report = part.check();
            placed.push(PlacedPart {
                part: kind,
                letter: kind.letter(),
                offset_mm: offset,
                volume_mm3: report.volume_mm3,
                triangles: report.triangles,
                watertight: report.is_watertight(),
            });
            mesh.append(&part);
        }
        (mesh, placed)
    }

    /// Cavity volume of mould `number` measured on the part meshes, mm³.
    pub fn cavity_volume_mm3(&self, number: u8) -> f64 {
        let (x, r) = (self.moulds.cavity_x_mm(), self.moulds.radius_mm());
        Self::kinds(number).iter().map(|k| volume_below_face_mm3(&self.part(*k).mesh, x, r)).sum()
    }

    /// The body volume the cavity of mould `number` should have, mm³.
    pub fn body_volume_mm3(&self, number: u8) -> f64 {
        let m = &self.moulds;
        let [c0, c1] = m.cavity_x_mm();
        let full = std::f64::consts::PI * m.radius_mm().powi(2) * (c1 - c0);
        if number == 1 {
            let channels: f64 = (0..m.channels().len()).map(|k| m.channel_length_mm(k)).sum();
            full / 2.0 - std::f64::consts::PI * m.tube_radius_mm.powi(2) / 2.0 * channels
        } else {
            full
        }
    }
}
