//! Tests of the moulds: geometry, watertightness, marks and files.

use super::*;
use crate::mould::mesh::*;
use crate::mould::{stl, MouldSet};

const ROUTINGS: [[f64; 5]; 4] = [[1.0, -2.0, 3.0, 0.5, -3.0], [0.0; 5], [4.0, 4.0, -4.0, 4.0, 4.0], [-4.1, 0.0, 4.1, -2.0, 0.0]];

fn set(y: &[f64; 5], params: &MouldParams) -> MouldSet {
    MouldSet::new(&Routing::new(y, 65.0, 5.0).unwrap(), 5.0, params).unwrap()
}

fn variants() -> Vec<MouldParams> {
    let d = MouldParams::default();
    vec![
        d.clone(),
        MouldParams { clamp_mm: 0.0, ..d.clone() },
        MouldParams { wall_mm: 5.0, clearance_mm: 0.3, ..d.clone() },
        MouldParams { tube_diameter_mm: 0.6, clearance_mm: 0.0, min_skin_mm: 0.2, ..d },
    ]
}

/// Segments where the plane x = `x` cuts the mesh's triangles, as (y, z) pairs.
pub(crate) fn slice(mesh: &Mesh, x: f64) -> Vec<[(f64, f64); 2]> {
    let mut out = Vec::new();
    for t in &mesh.triangles {
        let mut pts = Vec::new();
        for k in 0..3 {
            let (a, b) = (mesh.vertices[t[k] as usize], mesh.vertices[t[(k + 1) % 3] as usize]);
            if (a[0] - x) * (b[0] - x) < 0.0 {
                let f = (x - a[0]) / (b[0] - a[0]);
                pts.push((a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])));
            }
        }
        if pts.len() == 2 {
            out.push([pts[0], pts[1]]);
        }
    }
    out
}

#[test]
fn every_part_is_watertight_also_after_stl() {
    for y in &ROUTINGS {
        for p in variants() {
            let s = set(y, &p);
            for kind in [PartKind::Tray, PartKind::Lid, PartKind::Cover] {
                let mesh = &s.part(kind).mesh;
                let r = mesh.check();
                assert!(r.is_watertight(), "{kind:?} {y:?} {p:?}: {r:?}");
                assert_eq!(r.shell_volumes_mm3.len(), 1, "{kind:?}: one piece");
                // The file stores f32: it must stay closed after that rounding.
                let (_, back) = stl::read(&stl::to_bytes(mesh, "t")).unwrap();
                let rb = back.check();
                assert!(rb.is_watertight(), "{kind:?} {y:?} {p:?} as STL: {rb:?}");
                assert!((rb.volume_mm3 - r.volume_mm3).abs() < 1e-4 * r.volume_mm3);
            }
            for number in [1, 2] {
                let (plate, placed) = s.plate(number);
                let r = plate.check();
                assert!(r.is_watertight() && r.shell_volumes_mm3.len() == 2, "{r:?}");
                assert!(placed.iter().all(|p| p.watertight));
                // Every part sits on the bed.
                assert!(plate.bounds_mm().0[2].abs() < 1e-9);
            }
        }
    }
}

#[test]
fn the_protrusion_follows_the_routing_with_the_tube_diameter() {
    for y in &ROUTINGS {
        for p in variants() {
            let s = set(y, &p);
            let lid = &s.lid.mesh;
            let rho = p.tube_diameter_mm / 2.0;
            let routing = &s.moulds.channels()[0];
            let mut x = -p.clamp_mm + 0.137;
            while x < 65.0 {
                let yc = s.moulds.channel_y_mm(0, x);
                // Print frame: the lid is turned over, its protrusion at −y_c.
                let near = |q: &(f64, f64)| (q.0 + yc).abs() < 3.0 * rho;
                let segs: Vec<[(f64, f64); 2]> = slice(lid, x).into_iter().filter(|g| near(&g[0]) && near(&g[1])).collect();
                let crest = segs.iter().flatten().copied().fold((0.0, f64::NEG_INFINITY), |a, q| if q.1 > a.1 { q } else { a });
                assert!((-crest.0 - yc).abs() < 0.02, "x = {x}: crest at y = {} vs y_c = {yc}", -crest.0);
                assert!((crest.1 - rho).abs() < 0.02, "x = {x}: crest height {} vs ρ = {rho}", crest.1);
                // Width at half height across the channel: √3 ρ for a half tube of radius ρ.
                let crossings: Vec<f64> = segs
                    .iter()
                    .filter(|g| (g[0].1 - rho / 2.0) * (g[1].1 - rho / 2.0) < 0.0)
                    .map(|g| g[0].0 + (rho / 2.0 - g[0].1) / (g[1].1 - g[0].1) * (g[1].0 - g[0].0))
                    .collect();
                let (lo, hi) = crossings.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| (l.min(*y), h.max(*y)));
                let slope = if x > 0.0 { routing.channel_at(x).dy_ds } else { 0.0 };
                let width = (hi - lo) / (1.0 + slope * slope).sqrt();
                assert!((width - 3f64.sqrt() * rho).abs() < 0.02, "x = {x}: half-height width {width} vs √3 ρ = {}", 3f64.sqrt() * rho);
                x += 0.731;
            }
        }
    }
}

#[test]
fn cavities_hold_the_body() {
    for y in &ROUTINGS {
        for p in variants() {
            let s = set(y, &p);
            for number in [1, 2] {
                let (cavity, body) = (s.cavity_volume_mm3(number), s.body_volume_mm3(number));
                assert!(((cavity - body) / body).abs() < 0.005, "mould {number} {y:?} {p:?}: cavity {cavity} vs body {body}");
            }
            // The groove is really there: the protrusion inside the cavity is half the tube.
            let ridge = -volume_below_face_mm3(&s.lid.mesh, s.moulds.cavity_x_mm(), 5.0);
            let channel = std::f64::consts::PI * (p.tube_diameter_mm / 2.0).powi(2) / 2.0 * s.moulds.channel_length_mm(0);
            assert!((ridge - channel).abs() < 0.02 * channel, "protrusion {ridge} mm³ vs half tube {channel} mm³");
        }
    }
}

/// Triangles with every corner in |y| ≤ `y_max`, as canonical
/// (rotation-normalised, rounded) corner lists.
fn region(mesh: &Mesh, y_lo: f64, y_hi: f64) -> Vec<[[i64; 3]; 3]> {
    let mut out: Vec<[[i64; 3]; 3]> = mesh
        .triangles
        .iter()
        .filter_map(|t| {
            let c = t.map(|i| mesh.vertices[i as usize]);
            if !c.iter().all(|p| p[1] >= y_lo && p[1] <= y_hi) {
                return None;
            }
            let q = c.map(|p| p.map(|v| (v * 1e5).round() as i64));
            let k = (0..3).min_by_key(|&k| q[k]).unwrap();
            Some([q[k], q[(k + 1) % 3], q[(k + 2) % 3]])
        })
        .collect();
    out.sort();
    out
}

#[test]
fn a_mirrored_routing_gives_mirrored_moulds_but_not_mirrored_marks() {
    let p = MouldParams::default();
    for y in &ROUTINGS[..1] {
        let a = set(y, &p);
        let b = set(&y.map(|v| -v), &p);
        let r = 5.0;
        let yb = a.moulds.y_half_mm();
        for kind in [PartKind::Tray, PartKind::Lid, PartKind::Cover] {
            let (ma, mb) = (a.part(kind).mesh.mirrored_y(), &b.part(kind).mesh);
            // Channel, trough, openings: mirror images of each other.
            let (ra, rb) = (region(&ma, -r, r), region(mb, -r, r));
            assert!(ra.len() > 1000);
            assert_eq!(ra, rb, "{kind:?}: the cavity regions are not mirror images");
            // The marks are not mirrored: the mirrored print shows them backwards.
            let band = |m: &Mesh| [region(m, -yb, -r - 1.0), region(m, r + 1.0, yb)];
            assert_ne!(band(&ma), band(mb), "{kind:?}: the marks do not tell the mirrored print apart");
            // Marks, pins and channel together: the mirrored print is not the mirror routing's mould.
            assert_ne!(region(&ma, -yb, yb), region(mb, -yb, yb));
        }
    }
}

#[test]
fn the_marks_read_differently_when_mirrored() {
    for text in ["CL ^+Y", "CL v+Y", "T", "1", "2"] {
        let px = text_pixels(text, 0.0, 0.0);
        let flip_y: Vec<_> = px.iter().map(|(x, y)| (*x, [-y[1], -y[0]])).collect();
        let w = text_width_mm(text);
        let flip_x: Vec<_> = px.iter().map(|(x, y)| ([w - x[1], w - x[0]], *y)).collect();
        let key = |v: &[([f64; 2], [f64; 2])]| {
            let mut k: Vec<[i64; 4]> = v.iter().map(|(x, y)| [x[0], x[1], y[0], y[1]].map(|c| (c * 1e6).round() as i64)).collect();
            k.sort();
            k
        };
        assert_ne!(key(&px), key(&flip_y), "{text} reads the same mirrored in y");
        if text.len() > 1 {
            assert_ne!(key(&px), key(&flip_x), "{text} reads the same mirrored in x");
        }
    }
}

#[test]
fn pins_fit_their_holes_one_way_only() {
    let s = set(&ROUTINGS[0], &MouldParams::default());
    let m = &s.moulds;
    let pins: Vec<Feature> = m.features(PartKind::Tray).into_iter().filter(|f| f.dz_mm > 0.0).collect();
    assert_eq!(pins.len(), 3);
    for f in &pins {
        let (x, y) = ((f.x_mm[0] + f.x_mm[1]) / 2.0, (f.y_mm[0] + f.y_mm[1]) / 2.0);
        assert!(m.height_mm(PartKind::Tray, x, y) > 1.0);
        for kind in [PartKind::Lid, PartKind::Cover] {
            // Turned over onto the tray, (x, y) of the tray is (x, −y) of the part.
            let edge = PIN_MM / 2.0 + 0.05;
            for (dx, dy) in [(0.0, 0.0), (edge, 0.0), (-edge, 0.0), (0.0, edge), (0.0, -edge)] {
                assert!(m.height_mm(kind, x + dx, -(y + dy)) < -PIN_HEIGHT_MM, "{kind:?}: no hole for the pin at {x},{y}");
            }
        }
    }
    // Turning a half end for end (180° about z) puts a pin where there is no hole.
    let [x0, x1] = m.x_range_mm();
    let turned = pins.iter().any(|f| {
        let (x, y) = ((f.x_mm[0] + f.x_mm[1]) / 2.0, (f.y_mm[0] + f.y_mm[1]) / 2.0);
        m.height_mm(PartKind::Lid, x0 + x1 - x, y) > -PIN_HEIGHT_MM
    });
    assert!(turned);
}

#[test]
fn channels_near_the_surface_and_bad_parameters_are_refused() {
    let p = MouldParams::default();
    let near = Routing::new(&[4.5, 0.0, 0.0, 0.0, 0.0], 65.0, 5.0).unwrap();
    let e = Moulds::new(&near, 5.0, &p).unwrap_err();
    assert!(matches!(e, MouldError::ChannelTooClose { .. }), "{e}");
    assert!(e.to_string().contains("--max-offset-mm"), "{e}");
    let ok = Routing::new(&[1.0, 0.0, 0.0, 0.0, 0.0], 65.0, 5.0).unwrap();
    for bad in [
        MouldParams { tube_diameter_mm: 0.0, ..p.clone() },
        MouldParams { tube_diameter_mm: 6.0, ..p.clone() },
        MouldParams { clearance_mm: -0.1, ..p.clone() },
        MouldParams { wall_mm: 1.0, ..p.clone() },
        MouldParams { clamp_mm: f64::NAN, ..p.clone() },
    ] {
        let e = Moulds::new(&ok, 5.0, &bad).unwrap_err();
        assert!(matches!(e, MouldError::BadParameter { .. }), "{bad:?}: {e}");
    }
    let short = Routing::new(&[0.0; 5], 10.0, 5.0).unwrap();
    assert!(Moulds::new(&short, 5.0, &MouldParams { clamp_mm: 0.0, ..p.clone() }).is_err());
    // A size that is not a number or beyond any printer is refused by name.
    for (bad, name) in [
        (MouldParams { wall_mm: f64::NAN, ..p.clone() }, "wall_mm"),
        (MouldParams { wall_mm: 1e308, ..p.clone() }, "wall_mm"),
        (MouldParams { clamp_mm: 1e7, ..p.clone() }, "clamp_mm"),
    ] {
        match Moulds::new(&ok, 5.0, &bad).unwrap_err() {
            MouldError::BadParameter { name: got, problem } => assert_eq!(got, name, "{problem}"),
            e => panic!("{e}"),
        }
    }
}

/// The size check counts the triangles before meshing: an upper bound
/// within twice the built meshes' (steps of zero height weld away), so
/// the limit means about what it says; and a
/// mould within every size limit but too large to mesh is refused.
#[test]
fn the_triangle_estimate_matches_the_meshes_and_bounds_them() {
    for (length, wall) in [(65.0, 3.0), (300.0, 3.0), (65.0, 40.0)] {
        let routing = Routing::new(&[1.0, -2.0, 3.0, 0.5, -3.0], length, 5.0).unwrap();
        let params = MouldParams { wall_mm: wall, ..MouldParams::default() };
        let set = MouldSet::new(&routing, 5.0, &params).unwrap();
        let built: usize = [PartKind::Tray, PartKind::Lid, PartKind::Cover].iter().map(|k| set.part(*k).mesh.check().triangles).sum();
        let estimate = set.moulds.estimated_triangles();
        assert!(estimate >= built as f64 && estimate < 2.0 * built as f64, "L {length}, wall {wall}: {estimate} vs {built}");
    }
    let long = Routing::new(&[1.0, -2.0, 3.0, 0.5, -3.0], 9000.0, 5.0).unwrap();
    let e = Moulds::new(&long, 5.0, &MouldParams { wall_mm: 2000.0, ..MouldParams::default() }).unwrap_err();
    assert!(matches!(e, MouldError::TooLarge { .. }) && e.to_string().contains("triangles"), "{e}");
}


/// Three channels in the bending plane, well apart.
const TRIO: [[f64; 5]; 3] = [[3.0, 3.2, 2.5, 3.0, 3.3], [0.0, -0.5, 0.5, 0.0, 0.2], [-3.0, -2.5, -3.5, -3.0, -2.8]];

fn planar_set(ys: &[[f64; 5]], params: &MouldParams) -> MouldSet {
    let channels: Vec<Routing> = ys.iter().map(|y| Routing::new(y, 65.0, 5.0).unwrap()).collect();
    MouldSet::planar(&channels, 5.0, params).unwrap()
}

#[test]
fn several_channels_give_one_protrusion_each_and_closed_parts() {
    for p in variants() {
        let s = planar_set(&TRIO, &p);
        for kind in [PartKind::Tray, PartKind::Lid, PartKind::Cover] {
            let r = s.part(kind).mesh.check();
            assert!(r.is_watertight() && r.shell_volumes_mm3.len() == 1, "{kind:?} {p:?}: {r:?}");
            let (_, back) = stl::read(&stl::to_bytes(&s.part(kind).mesh, "t")).unwrap();
            assert!(back.check().is_watertight(), "{kind:?} as STL");
        }
        for number in [1, 2] {
            let (cavity, body) = (s.cavity_volume_mm3(number), s.body_volume_mm3(number));
            assert!(((cavity - body) / body).abs() < 0.005, "mould {number}: cavity {cavity} vs body {body}");
        }
        // Each protrusion's crest at y_c(s) of its own channel within 0.01 mm, at height ρ.
        let rho = p.tube_diameter_mm / 2.0;
        let mut worst: f64 = 0.0;
        for k in 0..TRIO.len() {
            let mut x = -p.clamp_mm + 0.137;
            while x < 65.0 {
                let yc = s.moulds.channel_y_mm(k, x);
                let near = |q: &(f64, f64)| (q.0 + yc).abs() < 3.0 * rho;
                let crest = s.lid.mesh.slice_x(x).into_iter().filter(|g| near(&g[0]) && near(&g[1])).flatten().fold((0.0, f64::NEG_INFINITY), |a, q| if q.1 > a.1 { q } else { a });
                worst = worst.max((-crest.0 - yc).abs());
                assert!((-crest.0 - yc).abs() < 0.01, "cable {} x = {x}: crest at y = {} vs y_c = {yc}", k + 1, -crest.0);
                assert!((crest.1 - rho).abs() < 0.01, "cable {} x = {x}: crest height {} vs ρ = {rho}", k + 1, crest.1);
                x += 0.731;
            }
        }
        assert!(worst < 0.01, "{worst}");
        // A notch per tube in the tip-end wall of tray and cover.
        for kind in [PartKind::Tray, PartKind::Cover] {
            let x = 65.0 + p.wall_mm / 2.0;
            for k in 0..TRIO.len() {
                let y = kind.frame_sign() * s.moulds.channel_y_mm(k, 65.0);
                assert!(s.moulds.height_mm(kind, x, y) <= -rho, "{kind:?}: no notch for cable {}", k + 1);
            }
            assert!(s.moulds.height_mm(kind, x, kind.frame_sign() * 1.5) == 0.0, "{kind:?}: wall between notches");
        }
    }
}

#[test]
fn mirrored_channels_give_mirrored_two_part_moulds() {
    let p = MouldParams::default();
    let a = planar_set(&TRIO, &p);
    let mirrored: Vec<[f64; 5]> = TRIO.iter().map(|y| y.map(|v| -v)).collect();
    let b = planar_set(&mirrored, &p);
    for kind in [PartKind::Tray, PartKind::Lid, PartKind::Cover] {
        let (ra, rb) = (region(&a.part(kind).mesh.mirrored_y(), -5.0, 5.0), region(&b.part(kind).mesh, -5.0, 5.0));
        assert!(ra.len() > 1000);
        assert_eq!(ra, rb, "{kind:?}: the cavity regions are not mirror images");
    }
}

#[test]
fn channels_too_close_to_each_other_are_refused_with_cables_s_and_gap() {
    let p = MouldParams::default();
    // Straight channels 1.2 mm apart: 0.2 mm of silicone between the 1 mm tubes.
    let near: Vec<Routing> = [[0.6; 5], [3.0; 5], [-0.6; 5]].iter().map(|y| Routing::new(y, 65.0, 5.0).unwrap()).collect();
    let e = Moulds::planar(&near, 5.0, &p).unwrap_err();
    match &e {
        MouldError::ChannelsTooClose { first: 1, second: 3, s_mm, gap_mm, needed_mm, .. } => {
            assert!(*s_mm < 0.1 && (gap_mm - 0.2).abs() < 1e-9 && *needed_mm == 0.3, "{e}");
        }
        _ => panic!("{e}"),
    }
    let text = e.to_string();
    assert!(text.contains("cables 1 and 3") && text.contains("0.200 mm") && text.contains("s = 0.00"), "{text}");
    // Crossing channels meet somewhere: refused where they do.
    let crossing: Vec<Routing> = [[2.0, 2.0, 0.0, -2.0, -2.0], [-2.0, -2.0, 0.0, 2.0, 2.0]].iter().map(|y| Routing::new(y, 65.0, 5.0).unwrap()).collect();
    match Moulds::planar(&crossing, 5.0, &p).unwrap_err() {
        MouldError::ChannelsTooClose { s_mm, gap_mm, .. } => assert!((s_mm - 32.5).abs() < 1.0 && gap_mm < -0.9, "{s_mm} {gap_mm}"),
        e => panic!("{e}"),
    }
    // One near the surface names its cable.
    let surface: Vec<Routing> = [[0.0; 5], [4.5, 0.0, 0.0, 0.0, 0.0]].iter().map(|y| Routing::new(y, 65.0, 5.0).unwrap()).collect();
    let e = Moulds::planar(&surface, 5.0, &p).unwrap_err();
    assert!(matches!(e, MouldError::ChannelTooClose { cable: 2, .. }) && e.to_string().contains("cable 2"), "{e}");
    // Apart by the skin and a little: accepted.
    let apart: Vec<Routing> = [[0.66; 5], [-0.66; 5]].iter().map(|y| Routing::new(y, 65.0, 5.0).unwrap()).collect();
    assert!(Moulds::planar(&apart, 5.0, &p).is_ok());
}
