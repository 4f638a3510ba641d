//! The body along s: a radius profile r(s) (piecewise linear through given
//! points) and segments of their own material, from which the section's
//! rigidities EA(s), GA(s), EI(s) and the weight per length follow
//! (model.md, "Non-uniform bodies").
//!
//! The actuator's EA, GA, EI are those of a solid section of radius
//! `radius_mm` (or a segment's own values); a profile scales them by
//! (r/radius_mm)², (r/radius_mm)², (r/radius_mm)⁴ and the weight by
//! (r/radius_mm)². Everything is piecewise polynomial between the
//! breakpoints (profile points and segment ends), so the weight beyond a
//! cut, ∫_s^L ρ r² dσ, has a closed form; the collocation puts span
//! boundaries at the breakpoints so each span's integrands stay smooth.

use serde::{Deserialize, Serialize};

/// One segment of the body with its own material, from the previous
/// segment's end (or the clamp) to `end_mm`. Properties left out are the
/// actuator's. Rigidities are those of a section of radius `radius_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// Where the segment ends, mm from the clamp (the last one ends at L).
    pub end_mm: f64,
    /// Axial rigidity EA, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ea_n: Option<f64>,
    /// Shear rigidity GA, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ga_n: Option<f64>,
    /// Bending rigidity EI, N·mm².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ei_n_mm2: Option<f64>,
    /// Material density, g/cm³.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density_g_cm3: Option<f64>,
}

/// Why a body (radius profile, segments, cable anchor) was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BodyError {
    /// A profile point or segment end is not a finite number.
    #[error("{what} {index} is not a finite number; give finite values in mm")]
    NotFinite { what: &'static str, index: usize },
    /// Profile points must rise strictly in s.
    #[error("radius profile point {index} (s = {} mm) is not after the previous one (s = {} mm): give the points in increasing s, each s once", crate::io::fmt_num(*s_mm), crate::io::fmt_num(*previous_mm))]
    ProfileOutOfOrder { index: usize, s_mm: f64, previous_mm: f64 },
    /// A profile radius is not positive.
    #[error("radius profile point {index} has r = {} mm at s = {} mm: every radius must be > 0 mm", crate::io::fmt_num(*r_mm), crate::io::fmt_num(*s_mm))]
    RadiusNotPositive { index: usize, s_mm: f64, r_mm: f64 },
    /// The profile does not cover the rod.
    #[error("the radius profile runs from s = {} mm to s = {} mm but must run from s = 0 to the rod length L = {} mm: add points at 0 and L (a cone is two points, \"0:R0,L:R1\")", crate::io::fmt_num(*first_mm), crate::io::fmt_num(*last_mm), crate::io::fmt_num(*length_mm))]
    ProfileDoesNotCover { first_mm: f64, last_mm: f64, length_mm: f64 },
    /// The profile has fewer than two points.
    #[error("a radius profile needs at least two points s:r (a cone is two), got {0}")]
    ProfileTooShort(usize),
    /// Segment ends must rise strictly.
    #[error(
        "segment {index} ends at s = {} mm, not after the previous end (s = {previous_mm} mm): give segments from the clamp to the tip, each ending after the last",
        crate::io::fmt_num(*end_mm)
    )]
    SegmentOutOfOrder { index: usize, end_mm: f64, previous_mm: f64 },
    /// The last segment must end at L.
    #[error("segment {index} ends at s = {} mm, but the last segment must end at the tip, L = {length_mm} mm", crate::io::fmt_num(*end_mm))]
    LastSegmentShort { index: usize, end_mm: f64, length_mm: f64 },
    /// A segment's material value is not positive.
    #[error("segment {index}: {name} = {} must be a positive, finite number (density ≥ 0)", crate::io::fmt_num(*value))]
    BadSegmentMaterial { index: usize, name: &'static str, value: f64 },
    /// The cable anchor lies outside the rod.
    #[error("the cable anchor s_k = {} mm is outside the rod: give 0 < s_k ≤ L = {} mm (omit it to knot the cable at the tip)", crate::io::fmt_num(*anchor_mm), crate::io::fmt_num(*length_mm))]
    AnchorOutside { anchor_mm: f64, length_mm: f64 },
}

/// One piece between consecutive breakpoints: the radius at both ends
/// (linear in between) and the material.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    start_mm: f64,
    end_mm: f64,
    r_start_mm: f64,
    r_end_mm: f64,
    ea_n: f64,
    ga_n: f64,
    ei_n_mm2: f64,
    density_g_cm3: f64,
}

impl Piece {
    #[inline]
    fn radius_at(&self, s: f64) -> f64 {
        let len = self.end_mm - self.start_mm;
        if len <= 0.0 {
            return self.r_start_mm;
        }
        let t = ((s - self.start_mm) / len).clamp(0.0, 1.0);
        self.r_start_mm + (self.r_end_mm - self.r_start_mm) * t
    }

    /// ∫_a^b ρ r² dσ over [a, b] ⊂ the piece (r linear: exact).
    #[inline]
    fn density_area_integral(&self, a: f64, b: f64) -> f64 {
        let (ra, rb) = (self.radius_at(a), self.radius_at(b));
        self.density_g_cm3 * (b - a) * (ra * ra + ra * rb + rb * rb) / 3.0
    }
}

/// The rigidities and radius of the section at one s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySection {
    /// Axial rigidity EA, N.
    pub ea_n: f64,
    /// Shear rigidity GA, N.
    pub ga_n: f64,
    /// Bending rigidity EI, N·mm².
    pub ei_n_mm2: f64,
    /// Radius r, mm.
    pub radius_mm: f64,
}

/// What a body is made of: the rod's length, its uniform section (radius
/// and material) and what varies along s ([`crate::model::Rod`] holds
/// these; `Rod::body` resolves them).
#[derive(Debug, Clone, Copy)]
pub struct BodyParts<'a> {
    /// Rod length L, mm.
    pub length_mm: f64,
    /// The radius the rigidities are given for, mm.
    pub radius_mm: f64,
    /// Axial rigidity EA, N.
    pub ea_n: f64,
    /// Shear rigidity GA, N.
    pub ga_n: f64,
    /// Bending rigidity EI, N·mm².
    pub ei_n_mm2: f64,
    /// Density, g/cm³.
    pub density_g_cm3: f64,
    /// Radius profile points (s, r), mm; empty: uniform.
    pub radius_profile_mm: &'a [(f64, f64)],
    /// Segments of their own material; empty: one material.
    pub segments: &'a [Segment],
    /// The cable's anchor, mm; `None`: the tip.
    pub cable_anchor_mm: Option<f64>,
}

/// A non-uniform body, resolved from a rod's [`BodyParts`]: pieces between the
/// breakpoints and the closed-form weight beyond each breakpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    length_mm: f64,
    radius_mm: f64,
    pieces: Vec<Piece>,
    /// ∫_{start of piece k}^L ρ r² dσ, g/cm³·mm³.
    distal: Vec<f64>,
}

/// Distinct breakpoints closer than this (relative to L) are merged.
pub(crate) const MERGE_TOLERANCE: f64 = 1e-9;

impl Body {
    /// Resolves and checks the body of `a`; `None` for the uniform cylinder
    /// (no profile, no segments), which the solver handles on its fast path.
    pub fn new(a: &BodyParts) -> Result<Option<Body>, BodyError> {
        check_anchor(a)?;
        if a.radius_profile_mm.is_empty() && a.segments.is_empty() {
            return Ok(None);
        }
        let length = a.length_mm;
        let profile: Vec<(f64, f64)> =
            if a.radius_profile_mm.is_empty() { vec![(0.0, a.radius_mm), (length, a.radius_mm)] } else { a.radius_profile_mm.to_vec() };
        check_profile(&profile, length)?;
        check_segments(a)?;
        // Breakpoints: the profile's interior points and the segments' ends.
        let mut cuts: Vec<f64> = vec![0.0, length];
        cuts.extend(profile.iter().map(|p| p.0).filter(|&s| s > 0.0 && s < length));
        cuts.extend(a.segments.iter().map(|g| g.end_mm).filter(|&s| s > 0.0 && s < length));
        let cuts = merge_sorted(cuts, length);
        let radius_at = |s: f64| -> f64 {
            let k = profile.partition_point(|p| p.0 <= s).clamp(1, profile.len() - 1);
            let ((s0, r0), (s1, r1)) = (profile[k - 1], profile[k]);
            r0 + (r1 - r0) * ((s - s0) / (s1 - s0)).clamp(0.0, 1.0)
        };
        let mut pieces = Vec::with_capacity(cuts.len() - 1);
        for w in cuts.windows(2) {
            let mid = 0.5 * (w[0] + w[1]);
            let seg = a.segments.iter().find(|g| mid < g.end_mm);
            pieces.push(Piece {
                start_mm: w[0],
                end_mm: w[1],
                r_start_mm: radius_at(w[0]),
                r_end_mm: radius_at(w[1]),
                ea_n: seg.and_then(|g| g.ea_n).unwrap_or(a.ea_n),
                ga_n: seg.and_then(|g| g.ga_n).unwrap_or(a.ga_n),
                ei_n_mm2: seg.and_then(|g| g.ei_n_mm2).unwrap_or(a.ei_n_mm2),
                density_g_cm3: seg.and_then(|g| g.density_g_cm3).unwrap_or(a.density_g_cm3),
            });
        }
        let mut distal = vec![0.0; pieces.len() + 1];
        for k in (0..pieces.len()).rev() {
            let p = &pieces[k];
            distal[k] = distal[k + 1] + p.density_area_integral(p.start_mm, p.end_mm);
        }
        distal.pop();
        Ok(Some(Body { length_mm: length, radius_mm: a.radius_mm, pieces, distal }))
    }

    #[inline]
    fn piece_index(&self, s: f64) -> usize {
        self.piece_index_side(s, false)
    }

    /// The piece holding `s`; at a breakpoint the left one with `left`.
    #[inline]
    fn piece_index_side(&self, s: f64, left: bool) -> usize {
        // Few pieces: a linear scan beats a binary search.
        let mut k = 0;
        while k + 1 < self.pieces.len() && (s > self.pieces[k].end_mm || (!left && s == self.pieces[k].end_mm)) {
            k += 1;
        }
        k
    }

    /// Radius r(s), mm.
    pub fn radius_at(&self, s: f64) -> f64 {
        self.pieces[self.piece_index(s)].radius_at(s)
    }

    /// The section at `s`: rigidities scaled by (r/radius_mm)², ², ⁴.
    #[inline]
    pub fn section_at(&self, s: f64) -> BodySection {
        self.section_at_side(s, false)
    }

    /// [`Body::section_at`], taking a jump at a breakpoint from the left
    /// with `left` (the right otherwise).
    #[inline]
    pub fn section_at_side(&self, s: f64, left: bool) -> BodySection {
        let p = &self.pieces[self.piece_index_side(s, left)];
        let r = p.radius_at(s);
        let k2 = (r / self.radius_mm).powi(2);
        BodySection { ea_n: p.ea_n * k2, ga_n: p.ga_n * k2, ei_n_mm2: p.ei_n_mm2 * k2 * k2, radius_mm: r }
    }

    /// ∫_s^L ρ(σ) r(σ)² dσ, g/cm³·mm³: the weight beyond the cut at `s` is
    /// this times π·1e-6·g (and the gravity scale).
    #[inline]
    pub fn distal_density_area(&self, s: f64) -> f64 {
        let k = self.piece_index(s);
        let p = &self.pieces[k];
        let beyond = if k + 1 < self.distal.len() { self.distal[k + 1] } else { 0.0 };
        beyond + p.density_area_integral(s.max(p.start_mm), p.end_mm)
    }

    /// Density ρ(s), g/cm³.
    pub fn density_at(&self, s: f64) -> f64 {
        self.pieces[self.piece_index(s)].density_g_cm3
    }

    /// Interior breakpoints (0 < s < L), mm, in order.
    pub fn breakpoints_mm(&self) -> Vec<f64> {
        self.pieces.iter().skip(1).map(|p| p.start_mm).collect()
    }

    /// The rod length, mm.
    pub fn length_mm(&self) -> f64 {
        self.length_mm
    }

    /// The smallest radius over [a, b], mm (r is linear between breakpoints).
    pub fn min_radius_mm(&self, a: f64, b: f64) -> f64 {
        let mut r = self.radius_at(a).min(self.radius_at(b));
        for p in &self.pieces {
            if p.start_mm > a && p.start_mm < b {
                r = r.min(p.r_start_mm);
            }
        }
        r
    }
}

/// Sorts `cuts`, merging points closer than [`MERGE_TOLERANCE`]·L.
pub(crate) fn merge_sorted(mut cuts: Vec<f64>, length_mm: f64) -> Vec<f64> {
    cuts.sort_by(f64::total_cmp);
    let tol = MERGE_TOLERANCE * length_mm;
    let mut out: Vec<f64> = Vec::with_capacity(cuts.len());
    for s in cuts {
        match out.last() {
            Some(&last) if s - last <= tol => {}
            _ => out.push(s),
        }
    }
    out
}

fn check_anchor(a: &BodyParts) -> Result<(), BodyError> {
    if let Some(k) = a.cable_anchor_mm {
        if !(k.is_finite() && k > 0.0 && k <= a.length_mm) {
            return Err(BodyError::AnchorOutside { anchor_mm: k, length_mm: a.length_mm });
        }
    }
    Ok(())
}

fn check_profile(profile: &[(f64, f64)], length_mm: f64) -> Result<(), BodyError> {
    if profile.len() < 2 {
        return Err(BodyError::ProfileTooShort(profile.len()));
    }
    for (index, &(s, r)) in profile.iter().enumerate() {
        if !(s.is_finite() && r.is_finite()) {
            return Err(BodyError::NotFinite { what: "radius profile point", index });
        }
        if r <= 0.0 {
            return Err(BodyError::RadiusNotPositive { index, s_mm: s, r_mm: r });
        }
        if index > 0 && s <= profile[index - 1].0 {
            return Err(BodyError::ProfileOutOfOrder { index, s_mm: s, previous_mm: profile[index - 1].0 });
        }
    }
    let (first, last) = (profile[0].0, profile[profile.len() - 1].0);
    let tol = MERGE_TOLERANCE * length_mm;
    if first.abs() > tol || (last - length_mm).abs() > tol {
        return Err(BodyError::ProfileDoesNotCover { first_mm: first, last_mm: last, length_mm });
    }
    Ok(())
}

fn check_segments(a: &BodyParts) -> Result<(), BodyError> {
    let n = a.segments.len();
    let mut previous = 0.0;
    for (index, g) in a.segments.iter().enumerate() {
        if !g.end_mm.is_finite() {
            return Err(BodyError::NotFinite { what: "segment end", index });
        }
        if g.end_mm <= previous {
            return Err(BodyError::SegmentOutOfOrder { index, end_mm: g.end_mm, previous_mm: previous });
        }
        if index + 1 == n && (g.end_mm - a.length_mm).abs() > MERGE_TOLERANCE * a.length_mm {
            return Err(BodyError::LastSegmentShort { index, end_mm: g.end_mm, length_mm: a.length_mm });
        }
        previous = g.end_mm;
        for (name, value, positive) in
            [("ea_n", g.ea_n, true), ("ga_n", g.ga_n, true), ("ei_n_mm2", g.ei_n_mm2, true), ("density_g_cm3", g.density_g_cm3, false)]
        {
            if let Some(v) = value {
                if !(v.is_finite() && (v > 0.0 || (!positive && v == 0.0))) {
                    return Err(BodyError::BadSegmentMaterial { index, name, value: v });
                }
            }
        }
    }
    Ok(())
}

/// Why a radius profile given as text could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProfileTextError {
    /// A point is not `s:r`.
    #[error("radius profile point {index} \"{item}\" is not s:r (two numbers in mm, e.g. \"0:15.4,305:6.4,360:4.8\")")]
    NotAPair {
        /// The point's index.
        index: usize,
        /// The text of the point.
        item: String,
    },
    /// A coordinate is not a number.
    #[error("radius profile point {index} \"{item}\": \"{number}\" is not a number")]
    NotANumber {
        /// The point's index.
        index: usize,
        /// The text of the point.
        item: String,
        /// The text that is not a number.
        number: String,
    },
    /// No points at all.
    #[error("the radius profile is empty: give points s:r in mm, e.g. \"0:15.4,305:6.4,360:4.8\"")]
    Empty,
}

/// Parses a radius profile "s:r,s:r,…" (mm), as on the command line.
pub fn parse_radius_profile(text: &str) -> Result<Vec<(f64, f64)>, ProfileTextError> {
    let mut out = Vec::new();
    for (index, item) in text.split(',').map(str::trim).filter(|t| !t.is_empty()).enumerate() {
        let (s, r) = item.split_once(':').ok_or_else(|| ProfileTextError::NotAPair { index, item: item.to_string() })?;
        let num = |t: &str| {
            t.trim().parse::<f64>().map_err(|_| ProfileTextError::NotANumber { index, item: item.to_string(), number: t.trim().to_string() })
        };
        out.push((num(s)?, num(r)?));
    }
    if out.is_empty() {
        return Err(ProfileTextError::Empty);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Rod;

    fn tapered() -> Rod {
        Rod { length_mm: 360.0, radius_mm: 15.4, radius_profile_mm: vec![(0.0, 15.4), (305.0, 6.4), (360.0, 4.8)], ..Rod::default() }
    }

    #[test]
    fn distal_weight_is_the_exact_integral() {
        let mut a = tapered();
        a.segments = vec![
            Segment { end_mm: 100.0, ea_n: None, ga_n: None, ei_n_mm2: Some(500.0), density_g_cm3: Some(1.2) },
            Segment { end_mm: 360.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
        ];
        let b = a.body().unwrap().unwrap();
        assert_eq!(b.breakpoints_mm(), vec![100.0, 305.0]);
        // Midpoint rule on a fine grid.
        for s in [0.0, 50.0, 100.0, 200.0, 305.0, 330.0, 360.0] {
            let n = 200_000;
            let h = (360.0 - s) / n as f64;
            let mut sum = 0.0;
            for i in 0..n {
                let x = s + (i as f64 + 0.5) * h;
                sum += b.density_at(x) * b.radius_at(x).powi(2) * h;
            }
            assert!((b.distal_density_area(s) - sum).abs() < 1e-6 * sum.max(1.0), "{s}: {} vs {sum}", b.distal_density_area(s));
        }
        let sec = b.section_at(50.0);
        let r = 15.4 + (6.4 - 15.4) * 50.0 / 305.0;
        assert!((sec.ei_n_mm2 - 500.0 * (r / 15.4f64).powi(4)).abs() < 1e-9);
        assert!((sec.ea_n - a.ea_n * (r / 15.4f64).powi(2)).abs() < 1e-12);
    }

    #[test]
    fn bad_bodies_name_where_and_what() {
        let mut a = tapered();
        a.radius_profile_mm = vec![(0.0, 15.4), (305.0, 6.4), (300.0, 4.8)];
        let e = a.body().unwrap_err().to_string();
        assert!(e.contains("point 2") && e.contains("increasing s"), "{e}");
        a.radius_profile_mm = vec![(0.0, 15.4), (305.0, 0.0), (360.0, 4.8)];
        let e = a.body().unwrap_err().to_string();
        assert!(e.contains("s = 305 mm") && e.contains("> 0"), "{e}");
        a.radius_profile_mm = vec![(0.0, 15.4), (300.0, 4.8)];
        let e = a.body().unwrap_err().to_string();
        assert!(e.contains("L = 360 mm"), "{e}");
        let mut a = tapered();
        a.cable_anchor_mm = Some(400.0);
        let e = a.body().unwrap_err().to_string();
        assert!(e.contains("anchor") && e.contains("400"), "{e}");
        assert!(Rod::default().body().unwrap().is_none());
        assert!(parse_radius_profile("0:15.4,305:6.4,360:4.8").unwrap().len() == 3);
        assert!(parse_radius_profile("0:15.4,305").unwrap_err().to_string().contains("s:r"));
    }
}
