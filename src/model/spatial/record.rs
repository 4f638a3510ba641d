//! What a spatial simulation writes: the `--cable` text form of a cable, the
//! `cablemap simulate` command of an actuator, the JSON record, the text
//! report and the 3-D centreline CSV (this module owns those formats;
//! docs/schema.md describes them).

use super::{Actuator, Cable, SpatialError, SpatialOptions, SpatialSimulation};
use crate::model::routing::CONTROL_POINTS;
use crate::model::STATUS_OK;
use serde_json::json;
use std::fmt::Write as _;

/// Parses the `--cable` form: `y=Y0,Y1,Y2,Y3,Y4 z=Z0,Z1,Z2,Z3,Z4 tension=T`
/// (whitespace-separated `key=value` fields; `z=` may be left out for a
/// planar cable; `anchor=S` knots it at s = S mm instead of the tip).
impl std::str::FromStr for Cable {
    type Err = SpatialError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let bad = |why: String| SpatialError::CableSpec { text: text.to_string(), why };
        let points = |key: &str, value: &str| -> Result<[f64; CONTROL_POINTS], SpatialError> {
            let v: Vec<f64> = value
                .split(',')
                .map(|x| x.trim().parse::<f64>().map_err(|_| bad(format!("{key}: '{}' is not a number", x.trim()))))
                .collect::<Result<_, _>>()?;
            v.try_into().map_err(|v: Vec<f64>| bad(format!("{key} needs {CONTROL_POINTS} control points, got {}", v.len())))
        };
        let number = |key: &str, value: &str| -> Result<f64, SpatialError> {
            value.trim().parse::<f64>().map_err(|_| bad(format!("{key}: '{value}' is not a number")))
        };
        let (mut y, mut z, mut tension, mut anchor) = (None, None, None, None);
        for field in text.split_whitespace() {
            let (key, value) = field.split_once('=').ok_or_else(|| bad(format!("'{field}' is not key=value")))?;
            let slot_taken = |taken: bool| if taken { Err(bad(format!("{key}= is given twice"))) } else { Ok(()) };
            match key {
                "y" => {
                    slot_taken(y.is_some())?;
                    y = Some(points(key, value)?);
                }
                "z" => {
                    slot_taken(z.is_some())?;
                    z = Some(points(key, value)?);
                }
                "tension" => {
                    slot_taken(tension.is_some())?;
                    tension = Some(number(key, value)?);
                }
                "anchor" => {
                    slot_taken(anchor.is_some())?;
                    anchor = Some(number(key, value)?);
                }
                other => return Err(bad(format!("unknown field '{other}' (fields: y, z, tension, anchor)"))),
            }
        }
        let y_mm = y.ok_or_else(|| bad("y= is missing".into()))?;
        let tension_n = tension.ok_or_else(|| bad("tension= is missing".into()))?;
        Ok(Cable { y_mm, z_mm: z.unwrap_or([0.0; CONTROL_POINTS]), tension_n, anchor_mm: anchor })
    }
}

/// The `--cable` form that [`Cable`]'s `FromStr` reads back to the same
/// cable bit for bit: `y=…` always, `z=…` only when out of plane, then
/// `tension=…` and `anchor=…` when knotted before the tip. Numbers are
/// Rust's shortest round-trip form.
impl std::fmt::Display for Cable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let list = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(",");
        write!(f, "y={}", list(&self.y_mm))?;
        if !self.is_planar() {
            write!(f, " z={}", list(&self.z_mm))?;
        }
        write!(f, " tension={}", self.tension_n)?;
        if let Some(anchor) = self.anchor_mm {
            write!(f, " anchor={anchor}")?;
        }
        Ok(())
    }
}

/// A `cablemap simulate` command line that solves an actuator again, and
/// what of it no flag can give.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateCommand {
    /// `cablemap simulate [rod flags] --cable "…" …`, ready to paste into a
    /// POSIX shell.
    pub text: String,
    /// Settings of the actuator or solver that differ from the defaults but
    /// have no flag (`gj_n_mm2 = 80`, …): the command solves with the default
    /// instead. Empty when the command reproduces the actuator exactly.
    pub missing: Vec<String>,
}

/// The `cablemap simulate` command of `actuator` solved with `options`:
/// a flag for each rod parameter that differs from the thesis's rod (the
/// defaults of `simulate`), `--gravity-direction`, `--steps-per-span`, and one
/// `--cable` per cable. Only what the 3-D solver models is written: it
/// refuses the planar solver's effects and bodies, so they are never set on
/// an actuator it solved.
pub fn simulate_command(actuator: &Actuator, options: &SpatialOptions) -> SimulateCommand {
    let rod = &actuator.rod;
    let thesis = crate::model::Rod::default();
    let mut flags: Vec<String> = Vec::new();
    let mut missing = Vec::new();
    for (flag, value, default) in [
        ("--length-mm", rod.length_mm, thesis.length_mm),
        ("--radius-mm", rod.radius_mm, thesis.radius_mm),
        ("--ea-n", rod.ea_n, thesis.ea_n),
        ("--ga-n", rod.ga_n, thesis.ga_n),
        ("--ei-n-mm2", rod.ei_n_mm2, thesis.ei_n_mm2),
        ("--density-g-cm3", rod.density_g_cm3, thesis.density_g_cm3),
        ("--gravity-direction-rad", rod.gravity.direction_rad, thesis.gravity.direction_rad),
        ("--gravity-scale", rod.gravity.scale, thesis.gravity.scale),
    ] {
        if value != default {
            flags.push(format!("{flag} {value}"));
        }
    }
    if !rod.gravity.enabled {
        flags.push("--no-gravity".into());
    }
    if rod.gravity.g_m_s2 != thesis.gravity.g_m_s2 {
        missing.push(format!("gravity.g_m_s2 = {}", rod.gravity.g_m_s2));
    }
    if let Some(gj) = actuator.gj_n_mm2 {
        missing.push(format!("gj_n_mm2 = {gj}"));
    }
    if let Some(g) = actuator.gravity_direction {
        flags.push(format!("--gravity-direction {},{},{}", g[0], g[1], g[2]));
    }
    let solver = SpatialOptions::default();
    if options.steps_per_span != solver.steps_per_span {
        flags.push(format!("--steps-per-span {}", options.steps_per_span));
    }
    if options.moment_tolerance_n_mm != solver.moment_tolerance_n_mm {
        missing.push(format!("solver.moment_tolerance_n_mm = {}", options.moment_tolerance_n_mm));
    }
    if options.max_passes != solver.max_passes {
        missing.push(format!("solver.max_passes = {}", options.max_passes));
    }
    // The cable text holds only digits, signs, '.', ',', '=', 'e' and spaces:
    // double quotes keep it one shell word.
    flags.extend(actuator.cables.iter().map(|c| format!("--cable \"{c}\"")));
    SimulateCommand { text: format!("cablemap simulate {}", flags.join(" ")), missing }
}

/// The JSON object of a spatial simulation (names in docs/schema.md). Keys
/// shared with the planar record mean the same; `a` is the in-plane series
/// (`a_bend_z`), the planar record's `a` for a planar rod.
pub fn simulation_json(sim: &SpatialSimulation) -> serde_json::Value {
    let p = &sim.pose;
    json!({
        "status": STATUS_OK,
        "cables": sim.actuator.cables,
        "tension_n": sim.actuator.cables.iter().map(|c| c.tension_n).collect::<Vec<_>>(),
        "gravity": sim.actuator.rod.gravity.enabled,
        "gravity_direction": sim.actuator.gravity_unit().ok(),
        "gj_n_mm2": sim.actuator.torsional_rigidity_n_mm2(),
        "tip_x_mm": p.tip_mm[0],
        "tip_y_mm": p.tip_mm[1],
        "tip_z_mm": p.tip_mm[2],
        "tip_tangent": p.tip_tangent,
        "tip_body_y_axis": p.tip_body_y_axis,
        "tip_angle_rad": p.tip_angle_rad,
        "length_mm": p.length_mm,
        "a": sim.a_bend_z,
        "a_bend_z": sim.a_bend_z,
        "a_bend_y": sim.a_bend_y,
        "a_twist": sim.a_twist,
        "length_basis": sim.length_basis,
        "iterations": p.passes,
    })
}

/// The human-readable report of `cablemap simulate` for several or spatial cables.
pub fn report(sim: &SpatialSimulation) -> String {
    let p = &sim.pose;
    let a = &sim.actuator;
    let mut out = String::new();
    let list = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ");
    for (i, c) in a.cables.iter().enumerate() {
        let anchor = c.anchor_mm.map_or(String::from("tip"), |s| format!("s = {s} mm"));
        let _ = writeln!(
            out,
            "cable {}        y [{}] mm, z [{}] mm, tension {:.6} N, anchor {anchor}",
            i + 1,
            list(&c.y_mm),
            list(&c.z_mm),
            c.tension_n
        );
    }
    let gravity = match (a.rod.gravity.enabled, a.gravity_unit()) {
        (true, Ok(g)) => format!("along ({:.4}, {:.4}, {:.4}), {:.4e} N/mm", g[0], g[1], g[2], a.rod.weight_n_per_mm()),
        _ => "off".into(),
    };
    let _ = writeln!(out, "gravity        {gravity}");
    let _ = writeln!(out, "torsion GJ     {:.4} N·mm²", a.torsional_rigidity_n_mm2());
    let _ = writeln!(out, "tip            x = {:.6} mm, y = {:.6} mm, z = {:.6} mm", p.tip_mm[0], p.tip_mm[1], p.tip_mm[2]);
    let t = p.tip_tangent;
    let _ = writeln!(out, "tip tangent    ({:.8}, {:.8}, {:.8}), {:.4}° from the clamp axis", t[0], t[1], t[2], p.tip_angle_rad.to_degrees());
    let b = p.tip_body_y_axis;
    let _ = writeln!(out, "tip body y     ({:.8}, {:.8}, {:.8})", b[0], b[1], b[2]);
    let _ = writeln!(out, "length ℓ       {:.6} mm", p.length_mm);
    let _ = writeln!(out, "coefficients   {} (bend z: in the x–y plane; bend y: out of it; twist: u_1)", sim.length_basis.describe());
    for i in 0..sim.a_bend_z.len() {
        let _ = writeln!(
            out,
            "a_{i:<12} bend z {:>15.8e}   bend y {:>15.8e}   twist {:>15.8e} mm^-1",
            sim.a_bend_z[i], sim.a_bend_y[i], sim.a_twist[i]
        );
    }
    let _ = writeln!(out, "iterations     {} integration pass(es)", p.passes);
    out
}

/// The 3-D centreline CSV: one row per solver node (clamp to tip) with the
/// position, frame, strains and each cable's global path point.
pub fn centreline_csv(sim: &SpatialSimulation) -> String {
    let mut out = String::from(
        "s_mm,x_mm,y_mm,z_mm,arc_length_mm,v1,v2,v3,u1_per_mm,u2_per_mm,u3_per_mm,body_y_x,body_y_y,body_y_z",
    );
    let n = sim.actuator.cables.len();
    for i in 1..=n {
        let _ = write!(out, ",cable{i}_x_mm,cable{i}_y_mm,cable{i}_z_mm");
    }
    out.push('\n');
    let paths = sim.cable_paths_mm();
    for (k, node) in sim.nodes.iter().enumerate() {
        let r = node.rotation;
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            node.s_mm,
            node.p_mm[0],
            node.p_mm[1],
            node.p_mm[2],
            node.arc_length_mm,
            node.v[0],
            node.v[1],
            node.v[2],
            node.u_per_mm[0],
            node.u_per_mm[1],
            node.u_per_mm[2],
            r[0][1],
            r[1][1],
            r[2][1]
        );
        for path in &paths {
            let q = path[k];
            let _ = write!(out, ",{},{},{}", q[0], q[1], q[2]);
        }
        out.push('\n');
    }
    out
}

/// Writes [`centreline_csv`] to `path` (atomically).
pub fn write_centreline_csv(path: &std::path::Path, sim: &SpatialSimulation) -> std::io::Result<()> {
    crate::io::write_atomic(path, centreline_csv(sim).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cable_text_form_parses_and_names_its_problems() {
        let c: Cable = "y=1,2,3,2,1 z=0,-1,-2,-1,0 tension=1.5".parse().unwrap();
        assert_eq!(c.y_mm, [1.0, 2.0, 3.0, 2.0, 1.0]);
        assert_eq!(c.z_mm, [0.0, -1.0, -2.0, -1.0, 0.0]);
        assert_eq!(c.tension_n, 1.5);
        assert_eq!(c.anchor_mm, None);
        let planar: Cable = "tension=2 y=-1,-1,-1,-1,-1 anchor=40".parse().unwrap();
        assert!(planar.is_planar());
        assert_eq!(planar.anchor_mm, Some(40.0));
        for (text, needle) in [
            ("y=1,2,3 tension=1", "5 control points, got 3"),
            ("y=1,2,3,4,5", "tension= is missing"),
            ("z=1,2,3,4,5 tension=1", "y= is missing"),
            ("y=1,2,x,4,5 tension=1", "'x' is not a number"),
            ("y=1,2,3,4,5 tension=1 colour=red", "unknown field 'colour'"),
            ("y=1,2,3,4,5 tension=1 tension=2", "given twice"),
            ("y=1,2,3,4,5 tension", "not key=value"),
        ] {
            let e = text.parse::<Cable>().unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
            assert!(e.contains("cable \""), "{e}");
        }
    }

    #[test]
    fn a_cables_text_form_reads_back_to_the_same_cable() {
        for c in [
            Cable::planar([3.0, 1.0, 2.5, 1.0, 3.0], 1.8000000000000003),
            Cable { y_mm: [0.1, -0.2, 0.3, 1e-7, 4.0], z_mm: [0.0, 1.0, -1.5, 0.0, 2.0], tension_n: 0.6, anchor_mm: Some(40.25) },
        ] {
            assert_eq!(c.to_string().parse::<Cable>().unwrap(), c, "{c}");
        }
        assert_eq!(Cable::planar([3.0, 1.0, 1.0, 1.0, 3.0], 1.8).to_string(), "y=3,1,1,1,3 tension=1.8");
    }

    #[test]
    fn the_simulate_command_gives_what_differs_from_the_thesis_rod() {
        let mut a = Actuator::with_cables(crate::model::Rod::default(), vec![Cable::planar([3.0; 5], 1.0), Cable::planar([-3.0; 5], 0.5)]);
        let plain = simulate_command(&a, &SpatialOptions::default());
        assert_eq!(plain.text, r#"cablemap simulate --cable "y=3,3,3,3,3 tension=1" --cable "y=-3,-3,-3,-3,-3 tension=0.5""#);
        assert!(plain.missing.is_empty());
        a.rod.ei_n_mm2 = 90.5;
        a.rod.gravity.enabled = false;
        a.gj_n_mm2 = Some(80.0);
        let options = SpatialOptions { steps_per_span: 16, ..SpatialOptions::default() };
        let c = simulate_command(&a, &options);
        assert!(c.text.starts_with("cablemap simulate --ei-n-mm2 90.5 --no-gravity --steps-per-span 16 --cable "), "{}", c.text);
        assert_eq!(c.missing, ["gj_n_mm2 = 80"]);
    }
}
