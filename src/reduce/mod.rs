//! Reduce: bin a sweep's tip positions into feasibility maps (thesis Ch. 4,
//! model-notes §5; the output contract is docs/maps.md).
//!
//! Two passes over the run's batches: the first keeps, per converged row, its
//! tip and a_0…a_2 (and restores the mirrored half when the run dropped
//! mirror images); cells, percentiles, modes and the picks are computed from
//! that; the second pass fetches the full rows of the picked designs.

mod columns;
pub mod explorer;
pub mod plots;
pub mod stats;
pub mod write;

use arrow::record_batch::RecordBatch;
use columns::RowColumns;
use serde::{Deserialize, Serialize};
use crate::shape::LengthBasis;
use stats::{quantile_sorted, quantiles};
use std::collections::{BTreeMap, HashMap};

/// Number of characteristic modes: a_0 in 4 ranges × a_1 in 3.
pub const MODES: usize = 12;

/// Why a reduction failed.
#[derive(Debug, thiserror::Error)]
pub enum ReduceError {
    /// The shards lack a column or hold it with an unusable type.
    #[error("sweep data: {0}")]
    Schema(String),
    /// Reading the run failed.
    #[error("reading the run: {0}")]
    Read(String),
    /// No converged row to map.
    #[error("the run has no converged solves to map ({failed} failed): check the spec and `cablemap status`")]
    Empty { failed: u64 },
    /// An option is out of range.
    #[error("{0}")]
    BadOption(String),
    /// Writing an output.
    #[error("writing {path}: {message}")]
    Write { path: String, message: String },
    /// Drawing a picture.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}

/// What the reducer needs to know about the run it reads.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunInfo {
    /// Whether the run dropped mirror images (the reducer restores them).
    pub mirrored: bool,
    /// Highest coefficient order stored (columns a0 … a{order}).
    pub order: usize,
    /// Tension range of the run, N.
    pub tension_range_n: [f64; 2],
    /// Rod radius, mm.
    pub radius_mm: f64,
    /// Rod length, mm.
    pub length_mm: f64,
    /// Where the data came from.
    pub run_dir: String,
    /// Hash of the run's spec.
    pub spec_hash: String,
    /// The length the run's a_i are per unit of.
    pub length_basis: LengthBasis,
}

/// Boundaries of the characteristic modes: a_0 split into 4 ranges by three
/// values, a_1 into 3 by two (both mm⁻¹, in the run's length basis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModeBoundaries {
    /// Ascending a_0 boundaries.
    pub a0: [f64; 3],
    /// Ascending a_1 boundaries.
    pub a1: [f64; 2],
}

impl ModeBoundaries {
    /// Checks that both lists are finite and ascending.
    pub fn validate(&self) -> Result<(), ReduceError> {
        let ok = |v: &[f64]| v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
        if ok(&self.a0) && ok(&self.a1) {
            Ok(())
        } else {
            Err(ReduceError::BadOption(format!(
                "mode boundaries must be finite and strictly ascending: a0 {:?}, a1 {:?}",
                self.a0, self.a1
            )))
        }
    }

    /// (a_0 range, a_1 range) of a coefficient pair.
    pub fn ranges(&self, a0: f64, a1: f64) -> (usize, usize) {
        (self.a0.iter().filter(|&&b| a0 >= b).count(), self.a1.iter().filter(|&&b| a1 >= b).count())
    }

    /// Mode index 3·i + j.
    pub fn mode(&self, a0: f64, a1: f64) -> usize {
        let (i, j) = self.ranges(a0, a1);
        3 * i + j
    }

    /// Bounds (lo, hi) of range `i` of a list (open ends are ±inf).
    fn bounds(list: &[f64], i: usize) -> (f64, f64) {
        let lo = if i == 0 { f64::NEG_INFINITY } else { list[i - 1] };
        let hi = if i == list.len() { f64::INFINITY } else { list[i] };
        (lo, hi)
    }
}

/// Options of a reduction.
#[derive(Debug, Clone)]
pub struct ReduceOptions {
    /// Cell size of the grid, mm.
    pub cell_mm: f64,
    /// Explicit mode boundaries; `None` takes quantiles of the data.
    pub mode_boundaries: Option<ModeBoundaries>,
    /// Designs kept per cell in designs.parquet.
    pub designs_per_cell: usize,
}

impl Default for ReduceOptions {
    fn default() -> Self {
        Self { cell_mm: 1.0, mode_boundaries: None, designs_per_cell: 16 }
    }
}

/// The summary written as summary.json (docs/maps.md).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MapSummary {
    /// Cell size, mm.
    pub cell_mm: f64,
    /// Lower-left corner of cell (0, 0), mm.
    pub x_min_mm: f64,
    /// See `x_min_mm`.
    pub y_min_mm: f64,
    /// Grid size in cells.
    pub nx: usize,
    /// See `nx`.
    pub ny: usize,
    /// Highest coefficient order in the run.
    pub order: usize,
    /// Whether the mirrored half was restored.
    pub mirrored: bool,
    /// Rows after mirroring.
    pub rows_total: u64,
    /// Converged rows after mirroring (the sum of cell counts).
    pub rows_converged: u64,
    /// Failed rows after mirroring.
    pub rows_failed: u64,
    /// Failed rows by status.
    pub failed_by_status: BTreeMap<String, u64>,
    /// Mode boundaries used.
    pub mode_boundaries: ModeBoundaries,
    /// `quantiles` or `explicit`.
    pub mode_boundaries_source: String,
    /// Non-empty cells.
    pub cells: usize,
    /// Tension range of the run, N.
    pub tension_range_n: [f64; 2],
    /// Rod radius, mm.
    pub radius_mm: f64,
    /// Rod length, mm.
    pub length_mm: f64,
    /// Where the data came from.
    pub run_dir: String,
    /// Hash of the run's spec.
    pub spec_hash: String,
    /// The length the coefficients (statistics, mode boundaries, designs)
    /// are per unit of: `rest` (the thesis's basis) or `deformed`. Maps
    /// written before this field existed were in the deformed basis.
    #[serde(default = "basis_of_maps_without_the_field")]
    pub length_basis: LengthBasis,
}

/// Maps written before `length_basis` was recorded had deformed-length a_i.
fn basis_of_maps_without_the_field() -> LengthBasis {
    LengthBasis::Deformed
}

/// Statistics of one coefficient in one cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoefficientStats {
    /// 10th percentile.
    pub p10: f64,
    /// 90th percentile.
    pub p90: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// One non-empty cell.
#[derive(Debug, Clone)]
pub struct CellStats {
    /// Cell column (x).
    pub ix: i32,
    /// Cell row (y).
    pub iy: i32,
    /// Cell centre, mm.
    pub x_mm: f64,
    /// Cell centre, mm.
    pub y_mm: f64,
    /// Simulations whose tip lies in the cell.
    pub count: i64,
    /// a_0 … a_min(order,2).
    pub coefficients: Vec<CoefficientStats>,
    /// Simulations per mode.
    pub modes: [i64; MODES],
}

/// A simulated design (one row of the run, mirrored if flagged).
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Cell column.
    pub ix: i32,
    /// Cell row.
    pub iy: i32,
    /// Routing number in the run.
    pub routing_id: i64,
    /// Whether this is the mirror image of the stored row.
    pub mirrored: bool,
    /// Control points, mm.
    pub y_mm: [f64; 5],
    /// Tension, N.
    pub tension_n: f64,
    /// Tip, mm.
    pub tip_x_mm: f64,
    /// Tip, mm.
    pub tip_y_mm: f64,
    /// Tip tangent angle, rad.
    pub tip_angle_rad: f64,
    /// a_0 … a_order.
    pub a: Vec<f64>,
}

/// One characteristic mode.
#[derive(Debug, Clone)]
pub struct ModeStats {
    /// Mode index 3·i + j.
    pub mode: usize,
    /// a_0 range i.
    pub a0_range: usize,
    /// a_1 range j.
    pub a1_range: usize,
    /// a_0 bounds.
    pub a0_bounds: (f64, f64),
    /// a_1 bounds.
    pub a1_bounds: (f64, f64),
    /// Simulations in the mode.
    pub count: i64,
    /// Cells where the mode occurs.
    pub cells: i64,
    /// The simulation nearest the mode's median (a_0, a_1).
    pub representative: Option<Design>,
}

/// Everything a map directory holds.
#[derive(Debug, Clone)]
pub struct MapData {
    /// summary.json.
    pub summary: MapSummary,
    /// cells.parquet.
    pub cells: Vec<CellStats>,
    /// modes.parquet.
    pub modes: Vec<ModeStats>,
    /// designs.parquet.
    pub designs: Vec<Design>,
}

/// One converged simulation as pass 1 keeps it.
#[derive(Debug, Clone, Copy)]
struct Sample {
    x: f64,
    y: f64,
    a: [f64; 3],
    /// Row number in pass order.
    row: u32,
    mirrored: bool,
}

/// Reduces a run. `batches` is called once per pass and must yield the same
/// rows in the same order each time.
pub fn reduce_batches<F, I>(info: &RunInfo, options: &ReduceOptions, mut batches: F) -> Result<MapData, ReduceError>
where
    F: FnMut() -> Result<I, ReduceError>,
    I: Iterator<Item = Result<RecordBatch, ReduceError>>,
{
    if !(options.cell_mm.is_finite() && options.cell_mm > 0.0) {
        return Err(ReduceError::BadOption(format!("cell size {} mm must be positive", crate::io::fmt_num(options.cell_mm))));
    }
    if info.order < 1 {
        return Err(ReduceError::BadOption("the run stores only a_0; modes need a_1: sweep with order ≥ 1".into()));
    }
    if let Some(b) = &options.mode_boundaries {
        b.validate()?;
    }
    let nk = info.order.min(2) + 1;
    // Pass 1: tips and coefficients of every converged row (and its mirror).
    let mut samples: Vec<Sample> = Vec::new();
    let mut failed_by_status: BTreeMap<String, u64> = BTreeMap::new();
    let mut rows_total = 0u64;
    let mut row = 0u32;
    for batch in batches()? {
        let cols = RowColumns::from_batch(&batch?, info.order)?;
        for i in 0..cols.len() {
            let self_mirror = cols.y_mm.iter().all(|y| y.value(i) == 0.0);
            let copies = if info.mirrored && !self_mirror { 2 } else { 1 };
            rows_total += copies;
            if !cols.converged(i) {
                *failed_by_status.entry(cols.status_of(i).to_string()).or_default() += copies;
            } else {
                let mut a = [0.0; 3];
                for (k, slot) in a.iter_mut().enumerate().take(nk) {
                    *slot = cols.a[k].value(i);
                }
                let s = Sample { x: cols.tip_x_mm.value(i), y: cols.tip_y_mm.value(i), a, row, mirrored: false };
                samples.push(s);
                if copies == 2 {
                    samples.push(Sample { y: -s.y, a: a.map(|v| -v), mirrored: true, ..s });
                }
            }
            row += 1;
        }
    }
    let rows_failed: u64 = failed_by_status.values().sum();
    if samples.is_empty() {
        return Err(ReduceError::Empty { failed: rows_failed });
    }
    // Quantiles of a_0 and a_1 over the converged rows, sorted once: they
    // give the default mode boundaries and the spreads (interquartile
    // ranges) that scale the distance to a mode's median.
    let sorted = |k: usize| -> Vec<f64> {
        let mut v: Vec<f64> = samples.iter().map(|s| s.a[k]).collect();
        v.sort_unstable_by(f64::total_cmp);
        v
    };
    let (a0, a1) = (sorted(0), sorted(1));
    let q0 = [0.25, 0.5, 0.75].map(|p| quantile_sorted(&a0, p));
    let q1 = [0.25, 1.0 / 3.0, 2.0 / 3.0, 0.75].map(|p| quantile_sorted(&a1, p));
    drop((a0, a1));
    let (s0, s1) = ((q0[2] - q0[0]).max(1e-12), (q1[3] - q1[0]).max(1e-12));
    let (boundaries, source) = match options.mode_boundaries {
        Some(b) => (b, "explicit"),
        None => (ModeBoundaries { a0: [q0[0], q0[1], q0[2]], a1: [q1[1], q1[2]] }, "quantiles"),
    };
    // Quantiles of too few distinct coefficients (a one-routing run) do not
    // split the modes; a map with such boundaries would be refused by
    // `feasible` and `design`, so it is refused here, with the fix.
    boundaries.validate().map_err(|e| {
        ReduceError::BadOption(format!(
            "{e}: the run's a0/a1 values are too few or too alike to split into modes by quantiles \
             (one routing, or a grid whose routings all bend alike); give explicit --a0-bounds B1,B2,B3 and \
             --a1-bounds C1,C2"
        ))
    })?;
    // The grid.
    let cell = options.cell_mm;
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for s in &samples {
        xmin = xmin.min(s.x);
        xmax = xmax.max(s.x);
        ymin = ymin.min(s.y);
        ymax = ymax.max(s.y);
    }
    let x0 = (xmin / cell).floor() * cell;
    let y0 = (ymin / cell).floor() * cell;
    // Cell indices are i32 in the tables: a cell so small that the reach
    // spans more than MAX_CELLS_PER_AXIS cells would overflow them (and no
    // picture of it could be drawn), so it is refused with the smallest
    // cell that works.
    let (span_x, span_y) = ((xmax - x0) / cell, (ymax - y0) / cell);
    let limit = MAX_CELLS_PER_AXIS as f64;
    if !(x0.is_finite() && y0.is_finite() && span_x < limit && span_y < limit) {
        let reach = (xmax - xmin).max(ymax - ymin);
        return Err(ReduceError::BadOption(format!(
            "--cell-mm {} is too small: the reach ({:.3} × {:.3} mm) would span more than {MAX_CELLS_PER_AXIS} cells per axis; \
             use --cell-mm ≥ {:.3e}",
            crate::io::fmt_num(cell),
            xmax - xmin,
            ymax - ymin,
            (reach / (limit - 2.0)).max(f64::MIN_POSITIVE)
        )));
    }
    let nx = (span_x.floor() as usize) + 1;
    let ny = (span_y.floor() as usize) + 1;
    let cell_of = |s: &Sample| -> (i32, i32) {
        (((s.x - x0) / cell).floor() as i32, ((s.y - y0) / cell).floor() as i32)
    };
    samples.sort_unstable_by_key(|s| {
        let (ix, iy) = cell_of(s);
        (ix, iy, s.row, s.mirrored)
    });
    // Per cell: counts, percentiles, modes, design picks.
    let mut cells = Vec::new();
    let mut picks: Vec<(u32, bool, i32, i32)> = Vec::new();
    let mut mode_cells = [0i64; MODES];
    let mut values = Vec::new();
    let mut start = 0;
    while start < samples.len() {
        let key = cell_of(&samples[start]);
        let mut end = start;
        while end < samples.len() && cell_of(&samples[end]) == key {
            end += 1;
        }
        let group = &mut samples[start..end];
        let mut coefficients = Vec::with_capacity(nk);
        for k in 0..nk {
            values.clear();
            values.extend(group.iter().map(|s| s.a[k]));
            values.sort_unstable_by(f64::total_cmp);
            coefficients.push(CoefficientStats {
                p10: quantile_sorted(&values, 0.1),
                p90: quantile_sorted(&values, 0.9),
                min: values[0],
                max: values[values.len() - 1],
            });
        }
        let mut modes = [0i64; MODES];
        for s in group.iter() {
            modes[boundaries.mode(s.a[0], s.a[1])] += 1;
        }
        for (m, &c) in modes.iter().enumerate() {
            if c > 0 {
                mode_cells[m] += 1;
            }
        }
        // Designs spanning the cell's a_0 range.
        group.sort_unstable_by(|p, q| p.a[0].total_cmp(&q.a[0]).then(p.row.cmp(&q.row)));
        let n = group.len();
        let keep = options.designs_per_cell.min(n);
        for j in 0..keep {
            let idx = if keep == 1 { n / 2 } else { j * (n - 1) / (keep - 1) };
            picks.push((group[idx].row, group[idx].mirrored, key.0, key.1));
        }
        cells.push(CellStats {
            ix: key.0,
            iy: key.1,
            x_mm: x0 + (key.0 as f64 + 0.5) * cell,
            y_mm: y0 + (key.1 as f64 + 0.5) * cell,
            count: (end - start) as i64,
            coefficients,
            modes,
        });
        start = end;
    }
    // Modes: counts and the sample nearest each mode's median (a_0, a_1),
    // distances scaled by the spread of each coefficient over the run.
    let mut by_mode: Vec<Vec<&Sample>> = vec![Vec::new(); MODES];
    for s in &samples {
        by_mode[boundaries.mode(s.a[0], s.a[1])].push(s);
    }
    let mut rep_rows: Vec<Option<(u32, bool)>> = vec![None; MODES];
    for (m, members) in by_mode.iter().enumerate() {
        if members.is_empty() {
            continue;
        }
        let med = |k: usize| quantiles(&members.iter().map(|s| s.a[k]).collect::<Vec<_>>(), &[0.5])[0];
        let (m0, m1) = (med(0), med(1));
        let best = members
            .iter()
            .min_by(|p, q| {
                let d = |s: &Sample| ((s.a[0] - m0) / s0).powi(2) + ((s.a[1] - m1) / s1).powi(2);
                d(p).total_cmp(&d(q)).then(p.row.cmp(&q.row))
            })
            .expect("non-empty");
        rep_rows[m] = Some((best.row, best.mirrored));
    }
    let rows_converged = samples.len() as u64;
    drop(by_mode);
    drop(samples);
    // Pass 2: the full rows of every pick.
    let mut wanted: HashMap<u32, Option<Design>> = picks.iter().map(|p| (p.0, None)).collect();
    for r in rep_rows.iter().flatten() {
        wanted.insert(r.0, None);
    }
    let mut row = 0u32;
    for batch in batches()? {
        let cols = RowColumns::from_batch(&batch?, info.order)?;
        for i in 0..cols.len() {
            if let Some(slot) = wanted.get_mut(&row) {
                *slot = Some(Design {
                    ix: 0,
                    iy: 0,
                    routing_id: cols.routing_id.value(i),
                    mirrored: false,
                    y_mm: std::array::from_fn(|k| cols.y_mm[k].value(i)),
                    tension_n: cols.tension_n.value(i),
                    tip_x_mm: cols.tip_x_mm.value(i),
                    tip_y_mm: cols.tip_y_mm.value(i),
                    tip_angle_rad: cols.tip_angle_rad.value(i),
                    a: cols.a.iter().map(|a| a.value(i)).collect(),
                });
            }
            row += 1;
        }
    }
    let fetch = |r: u32, mirrored: bool| -> Result<Design, ReduceError> {
        let d = wanted
            .get(&r)
            .and_then(|d| d.clone())
            .ok_or_else(|| ReduceError::Read("the run changed between the two passes: reduce again".into()))?;
        Ok(if mirrored {
            Design {
                mirrored: true,
                y_mm: d.y_mm.map(|v| -v),
                tip_y_mm: -d.tip_y_mm,
                tip_angle_rad: -d.tip_angle_rad,
                a: d.a.iter().map(|v| -v).collect(),
                ..d
            }
        } else {
            d
        })
    };
    let mut designs = Vec::with_capacity(picks.len());
    for &(r, mirrored, ix, iy) in &picks {
        designs.push(Design { ix, iy, ..fetch(r, mirrored)? });
    }
    let mut modes = Vec::with_capacity(MODES);
    for m in 0..MODES {
        let (i, j) = (m / 3, m % 3);
        let count = cells.iter().map(|c| c.modes[m]).sum();
        let representative = match rep_rows[m] {
            Some((r, mirrored)) => {
                let d = fetch(r, mirrored)?;
                let ix = ((d.tip_x_mm - x0) / cell).floor() as i32;
                let iy = ((d.tip_y_mm - y0) / cell).floor() as i32;
                Some(Design { ix, iy, ..d })
            }
            None => None,
        };
        modes.push(ModeStats {
            mode: m,
            a0_range: i,
            a1_range: j,
            a0_bounds: ModeBoundaries::bounds(&boundaries.a0, i),
            a1_bounds: ModeBoundaries::bounds(&boundaries.a1, j),
            count,
            cells: mode_cells[m],
            representative,
        });
    }
    let summary = MapSummary {
        cell_mm: cell,
        x_min_mm: x0,
        y_min_mm: y0,
        nx,
        ny,
        order: info.order,
        mirrored: info.mirrored,
        rows_total,
        rows_converged,
        rows_failed,
        failed_by_status,
        mode_boundaries: boundaries,
        mode_boundaries_source: source.into(),
        cells: cells.len(),
        tension_range_n: info.tension_range_n,
        radius_mm: info.radius_mm,
        length_mm: info.length_mm,
        run_dir: info.run_dir.clone(),
        spec_hash: info.spec_hash.clone(),
        length_basis: info.length_basis,
    };
    Ok(MapData { summary, cells, modes, designs })
}

/// Most cells along either axis of a map (cell indices are stored as i32;
/// 100 000 cells resolve a 100 mm reach to 1 µm).
pub const MAX_CELLS_PER_AXIS: usize = 100_000;

/// Unit of a_k for labels: κ = Σ a_k P_k(t) with t dimensionless, so every
/// coefficient is a curvature.
pub const COEFFICIENT_UNIT: &str = "mm⁻¹";

/// Writes the map directory `dir` as a whole: everything is written into a
/// staging directory beside it (`.NAME.tmp-TOKEN`), which then replaces
/// `dir` by rename, so a reader sees the old map or the new one, never a
/// mix (an interrupted reduce leaves the old map untouched). `dir` must be
/// new, empty, or an earlier map (it has summary.json); it must not be, or
/// lie directly inside, a sweep run directory.
pub fn write_map_replacing(
    dir: &std::path::Path,
    map: &MapData,
    actuator: &crate::model::Actuator,
    solver: &crate::model::SolverOptions,
) -> Result<Vec<plots::Picture>, ReduceError> {
    use std::path::Path;
    let werr = |path: &Path, message: String| ReduceError::Write { path: path.display().to_string(), message };
    let name = check_map_out(dir)?;
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    std::fs::create_dir_all(&parent).map_err(|e| werr(&parent, format!("cannot create ({e})")))?;
    remove_abandoned_staging(&parent, &name);
    let staging = parent.join(format!(".{name}.tmp-{}", crate::io::unique_token()));
    std::fs::create_dir(&staging).map_err(|e| werr(&staging, format!("cannot create ({e})")))?;
    // Held while writing so that another reduce does not clear it away.
    let lock = std::fs::File::open(&staging).ok();
    if let Some(l) = &lock {
        let _ = l.try_lock();
    }
    let written = write_map(&staging, map, actuator, solver).and_then(|pictures| {
        crate::io::sync_dir(&staging);
        replace_dir(&staging, dir, &parent, &name).map_err(|e| werr(dir, format!("cannot put the new map in place ({e})")))?;
        Ok(pictures)
    });
    if written.is_err() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    drop(lock);
    written
}

/// Checks that `dir` can take a map (see [`write_map_replacing`]) before
/// any work is done; returns its file name.
pub fn check_map_out(dir: &std::path::Path) -> Result<String, ReduceError> {
    use std::path::Path;
    let werr = |path: &Path, message: String| ReduceError::BadOption(format!("map directory {}: {message}", path.display()));
    crate::io::check_not_in_run_dir(dir, "--out").map_err(ReduceError::BadOption)?;
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).filter(|n| n != "." && n != "..");
    let Some(name) = name else {
        return Err(werr(dir, "give a map directory by name (not '.' or '..'): it is replaced as a whole".into()));
    };
    match std::fs::read_dir(dir) {
        Ok(mut entries) => {
            if entries.next().is_some() && !dir.join("summary.json").is_file() {
                return Err(werr(
                    dir,
                    "exists and is not a cablemap map (no summary.json), and a map directory is replaced as a whole: \
                     give a new directory, or an earlier map to replace"
                        .into(),
                ));
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(werr(dir, format!("cannot be read as a directory ({e})"))),
    }
    Ok(name)
}

/// Moves `staging` to `dir`: directly when `dir` is absent or empty, else
/// by an atomic exchange (Linux), else by moving the old map aside first
/// and deleting it after (a moment without `dir`, never a mixed one).
fn replace_dir(staging: &std::path::Path, dir: &std::path::Path, parent: &std::path::Path, name: &str) -> std::io::Result<()> {
    match std::fs::rename(staging, dir) {
        Ok(()) => {}
        Err(_) if dir.is_dir() && crate::io::exchange(staging, dir)? => {
            // `staging` now holds the old map.
            let _ = std::fs::remove_dir_all(staging);
        }
        Err(_) if dir.is_dir() => {
            let old = parent.join(format!(".{name}.old-{}", crate::io::unique_token()));
            std::fs::rename(dir, &old)?;
            if let Err(e) = std::fs::rename(staging, dir) {
                let _ = std::fs::rename(&old, dir);
                return Err(e);
            }
            let _ = std::fs::remove_dir_all(&old);
        }
        Err(e) => return Err(e),
    }
    crate::io::sync_dir(parent);
    Ok(())
}

/// Removes staging and old-map directories of `name` left by killed
/// reduces (no writer holds their lock, or they are stale).
fn remove_abandoned_staging(parent: &std::path::Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else { return };
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let left = crate::io::is_temp_of(&file_name, name)
            || file_name.strip_prefix(&format!(".{name}.old-")).is_some_and(|t| !t.is_empty());
        if left && entry.path().is_dir() && crate::io::is_abandoned(&entry.path()) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Writes the whole map directory: tables, pictures and index.html.
/// `actuator` and `solver` re-simulate the mode representatives for drawing.
/// Writes in place; [`write_map_replacing`] is what the commands use.
pub fn write_map(
    dir: &std::path::Path,
    map: &MapData,
    actuator: &crate::model::Actuator,
    solver: &crate::model::SolverOptions,
) -> Result<Vec<plots::Picture>, ReduceError> {
    use plots::{draw_heatmap, Picture, Scale};
    std::fs::create_dir_all(dir)
        .map_err(|e| ReduceError::Write { path: dir.display().to_string(), message: e.to_string() })?;
    write::write_tables(dir, map)?;
    let s = &map.summary;
    let mut pictures = Vec::new();
    let reach: Vec<(i32, i32, f64)> = map.cells.iter().map(|c| (c.ix, c.iy, c.count as f64)).collect();
    draw_heatmap(&dir.join("reach.png"), s, "Reachable tip positions: simulations per cell", "simulations per cell (log scale)", &reach, Scale::Log)?;
    pictures.push(Picture {
        file: "reach.png".into(),
        title: "Reach (thesis Fig. 4.1)".into(),
        explanation: format!(
            "Every {} mm cell that some routing and tension puts the tip in; the colour counts the simulations, so dark cells are reached by few configurations.",
            s.cell_mm
        ),
    });
    let nk = map.cells.first().map_or(0, |c| c.coefficients.len());
    for k in 0..nk {
        let stats = |f: &dyn Fn(&CoefficientStats) -> f64| -> Vec<(i32, i32, f64)> {
            map.cells.iter().map(|c| (c.ix, c.iy, f(&c.coefficients[k]))).collect()
        };
        let unit = format!("a{k} ({COEFFICIENT_UNIT}, {} basis)", s.length_basis);
        for (name, what, values, scale) in [
            ("p10", "10th percentile", stats(&|c| c.p10), Scale::Symmetric),
            ("p90", "90th percentile", stats(&|c| c.p90), Scale::Symmetric),
            ("gap", "90th − 10th percentile", stats(&|c| c.p90 - c.p10), Scale::Linear),
        ] {
            let file = format!("a{k}_{name}.png");
            let title = format!("a{k}: {what} per cell");
            draw_heatmap(&dir.join(&file), s, &title, &unit, &values, scale)?;
            // Thesis Fig. 4.2 shows a0, Fig. 4.3 a1; the thesis has no a2 map.
            let figure = match k {
                0 => " (as thesis Fig. 4.2)",
                1 => " (as thesis Fig. 4.3)",
                _ => "",
            };
            let basis = s.length_basis.describe();
            let explanation = match name {
                "gap" => format!("Spread of a{k} ({COEFFICIENT_UNIT}, {basis}) among the configurations reaching each cell: a large gap means more than one mode of deformation reaches it{figure}."),
                _ => format!("The {what} of a{k} ({COEFFICIENT_UNIT}, {basis}) over the simulations whose tip falls in each cell{figure}."),
            };
            pictures.push(Picture { file, title, explanation });
        }
    }
    // Representative shapes, re-simulated from their routing and tension.
    let shapes: Vec<Option<crate::plot::BodyDrawing>> = map
        .modes
        .iter()
        .map(|m| {
            let d = m.representative.as_ref()?;
            let routing = crate::model::Routing::new(&d.y_mm, actuator.length_mm, actuator.radius_mm).ok()?;
            let sim = crate::model::simulate(actuator, solver, &routing, d.tension_n, 1, crate::shape::LengthBasis::default()).ok()?;
            Some(crate::plot::BodyDrawing::of_simulation(&sim, actuator.radius_mm, format!("mode {}", m.mode), plotters::style::full_palette::BLUE_800))
        })
        .collect();
    plots::draw_modes(&dir.join("modes.png"), map, &shapes)?;
    pictures.push(Picture {
        file: "modes.png".into(),
        title: "Characteristic modes (thesis Fig. 4.4)".into(),
        explanation: format!(
            "a0 split into 4 ranges (rows) and a1 into 3 (columns), a_i {}; each panel maps where that combination occurs and draws the simulation nearest the mode's median coefficients.",
            s.length_basis.describe()
        ),
    });
    explorer::write_explorer(dir, map, actuator, &shapes, &pictures)?;
    Ok(pictures)
}

#[cfg(test)]
mod tests {
    use super::*;
    use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
    use arrow::datatypes::{DataType, Field, Schema};
    use std::sync::Arc;

    /// Rows (routing, tension, status, tip x, tip y, a0, a1, a2) as a sweep batch.
    type Row = ([f64; 5], f64, &'static str, f64, f64, [f64; 3]);

    fn batch(rows: &[Row]) -> RecordBatch {
        let f = |name: &str, v: Vec<Option<f64>>| -> (Field, ArrayRef) {
            (Field::new(name, DataType::Float64, true), Arc::new(Float64Array::from(v)))
        };
        let ok = |r: &Row| r.2 == "ok";
        let mut cols: Vec<(Field, ArrayRef)> = vec![
            (Field::new("routing_id", DataType::Int64, false), Arc::new(Int64Array::from((0..rows.len() as i64).collect::<Vec<_>>()))),
            (Field::new("status", DataType::Utf8, false), Arc::new(StringArray::from(rows.iter().map(|r| r.2).collect::<Vec<_>>()))),
        ];
        for k in 0..5 {
            cols.push(f(&format!("y{k}_mm"), rows.iter().map(|r| Some(r.0[k])).collect()));
        }
        cols.push(f("tension_n", rows.iter().map(|r| Some(r.1)).collect()));
        cols.push(f("tip_x_mm", rows.iter().map(|r| ok(r).then_some(r.3)).collect()));
        cols.push(f("tip_y_mm", rows.iter().map(|r| ok(r).then_some(r.4)).collect()));
        cols.push(f("tip_angle_rad", rows.iter().map(|r| ok(r).then_some(0.1)).collect()));
        for k in 0..3 {
            cols.push(f(&format!("a{k}"), rows.iter().map(|r| ok(r).then_some(r.5[k])).collect()));
        }
        let (fields, arrays): (Vec<Field>, Vec<ArrayRef>) = cols.into_iter().unzip();
        RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays).unwrap()
    }

    fn info(mirrored: bool) -> RunInfo {
        RunInfo {
            mirrored,
            order: 2,
            tension_range_n: [1.0, 2.0],
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "test".into(),
            spec_hash: "x".into(),
            length_basis: LengthBasis::Rest,
        }
    }

    fn run(rows: &[Row], mirrored: bool, options: &ReduceOptions) -> MapData {
        let b = batch(rows);
        reduce_batches(&info(mirrored), options, || Ok(vec![Ok(b.clone())].into_iter())).unwrap()
    }

    fn pseudo_rows(n: usize) -> Vec<Row> {
        // A deterministic scatter of tips over a few cells.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|i| {
                let y = [next() * 2.0 - 1.0, 1.0, 0.0, -1.0, 0.5];
                let status = if i % 17 == 3 { "shooting_not_converged" } else { "ok" };
                (y, 1.0 + next(), status, 50.0 + 4.0 * next(), 1.0 + 3.0 * next(), [next() - 0.5, next() - 0.3, next()])
            })
            .collect()
    }

    #[test]
    fn counts_sum_to_converged_rows_and_percentiles_match_a_reference() {
        let rows = pseudo_rows(400);
        let map = run(&rows, false, &ReduceOptions::default());
        let converged = rows.iter().filter(|r| r.2 == "ok").count() as i64;
        assert_eq!(map.cells.iter().map(|c| c.count).sum::<i64>(), converged);
        assert_eq!(map.summary.rows_failed, rows.len() as u64 - converged as u64);
        for c in &map.cells {
            // Straightforward reference: collect the cell's values, sort, interpolate.
            let mut a0: Vec<f64> = rows
                .iter()
                .filter(|r| r.2 == "ok")
                .filter(|r| (r.3 - map.summary.x_min_mm).div_euclid(1.0) as i32 == c.ix)
                .filter(|r| (r.4 - map.summary.y_min_mm).div_euclid(1.0) as i32 == c.iy)
                .map(|r| r.5[0])
                .collect();
            assert_eq!(a0.len() as i64, c.count);
            a0.sort_by(f64::total_cmp);
            let pos = 0.1 * (a0.len() - 1) as f64;
            let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
            let p10 = a0[lo] + (a0[hi] - a0[lo]) * (pos - lo as f64);
            assert!((c.coefficients[0].p10 - p10).abs() < 1e-15);
            assert_eq!(c.modes.iter().sum::<i64>(), c.count, "mode counts sum to the cell count");
        }
        assert_eq!(map.modes.iter().map(|m| m.count).sum::<i64>(), converged);
        // Designs come from their own cell.
        for d in &map.designs {
            let ix = ((d.tip_x_mm - map.summary.x_min_mm) / map.summary.cell_mm).floor() as i32;
            assert_eq!((ix, d.iy), (d.ix, ((d.tip_y_mm - map.summary.y_min_mm) / map.summary.cell_mm).floor() as i32));
        }
    }

    #[test]
    fn mirroring_doubles_all_but_the_self_mirror_routing() {
        let mut rows = pseudo_rows(100);
        rows.push(([0.0; 5], 1.5, "ok", 60.0, 0.2, [0.0, 0.0, 0.0]));
        let converged = rows.iter().filter(|r| r.2 == "ok").count() as i64;
        let map = run(&rows, true, &ReduceOptions::default());
        assert_eq!(map.cells.iter().map(|c| c.count).sum::<i64>(), 2 * converged - 1);
        assert!(map.designs.iter().any(|d| d.mirrored && d.tip_y_mm < 0.0));
        for d in map.designs.iter().filter(|d| d.mirrored) {
            let original = rows.iter().find(|r| r.0 == d.y_mm.map(|v| -v) && r.1 == d.tension_n).unwrap();
            assert_eq!(d.tip_y_mm, -original.4);
            assert_eq!(d.a[0], -original.5[0]);
        }
    }

    #[test]
    fn explicit_boundaries_are_used_and_checked() {
        let rows = pseudo_rows(50);
        let b = ModeBoundaries { a0: [-0.2, 0.0, 0.2], a1: [-0.1, 0.1] };
        let map = run(&rows, false, &ReduceOptions { mode_boundaries: Some(b), ..Default::default() });
        assert_eq!(map.summary.mode_boundaries_source, "explicit");
        for r in rows.iter().filter(|r| r.2 == "ok") {
            let m = b.mode(r.5[0], r.5[1]);
            assert!(map.modes[m].count > 0);
        }
        let bad = ModeBoundaries { a0: [0.2, 0.0, 0.3], a1: [-0.1, 0.1] };
        let e = reduce_batches(&info(false), &ReduceOptions { mode_boundaries: Some(bad), ..Default::default() }, || {
            Ok(Vec::<Result<RecordBatch, ReduceError>>::new().into_iter())
        })
        .unwrap_err();
        assert!(e.to_string().contains("ascending"), "{e}");
    }
}

#[cfg(test)]
mod picture_tests {
    use super::*;
    use crate::model::{Actuator, Routing, Simulator, SolverOptions};
    use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
    use arrow::datatypes::{DataType, Field, Schema};
    use std::sync::Arc;

    /// A small real run: 3 levels per control point, 4 tensions, as one batch.
    fn small_run() -> RecordBatch {
        let actuator = Actuator::default();
        let mut sim = Simulator::new(&actuator, &SolverOptions::default()).unwrap();
        let (mut ids, mut status, mut ys, mut t, mut out) = (vec![], vec![], vec![[0.0; 5]; 0], vec![], vec![]);
        for id in 0..243i64 {
            let mut k = id;
            let y: [f64; 5] = std::array::from_fn(|_| {
                let level = (k % 3) as f64 - 1.0;
                k /= 3;
                level * 3.0
            });
            sim.set_routing(&Routing::new(&y, 65.0, 5.0).unwrap());
            for tension in [1.0, 1.3, 1.6, 2.0] {
                let pose = sim.solve(tension).unwrap();
                let mut a = [0.0; 3];
                sim.coefficients_into(crate::shape::LengthBasis::default(), &mut a);
                ids.push(id);
                status.push("ok");
                ys.push(y);
                t.push(tension);
                out.push([pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad, a[0], a[1], a[2]]);
            }
        }
        let mut fields = vec![Field::new("routing_id", DataType::Int64, false), Field::new("status", DataType::Utf8, false)];
        let mut cols: Vec<ArrayRef> = vec![Arc::new(Int64Array::from(ids)), Arc::new(StringArray::from(status))];
        for k in 0..5 {
            fields.push(Field::new(format!("y{k}_mm"), DataType::Float64, false));
            cols.push(Arc::new(Float64Array::from(ys.iter().map(|y| y[k]).collect::<Vec<_>>())));
        }
        fields.push(Field::new("tension_n", DataType::Float64, false));
        cols.push(Arc::new(Float64Array::from(t)));
        for (j, name) in ["tip_x_mm", "tip_y_mm", "tip_angle_rad", "a0", "a1", "a2"].iter().enumerate() {
            fields.push(Field::new(*name, DataType::Float64, true));
            cols.push(Arc::new(Float64Array::from(out.iter().map(|o| o[j]).collect::<Vec<_>>())));
        }
        RecordBatch::try_new(Arc::new(Schema::new(fields)), cols).unwrap()
    }

    #[test]
    fn map_directory_has_tables_and_non_blank_pictures() {
        let b = small_run();
        let info = RunInfo {
            mirrored: false,
            order: 2,
            tension_range_n: [1.0, 2.0],
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "small".into(),
            spec_hash: "h".into(),
            length_basis: LengthBasis::Rest,
        };
        let map = reduce_batches(&info, &ReduceOptions::default(), || Ok(vec![Ok(b.clone())].into_iter())).unwrap();
        let dir = std::env::var_os("CABLEMAP_KEEP_MAP").map(std::path::PathBuf::from);
        let tmp = tempfile::tempdir().unwrap();
        let dir = dir.unwrap_or_else(|| tmp.path().to_path_buf());
        let pictures = write_map(&dir, &map, &Actuator::default(), &SolverOptions::default()).unwrap();
        assert_eq!(pictures.len(), 1 + 3 * 3 + 1);
        for p in &pictures {
            let img = image::open(dir.join(&p.file)).unwrap().to_rgb8();
            // Sized from the map's extent at equal aspect (plots.rs checks the aspect).
            let (w, h) = img.dimensions();
            assert!(w >= 600 && h >= 400 && w <= 2400 && h <= 4000, "{}: {w}×{h}", p.file);
            // Not blank: many distinct colours and a good share of non-white pixels.
            let non_white = img.pixels().filter(|px| px.0 != [255, 255, 255]).count();
            let mut colours: Vec<[u8; 3]> = img.pixels().map(|px| px.0).collect();
            colours.sort_unstable();
            colours.dedup();
            assert!(non_white * 50 > img.pixels().len(), "{}: {non_white} non-white pixels", p.file);
            assert!(colours.len() > 20, "{}: only {} colours", p.file, colours.len());
        }
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert!(html.contains("<script src=\"explorer-data.js\">"));
        let data = std::fs::read_to_string(dir.join(explorer::DATA_FILE)).unwrap();
        let json = data.trim().strip_prefix("// Written by `cablemap reduce`: the map explorer's data (index.html).\nwindow.CABLEMAP_MAP = ").unwrap();
        let v: serde_json::Value = serde_json::from_str(json.strip_suffix(';').unwrap()).unwrap();
        for p in &pictures {
            assert!(v["pictures"].as_array().unwrap().iter().any(|f| f["file"] == p.file.as_str()), "{}", p.file);
        }
        assert_eq!(v["cells"]["ix"].as_array().unwrap().len(), map.cells.len());
        assert_eq!(v["designs"]["ix"].as_array().unwrap().len(), map.designs.len());
        // Every a_i is a curvature (mm⁻¹) and the page names the basis.
        assert!(!html.contains("mm⁻²") && !data.contains("mm⁻²"));
        assert_eq!(v["length_basis_description"], "per unit rest length L (the thesis's basis)");
        assert!(pictures.iter().filter(|p| p.file.starts_with("a2")).all(|p| !p.explanation.contains("Fig.")));
        for table in ["cells.parquet", "modes.parquet", "designs.parquet", "summary.json"] {
            assert!(dir.join(table).exists(), "{table}");
        }
    }
}

/// Columns the reducer reads from a sweep (docs/schema.md).
fn needed_columns(order: usize) -> Vec<String> {
    let mut cols: Vec<String> = ["routing_id", "status", "y0_mm", "y1_mm", "y2_mm", "y3_mm", "y4_mm", "tension_n", "tip_x_mm", "tip_y_mm", "tip_angle_rad"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    cols.extend((0..=order).map(|k| format!("a{k}")));
    cols
}

/// Reduces the sweep run in `run_dir` (refusing an unfinished run unless
/// `partial`). Returns the map and the run's spec (for drawing).
pub fn reduce_run(
    run_dir: &std::path::Path,
    partial: bool,
    options: &ReduceOptions,
) -> Result<(MapData, crate::sweep::SweepSpec), crate::Error> {
    use crate::sweep::{open_run, Completeness};
    let completeness = if partial { Completeness::AllowPartial } else { Completeness::Complete };
    let run = open_run(run_dir, completeness)?;
    let spec = run.spec().clone();
    let info = RunInfo {
        mirrored: spec.grid.mirror_dedup,
        order: spec.output.order,
        tension_range_n: [spec.tension.min_n, spec.tension.max_n],
        radius_mm: spec.actuator.radius_mm,
        length_mm: spec.actuator.length_mm,
        run_dir: run_dir.display().to_string(),
        spec_hash: run.manifest().spec_sha256.clone(),
        length_basis: spec.output.length_basis,
    };
    let columns = needed_columns(info.order);
    let names: Vec<&str> = columns.iter().map(String::as_str).collect();
    let map = reduce_batches(&info, options, || {
        let batches = run.batches_projected(&names).map_err(|e| ReduceError::Read(e.to_string()))?;
        Ok(batches.map(|b| b.map_err(|e| ReduceError::Read(e.to_string()))))
    })?;
    Ok((map, spec))
}
