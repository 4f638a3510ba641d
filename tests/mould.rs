//! `cablemap mould` as a user runs it: files, read-back of the STL from
//! disk (closed, oriented, the channel where the routing puts it), the
//! design → mould path, and bad input.

use cablemap::model::Routing;
use cablemap::mould::{mesh::Mesh, stl};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cablemap")).args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn read_stl(path: &Path) -> (String, Mesh) {
    stl::read(&std::fs::read(path).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Highest point of the shell's cut by the plane x = `x` near `y_near`, (y, z).
fn crest(mesh: &Mesh, x: f64, y_near: f64) -> (f64, f64) {
    let mut best = (f64::NAN, f64::NEG_INFINITY);
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (mesh.vertices[t[k] as usize], mesh.vertices[t[(k + 1) % 3] as usize]);
            if (a[0] - x) * (b[0] - x) < 0.0 {
                let f = (x - a[0]) / (b[0] - a[0]);
                let (y, z) = (a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]));
                if (y - y_near).abs() < 1.5 && z > best.1 {
                    best = (y, z);
                }
            }
        }
    }
    best
}

#[test]
fn mould_writes_closed_stl_with_the_channel_where_the_routing_puts_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let ys = [1.0, -2.0, 3.0, 0.5, -3.0];
    let (ok, stdout, stderr) = run(&["mould", "--routing", "1,-2,3,0.5,-3", "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("mould1.stl") && stdout.contains("cavity 1"), "{stdout}");
    for f in ["mould1.stl", "mould2.stl", "mould1.png", "mould2.png", "channel.csv", "mould.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out.join("mould.json")).unwrap()).unwrap();
    for number in [1, 2] {
        let (title, mesh) = read_stl(&out.join(format!("mould{number}.stl")));
        assert!(title.starts_with(&format!("cablemap mould{number}, units mm")), "{title}");
        let report = mesh.check();
        assert!(report.is_watertight(), "mould{number}.stl: {report:?}");
        assert_eq!(report.shell_volumes_mm3.len(), 2, "two parts per plate");
        let parts = summary["files"][number - 1]["parts"].as_array().unwrap();
        let listed: f64 = parts.iter().map(|p| p["volume_mm3"].as_f64().unwrap()).sum();
        assert!((report.volume_mm3 - listed).abs() < 1e-4 * listed, "{} vs {listed}", report.volume_mm3);
        assert!(mesh.bounds_mm().0[2].abs() < 1e-6, "parts stand on z = 0");
        let (cavity, body) = (summary[format!("mould{number}_cavity_mm3")].as_f64().unwrap(), summary[format!("mould{number}_body_mm3")].as_f64().unwrap());
        assert!(((cavity - body) / body).abs() < 0.005, "mould {number}: cavity {cavity} vs body {body}");
    }
    // The lid (second part of mould1.stl) as read from the file: its crest
    // follows y_c(s), turned over (y → −y) and moved by the listed offset.
    let (_, mesh) = read_stl(&out.join("mould1.stl"));
    assert_eq!(summary["files"][0]["file"], "mould1.stl");
    let lid_entry = &summary["files"][0]["parts"][1];
    assert_eq!(lid_entry["part"], "lid");
    let off: Vec<f64> = lid_entry["offset_mm"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let routing = Routing::new(&ys, 65.0, 5.0).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..120 {
        let x = 0.1 + k as f64 * 0.54;
        let yc = routing.channel_at(x).y_mm;
        let (y, z) = crest(&mesh, x, off[1] - yc);
        let err = (-(y - off[1]) - yc).abs();
        worst = worst.max(err);
        assert!((z - off[2] - 0.5).abs() < 0.02, "x = {x}: crest height {} mm", z - off[2]);
    }
    assert!(worst < 0.02, "crest off y_c(s) by up to {worst} mm");
    // Preview: two views in one picture.
    let png = image::open(out.join("mould1.png")).unwrap();
    assert_eq!((png.width(), png.height()), (1400, 1100));
    let csv = std::fs::read_to_string(out.join("channel.csv")).unwrap();
    assert!(csv.starts_with("s_mm,y_mm,dy_ds\n1") || csv.starts_with("s_mm,y_mm,dy_ds\n0"), "{}", &csv[..40]);
}

#[test]
fn design_out_moulds_and_mould_design_agree() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("d");
    let (ok, stdout, stderr) = run(&[
        "design", "--target", "x=50,y=5", "--starts", "2", "--max-offset-mm", "4", "--out", d.to_str().unwrap(), "--moulds",
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("mould1.stl"), "{stdout}");
    for f in ["design.json", "mould.svg", "mould1.stl", "mould2.stl", "mould1.png", "mould.json"] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    // The same moulds from the design file.
    let again = dir.path().join("again");
    let (ok, _, stderr) = run(&["mould", "--design", d.join("design.json").to_str().unwrap(), "--out", again.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    for f in ["mould1.stl", "mould2.stl"] {
        assert_eq!(std::fs::read(d.join(f)).unwrap(), std::fs::read(again.join(f)).unwrap(), "{f} differs");
    }
    // --moulds needs --out.
    let (ok, _, stderr) = run(&["design", "--target", "x=50,y=5", "--moulds"]);
    assert!(!ok && stderr.contains("--out"), "{stderr}");
}

#[test]
fn bad_mould_input_is_refused_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let o = out.to_str().unwrap();
    let (ok, _, stderr) = run(&["mould", "--out", o]);
    assert!(!ok && stderr.contains("--routing"), "{stderr}");
    let (ok, _, stderr) = run(&["mould", "--routing", "4.6,0,0,0,0", "--out", o]);
    assert!(!ok && stderr.contains("comes within") && stderr.contains("--max-offset-mm"), "{stderr}");
    let (ok, _, stderr) = run(&["mould", "--routing", "1,2,3", "--out", o]);
    assert!(!ok && stderr.contains("5 control points"), "{stderr}");
    let (ok, _, stderr) = run(&["mould", "--routing", "0,0,0,0,0", "--tube-diameter-mm", "0", "--out", o]);
    assert!(!ok && stderr.contains("--tube-diameter-mm"), "{stderr}");
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"tension_n\": 1}").unwrap();
    let (ok, _, stderr) = run(&["mould", "--design", bad.to_str().unwrap(), "--out", o]);
    assert!(!ok && stderr.contains("routing_mm"), "{stderr}");
    assert!(!out.join("mould1.stl").exists());
}

/// Centre of the loop that the plane x = `x` cuts from `mesh` near `near`
/// (length-weighted midpoints of the cut's segments), (y, z).
fn section_centre(mesh: &Mesh, x: f64, near: [f64; 2]) -> [f64; 2] {
    let (mut sy, mut sz, mut w) = (0.0, 0.0, 0.0);
    for [a, b] in mesh.slice_x(x) {
        let mid = [(a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0];
        if (mid[0] - near[0]).hypot(mid[1] - near[1]) < 1.0 {
            let len = (a.0 - b.0).hypot(a.1 - b.1);
            sy += mid[0] * len;
            sz += mid[1] * len;
            w += len;
        }
    }
    [sy / w, sz / w]
}

#[test]
fn mould_actuator_casts_every_planar_channel_with_its_own_protrusion() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/moulds/planar-trio.toml");
    let (ok, stdout, stderr) = run(&["mould", "--actuator", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("3 channels") && stdout.contains("channel_3.csv"), "{stdout}");
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out.join("mould.json")).unwrap()).unwrap();
    assert_eq!(summary["style"], "two_part");
    for number in [1, 2] {
        let (_, mesh) = read_stl(&out.join(format!("mould{number}.stl")));
        let report = mesh.check();
        assert!(report.is_watertight() && report.shell_volumes_mm3.len() == 2, "mould{number}.stl: {report:?}");
    }
    let actuator = cablemap::model::Actuator::read(&file).unwrap();
    let (_, mesh) = read_stl(&out.join("mould1.stl"));
    let off: Vec<f64> = summary["files"][0]["parts"][1]["offset_mm"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let mut worst: f64 = 0.0;
    for cable in &actuator.cables {
        let routing = Routing::new(cable.y_mm, 65.0, 5.0).unwrap();
        for k in 0..120 {
            let x = 0.1 + k as f64 * 0.54;
            let yc = routing.channel_at(x).y_mm;
            let (y, z) = crest(&mesh, x, off[1] - yc);
            worst = worst.max((-(y - off[1]) - yc).abs());
            assert!((z - off[2] - 0.5).abs() < 0.01, "x = {x}: crest height {} mm", z - off[2]);
        }
    }
    // From the f32 file: within 0.01 mm of each channel's y_c(s).
    assert!(worst < 0.01, "crest off y_c(s) by up to {worst} mm");
    let csv = std::fs::read_to_string(out.join("channel_2.csv")).unwrap();
    // Cable K's channel_K.csv, the one format of an actuator's channels (z ≡ 0 here).
    assert!(csv.starts_with("s_mm,y_mm,z_mm,dy_ds,dz_ds\n0.0000,0.000000,0.000000,"), "{}", &csv[..60]);
    let channels = actuator.channels().unwrap();
    assert_eq!(csv, channels[1].csv(65.0), "the mould writes cable 2's channel as the actuator's one writer does");
}

#[test]
fn mould_actuator_prints_spatial_channels_as_a_body_with_lumens_and_cores() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/moulds/spatial-pair-tapered.toml");
    let (ok, stdout, stderr) = run(&["mould", "--actuator", file.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("2 lumen(s)") && stdout.contains("body.stl"), "{stdout}");
    let summary: Value = serde_json::from_str(&std::fs::read_to_string(out.join("mould.json")).unwrap()).unwrap();
    assert_eq!(summary["style"], "lumens");
    let (_, body) = read_stl(&out.join("body.stl"));
    let (_, core) = read_stl(&out.join("core.stl"));
    for (mesh, shells, entry) in [(&body, 1, 0), (&core, 2, 1)] {
        let r = mesh.check();
        assert!(r.is_watertight() && r.shell_volumes_mm3.len() == shells, "{r:?}");
        let listed = summary["files"][entry]["volume_mm3"].as_f64().unwrap();
        assert!((r.volume_mm3 - listed).abs() < 1e-4 * listed);
    }
    let expected = summary["body_expected_mm3"].as_f64().unwrap();
    assert!(((body.volume_mm3() - expected) / expected).abs() < 0.002);
    // The outline follows the taper: r = 6 at the clamp, 5 at the tip.
    let (lo, hi) = body.bounds_mm();
    assert!((hi[1] - 6.0).abs() < 1e-4 && (lo[0] + 10.0).abs() < 1e-6 && (hi[0] - 65.0).abs() < 1e-6, "{lo:?} {hi:?}");
    // Each lumen (and core) is centred on its channel, read from the files.
    let actuator = cablemap::model::Actuator::read(&file).unwrap();
    let channels = actuator.channels().unwrap();
    let mut worst: f64 = 0.0;
    for ch in &channels {
        for k in 0..100 {
            let s = 0.31 + k as f64 * 0.6437;
            let c = ch.at(s).r_mm;
            for mesh in [&body, &core] {
                let got = section_centre(mesh, s, c);
                worst = worst.max((got[0] - c[0]).hypot(got[1] - c[1]));
            }
        }
    }
    assert!(worst < 0.01, "lumen centre off the channel by up to {worst} mm");
    // Forcing the two-part mould on spatial channels is refused with the reason.
    let (ok, _, stderr) = run(&["mould", "--actuator", file.to_str().unwrap(), "--style", "two-part", "--out", dir.path().join("x").to_str().unwrap()]);
    assert!(!ok && stderr.contains("radius profile") && stderr.contains("--style lumens"), "{stderr}");
}

#[test]
fn mould_actuator_refuses_channels_too_close_naming_cables_s_and_gap() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().join("m");
    let o = o.to_str().unwrap();
    let (ok, _, stderr) = run(&["mould", "--cable", "y=0.6,0.6,0.6,0.6,0.6 tension=1", "--cable", "y=-0.6,-0.6,-0.6,-0.6,-0.6 tension=1", "--out", o]);
    assert!(!ok && stderr.contains("cables 1 and 2") && stderr.contains("0.200 mm") && stderr.contains("s = 0.00"), "{stderr}");
    let (ok, _, stderr) = run(&["mould", "--cable", "y=3,3,3,3,3 z=3,3,3,3,3 tension=1", "--out", o]);
    assert!(!ok && stderr.contains("lumen of cable 1") && stderr.contains("0.257 mm"), "{stderr}");
    let (ok, _, stderr) = run(&["mould", "--cable", "y=1,1,1,1,1 tension=1", "--cable", "y=-3,-3,-3,-3,-3 z=0,1,0,0,0 tension=1", "--style", "two-part", "--out", o]);
    assert!(!ok && stderr.contains("cable 2 leaves the bending plane"), "{stderr}");
    let (ok, _, stderr) = run(&["mould", "--cable", "y=1,1,1,1,1 tension=1 anchor=40", "--out", o]);
    assert!(!ok && stderr.contains("cable 1 knotted before the tip"), "{stderr}");
    assert!(!Path::new(o).exists());
}

#[test]
fn a_routing_is_the_actuator_with_that_one_planar_cable() {
    // `--routing` and the same channel as `--cable` give the same files,
    // in every style.
    let dir = tempfile::tempdir().unwrap();
    for style in ["auto", "lumens"] {
        let a = dir.path().join(format!("routing-{style}"));
        let b = dir.path().join(format!("cable-{style}"));
        let (ok, ja, stderr) = run(&["mould", "--routing", "2,3,-1,2,1", "--style", style, "--json", "--out", a.to_str().unwrap()]);
        assert!(ok, "{stderr}");
        let (ok, jb, stderr) = run(&["mould", "--cable", "y=2,3,-1,2,1 tension=0", "--style", style, "--json", "--out", b.to_str().unwrap()]);
        assert!(ok, "{stderr}");
        assert_eq!(ja, jb, "{style}");
        let mut names: Vec<_> = std::fs::read_dir(&a).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.sort();
        assert!(names.len() >= 3, "{names:?}");
        for name in names {
            assert_eq!(std::fs::read(a.join(&name)).unwrap(), std::fs::read(b.join(&name)).unwrap(), "{style}: {name:?} differs");
        }
    }
}
