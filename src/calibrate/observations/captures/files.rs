//! The several-cable measurement files (docs/measurements.md, "Captures and
//! 3-D markers"): a captures file, one row per capture with one actuation
//! column per cable, and a markers file, body-fixed points measured in 3-D
//! in the clamp frame. CSV or Parquet, read through the planar files' one
//! table of text cells, so every error names the file, the row and the
//! column.

use crate::model::Actuator;
use crate::calibrate::error::RowConflict;
use crate::calibrate::data::{check_unique_columns, column_index, read_table, Cells, Direction, Table};
use crate::calibrate::{CalibrateError, HoldoutError};
use std::collections::BTreeMap;
use std::path::Path;

pub use crate::model::Actuation;

/// One capture: a static (or protocol) reading with every cable's actuation.
#[derive(Debug, Clone, PartialEq)]
pub struct Capture {
    /// Measurement id (unique in the file).
    pub measurement: i64,
    /// Each cable's actuation, cables 1 … K in the actuator's order.
    pub actuation: Vec<Actuation>,
    /// How the reading was reached (friction's direction; `static`: an
    /// independent capture from a virgin rod).
    pub direction: Direction,
    /// Protocol step (the row's order when the file has no `step` column).
    pub step: i64,
    /// Time held before the reading, s (creep).
    pub dwell_s: f64,
    /// Data row (from 1), for messages.
    pub row: usize,
}

impl Capture {
    /// Each cable's tension, N (0 for a displacement-driven cable, whose
    /// tension the solve finds).
    pub fn tensions_n(&self) -> Vec<f64> {
        self.actuation.iter().map(|a| if let Actuation::Tension(t) = a { *t } else { 0.0 }).collect()
    }

    /// The cables that pull (tension or displacement above 0), 1-based.
    pub fn pulling_cables(&self) -> Vec<usize> {
        self.actuation
            .iter()
            .enumerate()
            .filter(|(_, a)| matches!(a, Actuation::Tension(v) | Actuation::Displacement(v) if *v > 0.0))
            .map(|(i, _)| i + 1)
            .collect()
    }

    /// The largest actuation, in its own unit (orders captures in a chain).
    pub fn magnitude(&self) -> f64 {
        self.actuation.iter().map(|a| match a {
            Actuation::Tension(v) | Actuation::Displacement(v) => *v,
        }).fold(0.0, f64::max)
    }
}

/// One body-fixed point measured in one capture: the point at rest arc
/// length `s_mm` with body-frame offsets (`offset_y_mm`, `offset_z_mm`)
/// from the centreline, measured at (`x_mm`, `y_mm`, `z_mm`) in the clamp
/// frame. A point beyond the tip (s > L) sits on the tip cross-section's
/// rigid extension: p(L) + R(L) (s − L, y, z).
#[derive(Debug, Clone, PartialEq)]
pub struct MarkerReading {
    /// The marker's name (`p1`, `tip`, …).
    pub marker: String,
    /// Rest arc length from the clamp, mm.
    pub s_mm: f64,
    /// Offset along the body y axis, mm.
    pub offset_y_mm: f64,
    /// Offset along the body z axis, mm.
    pub offset_z_mm: f64,
    /// Measured position, clamp frame, mm.
    pub measured_mm: [f64; 3],
    /// The point's own noise (standard deviation), mm, when the file gives it.
    pub sd_mm: Option<f64>,
    /// Data row of the markers file (from 1; 0 for tip columns of the captures file).
    pub row: usize,
}

/// Captures and their markers, as read: the data of a 3-D calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureSet {
    /// The captures, in file order.
    pub captures: Vec<Capture>,
    /// Each capture's markers by measurement id (in file order).
    pub markers: BTreeMap<i64, Vec<MarkerReading>>,
}

impl CaptureSet {
    /// Every marker reading, paired with its capture's index.
    pub fn readings(&self) -> impl Iterator<Item = (usize, &MarkerReading)> {
        self.captures
            .iter()
            .enumerate()
            .flat_map(move |(i, c)| self.markers.get(&c.measurement).into_iter().flatten().map(move |m| (i, m)))
    }

    /// Number of marker readings.
    pub fn reading_count(&self) -> usize {
        self.readings().count()
    }

    /// The marker names in order of first appearance.
    pub fn marker_names(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for (_, m) in self.readings() {
            if !names.contains(&m.marker) {
                names.push(m.marker.clone());
            }
        }
        names
    }

    /// The captures (and their markers) whose index `keep` accepts.
    pub fn subset(&self, keep: impl Fn(&Capture) -> bool) -> CaptureSet {
        let captures: Vec<Capture> = self.captures.iter().filter(|c| keep(c)).cloned().collect();
        let markers = captures.iter().filter_map(|c| self.markers.get(&c.measurement).map(|m| (c.measurement, m.clone()))).collect();
        CaptureSet { captures, markers }
    }

    /// The captures fitted and those held out: with `cable` (1-based, of
    /// `cables`), those where it does not pull and those where it does;
    /// without, all and none.
    pub fn hold_out_cable(&self, cable: Option<usize>, cables: usize) -> Result<(CaptureSet, Option<CaptureSet>), CalibrateError> {
        let Some(k) = cable else { return Ok((self.clone(), None)) };
        if k == 0 || k > cables {
            return Err(HoldoutError::NoSuchCable { cable: k, cables }.into());
        }
        let train = self.subset(|c| !c.pulling_cables().contains(&k));
        let test = self.subset(|c| c.pulling_cables().contains(&k));
        if train.captures.is_empty() || test.captures.is_empty() {
            return Err(HoldoutError::NotSeparable { cable: k, pulling: test.captures.len(), others: train.captures.len() }.into());
        }
        Ok((train, Some(test)))
    }
}

/// Largest cable count a captures file may name (the actuator's limit).
const MAX_CABLE_COLUMNS: usize = crate::model::MAX_CABLES;

/// Reads a captures file for an actuator with `cables` cables: columns
/// `measurement`, per cable `tension_K_n` or `displacement_K_mm` (K = 1 …
/// `cables`), `direction`, `dwell_s`, optional `step` and optional tip
/// columns `tip_x_mm, tip_y_mm, tip_z_mm` (a marker named `tip` at s = L);
/// other columns are ignored. `length_mm` places the tip marker.
pub fn read_captures(path: &Path, cables: usize, length_mm: f64) -> Result<(Vec<Capture>, BTreeMap<i64, Vec<MarkerReading>>), CalibrateError> {
    let table = read_table(path)?;
    check_unique_columns(path, &table)?;
    if table.rows.is_empty() {
        return Err(CalibrateError::Empty { path: path.display().to_string() });
    }
    let has = |name: &str| table.header.iter().any(|h| h == name);
    // Cable columns beyond the actuator's cables are a mismatch, not extra data.
    for k in cables + 1..=MAX_CABLE_COLUMNS {
        for name in [format!("tension_{k}_n"), format!("displacement_{k}_mm")] {
            if has(&name) {
                return Err(crate::calibrate::InvalidRequest::CableColumnBeyond { path: path.to_path_buf(), column: name, cable: k, cables }.into());
            }
        }
    }
    let mut cable_cols = Vec::with_capacity(cables);
    for k in 1..=cables {
        let (t, d) = (format!("tension_{k}_n"), format!("displacement_{k}_mm"));
        let col = match (has(&t), has(&d)) {
            (true, false) => (column_index(path, &table, &t)?, t, true),
            (false, true) => (column_index(path, &table, &d)?, d, false),
            (true, true) => {
                return Err(crate::calibrate::InvalidRequest::BothDrives { path: path.to_path_buf(), tension: t, displacement: d, cable: k }.into())
            }
            (false, false) => {
                return Err(CalibrateError::MissingColumn { path: path.display().to_string(), column: format!("{t}' (or '{d}"), found: table.header.join(",") })
            }
        };
        cable_cols.push(col);
    }
    let m_idx = column_index(path, &table, "measurement")?;
    let dir_idx = column_index(path, &table, "direction")?;
    let dwell_idx = column_index(path, &table, "dwell_s")?;
    let step_idx = table.header.iter().position(|h| h == "step");
    let tip_names = ["tip_x_mm", "tip_y_mm", "tip_z_mm"];
    let tip_present: Vec<bool> = tip_names.iter().map(|n| has(n)).collect();
    let tip_idx = if tip_present.iter().all(|&p| p) {
        Some(tip_names.map(|n| column_index(path, &table, n).expect("present")))
    } else if tip_present.iter().any(|&p| p) {
        let missing: Vec<&str> = tip_names.iter().zip(&tip_present).filter(|(_, p)| !**p).map(|(n, _)| *n).collect();
        return Err(CalibrateError::MissingColumn { path: path.display().to_string(), column: missing.join("', '"), found: table.header.join(",") });
    } else {
        None
    };
    let mut captures = Vec::with_capacity(table.rows.len());
    let mut tips = BTreeMap::new();
    let mut seen = BTreeMap::new();
    for (i, cells) in table.rows.iter().enumerate() {
        let c = Cells { path, row: i + 1, cells };
        let measurement = c.int(m_idx, "measurement")?;
        if let Some(first) = seen.insert(measurement, i + 1) {
            return Err(CalibrateError::Inconsistent {
                path: path.display().to_string(),
                row: i + 1,
                conflict: RowConflict::CaptureId { measurement, first },
            });
        }
        let mut actuation = Vec::with_capacity(cables);
        for (idx, name, is_tension) in &cable_cols {
            let v = c.float(*idx, name)?;
            if v < 0.0 {
                let expected = if *is_tension { "a tension ≥ 0 N (a cable cannot push)" } else { "a displacement ≥ 0 mm (a cable cannot push)" };
                return Err(c.bad(name, &cells[*idx], expected));
            }
            actuation.push(if *is_tension { Actuation::Tension(v) } else { Actuation::Displacement(v) });
        }
        let direction = match c.text(dir_idx, "direction")?.to_ascii_lowercase().as_str() {
            "load" => Direction::Load,
            "unload" => Direction::Unload,
            "rest" => Direction::Rest,
            "static" => Direction::Static,
            _ => return Err(c.bad("direction", &cells[dir_idx], "one of load, unload, rest, static")),
        };
        if direction == Direction::Rest {
            if let Some((idx, name, _)) = cable_cols.iter().zip(&actuation).find(|(_, a)| !matches!(a, Actuation::Tension(v) | Actuation::Displacement(v) if *v == 0.0)).map(|(c, _)| c) {
                return Err(c.bad(name, &cells[*idx], "0 on a rest row (direction = rest means no cable pulls)"));
            }
        }
        let dwell_s = c.float(dwell_idx, "dwell_s")?;
        if dwell_s < 0.0 {
            return Err(c.bad("dwell_s", &cells[dwell_idx], "a dwell time ≥ 0 s"));
        }
        let step = match step_idx {
            Some(idx) => c.int(idx, "step")?,
            None => i as i64,
        };
        if let Some(idx) = tip_idx {
            let p = [c.float(idx[0], "tip_x_mm")?, c.float(idx[1], "tip_y_mm")?, c.float(idx[2], "tip_z_mm")?];
            let tip = MarkerReading { marker: "tip".into(), s_mm: length_mm, offset_y_mm: 0.0, offset_z_mm: 0.0, measured_mm: p, sd_mm: None, row: 0 };
            tips.insert(measurement, vec![tip]);
        }
        captures.push(Capture { measurement, actuation, direction, step, dwell_s, row: i + 1 });
    }
    Ok((captures, tips))
}

/// Columns a markers file must have.
pub const MARKER_COLUMNS: [&str; 8] = ["measurement", "marker", "s_mm", "offset_y_mm", "offset_z_mm", "x_mm", "y_mm", "z_mm"];

/// Farthest a marker may sit beyond the tip, as a share of the rod's
/// length: a point on a short rigid extension (a tip cap, a marker stalk),
/// not a second rod.
const MAX_BEYOND_TIP_PER_LENGTH: f64 = 0.5;

/// Reads a markers file (`measurement, marker, s_mm, offset_y_mm,
/// offset_z_mm, x_mm, y_mm, z_mm[, sd_mm]`): every measurement id must be a
/// capture's, each marker named once per capture, 0 ≤ s ≤ 1.5 L.
pub fn read_markers_3d(path: &Path, captures: &[Capture], length_mm: f64) -> Result<BTreeMap<i64, Vec<MarkerReading>>, CalibrateError> {
    let table: Table = read_table(path)?;
    check_unique_columns(path, &table)?;
    if table.rows.is_empty() {
        return Err(CalibrateError::Empty { path: path.display().to_string() });
    }
    let idx: Vec<usize> = MARKER_COLUMNS.iter().map(|n| column_index(path, &table, n)).collect::<Result<_, _>>()?;
    let sd_idx = table.header.iter().position(|h| h == "sd_mm");
    let known: std::collections::HashSet<i64> = captures.iter().map(|c| c.measurement).collect();
    let mut out: BTreeMap<i64, Vec<MarkerReading>> = BTreeMap::new();
    let far = length_mm * (1.0 + MAX_BEYOND_TIP_PER_LENGTH);
    for (i, cells) in table.rows.iter().enumerate() {
        let c = Cells { path, row: i + 1, cells };
        let id = c.int(idx[0], "measurement")?;
        if !known.contains(&id) {
            return Err(c.bad("measurement", &cells[idx[0]], "the id of a capture in the captures file"));
        }
        let marker = c.text(idx[1], "marker")?.to_string();
        let s_mm = c.float(idx[2], "s_mm")?;
        if !(0.0..=far).contains(&s_mm) {
            return Err(c.bad(
                "s_mm",
                &cells[idx[2]],
                &format!("a rest arc length from the clamp, 0 ≤ s ≤ {} mm (L = {length_mm} mm; a point beyond the tip sits on the tip's rigid extension)", crate::io::fmt_num(far)),
            ));
        }
        let sd_mm = match sd_idx {
            Some(k) if !cells[k].trim().is_empty() => {
                let v = c.float(k, "sd_mm")?;
                if v <= 0.0 {
                    return Err(c.bad("sd_mm", &cells[k], "a standard deviation > 0 mm (or an empty cell)"));
                }
                Some(v)
            }
            _ => None,
        };
        let reading = MarkerReading {
            marker,
            s_mm,
            offset_y_mm: c.float(idx[3], "offset_y_mm")?,
            offset_z_mm: c.float(idx[4], "offset_z_mm")?,
            measured_mm: [c.float(idx[5], "x_mm")?, c.float(idx[6], "y_mm")?, c.float(idx[7], "z_mm")?],
            sd_mm,
            row: i + 1,
        };
        let list = out.entry(id).or_default();
        if let Some(first) = list.iter().find(|m| m.marker == reading.marker) {
            return Err(CalibrateError::Inconsistent {
                path: path.display().to_string(),
                row: i + 1,
                conflict: RowConflict::MarkerTwice { marker: reading.marker.clone(), measurement: id, first: first.row },
            });
        }
        list.push(reading);
    }
    Ok(out)
}

/// Reads captures and markers for an actuator with `cables` cables and
/// length `length_mm`: the markers file's points and the captures file's
/// tip columns (a marker `tip`); every capture needs at least one point.
pub fn read_capture_set(captures_path: &Path, markers_path: Option<&Path>, cables: usize, length_mm: f64) -> Result<CaptureSet, CalibrateError> {
    let (captures, mut markers) = read_captures(captures_path, cables, length_mm)?;
    if let Some(p) = markers_path {
        for (id, list) in read_markers_3d(p, &captures, length_mm)? {
            let entry = markers.entry(id).or_default();
            if let Some(m) = list.iter().find(|m| entry.iter().any(|t| t.marker == m.marker)) {
                return Err(CalibrateError::Inconsistent {
                    path: p.display().to_string(),
                    row: m.row,
                    conflict: RowConflict::MarkerIsTip { marker: m.marker.clone(), measurement: id },
                });
            }
            entry.extend(list);
        }
    }
    if let Some(c) = captures.iter().find(|c| markers.get(&c.measurement).is_none_or(|m| m.is_empty())) {
        return Err(CalibrateError::Inconsistent {
            path: captures_path.display().to_string(),
            row: c.row,
            conflict: RowConflict::NoPoint { measurement: c.measurement },
        });
    }
    Ok(CaptureSet { captures, markers })
}

/// Writes captures as CSV (the format [`read_captures`] reads).
pub fn captures_csv(captures: &[Capture]) -> String {
    let mut out = String::from("measurement");
    if let Some(first) = captures.first() {
        for (k, a) in first.actuation.iter().enumerate() {
            out.push_str(&match a {
                Actuation::Tension(_) => format!(",tension_{}_n", k + 1),
                Actuation::Displacement(_) => format!(",displacement_{}_mm", k + 1),
            });
        }
    }
    out.push_str(",direction,step,dwell_s\n");
    for c in captures {
        out.push_str(&c.measurement.to_string());
        for a in &c.actuation {
            let (Actuation::Tension(v) | Actuation::Displacement(v)) = a;
            out.push_str(&format!(",{v}"));
        }
        out.push_str(&format!(",{},{},{}\n", c.direction.as_str(), c.step, c.dwell_s));
    }
    out
}

/// Writes markers as CSV (the format [`read_markers_3d`] reads).
pub fn markers_3d_csv(set: &CaptureSet) -> String {
    let mut out = String::from("measurement,marker,s_mm,offset_y_mm,offset_z_mm,x_mm,y_mm,z_mm,sd_mm\n");
    for (i, m) in set.readings() {
        let id = set.captures[i].measurement;
        let sd = m.sd_mm.map(|v| v.to_string()).unwrap_or_default();
        let [x, y, z] = m.measured_mm;
        out.push_str(&format!("{id},{},{},{},{},{x},{y},{z},{sd}\n", m.marker, m.s_mm, m.offset_y_mm, m.offset_z_mm));
    }
    out
}

/// Reads an actuator file.
pub(crate) fn read_actuator(path: &Path) -> Result<Actuator, CalibrateError> {
    Actuator::read(path).map_err(|e| CalibrateError::Actuator(e.into()))
}

/// Reads captures and markers files for `actuator`'s cables and length.
pub(crate) fn read_actuator_set(captures: &Path, markers: Option<&Path>, actuator: &Actuator) -> Result<CaptureSet, CalibrateError> {
    read_capture_set(captures, markers, actuator.cables.len(), actuator.rod.length_mm)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn soromox(file: &str) -> std::path::PathBuf {
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/soromox").join(file)
    }

    #[test]
    fn reads_the_soromox_files_as_they_are() {
        let set = read_capture_set(&soromox("captures.csv"), Some(&soromox("markers.csv")), 2, 360.0).unwrap();
        assert_eq!(set.captures.len(), 14);
        assert_eq!(set.reading_count(), 56);
        assert_eq!(set.marker_names(), ["p1", "p2", "p3", "p4"]);
        let c = &set.captures[7];
        assert_eq!((c.measurement, c.direction, c.pulling_cables()), (8, Direction::Static, vec![2]));
        assert_eq!(c.actuation, vec![Actuation::Tension(0.0), Actuation::Tension(1.538462)]);
        let p4 = &set.markers[&1][3];
        assert_eq!((p4.marker.as_str(), p4.s_mm, p4.measured_mm, p4.sd_mm), ("p4", 368.0, [363.764, 48.512, 22.666], Some(0.0606)));
        assert_eq!(set.markers[&1][0].offset_z_mm, 25.0);
    }

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn errors_name_file_row_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let good = "measurement,tension_1_n,tension_2_n,direction,dwell_s\n1,1.0,0,static,2\n2,0,2.0,static,2\n";
        let caps = write(d, "c.csv", good);
        let err = |c: &Path, m: &str| read_capture_set(c, Some(&write(d, "m.csv", m)), 2, 100.0).unwrap_err().to_string();
        let head = "measurement,marker,s_mm,offset_y_mm,offset_z_mm,x_mm,y_mm,z_mm\n";
        let e = err(&caps, &format!("{head}1,a,50,0,0,50,0,0\n2,a,50,0,0,50,x,0\n"));
        assert!(e.contains("m.csv") && e.contains("row 2") && e.contains("'y_mm'") && e.contains("'x'"), "{e}");
        let e = err(&caps, &format!("{head}1,a,50,0,0,50,0,0\n3,a,50,0,0,50,0,0\n"));
        assert!(e.contains("row 2") && e.contains("measurement"), "{e}");
        let e = err(&caps, &format!("{head}1,a,500,0,0,50,0,0\n"));
        assert!(e.contains("row 1") && e.contains("s_mm"), "{e}");
        let e = err(&caps, &format!("{head}1,a,50,0,0,50,0,0\n1,a,60,0,0,50,0,0\n"));
        assert!(e.contains("row 2") && e.contains("twice"), "{e}");
        let e = err(&caps, "measurement,marker,s_mm,offset_y_mm,x_mm,y_mm,z_mm\n1,a,50,0,50,0,0\n");
        assert!(e.contains("offset_z_mm"), "{e}");
        let e = err(&caps, &format!("{head}1,a,50,0,0,50,0,0\n"));
        assert!(e.contains("c.csv") && e.contains("capture 2 has no measured point"), "{e}");
        let bad = write(d, "c2.csv", "measurement,tension_1_n,direction,dwell_s\n1,1.0,static,2\n");
        let e = err(&bad, &format!("{head}1,a,50,0,0,50,0,0\n"));
        assert!(e.contains("c2.csv") && e.contains("tension_2_n"), "{e}");
        let bad = write(d, "c3.csv", "measurement,tension_1_n,tension_2_n,direction,dwell_s\n1,-1.0,0,static,2\n");
        let e = err(&bad, &format!("{head}1,a,50,0,0,50,0,0\n"));
        assert!(e.contains("c3.csv") && e.contains("row 1") && e.contains("tension_1_n"), "{e}");
        let bad = write(d, "c4.csv", "measurement,tension_1_n,tension_2_n,tension_3_n,direction,dwell_s\n1,1,0,0,static,2\n");
        let e = err(&bad, &format!("{head}1,a,50,0,0,50,0,0\n"));
        assert!(e.contains("cable 3") && e.contains("2 cable"), "{e}");
    }

    #[test]
    fn tip_columns_displacements_and_parquet() {
        use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
        use arrow::record_batch::RecordBatch;
        use std::sync::Arc;
        let dir = tempfile::tempdir().unwrap();
        let caps = write(dir.path(), "c.csv", "measurement,displacement_1_mm,direction,dwell_s,tip_x_mm,tip_y_mm,tip_z_mm\n4,1.5,load,0,60,1,2\n");
        let set = read_capture_set(&caps, None, 1, 65.0).unwrap();
        assert_eq!(set.captures[0].actuation, vec![Actuation::Displacement(1.5)]);
        assert_eq!(set.markers[&4][0].measured_mm, [60.0, 1.0, 2.0]);
        assert_eq!(set.markers[&4][0].s_mm, 65.0);
        // The markers file as Parquet reads as its CSV does.
        let f = |v: Vec<f64>| Arc::new(Float64Array::from(v)) as ArrayRef;
        let batch = RecordBatch::try_from_iter(vec![
            ("measurement", Arc::new(Int64Array::from(vec![4])) as ArrayRef),
            ("marker", Arc::new(StringArray::from(vec!["m"])) as ArrayRef),
            ("s_mm", f(vec![30.0])),
            ("offset_y_mm", f(vec![0.0])),
            ("offset_z_mm", f(vec![5.0])),
            ("x_mm", f(vec![29.0])),
            ("y_mm", f(vec![0.1 + 0.2])),
            ("z_mm", f(vec![5.0])),
        ])
        .unwrap();
        let path = dir.path().join("m.parquet");
        let mut w = parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&path).unwrap(), batch.schema(), None).unwrap();
        w.write(&batch).unwrap();
        w.close().unwrap();
        let set = read_capture_set(&caps, Some(&path), 1, 65.0).unwrap();
        assert_eq!(set.markers[&4][1].measured_mm[1], 0.1 + 0.2, "floats survive exactly");
        // And round trip through CSV.
        let again = write(dir.path(), "again.csv", &markers_3d_csv(&set));
        let caps2 = write(dir.path(), "c2.csv", &captures_csv(&set.captures));
        let set2 = read_capture_set(&caps2, Some(&again), 1, 65.0).unwrap();
        assert_eq!(set2.reading_count(), 2);
        assert_eq!(set2.markers[&4][1].measured_mm, set.markers[&4][1].measured_mm);
    }
}
