//! Tests of the printed body with lumens and its cores.

use super::*;
use crate::model::{Cable, Rod};
use crate::mould::{stl, MouldError};

fn actuator(cables: Vec<Cable>) -> Actuator {
    Actuator::with_cables(Rod::default(), cables)
}

fn spatial_pair() -> Actuator {
    actuator(vec![
        Cable::spatial([2.0, 2.5, -1.0, 1.5, 2.0], [0.0, 1.5, 2.5, 1.0, -1.0], 1.0),
        Cable::spatial([-2.0, -2.0, 1.0, -2.5, -2.0], [0.5, -1.5, -1.5, 0.0, 1.5], 1.0),
    ])
}

#[test]
fn body_and_cores_are_watertight_with_their_volumes() {
    let tapered = {
        let mut a = spatial_pair();
        a.rod.radius_profile_mm = vec![(0.0, 6.0), (65.0, 5.0)];
        a
    };
    let three = actuator(vec![
        Cable::spatial([3.0; 5], [0.0, 1.0, 0.0, -1.0, 0.0], 1.0),
        Cable::spatial([-1.5, -1.5, -1.5, -1.5, -1.5], [2.6, 2.6, 2.0, 2.6, 2.6], 1.0),
        Cable::planar([-1.5, -2.0, -2.5, -2.0, -1.5], 1.0),
    ]);
    for (a, params) in [
        (spatial_pair(), MouldParams::default()),
        (spatial_pair(), MouldParams { clamp_mm: 0.0, ..MouldParams::default() }),
        (tapered, MouldParams::default()),
        (three, MouldParams { tube_diameter_mm: 0.8, ..MouldParams::default() }),
    ] {
        let l = Lumens::new(&a, &params).unwrap();
        let body = l.body().unwrap();
        let r = body.check();
        assert!(r.is_watertight(), "{r:?}");
        assert_eq!(r.shell_volumes_mm3.len(), 1);
        let expected = l.body_expected_mm3();
        assert!(((r.volume_mm3 - expected) / expected).abs() < 0.002, "body {} vs {expected}", r.volume_mm3);
        let cores = l.cores();
        let rc = cores.check();
        assert!(rc.is_watertight(), "{rc:?}");
        assert_eq!(rc.shell_volumes_mm3.len(), a.cables.len());
        let expected = l.core_expected_mm3();
        assert!(((rc.volume_mm3 - expected) / expected).abs() < 0.01, "cores {} vs {expected}", rc.volume_mm3);
        // Still closed after the STL's f32 rounding.
        for m in [&body, &cores] {
            let (_, back) = stl::read(&stl::to_bytes(m, "t")).unwrap();
            assert!(back.check().is_watertight());
        }
    }
}

/// The lumen's section cut from the mesh at x (between stations): the
/// centre of the loop's segments near `near` (length-weighted midpoints).
fn section_centre(mesh: &crate::mould::mesh::Mesh, x: f64, near: [f64; 2], within: f64) -> [f64; 2] {
    let (mut sy, mut sz, mut w) = (0.0, 0.0, 0.0);
    for seg in mesh.slice_x(x) {
        let (a, b) = (seg[0], seg[1]);
        let mid = [(a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0];
        if (mid[0] - near[0]).hypot(mid[1] - near[1]) < within {
            let len = (a.0 - b.0).hypot(a.1 - b.1);
            sy += mid[0] * len;
            sz += mid[1] * len;
            w += len;
        }
    }
    [sy / w, sz / w]
}

#[test]
fn each_lumen_is_centred_on_its_channel() {
    let a = spatial_pair();
    let l = Lumens::new(&a, &MouldParams::default()).unwrap();
    let body = l.body().unwrap();
    let cores = l.cores();
    let mut worst: f64 = 0.0;
    for k in 0..2 {
        let mut x = 0.0731;
        while x < 65.0 {
            let c = l.channels()[k].at(x).r_mm;
            for mesh in [&body, &cores] {
                let got = section_centre(mesh, x, c, 1.0);
                let err = (got[0] - c[0]).hypot(got[1] - c[1]);
                worst = worst.max(err);
                assert!(err < 0.01, "cable {} at s = {x}: lumen centre {got:?} vs channel {c:?}", k + 1);
            }
            x += 0.617;
        }
    }
    eprintln!("largest lumen-centre error {worst:.2e} mm");
}

#[test]
fn mirrored_channels_give_the_mirrored_body() {
    let a = spatial_pair();
    let mut m = a.clone();
    for c in &mut m.cables {
        c.y_mm = c.y_mm.map(|v| -v);
    }
    let p = MouldParams::default();
    let (la, lm) = (Lumens::new(&a, &p).unwrap(), Lumens::new(&m, &p).unwrap());
    // Outline and lumen walls (every triangle off the end faces) are exact mirror images.
    let walls = |mesh: &crate::mould::mesh::Mesh| {
        let mut out: Vec<[[i64; 3]; 3]> = mesh
            .triangles
            .iter()
            .filter_map(|t| {
                let c = t.map(|i| mesh.vertices[i as usize]);
                if c.iter().all(|p| p[0] == c[0][0]) {
                    return None;
                }
                let q = c.map(|p| p.map(|v| (v * 1e5).round() as i64));
                let k = (0..3).min_by_key(|&k| q[k]).unwrap();
                Some([q[k], q[(k + 1) % 3], q[(k + 2) % 3]])
            })
            .collect();
        out.sort();
        out
    };
    for (ma, mm) in [(la.body().unwrap(), lm.body().unwrap()), (la.cores(), lm.cores())] {
        let (wa, wm) = (walls(&ma.mirrored_y()), walls(&mm));
        assert!(wa.len() > 1000);
        assert_eq!(wa, wm, "the walls are not mirror images");
        assert!((ma.volume_mm3() - mm.volume_mm3()).abs() < 1e-6 * ma.volume_mm3());
        // The end faces: the same area.
        let face_area = |mesh: &crate::mould::mesh::Mesh| -> f64 {
            mesh.triangles.iter().map(|t| t.map(|i| mesh.vertices[i as usize])).filter(|c| c.iter().all(|p| p[0] == c[0][0])).map(|c| {
                ((c[1][1] - c[0][1]) * (c[2][2] - c[0][2]) - (c[1][2] - c[0][2]) * (c[2][1] - c[0][1])).abs() / 2.0
            }).sum()
        };
        assert!((face_area(&ma) - face_area(&mm)).abs() < 1e-9 * face_area(&ma));
    }
}

#[test]
fn lumens_too_close_are_refused_naming_cable_s_and_gap() {
    let p = MouldParams::default();
    // Near the surface: 4.243 mm from the axis, r = 5, tube 1: 0.257 mm of skin, 0.3 needed.
    let a = actuator(vec![Cable::spatial([3.0; 5], [3.0; 5], 1.0)]);
    let e = Lumens::new(&a, &p).unwrap_err();
    assert!(matches!(e, MouldError::LumenTooClose { cable: 1, .. }), "{e}");
    let text = e.to_string();
    assert!(text.contains("cable 1") && text.contains("s = 0.00") && text.contains("0.257") && text.contains("nearer the axis"), "{text}");
    // Two straight lumens 1.2 mm apart (centre to centre): 0.2 mm of silicone.
    let b = actuator(vec![Cable::spatial([0.6; 5], [1.0; 5], 1.0), Cable::spatial([-0.6; 5], [1.0; 5], 1.0)]);
    let e = Lumens::new(&b, &p).unwrap_err();
    match &e {
        MouldError::ChannelsTooClose { first: 1, second: 2, s_mm, gap_mm, .. } => {
            assert!(*s_mm < 0.1, "{e}");
            assert!((gap_mm - 0.2).abs() < 1e-9, "{e}");
        }
        _ => panic!("{e}"),
    }
    assert!(e.to_string().contains("cables 1 and 2") && e.to_string().contains("farther apart"), "{e}");
    // A cable knotted before the tip, and segments, are refused by name.
    let mut c = spatial_pair();
    c.cables[1].anchor_mm = Some(40.0);
    let e = Lumens::new(&c, &p).unwrap_err();
    assert!(e.to_string().contains("cable 2 knotted before the tip"), "{e}");
}
