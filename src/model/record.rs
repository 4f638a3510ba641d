//! The files and records `cablemap simulate` writes for other tools: the
//! one-line JSON record of a solve (its field names are shared with the sweep's
//! columns) and the centreline CSV. This module owns both formats: their field
//! and column names, writers and readers.

use super::routing::ControlPoints;
use super::{CentrelinePoint, Simulation, TipPose, STATUS_OK};
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One solve as other tools read it (`cablemap simulate --json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulationRecord {
    /// Always [`STATUS_OK`]: failed solves are errors, not records.
    pub status: String,
    /// Routing control points y_0..y_4, mm.
    pub routing_mm: ControlPoints,
    /// Tension, tip pose, deformed length and integration passes (their
    /// fields appear at the top level of the record).
    #[serde(flatten)]
    pub pose: TipPose,
    /// Curvature coefficients a_0..a_n, mm⁻¹, in `length_basis`.
    pub a: Vec<f64>,
    /// The length the coefficients are per unit of.
    pub length_basis: LengthBasis,
}

impl From<&Simulation> for SimulationRecord {
    fn from(sim: &Simulation) -> Self {
        SimulationRecord {
            status: STATUS_OK.to_string(),
            routing_mm: sim.routing_mm,
            pose: sim.pose,
            a: sim.a.clone(),
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

/// The centreline CSV text: a header of [`CENTRELINE_COLUMNS`], one row per
/// solver node (numbers printed so they read back exactly). For a cable
/// anchored before the tip, a row lies exactly at the anchor, where the
/// cable's path ends, and the rows beyond it leave `channel_y_mm`,
/// `cable_x_mm` and `cable_y_mm` empty.
pub fn centreline_csv(centreline: &[CentrelinePoint]) -> String {
    // The solver marks "no channel or cable here" by NaN.
    let cable = |v: f64| if v.is_nan() { String::new() } else { v.to_string() };
    let mut out = CENTRELINE_COLUMNS.join(",");
    out.push('\n');
    for c in centreline {
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}\n",
            c.s_mm,
            c.x_mm,
            c.y_mm,
            c.frame_angle_rad,
            c.tangent_angle_rad,
            c.arc_length_mm,
            c.v1,
            c.v2,
            c.u_per_mm,
            cable(c.channel_y_mm),
            cable(c.cable_x_mm),
            cable(c.cable_y_mm)
        ));
    }
    out
}

/// Writes the centreline CSV of `sim` to `path` atomically.
pub fn write_centreline_csv(path: &Path, sim: &Simulation) -> std::io::Result<()> {
    crate::io::write_atomic(path, centreline_csv(&sim.centreline).as_bytes())
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

/// Reads a centreline CSV written by [`write_centreline_csv`]: one row of the
/// 12 columns per node, in order (the cable tension is not in the file and
/// reads as NaN, as do the empty channel and cable fields beyond an anchor).
pub fn read_centreline_csv(path: &Path) -> Result<Vec<CentrelinePoint>, CentrelineCsvError> {
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
        points.push(CentrelinePoint {
            s_mm: v[0],
            x_mm: v[1],
            y_mm: v[2],
            frame_angle_rad: v[3],
            tangent_angle_rad: v[4],
            arc_length_mm: v[5],
            v1: v[6],
            v2: v[7],
            u_per_mm: v[8],
            channel_y_mm: v[9],
            cable_x_mm: v[10],
            cable_y_mm: v[11],
            cable_tension_n: f64::NAN,
        });
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{simulate, Rod, Routing, SolverOptions};

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
        write_centreline_csv(&path, &sim).unwrap();
        let back = read_centreline_csv(&path).unwrap();
        assert_eq!(back.len(), sim.centreline.len());
        for (b, c) in back.iter().zip(&sim.centreline) {
            assert_eq!((b.s_mm, b.x_mm, b.y_mm, b.u_per_mm, b.cable_y_mm), (c.s_mm, c.x_mm, c.y_mm, c.u_per_mm, c.cable_y_mm));
        }
        std::fs::write(&path, "s,x\n1,2\n").unwrap();
        assert!(matches!(read_centreline_csv(&path), Err(CentrelineCsvError::Header { .. })));
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
        let text = centreline_csv(&sim.centreline);
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
        write_centreline_csv(&path, &sim).unwrap();
        let back = read_centreline_csv(&path).unwrap();
        for (b, c) in back.iter().zip(&sim.centreline) {
            assert_eq!((b.s_mm, b.x_mm, b.y_mm), (c.s_mm, c.x_mm, c.y_mm));
            let same = |p: f64, q: f64| p == q || (p.is_nan() && q.is_nan());
            assert!(same(b.cable_x_mm, c.cable_x_mm) && same(b.channel_y_mm, c.channel_y_mm), "at s = {}", c.s_mm);
        }
        // An empty field anywhere else is still an error.
        std::fs::write(&path, text.replacen(&format!("\n{},", rows[1][0]), "\n,", 1)).unwrap();
        assert!(matches!(read_centreline_csv(&path), Err(CentrelineCsvError::Row { .. })));
    }

    #[test]
    fn record_round_trips_through_json() {
        let record = SimulationRecord::from(&solve());
        let back: SimulationRecord = serde_json::from_str(&record.to_json_line()).unwrap();
        assert_eq!(back, record);
        assert!(record.to_json_line().starts_with("{\"a\":["), "keys are sorted");
    }
}
