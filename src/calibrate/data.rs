//! Measurement files (`docs/measurements.md`): one row per tip reading, as
//! CSV or Parquet, and an optional file of measured centreline points.
//!
//! Both formats go through one table of text cells, so every check (missing
//! columns, malformed or impossible values, inconsistent routings) is the
//! same and every error names the file, the row and the column.
//!
//! CSV is split here, not by the `csv` crate: that crate reads a stray
//! quote inside an unquoted field as text and an unclosed quote as a field
//! running to the end of the file, where a measurement file must be refused
//! with the row ([`CsvLineError`]); it also does not take lines ended by a
//! lone CR or the `#` geometry header.

use super::error::{CsvLineError, GeometryProblem, RowConflict, TableProblem};
use super::{CalibrateError, HoldoutError};
use crate::model::routing::{ControlPoints, CONTROL_POINTS};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Columns every measurement file must have.
pub const REQUIRED_COLUMNS: [&str; 15] = [
    "measurement",
    "routing",
    "y0_mm",
    "y1_mm",
    "y2_mm",
    "y3_mm",
    "y4_mm",
    "tension_n",
    "direction",
    "step",
    "dwell_s",
    "tip_x_mm",
    "tip_y_mm",
    "tip_angle_rad",
    "clamp_tilt_rad",
];
/// Number of columns of [`REQUIRED_COLUMNS`] that are required; the rest are optional.
const N_REQUIRED: usize = 14;

/// Direction of the step that led to a reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Tension raised to this value.
    Load,
    /// Tension lowered to this value.
    Unload,
    /// No tension (before loading or after unloading).
    Rest,
    /// An independent capture, not part of one load/unload protocol: the
    /// model solves it from a virgin, unloaded rod (no history carried over).
    Static,
}

impl Direction {
    /// The name used in files.
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Load => "load",
            Direction::Unload => "unload",
            Direction::Rest => "rest",
            Direction::Static => "static",
        }
    }
}

/// One tip reading.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// Measurement id (unique in the file).
    pub measurement: i64,
    /// Routing id.
    pub routing: String,
    /// Routing control points y0..y4, mm.
    pub routing_mm: ControlPoints,
    /// Cable tension at the base, N.
    pub tension_n: f64,
    /// Direction of the step.
    pub direction: Direction,
    /// Order within the routing's protocol.
    pub step: i64,
    /// Seconds held at the tension before the reading.
    pub dwell_s: f64,
    /// Measured tip position along the clamp axis, mm.
    pub tip_x_mm: f64,
    /// Measured tip position across the clamp axis, mm.
    pub tip_y_mm: f64,
    /// Measured tip tangent angle from the clamp axis, rad.
    pub tip_angle_rad: f64,
    /// Clamp axis from the vertical, rad (toward +y positive).
    pub clamp_tilt_rad: f64,
    /// Noise (standard deviation) of this row's tip x, y and centreline
    /// points, mm, if the file gives it (else the command's `--noise-mm`).
    pub noise_mm: Option<f64>,
    /// Noise of this row's tip angle, degrees, if the file gives it.
    pub noise_deg: Option<f64>,
    /// Row in the file (1 = first data row), for messages.
    pub row: usize,
}

/// The readings of one routing, in protocol order.
#[derive(Debug, Clone, PartialEq)]
pub struct RoutingGroup {
    /// Routing id.
    pub routing: String,
    /// Routing control points, mm.
    pub routing_mm: ControlPoints,
    /// Clamp tilt, rad.
    pub clamp_tilt_rad: f64,
    /// Indices into [`Dataset::rows`], sorted by step.
    pub rows: Vec<usize>,
}

/// A validated measurement file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Dataset {
    /// Rows in file order.
    pub rows: Vec<Measurement>,
    /// The actuator the file describes in its geometry header (`# key =
    /// value` lines before the column names: `actuator_file = "x.toml"`
    /// and/or actuator fields), if it has one.
    pub actuator: Option<crate::model::Rod>,
}

impl Dataset {
    /// Routings in order of first appearance, each with its rows by step.
    pub fn groups(&self) -> Vec<RoutingGroup> {
        let mut order: Vec<String> = Vec::new();
        let mut by_id: HashMap<&str, Vec<usize>> = HashMap::new();
        for (i, m) in self.rows.iter().enumerate() {
            by_id.entry(&m.routing).or_insert_with(|| {
                order.push(m.routing.clone());
                Vec::new()
            });
            by_id.get_mut(m.routing.as_str()).expect("inserted").push(i);
        }
        order
            .into_iter()
            .map(|id| {
                let mut rows = by_id.remove(id.as_str()).expect("known id");
                rows.sort_by_key(|&i| self.rows[i].step);
                let first = &self.rows[rows[0]];
                RoutingGroup { routing: id, routing_mm: first.routing_mm, clamp_tilt_rad: first.clamp_tilt_rad, rows }
            })
            .collect()
    }
}

/// A table of text cells with a header, as read from CSV or Parquet.
pub(crate) struct Table {
    /// Column names.
    pub(crate) header: Vec<String>,
    /// Data rows, cells as text.
    pub(crate) rows: Vec<Vec<String>>,
    /// The '#' lines before the header, '#' removed (CSV only).
    front: String,
}

/// Reads a measurement file; `.parquet` files are read as Parquet, anything
/// else as CSV.
pub fn read_measurements(path: &Path) -> Result<Dataset, CalibrateError> {
    let table = read_table(path)?;
    let mut data = parse_measurements(path, &table)?;
    data.actuator = actuator_of_front_matter(path, &table.front)?;
    Ok(data)
}

/// The actuator of a measurement file's geometry header: TOML lines, each
/// behind a '#' before the column names. `actuator_file = "name.toml"`
/// (relative to the measurement file) loads an actuator file; any other
/// keys are actuator fields (`length_mm = 360`, `radius_profile_mm =
/// [[0, 15.4], [305, 6.4], [360, 4.8]]`, `cable_anchor_mm = 305`) set on
/// top of it (or of the thesis's actuator). `None` without a header.
fn actuator_of_front_matter(path: &Path, front: &str) -> Result<Option<crate::model::Rod>, CalibrateError> {
    use crate::model::Rod;
    let bad = |problem: GeometryProblem| CalibrateError::Geometry { path: path.display().to_string(), problem };
    if front.trim().is_empty() {
        return Ok(None);
    }
    let mut table: toml::Table = toml::from_str(front).map_err(|e| bad(GeometryProblem::Toml(e)))?;
    if table.is_empty() {
        return Ok(None);
    }
    let base = match table.remove("actuator_file") {
        None => Rod::default(),
        Some(toml::Value::String(name)) => {
            let file = path.parent().unwrap_or(Path::new(".")).join(&name);
            Rod::from_toml_file(&file).map_err(|e| bad(e.into()))?
        }
        Some(other) => return Err(bad(GeometryProblem::ActuatorFileName { value: other.to_string() })),
    };
    if table.is_empty() {
        return Ok(Some(base));
    }
    let mut merged = toml::Table::try_from(&base).map_err(|e| bad(GeometryProblem::Merge(e)))?;
    for (k, v) in table {
        merged.insert(k, v);
    }
    let text = toml::to_string(&merged).map_err(|e| bad(GeometryProblem::Merge(e)))?;
    Rod::from_toml_str(&text).map(Some).map_err(|e| bad(e.into()))
}

/// Reads a CSV or (by its `.parquet` extension) Parquet file as text cells.
pub(crate) fn read_table(path: &Path) -> Result<Table, CalibrateError> {
    let is_parquet = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("parquet"));
    if is_parquet {
        read_parquet_table(path)
    } else {
        let text = crate::io::read_utf8(path)
            .map_err(|source| CalibrateError::Io { context: format!("reading {}", path.display()), source })?;
        parse_csv(path, &text)
    }
}

/// Splits CSV text into cells: comma-separated, fields optionally in double
/// quotes ("" inside quotes is a quote), blank lines skipped.
fn parse_csv(path: &Path, text: &str) -> Result<Table, CalibrateError> {
    // Lines that end in CR alone (classic Mac OS, some instrument software)
    // are lines too; CR LF and LF need nothing (str::lines drops the CR).
    let text: std::borrow::Cow<str> =
        if text.contains('\r') && !text.contains('\n') { text.replace('\r', "\n").into() } else { text.into() };
    // The geometry header: '#' lines before the column names.
    let text = text.trim_start_matches('\u{feff}');
    let mut front = String::new();
    let mut body_start = 0;
    for line in text.split_inclusive('\n') {
        let t = line.trim();
        if t.starts_with('#') {
            front.push_str(t.trim_start_matches('#'));
            front.push('\n');
        } else if !t.is_empty() {
            break;
        }
        body_start += line.len();
    }
    let text = &text[body_start..];
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let Some((_, head)) = lines.next() else {
        return Err(CalibrateError::Empty { path: path.display().to_string() });
    };
    let header: Vec<String> = split_csv_line(head.trim_start_matches('\u{feff}'))
        .map_err(|e| CalibrateError::Malformed { path: path.display().to_string(), row: 0, problem: e.into() })?
        .into_iter()
        .map(|h| h.trim().to_string())
        .collect();
    if header.len() == 1 {
        // One column: most likely another delimiter (a spreadsheet's
        // semicolons, a tab export); say so instead of "missing column".
        for (sep, name) in [(';', "semicolon"), ('\t', "tab"), ('|', "pipe")] {
            if head.contains(sep) {
                return Err(CalibrateError::Malformed { path: path.display().to_string(), row: 0, problem: TableProblem::OtherDelimiter { name } });
            }
        }
    }
    let mut rows = Vec::new();
    for (data_row, (_, line)) in lines.enumerate() {
        let row = data_row + 1;
        let cells = split_csv_line(line)
            .map_err(|e| CalibrateError::Malformed { path: path.display().to_string(), row, problem: e.into() })?;
        if cells.len() != header.len() {
            return Err(CalibrateError::Malformed {
                path: path.display().to_string(),
                row,
                problem: TableProblem::FieldCount { fields: cells.len(), header: header.len() },
            });
        }
        rows.push(cells);
    }
    Ok(Table { header, rows, front })
}

fn split_csv_line(line: &str) -> Result<Vec<String>, CsvLineError> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    let mut was_quoted = false;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            (true, '"') => quoted = false,
            (true, _) => cell.push(c),
            (false, '"') if cell.trim().is_empty() && !was_quoted => {
                cell.clear();
                quoted = true;
                was_quoted = true;
            }
            (false, ',') => {
                cells.push(std::mem::take(&mut cell));
                was_quoted = false;
            }
            (false, '"') => return Err(CsvLineError::StrayQuote),
            (false, _) => cell.push(c),
        }
    }
    if quoted {
        return Err(CsvLineError::Unclosed);
    }
    cells.push(cell);
    Ok(cells.into_iter().map(|c| c.trim().to_string()).collect())
}

fn read_parquet_table(path: &Path) -> Result<Table, CalibrateError> {
    use arrow::util::display::{ArrayFormatter, FormatOptions};
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let err = |problem: TableProblem| CalibrateError::Malformed { path: path.display().to_string(), row: 0, problem };
    let file = std::fs::File::open(path)
        .map_err(|source| CalibrateError::Io { context: format!("opening {}", path.display()), source })?;
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .map_err(|e| err(TableProblem::NotParquet(e)))?
        .build()
        .map_err(|e| err(TableProblem::NotParquet(e)))?;
    let mut header: Option<Vec<String>> = None;
    let mut rows = Vec::new();
    let options = FormatOptions::default().with_null("");
    for batch in reader {
        let batch = batch.map_err(|e| err(TableProblem::ParquetData(e)))?;
        let names: Vec<String> = batch.schema().fields().iter().map(|f| f.name().clone()).collect();
        header.get_or_insert(names);
        let formatters = batch
            .columns()
            .iter()
            .map(|c| ArrayFormatter::try_new(c.as_ref(), &options))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| err(TableProblem::ColumnType(e)))?;
        for i in 0..batch.num_rows() {
            rows.push(formatters.iter().map(|f| f.value(i).to_string()).collect());
        }
    }
    let Some(header) = header else {
        return Err(CalibrateError::Empty { path: path.display().to_string() });
    };
    Ok(Table { header, rows, front: String::new() })
}

/// Column lookup that names what is missing.
pub(crate) fn column_index(path: &Path, table: &Table, name: &str) -> Result<usize, CalibrateError> {
    table.header.iter().position(|h| h == name).ok_or_else(|| CalibrateError::MissingColumn {
        path: path.display().to_string(),
        column: name.to_string(),
        found: table.header.join(","),
    })
}

/// One row's cells, for checked reads whose errors name file, row and column.
pub(crate) struct Cells<'a> {
    /// The file.
    pub(crate) path: &'a Path,
    /// Data row, from 1.
    pub(crate) row: usize,
    /// The cells.
    pub(crate) cells: &'a [String],
}

impl Cells<'_> {
    /// The error for `value` in `column` that is not `expected`.
    pub(crate) fn bad(&self, column: &str, value: &str, expected: &str) -> CalibrateError {
        CalibrateError::BadValue {
            path: self.path.display().to_string(),
            row: self.row,
            column: column.to_string(),
            value: value.to_string(),
            expected: expected.to_string(),
        }
    }
    /// A non-empty cell.
    pub(crate) fn text(&self, idx: usize, column: &str) -> Result<&str, CalibrateError> {
        let v = self.cells[idx].as_str();
        if v.is_empty() {
            return Err(self.bad(column, v, "a value (the cell is empty)"));
        }
        Ok(v)
    }
    /// A finite number.
    pub(crate) fn float(&self, idx: usize, column: &str) -> Result<f64, CalibrateError> {
        let v = self.text(idx, column)?;
        match v.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(self.bad(column, v, "a finite number")),
        }
    }
    /// An integer.
    pub(crate) fn int(&self, idx: usize, column: &str) -> Result<i64, CalibrateError> {
        let v = self.text(idx, column)?;
        v.parse::<i64>().map_err(|_| self.bad(column, v, "an integer"))
    }
}

/// Refuses a header that names a column twice: which of the two a reader
/// takes is arbitrary, so neither is (the error names both positions).
pub(crate) fn check_unique_columns(path: &Path, table: &Table) -> Result<(), CalibrateError> {
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, name) in table.header.iter().enumerate() {
        if let Some(first) = seen.insert(name.as_str(), i) {
            return Err(CalibrateError::Malformed {
                path: path.display().to_string(),
                row: 0,
                problem: TableProblem::DuplicateColumn { name: name.clone(), first: first + 1, second: i + 1 },
            });
        }
    }
    Ok(())
}

fn parse_measurements(path: &Path, table: &Table) -> Result<Dataset, CalibrateError> {
    check_unique_columns(path, table)?;
    let mut idx = [usize::MAX; REQUIRED_COLUMNS.len()];
    for (slot, name) in idx.iter_mut().zip(REQUIRED_COLUMNS).take(N_REQUIRED) {
        *slot = column_index(path, table, name)?;
    }
    let tilt_idx = table.header.iter().position(|h| h == "clamp_tilt_rad");
    let noise_mm_idx = table.header.iter().position(|h| h == "noise_mm");
    let noise_deg_idx = table.header.iter().position(|h| h == "noise_deg");
    if table.rows.is_empty() {
        return Err(CalibrateError::Empty { path: path.display().to_string() });
    }
    let mut rows = Vec::with_capacity(table.rows.len());
    let mut ids: HashMap<i64, usize> = HashMap::new();
    let mut steps: HashMap<(String, i64), usize> = HashMap::new();
    let mut routings: BTreeMap<String, ([f64; CONTROL_POINTS], f64, usize)> = BTreeMap::new();
    for (i, cells) in table.rows.iter().enumerate() {
        let c = Cells { path, row: i + 1, cells };
        let col = |k: usize| REQUIRED_COLUMNS[k];
        let measurement = c.int(idx[0], col(0))?;
        let routing = c.text(idx[1], col(1))?.to_string();
        let mut y_mm = [0.0; CONTROL_POINTS];
        for (j, y) in y_mm.iter_mut().enumerate() {
            *y = c.float(idx[2 + j], col(2 + j))?;
        }
        let tension_n = c.float(idx[7], col(7))?;
        if tension_n < 0.0 {
            return Err(c.bad(col(7), &cells[idx[7]], "a tension ≥ 0 N (a cable cannot push)"));
        }
        let direction = match c.text(idx[8], col(8))?.to_ascii_lowercase().as_str() {
            "load" => Direction::Load,
            "unload" => Direction::Unload,
            "rest" => Direction::Rest,
            "static" => Direction::Static,
            _ => return Err(c.bad(col(8), &cells[idx[8]], "one of load, unload, rest, static")),
        };
        if direction == Direction::Rest && tension_n != 0.0 {
            return Err(c.bad(col(7), &cells[idx[7]], "0 on a rest row (direction = rest means no tension)"));
        }
        let step = c.int(idx[9], col(9))?;
        let dwell_s = c.float(idx[10], col(10))?;
        if dwell_s < 0.0 {
            return Err(c.bad(col(10), &cells[idx[10]], "a dwell time ≥ 0 s"));
        }
        let tip_x_mm = c.float(idx[11], col(11))?;
        let tip_y_mm = c.float(idx[12], col(12))?;
        let tip_angle_rad = c.float(idx[13], col(13))?;
        if tip_angle_rad.abs() > 4.0 * std::f64::consts::PI {
            return Err(c.bad(col(13), &cells[idx[13]], "an angle in radians (|θ| ≤ 4π); was it given in degrees?"));
        }
        let clamp_tilt_rad = match tilt_idx {
            Some(k) if !cells[k].is_empty() => c.float(k, "clamp_tilt_rad")?,
            _ => 0.0,
        };
        if clamp_tilt_rad.abs() > std::f64::consts::TAU {
            let k = tilt_idx.expect("read from the column");
            return Err(c.bad("clamp_tilt_rad", &cells[k], "an angle in radians (|θ| ≤ 2π); was it given in degrees?"));
        }
        let noise = |k: Option<usize>, name: &str| -> Result<Option<f64>, CalibrateError> {
            match k {
                Some(k) if !cells[k].is_empty() => {
                    let v = c.float(k, name)?;
                    if v > 0.0 {
                        Ok(Some(v))
                    } else {
                        Err(c.bad(name, &cells[k], "a noise level > 0 (a standard deviation), or an empty cell for the default"))
                    }
                }
                _ => Ok(None),
            }
        };
        let noise_mm = noise(noise_mm_idx, "noise_mm")?;
        let noise_deg = noise(noise_deg_idx, "noise_deg")?;
        if let Some(first) = ids.insert(measurement, c.row) {
            return Err(CalibrateError::Inconsistent {
                path: path.display().to_string(),
                row: c.row,
                conflict: RowConflict::MeasurementId { measurement, first },
            });
        }
        if let Some(first) = steps.insert((routing.clone(), step), c.row) {
            return Err(CalibrateError::Inconsistent {
                path: path.display().to_string(),
                row: c.row,
                conflict: RowConflict::StepTwice { routing: routing.clone(), step, first, row: c.row },
            });
        }
        match routings.get(&routing) {
            Some((y0, t0, first)) if *y0 != y_mm || *t0 != clamp_tilt_rad => {
                return Err(CalibrateError::Inconsistent {
                    path: path.display().to_string(),
                    row: c.row,
                    conflict: RowConflict::RoutingChanged {
                        routing: routing.clone(),
                        y_mm,
                        tilt_rad: clamp_tilt_rad,
                        first_y_mm: *y0,
                        first_tilt_rad: *t0,
                        first: *first,
                    },
                });
            }
            Some(_) => {}
            None => {
                routings.insert(routing.clone(), (y_mm, clamp_tilt_rad, c.row));
            }
        }
        rows.push(Measurement {
            measurement,
            routing,
            routing_mm: ControlPoints(y_mm),
            tension_n,
            direction,
            step,
            dwell_s,
            tip_x_mm,
            tip_y_mm,
            tip_angle_rad,
            clamp_tilt_rad,
            noise_mm,
            noise_deg,
            row: c.row,
        });
    }
    Ok(Dataset { rows, actuator: None })
}

/// The geometry header of a measurement file for actuator `a`: its body
/// (length, radius, radius profile, segments, cable anchor) as `# key =
/// value` TOML lines. Rigidities and effects are left out: they are what
/// calibrate and diagnose fit.
pub fn geometry_header(a: &crate::model::Rod) -> String {
    #[derive(serde::Serialize)]
    struct Geometry<'a> {
        length_mm: f64,
        radius_mm: f64,
        #[serde(skip_serializing_if = "Option::is_none")]
        cable_anchor_mm: Option<f64>,
        #[serde(skip_serializing_if = "<[_]>::is_empty")]
        radius_profile_mm: &'a [(f64, f64)],
        #[serde(skip_serializing_if = "<[_]>::is_empty")]
        segments: &'a [crate::model::Segment],
    }
    let g = Geometry {
        length_mm: a.length_mm,
        radius_mm: a.radius_mm,
        cable_anchor_mm: a.cable_anchor_mm,
        radius_profile_mm: &a.radius_profile_mm,
        segments: &a.segments,
    };
    let text = toml::to_string(&g).unwrap_or_default();
    text.lines().filter(|l| !l.trim().is_empty()).map(|l| format!("# {l}\n")).collect()
}

/// Writes a measurement file as CSV (all columns, full precision), with the
/// geometry header of [`Dataset::actuator`] if it has one.
pub fn measurements_csv(data: &Dataset) -> String {
    let with_noise = data.rows.iter().any(|m| m.noise_mm.is_some() || m.noise_deg.is_some());
    let mut out = data.actuator.as_ref().map(geometry_header).unwrap_or_default();
    out.push_str(&REQUIRED_COLUMNS.join(","));
    if with_noise {
        out.push_str(",noise_mm,noise_deg");
    }
    out.push('\n');
    for m in &data.rows {
        let y: Vec<String> = m.routing_mm.iter().map(|v| v.to_string()).collect();
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{}\n",
            m.measurement,
            quote(&m.routing),
            y.join(","),
            m.tension_n,
            m.direction.as_str(),
            m.step,
            m.dwell_s,
            m.tip_x_mm,
            m.tip_y_mm,
            m.tip_angle_rad,
            m.clamp_tilt_rad,
        ));
        if with_noise {
            out.pop();
            let cell = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
            out.push_str(&format!(",{},{}\n", cell(m.noise_mm), cell(m.noise_deg)));
        }
    }
    out
}

fn quote(text: &str) -> String {
    if text.contains([',', '"']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// Measured centreline points of one reading, clamp first, mm.
pub type CentrelinePoints = BTreeMap<i64, Vec<[f64; 2]>>;

/// Reads a centreline file (`measurement,x_mm,y_mm`, points in order from
/// the clamp); every measurement id must exist in `data`.
pub fn read_centrelines(path: &Path, data: &Dataset) -> Result<CentrelinePoints, CalibrateError> {
    let table = read_table(path)?;
    let m_idx = column_index(path, &table, "measurement")?;
    let x_idx = column_index(path, &table, "x_mm")?;
    let y_idx = column_index(path, &table, "y_mm")?;
    let known: std::collections::HashSet<i64> = data.rows.iter().map(|m| m.measurement).collect();
    let mut out = CentrelinePoints::new();
    for (i, cells) in table.rows.iter().enumerate() {
        let c = Cells { path, row: i + 1, cells };
        let id = c.int(m_idx, "measurement")?;
        if !known.contains(&id) {
            return Err(c.bad("measurement", &cells[m_idx], "the id of a row in the measurement file"));
        }
        let p = [c.float(x_idx, "x_mm")?, c.float(y_idx, "y_mm")?];
        out.entry(id).or_default().push(p);
    }
    Ok(out)
}

/// A marker that is not on the centreline: a point fixed to the body at
/// rest arc length `s_mm` and lateral offset `offset_mm` along the body
/// frame's second axis (toward the side the channel offsets y_i point to
/// in the unbent rod), and where it was measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Marker {
    /// Rest arc length from the clamp, mm (0 ≤ s ≤ L).
    pub s_mm: f64,
    /// Lateral offset in the body frame, mm.
    pub offset_mm: f64,
    /// Measured position along the clamp axis, mm.
    pub x_mm: f64,
    /// Measured position across the clamp axis, mm.
    pub y_mm: f64,
}

/// Markers of each reading, by measurement id.
pub type MarkerPoints = BTreeMap<i64, Vec<Marker>>;

/// Reads a marker file (`measurement,s_mm,offset_mm,x_mm,y_mm`); every
/// measurement id must exist in `data` and 0 ≤ s ≤ `length_mm`.
pub fn read_markers(path: &Path, data: &Dataset, length_mm: f64) -> Result<MarkerPoints, CalibrateError> {
    let table = read_table(path)?;
    let idx: Vec<usize> =
        ["measurement", "s_mm", "offset_mm", "x_mm", "y_mm"].iter().map(|n| column_index(path, &table, n)).collect::<Result<_, _>>()?;
    let known: std::collections::HashSet<i64> = data.rows.iter().map(|m| m.measurement).collect();
    let mut out = MarkerPoints::new();
    for (i, cells) in table.rows.iter().enumerate() {
        let c = Cells { path, row: i + 1, cells };
        let id = c.int(idx[0], "measurement")?;
        if !known.contains(&id) {
            return Err(c.bad("measurement", &cells[idx[0]], "the id of a row in the measurement file"));
        }
        let s_mm = c.float(idx[1], "s_mm")?;
        if !(0.0..=length_mm).contains(&s_mm) {
            return Err(c.bad("s_mm", &cells[idx[1]], &format!("a rest arc length from the clamp, 0 ≤ s ≤ L = {length_mm} mm")));
        }
        let marker = Marker { s_mm, offset_mm: c.float(idx[2], "offset_mm")?, x_mm: c.float(idx[3], "x_mm")?, y_mm: c.float(idx[4], "y_mm")? };
        out.entry(id).or_default().push(marker);
    }
    Ok(out)
}

/// Writes markers as CSV.
pub fn markers_csv(markers: &MarkerPoints) -> String {
    let mut out = String::from("measurement,s_mm,offset_mm,x_mm,y_mm\n");
    for (id, ms) in markers {
        for m in ms {
            out.push_str(&format!("{id},{},{},{},{}\n", m.s_mm, m.offset_mm, m.x_mm, m.y_mm));
        }
    }
    out
}

/// Writes centreline points as CSV.
pub fn centrelines_csv(points: &CentrelinePoints) -> String {
    let mut out = String::from("measurement,x_mm,y_mm\n");
    for (id, pts) in points {
        for p in pts {
            out.push_str(&format!("{id},{},{}\n", p[0], p[1]));
        }
    }
    out
}

/// Splits the routings into fitted and held-out ones.
pub fn split_holdout(data: &Dataset, holdout: Option<&str>) -> Result<(Vec<RoutingGroup>, Option<RoutingGroup>), CalibrateError> {
    let groups = data.groups();
    let Some(id) = holdout else {
        return Ok((groups, None));
    };
    let ids: Vec<&str> = groups.iter().map(|g| g.routing.as_str()).collect();
    let Some(pos) = groups.iter().position(|g| g.routing == id) else {
        return Err(HoldoutError::UnknownRouting { routing: id.to_string(), routings: ids.iter().map(|r| r.to_string()).collect() }.into());
    };
    let mut train = groups;
    let held = train.remove(pos);
    if train.is_empty() {
        return Err(HoldoutError::OnlyRouting { routing: id.to_string() }.into());
    }
    Ok((train, Some(held)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "measurement,routing,y0_mm,y1_mm,y2_mm,y3_mm,y4_mm,tension_n,direction,step,dwell_s,tip_x_mm,tip_y_mm,tip_angle_rad";

    fn parse(text: &str) -> Result<Dataset, CalibrateError> {
        let p = Path::new("m.csv");
        parse_measurements(p, &parse_csv(p, text)?)
    }

    #[test]
    fn reads_a_file_with_extra_columns_and_quotes() {
        let text = format!(
            "{HEADER},note\n1,\"a,b\",1,1,1,1,1,0,rest,0,5,65,0,0,\"x \"\"y\"\"\"\n2,\"a,b\",1,1,1,1,1,0.5,load,1,5,60,10,0.3,\n"
        );
        let d = parse(&text).unwrap();
        assert_eq!(d.rows.len(), 2);
        assert_eq!(d.rows[0].routing, "a,b");
        assert_eq!(d.rows[1].direction, Direction::Load);
        assert_eq!(d.groups().len(), 1);
        // Round trip through the writer.
        let again = parse(&measurements_csv(&d)).unwrap();
        assert_eq!(again.rows.iter().map(|r| r.tip_y_mm).collect::<Vec<_>>(), vec![0.0, 10.0]);
    }

    #[test]
    fn reads_static_captures_and_per_row_noise() {
        let text = format!("{HEADER},noise_mm,noise_deg\n1,a,1,1,1,1,1,0.5,static,0,5,60,10,0.3,0.8,\n2,a,1,1,1,1,1,1.5,Static,1,5,55,20,0.6,,3\n");
        let d = parse(&text).unwrap();
        assert_eq!(d.rows[0].direction, Direction::Static);
        assert_eq!((d.rows[0].noise_mm, d.rows[0].noise_deg), (Some(0.8), None));
        assert_eq!((d.rows[1].noise_mm, d.rows[1].noise_deg), (None, Some(3.0)));
        let again = parse(&measurements_csv(&d)).unwrap();
        assert_eq!(again, Dataset { rows: d.rows.clone(), actuator: None });
        let bad = parse(&format!("{HEADER},noise_mm\n1,a,1,1,1,1,1,0.5,load,0,5,60,10,0.3,0\n")).unwrap_err().to_string();
        assert!(bad.contains("noise_mm") && bad.contains("row 1"), "{bad}");
    }

    #[test]
    fn reads_parquet_like_csv() {
        use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
        use arrow::record_batch::RecordBatch;
        use std::sync::Arc;
        let f = |v: Vec<f64>| Arc::new(Float64Array::from(v)) as ArrayRef;
        let mut cols: Vec<(&str, ArrayRef)> = vec![
            ("measurement", Arc::new(Int64Array::from(vec![1, 2]))),
            ("routing", Arc::new(StringArray::from(vec!["a", "a"]))),
        ];
        for name in ["y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm"] {
            cols.push((name, f(vec![1.5, 1.5])));
        }
        cols.push(("tension_n", f(vec![0.0, 0.7])));
        cols.push(("direction", Arc::new(StringArray::from(vec!["rest", "load"]))));
        cols.push(("step", Arc::new(Int64Array::from(vec![0, 1]))));
        cols.push(("dwell_s", f(vec![5.0, 5.0])));
        cols.push(("tip_x_mm", f(vec![65.0, 61.25])));
        cols.push(("tip_y_mm", f(vec![0.0, 0.1 + 0.2])));
        cols.push(("tip_angle_rad", f(vec![0.0, 0.5])));
        let batch = RecordBatch::try_from_iter(cols).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.parquet");
        let file = std::fs::File::create(&path).unwrap();
        let mut w = parquet::arrow::ArrowWriter::try_new(file, batch.schema(), None).unwrap();
        w.write(&batch).unwrap();
        w.close().unwrap();
        let d = read_measurements(&path).unwrap();
        assert_eq!(d.rows.len(), 2);
        assert_eq!(d.rows[1].tip_y_mm, 0.1 + 0.2, "floats survive exactly");
        assert_eq!(d.rows[1].direction, Direction::Load);
        std::fs::write(&path, b"not parquet").unwrap();
        let e = read_measurements(&path).unwrap_err().to_string();
        assert!(e.contains("m.parquet") && e.contains("Parquet"), "{e}");
    }

    #[test]
    fn the_geometry_header_gives_the_body_and_round_trips() {
        let mut a = crate::model::Rod { length_mm: 360.0, cable_anchor_mm: Some(305.0), ..Default::default() };
        a.radius_profile_mm = vec![(0.0, 15.4), (305.0, 6.4), (360.0, 4.8)];
        crate::calibrate::Effect::Friction.apply(&mut a, 0.3);
        let header = geometry_header(&a);
        assert!(header.lines().all(|l| l.starts_with("# ")) && !header.contains("friction"), "{header}");
        let text = format!("{header}measurement,routing,y0_mm,y1_mm,y2_mm,y3_mm,y4_mm,tension_n,direction,step,dwell_s,tip_x_mm,tip_y_mm,tip_angle_rad\n1,a,0,1,1,1,1,0,rest,0,0,360,0,0\n");
        let p = Path::new("m.csv");
        let table = parse_csv(p, &text).unwrap();
        let body = actuator_of_front_matter(p, &table.front).unwrap().unwrap();
        assert_eq!((body.length_mm, body.cable_anchor_mm, &body.radius_profile_mm), (360.0, Some(305.0), &a.radius_profile_mm));
        assert_eq!(crate::calibrate::Effect::Friction.current(&body), None);
        assert_eq!(parse_measurements(p, &table).unwrap().rows.len(), 1);
        // A bad body in the header is named.
        let bad = parse_csv(p, "# radius_profile_mm = [[0.0, 5.0], [30.0, -1.0], [65.0, 4.0]]\nmeasurement\n").unwrap();
        let e = actuator_of_front_matter(p, &bad.front).unwrap_err().to_string();
        assert!(e.contains("m.csv") && e.contains("geometry header") && e.contains("s = 30 mm"), "{e}");
        let e = actuator_of_front_matter(p, "lenght_mm = 3\n").unwrap_err().to_string();
        assert!(e.contains("lenght_mm"), "{e}");
    }

    #[test]
    fn errors_name_the_row_and_column() {
        let missing = parse("measurement,routing\n1,a\n").unwrap_err().to_string();
        assert!(missing.contains("y0_mm"), "{missing}");
        let cases = [
            ("1,a,1,1,1,1,1,-1,load,1,5,60,10,0.3", "row 1", "tension_n"),
            ("1,a,1,1,1,1,1,1,sideways,1,5,60,10,0.3", "row 1", "direction"),
            ("1,a,1,1,1,1,1,1,rest,1,5,60,10,0.3", "row 1", "tension_n"),
            ("1,a,1,1,x,1,1,1,load,1,5,60,10,0.3", "row 1", "y2_mm"),
            ("1,a,1,1,1,1,1,1,load,1,5,60,10,45", "row 1", "tip_angle_rad"),
            ("1,a,1,1,1,1,1,1,load,1,5,60,,0.3", "row 1", "tip_y_mm"),
            ("1,a,1,1,1,1,1,1,load,1,5,60,10", "row 1", "fields"),
        ];
        for (line, row, what) in cases {
            let e = parse(&format!("{HEADER}\n{line}\n")).unwrap_err().to_string();
            assert!(e.contains(row) && e.contains(what), "{line}: {e}");
        }
        let dup = parse(&format!("{HEADER}\n1,a,1,1,1,1,1,1,load,1,5,60,10,0.3\n2,a,1,1,1,1,1,1,load,1,5,60,10,0.3\n"));
        assert!(dup.unwrap_err().to_string().contains("step 1 twice"));
        let clash = parse(&format!("{HEADER}\n1,a,1,1,1,1,1,1,load,1,5,60,10,0.3\n2,a,2,1,1,1,1,1,load,2,5,60,10,0.3\n"));
        let e = clash.unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("own id"), "{e}");
        assert!(matches!(parse(""), Err(CalibrateError::Empty { .. })));
    }
}
