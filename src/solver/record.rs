//! What a simulation writes for other tools and for people, for every
//! backend: this module owns the formats (field and column names, writers
//! and readers; docs/schema.md describes them).
//!
//! - The planar record (`simulate --routing … --json`, [`SimulationRecord`]):
//!   one line of JSON whose field names are shared with the sweep's columns;
//!   `tip_angle_rad` is the signed, continuous tangent angle θ(L).
//! - The actuator record (`simulate --cable …`/`--actuator … --json`,
//!   [`simulation_json`]) and its text report ([`report`]): every cable,
//!   the tip in 3-D, the three coefficient series; `tip_angle_rad` there is
//!   the unsigned angle of the tip tangent from the clamp axis.
//! - The planar centreline CSV ([`planar_centreline_csv`], 12 columns, read
//!   back by [`read_planar_centreline_csv`]) and the actuator's 3-D
//!   centreline CSV ([`actuator_centreline_csv`], every cable's path). Both
//!   leave a cable's fields empty beyond its anchor.
//! - The `cablemap simulate` command that solves an actuator again
//!   ([`simulate_command`]).

use crate::model::routing::ControlPoints;
use super::SolverOptions;
use crate::model::Actuator;
use super::{CentrelinePoint, Simulation, STATUS_OK};
use crate::solver::result::PlanarPoint;
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;

/// One planar solve as other tools read it (`cablemap simulate --json` with
/// `--routing`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulationRecord {
    /// Always [`STATUS_OK`]: failed solves are errors, not records.
    pub status: String,
    /// Routing control points y_0..y_4, mm.
    pub routing_mm: ControlPoints,
    /// Tension, N (of a displacement-driven cable, the tension found).
    pub tension_n: f64,
    /// The cable's displacement Δℓ at the base, mm: the pulled-in length
    /// (its path's shortening plus its stretch); the command of a
    /// displacement-driven cable, the displacement a tension produced
    /// otherwise. `null` from the RK4 method, which does not integrate the
    /// cable's path.
    #[serde(default)]
    pub displacement_mm: Option<f64>,
    /// Tip position along the clamp axis, mm.
    pub tip_x_mm: f64,
    /// Tip position across the clamp axis, mm.
    pub tip_y_mm: f64,
    /// Tangent angle θ(L) of the centreline at the tip from the clamp axis,
    /// rad: signed, continuous from the clamp (not wrapped).
    pub tip_angle_rad: f64,
    /// Angle of the tip cross-section's axis (frame angle φ(L)), rad.
    pub tip_frame_angle_rad: f64,
    /// Tangent angle of the centreline at the clamp, rad.
    pub base_angle_rad: f64,
    /// Deformed arc length ℓ of the centreline, mm.
    pub length_mm: f64,
    /// Integration passes used.
    pub iterations: u32,
    /// Curvature coefficients a_0..a_n, mm⁻¹, in `length_basis` (the
    /// in-plane series a_bend_z).
    pub a: Vec<f64>,
    /// The length the coefficients are per unit of.
    pub length_basis: LengthBasis,
}

impl From<&Simulation> for SimulationRecord {
    fn from(sim: &Simulation) -> Self {
        let p = &sim.pose;
        SimulationRecord {
            status: STATUS_OK.to_string(),
            routing_mm: sim.routing_mm(),
            tension_n: p.tension_n(),
            displacement_mm: Some(p.displacement_mm()).filter(|d| d.is_finite()),
            tip_x_mm: p.tip_x_mm,
            tip_y_mm: p.tip_y_mm,
            tip_angle_rad: p.tip_angle_rad,
            tip_frame_angle_rad: p.tip_frame_angle_rad,
            base_angle_rad: p.base_angle_rad,
            length_mm: p.length_mm,
            iterations: p.iterations,
            a: sim.a_bend_z.clone(),
            length_basis: sim.length_basis,
        }
    }
}

impl SimulationRecord {
    /// The record as one line of JSON, keys in alphabetical order.
    pub fn to_json_line(&self) -> String {
        // Through a Value: its map keeps keys sorted, the order this record
        // has always been printed in.
        serde_json::to_value(self).expect("records serialise").to_string()
    }
}

/// Columns of the centreline CSV, in order.
pub const CENTRELINE_COLUMNS: [&str; 12] = [
    "s_mm",
    "x_mm",
    "y_mm",
    "frame_angle_rad",
    "tangent_angle_rad",
    "arc_length_mm",
    "v1",
    "v2",
    "u_per_mm",
    "channel_y_mm",
    "cable_x_mm",
    "cable_y_mm",
];

/// The columns of the channel and the cable ([`CENTRELINE_COLUMNS`]' last
/// three): empty in the rows beyond a cable's anchor, where there is neither.
const CABLE_COLUMNS: std::ops::Range<usize> = 9..12;

/// The planar centreline CSV text: a header of [`CENTRELINE_COLUMNS`], one
/// row per solver node (numbers printed so they read back exactly), cable 1
/// in the plane. For a cable anchored before the tip, a row lies exactly at
/// the anchor, where the cable's path ends, and the rows beyond it leave
/// `channel_y_mm`, `cable_x_mm` and `cable_y_mm` empty.
pub fn planar_centreline_csv(centreline: &[CentrelinePoint]) -> String {
    let mut out = CENTRELINE_COLUMNS.join(",");
    out.push('\n');
    for c in centreline {
        let cable = &c.cables[0];
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            c.s_mm,
            c.x_mm,
            c.y_mm,
            c.frame_angle_rad,
            c.tangent_angle_rad,
            c.arc_length_mm,
            c.v[0],
            c.v[1],
            c.u_per_mm[2],
            cable_field(cable.channel_mm[0]),
            cable_field(cable.position_mm[0]),
            cable_field(cable.position_mm[1])
        ));
    }
    out
}

/// A cable's coordinate in a CSV: empty where there is no cable (the
/// solver's NaN beyond its anchor), else the number read back exactly.
fn cable_field(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        v.to_string()
    }
}

/// Writes the planar centreline CSV of `sim` to `path` atomically.
pub fn write_planar_centreline_csv(path: &Path, sim: &Simulation) -> std::io::Result<()> {
    crate::io::write_atomic(path, planar_centreline_csv(&sim.centreline).as_bytes())
}

/// Why a centreline CSV could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CentrelineCsvError {
    /// The file could not be read.
    #[error("reading centreline CSV {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The header is not [`CENTRELINE_COLUMNS`].
    #[error("centreline CSV {path}: header is not {expected}; write it with `cablemap simulate --csv`")]
    Header {
        /// The file.
        path: String,
        /// The expected header.
        expected: String,
    },
    /// A row has the wrong number of fields or a non-number.
    #[error("centreline CSV {path}, line {line}: {problem}")]
    Row {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        problem: String,
    },
}

/// Reads a centreline CSV written by [`write_planar_centreline_csv`]: one
/// row of the 12 columns per node, in order (the cable tension is not in
/// the file and reads as NaN, as do the empty channel and cable fields
/// beyond an anchor; the cable's position follows from the channel).
pub fn read_planar_centreline_csv(path: &Path) -> Result<Vec<CentrelinePoint>, CentrelineCsvError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CentrelineCsvError::Io { path: name.clone(), source })?;
    let mut lines = text.lines();
    let expected = CENTRELINE_COLUMNS.join(",");
    if lines.next().map(str::trim) != Some(expected.as_str()) {
        return Err(CentrelineCsvError::Header { path: name, expected });
    }
    let mut points = Vec::new();
    for (i, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let row = |problem: String| CentrelineCsvError::Row { path: name.clone(), line: i + 2, problem };
        let v: Vec<f64> = line
            .split(',')
            .enumerate()
            .map(|(column, f)| match f.trim() {
                "" if CABLE_COLUMNS.contains(&column) => Ok(f64::NAN),
                f => f.parse::<f64>().map_err(|_| row(format!("'{f}' is not a number"))),
            })
            .collect::<Result<_, _>>()?;
        if v.len() != CENTRELINE_COLUMNS.len() {
            return Err(row(format!("{} fields, expected {}", v.len(), CENTRELINE_COLUMNS.len())));
        }
        let mut point = CentrelinePoint::from(PlanarPoint {
            s_mm: v[0],
            x_mm: v[1],
            y_mm: v[2],
            frame_angle_rad: v[3],
            frame_sin_cos: v[3].sin_cos(),
            tangent_angle_rad: v[4],
            arc_length_mm: v[5],
            v1: v[6],
            v2: v[7],
            u_per_mm: v[8],
            channel_y_mm: v[9],
            cable_tension_n: f64::NAN,
        });
        // The cable's position as written (exactly, not recomputed).
        point.cables[0].position_mm[0] = v[10];
        point.cables[0].position_mm[1] = v[11];
        points.push(point);
    }
    Ok(points)
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
pub fn simulate_command(actuator: &Actuator, options: &SolverOptions) -> SimulateCommand {
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
    if rod.rest_curvature_per_mm != 0.0 {
        missing.push(format!("rest_curvature_per_mm = {}", rod.rest_curvature_per_mm));
    }
    if let Some(g) = actuator.gravity_direction {
        flags.push(format!("--gravity-direction {},{},{}", g[0], g[1], g[2]));
    }
    let solver = SolverOptions::default();
    if options.spatial_steps_per_span != solver.spatial_steps_per_span {
        flags.push(format!("--steps-per-span {}", options.spatial_steps_per_span));
    }
    if options.spatial_moment_tolerance_n_mm != solver.spatial_moment_tolerance_n_mm {
        missing.push(format!("solver.moment_tolerance_n_mm = {}", options.spatial_moment_tolerance_n_mm));
    }
    if options.spatial_max_passes != solver.spatial_max_passes {
        missing.push(format!("solver.max_passes = {}", options.spatial_max_passes));
    }
    // The cable text holds only digits, signs, '.', ',', '=', 'e' and spaces:
    // double quotes keep it one shell word.
    flags.extend(actuator.cables.iter().map(|c| format!("--cable \"{c}\"")));
    SimulateCommand { text: format!("cablemap simulate {}", flags.join(" ")), missing }
}

/// The actuator record: the JSON object of a simulation given by its
/// cables (names in docs/schema.md). Keys shared with the planar record mean
/// the same, except `tip_angle_rad`, here the unsigned angle of the tip
/// tangent from the clamp axis ([`crate::solver::TipPose::angle_from_clamp_axis_rad`]);
/// `a` is the in-plane series (`a_bend_z`), the planar record's `a` for a
/// planar rod.
pub fn simulation_json(sim: &Simulation) -> serde_json::Value {
    let p = &sim.pose;
    json!({
        "status": STATUS_OK,
        "cables": sim.actuator.cables,
        "tension_n": p.tensions_n.to_vec(),
        "displacement_mm": p.displacements_mm.iter().map(|&d| Some(d).filter(|d| d.is_finite())).collect::<Vec<_>>(),
        "gravity": sim.actuator.rod.gravity.enabled,
        "gravity_direction": sim.actuator.gravity_unit().ok(),
        "gj_n_mm2": sim.actuator.torsional_rigidity_n_mm2(),
        "tip_x_mm": p.tip_x_mm,
        "tip_y_mm": p.tip_y_mm,
        "tip_z_mm": p.tip_z_mm,
        "tip_tangent": p.tip_tangent(),
        "tip_body_y_axis": p.tip_body_y_axis(),
        "tip_angle_rad": p.angle_from_clamp_axis_rad(),
        "length_mm": p.length_mm,
        "a": sim.a_bend_z,
        "a_bend_z": sim.a_bend_z,
        "a_bend_y": sim.a_bend_y,
        "a_twist": sim.a_twist,
        "length_basis": sim.length_basis,
        "iterations": p.iterations,
    })
}

/// The human-readable report of `cablemap simulate --routing …`: one
/// planar cable (its routing, tension and displacement, the tip, angles,
/// length and a_i of the in-plane series).
pub fn planar_report(sim: &Simulation) -> String {
    let p = &sim.pose;
    let rod = &sim.actuator.rod;
    let mut out = String::new();
    let list = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ");
    let _ = writeln!(out, "routing        [{}] mm", list(&sim.routing_mm().0));
    let _ = writeln!(out, "tension        {:.6} N   (gravity {})", p.tension_n(), if rod.gravity.enabled { "on" } else { "off" });
    let given = sim.actuator.cables.first().is_some_and(|c| c.displacement_mm.is_some());
    let _ = match p.displacement_mm() {
        d if !d.is_finite() => writeln!(out, "displacement   not integrated by the RK4 method"),
        d if given => writeln!(out, "displacement   {d:.6} mm (given; the tension above is found)"),
        d => writeln!(out, "displacement   {d:.6} mm (pulled in at the base)"),
    };
    let _ = writeln!(out, "tip            x = {:.6} mm, y = {:.6} mm", p.tip_x_mm, p.tip_y_mm);
    let _ = writeln!(out, "tip angle      {:.8} rad ({:.4}°)", p.tip_angle_rad, p.tip_angle_rad.to_degrees());
    let _ = writeln!(out, "base angle     {:.8} rad ({:.4}°)", p.base_angle_rad, p.base_angle_rad.to_degrees());
    let _ = writeln!(out, "length ℓ       {:.6} mm", p.length_mm);
    let _ = writeln!(out, "coefficients   a_i {}", sim.length_basis.describe());
    for (i, a) in sim.a_bend_z.iter().enumerate() {
        let _ = writeln!(out, "a_{i:<12} {a:.8e} mm^-1");
    }
    let _ = writeln!(out, "iterations     {} integration pass(es)", p.iterations);
    out
}

/// The human-readable report of `cablemap simulate` for an actuator given by
/// its cables.
pub fn report(sim: &Simulation) -> String {
    let p = &sim.pose;
    let a = &sim.actuator;
    let mut out = String::new();
    let list = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ");
    for (i, c) in a.cables.iter().enumerate() {
        let anchor = c.anchor_mm.map_or(String::from("tip"), |s| format!("s = {s} mm"));
        // Both actuations, the given one first.
        let (tension, displacement) = (p.tensions_n[i], p.displacements_mm[i]);
        let displacement = if displacement.is_finite() { format!("{displacement:.6} mm") } else { "not integrated (RK4)".into() };
        let actuation = match c.displacement_mm {
            Some(_) => format!("displacement {displacement} (given), tension {tension:.6} N"),
            None => format!("tension {tension:.6} N, displacement {displacement}"),
        };
        let _ = writeln!(out, "cable {}        y [{}] mm, z [{}] mm, {actuation}, anchor {anchor}", i + 1, list(&c.y_mm), list(&c.z_mm));
    }
    let gravity = match (a.rod.gravity.enabled, a.gravity_unit()) {
        (true, Ok(g)) => format!("along ({:.4}, {:.4}, {:.4}), {:.4e} N/mm", g[0], g[1], g[2], a.rod.weight_n_per_mm()),
        _ => "off".into(),
    };
    let _ = writeln!(out, "gravity        {gravity}");
    let _ = writeln!(out, "torsion GJ     {:.4} N·mm²", a.torsional_rigidity_n_mm2());
    let _ = writeln!(out, "tip            x = {:.6} mm, y = {:.6} mm, z = {:.6} mm", p.tip_x_mm, p.tip_y_mm, p.tip_z_mm);
    let t = p.tip_tangent();
    let _ = writeln!(out, "tip tangent    ({:.8}, {:.8}, {:.8}), {:.4}° from the clamp axis", t[0], t[1], t[2], p.angle_from_clamp_axis_rad().to_degrees());
    let b = p.tip_body_y_axis();
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
    let _ = writeln!(out, "iterations     {} integration pass(es)", p.iterations);
    out
}

/// The actuator's 3-D centreline CSV: one row per solver node (clamp to
/// tip) with the position, frame, strains and each cable's global path
/// point, empty beyond the cable's anchor (a row lies exactly at it).
pub fn actuator_centreline_csv(sim: &Simulation) -> String {
    let mut out = String::from(
        "s_mm,x_mm,y_mm,z_mm,arc_length_mm,v1,v2,v3,u1_per_mm,u2_per_mm,u3_per_mm,body_y_x,body_y_y,body_y_z",
    );
    let n = sim.actuator.cables.len();
    for i in 1..=n {
        let _ = write!(out, ",cable{i}_x_mm,cable{i}_y_mm,cable{i}_z_mm");
    }
    out.push('\n');
    for node in &sim.centreline {
        let r = node.rotation;
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            node.s_mm,
            node.x_mm,
            node.y_mm,
            node.z_mm,
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
        for cable in node.cables.iter() {
            let q = cable.position_mm;
            let _ = write!(out, ",{},{},{}", cable_field(q[0]), cable_field(q[1]), cable_field(q[2]));
        }
        out.push('\n');
    }
    out
}

/// Writes [`actuator_centreline_csv`] to `path` (atomically).
pub fn write_actuator_centreline_csv(path: &Path, sim: &Simulation) -> std::io::Result<()> {
    crate::io::write_atomic(path, actuator_centreline_csv(sim).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Cable, Rod, Routing};
    use crate::solver::{simulate, SolverOptions};

    fn solve() -> Simulation {
        let a = Rod::default();
        let routing = Routing::new(&[0.0, 1.0, -2.0, 3.0, 0.5], a.length_mm, a.radius_mm).unwrap();
        simulate(&a, &SolverOptions::default(), &routing, 1.5, 3, LengthBasis::Rest).unwrap()
    }

    #[test]
    fn centreline_csv_reads_back_exactly() {
        let sim = solve();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.csv");
        write_planar_centreline_csv(&path, &sim).unwrap();
        let back = read_planar_centreline_csv(&path).unwrap();
        assert_eq!(back.len(), sim.centreline.len());
        for (b, c) in back.iter().zip(&sim.centreline) {
            assert_eq!((b.s_mm, b.x_mm, b.y_mm, b.u_per_mm, b.cables[0].position_mm), (c.s_mm, c.x_mm, c.y_mm, c.u_per_mm, c.cables[0].position_mm));
        }
        std::fs::write(&path, "s,x\n1,2\n").unwrap();
        assert!(matches!(read_planar_centreline_csv(&path), Err(CentrelineCsvError::Header { .. })));
    }

    /// A cable knotted before the tip: its path ends on a row exactly at the
    /// anchor, and beyond it the channel and cable columns are empty (not the
    /// centreline, as if the cable ran on to the tip).
    #[test]
    fn an_anchored_cable_ends_at_its_anchor_in_the_csv() {
        let anchor_mm = 45.3;
        let a = Rod { cable_anchor_mm: Some(anchor_mm), ..Rod::default() };
        let routing = Routing::for_actuator([0.0, 1.0, -2.0, 3.0, 0.5], &a).unwrap();
        let sim = simulate(&a, &SolverOptions::default(), &routing, 1.5, 3, LengthBasis::Rest).unwrap();
        let text = planar_centreline_csv(&sim.centreline);
        let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
        let at = rows.iter().position(|r| r[0].parse::<f64>().unwrap() == anchor_mm).expect("a row exactly at the anchor");
        let end = routing.channel_at(anchor_mm).y_mm;
        assert_eq!(rows[at][9].parse::<f64>().unwrap(), end, "the channel's offset at the anchor");
        for (i, r) in rows.iter().enumerate() {
            let cable_fields = &r[9..12];
            if i <= at {
                assert!(cable_fields.iter().all(|f| f.parse::<f64>().is_ok()), "row {i}: {r:?}");
            } else {
                assert!(cable_fields.iter().all(|f| f.is_empty()), "row {i} lies beyond the anchor: {r:?}");
            }
        }
        assert!(at + 1 < rows.len() && (rows.last().unwrap()[0].parse::<f64>().unwrap() - a.length_mm).abs() < 1e-9);
        // The empty fields read back as NaN, the rest exactly.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.csv");
        write_planar_centreline_csv(&path, &sim).unwrap();
        let back = read_planar_centreline_csv(&path).unwrap();
        for (b, c) in back.iter().zip(&sim.centreline) {
            assert_eq!((b.s_mm, b.x_mm, b.y_mm), (c.s_mm, c.x_mm, c.y_mm));
            let same = |p: f64, q: f64| p == q || (p.is_nan() && q.is_nan());
            let (bc, cc) = (&b.cables[0], &c.cables[0]);
            assert!(same(bc.position_mm[0], cc.position_mm[0]) && same(bc.channel_mm[0], cc.channel_mm[0]), "at s = {}", c.s_mm);
        }
        // An empty field anywhere else is still an error.
        std::fs::write(&path, text.replacen(&format!("\n{},", rows[1][0]), "\n,", 1)).unwrap();
        assert!(matches!(read_planar_centreline_csv(&path), Err(CentrelineCsvError::Row { .. })));
    }

    #[test]
    fn record_round_trips_through_json() {
        let record = SimulationRecord::from(&solve());
        let back: SimulationRecord = serde_json::from_str(&record.to_json_line()).unwrap();
        assert_eq!(back, record);
        assert!(record.to_json_line().starts_with("{\"a\":["), "keys are sorted");
    }

    #[test]
    fn the_simulate_command_gives_what_differs_from_the_thesis_rod() {
        let mut a = Actuator::with_cables(crate::model::Rod::default(), vec![Cable::planar([3.0; 5], 1.0), Cable::planar([-3.0; 5], 0.5)]);
        let plain = simulate_command(&a, &SolverOptions::default());
        assert_eq!(plain.text, r#"cablemap simulate --cable "y=3,3,3,3,3 tension=1" --cable "y=-3,-3,-3,-3,-3 tension=0.5""#);
        assert!(plain.missing.is_empty());
        a.rod.ei_n_mm2 = 90.5;
        a.rod.gravity.enabled = false;
        a.gj_n_mm2 = Some(80.0);
        let options = SolverOptions { spatial_steps_per_span: 16, ..SolverOptions::default() };
        let c = simulate_command(&a, &options);
        assert!(c.text.starts_with("cablemap simulate --ei-n-mm2 90.5 --no-gravity --steps-per-span 16 --cable "), "{}", c.text);
        assert_eq!(c.missing, ["gj_n_mm2 = 80"]);
    }

    /// Beyond an anchor both centreline CSVs leave the cable's fields empty,
    /// with a row exactly at the anchor: the planar one of `--routing` and
    /// the actuator's of `--cable`, whichever backend solved it.
    #[test]
    fn both_centreline_csvs_end_an_anchored_cable_at_its_anchor() {
        let anchor_mm = 40.0;
        let y = [0.0, 1.0, 2.0, 3.0, 4.0];
        let planar = Actuator::with_cables(Rod::default(), vec![Cable { anchor_mm: Some(anchor_mm), ..Cable::planar(y, 1.2) }]);
        let mut two = planar.clone();
        two.cables.push(Cable::planar([-1.0; 5], 0.5));
        for actuator in [planar, two] {
            let sim = crate::solver::simulate_actuator(
                &actuator,
                &SolverOptions::default(),
                crate::solver::Given::default(),
                None,
                3,
                LengthBasis::Rest,
            )
            .unwrap();
            let text = actuator_centreline_csv(&sim);
            let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
            let at = rows.iter().position(|r| r[0].parse::<f64>().unwrap() == anchor_mm).expect("a row at the anchor");
            for (i, r) in rows.iter().enumerate() {
                let cable_1 = &r[14..17];
                if i <= at {
                    assert!(cable_1.iter().all(|f| f.parse::<f64>().is_ok()), "{:?}, row {i}: {r:?}", sim.backend);
                } else {
                    assert!(cable_1.iter().all(|f| f.is_empty()), "{:?}, row {i} lies beyond the anchor: {r:?}", sim.backend);
                }
                // A cable knotted at the tip runs to the tip.
                assert!(r[17..].iter().all(|f| f.parse::<f64>().is_ok()), "{r:?}");
            }
            assert!(at + 1 < rows.len());
            if actuator.cables.len() == 1 {
                // The planar CSV of the same solve agrees.
                let planar_rows: Vec<String> = planar_centreline_csv(&sim.centreline).lines().skip(1).map(String::from).collect();
                assert_eq!(planar_rows.len(), rows.len());
                assert!(planar_rows[at + 1].ends_with(",,,"), "{}", planar_rows[at + 1]);
            }
        }
    }
}
