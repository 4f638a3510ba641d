//! The one reduce pipeline: a run of any kind into its map. [`reduce_batches`]
//! runs the stages over a run's rows in the planar row layout (pass 1 into
//! scratch samples, modes, grid, partitioned cells, pass 2 for the kept
//! designs); [`reduce_run`] maps a planar sweep, and [`reduce_cable_run`] a
//! cable sweep: its reach and, for a planar run, its feasibility map by the
//! same stages (`source::planar_batch` lays its rows out as planar rows).

use super::drawings::ModeDrawings;
use super::grid;
use super::modes;
use super::output::{check_map_out, write_cable_map};
use super::partition;
use crate::plot::Picture;
use super::reach::Reach;
use super::samples;
use super::source::{planar_batch, planar_columns, run_info, RunInfo};
use super::spill;
use super::tables::{self, PLANAR_MAP_DIR};
use super::{fetch, ReachMapSummary, Design, MapCables, MapData, MapSummary, ReduceError, ReduceOptions, CELL_STATS_ORDER, MODES};
use crate::solver::STATUS_OK;
use crate::sweep::schema::STATUS_INVALID_ROUTING;
use crate::solver::SolverOptions;
use crate::sweep::spec::{CablesGrid, PlanarGrid};
use crate::sweep::{open_run, Completeness, RunKind, SweepError, SweepRun};
use arrow::record_batch::RecordBatch;
use std::path::Path;

/// Reduces a run. `batches` is called once per pass and must yield the same
/// rows in the same order each time.
///
/// What each stage needs of the run, so that it can be computed without
/// holding every row: the mode split, the run's a_0/a_1 quantiles; the
/// grid, the tips' extent; a cell, its own samples only (cells can be done
/// range by range and concatenated in (ix, iy) order); a mode's
/// representative, the mode's medians and its nearest member (ties to the
/// lowest simulation, so any partition gives the same pick); pass 2, the
/// row numbers wanted.
pub fn reduce_batches<F, I>(info: &RunInfo, options: &ReduceOptions, mut batches: F) -> Result<MapData, ReduceError>
where
    F: FnMut() -> Result<I, ReduceError>,
    I: Iterator<Item = Result<RecordBatch, ReduceError>>,
{
    check_options(info, options)?;
    let scratch = spill::ScratchDir::new(&options.scratch_parent())?;
    let mut out = spill::SampleSink::new(&scratch.path.join("samples"), options.memory_samples);
    let pass1 = samples::spill_samples(info, batches()?, 0, &mut out)?;
    reduce_spilled(info, options, out.finish()?, &pass1, &scratch.path, batches)
}

/// The reduction after pass 1: from its `samples` (in memory or in scratch
/// files) and results `pass1`, with pass 2 over `batches`.
pub(crate) fn reduce_spilled<F, I>(
    info: &RunInfo,
    options: &ReduceOptions,
    samples: spill::Samples,
    pass1: &samples::Pass1,
    scratch: &std::path::Path,
    mut batches: F,
) -> Result<MapData, ReduceError>
where
    F: FnMut() -> Result<I, ReduceError>,
    I: Iterator<Item = Result<RecordBatch, ReduceError>>,
{
    let tally = pass1.tally.clone();
    if pass1.samples == 0 {
        return Err(ReduceError::Empty { failed: tally.rows_failed() });
    }
    let split = modes::split(&samples, options.mode_boundaries)?;
    let grid = grid::Grid::spanning(&pass1.extent, options.cell_mm)?;
    let nk = info.order.min(CELL_STATS_ORDER) + 1;
    let setup = partition::CellSetup { grid: &grid, split: &split, nk, designs_per_cell: options.designs_per_cell };
    let tabulated = partition::tabulate(samples, pass1.samples, &setup, options.memory_samples, scratch)?;
    let (cells, representatives) = (tabulated.cells, tabulated.representatives);
    let rows_converged = pass1.samples;
    let wanted = cells.picks.iter().map(|p| p.at).chain(representatives.iter().flatten().copied());
    let rows = fetch::Fetched::read(info.order, wanted, batches()?)?;
    let designs = cells
        .picks
        .iter()
        .map(|p| Ok(Design { ix: p.ix, iy: p.iy, ..rows.design(p.at)? }))
        .collect::<Result<Vec<_>, ReduceError>>()?;
    let mut fetched: [Option<Design>; MODES] = Default::default();
    for (slot, at) in fetched.iter_mut().zip(representatives) {
        if let Some(at) = at {
            let d = rows.design(at)?;
            let (ix, iy) = grid.cell_of(d.tip_x_mm, d.tip_y_mm);
            *slot = Some(Design { ix, iy, ..d });
        }
    }
    let modes = modes::table(&cells, &split.boundaries, fetched);
    let summary = MapSummary {
        format: tables::MAP_FORMAT.into(),
        cell_mm: grid.cell_mm,
        x_min_mm: grid.x_min_mm,
        y_min_mm: grid.y_min_mm,
        nx: grid.nx,
        ny: grid.ny,
        order: info.order,
        mirrored: info.mirrored,
        rows_total: tally.rows_total,
        rows_converged,
        rows_failed: tally.rows_failed(),
        failed_by_status: tally.failed_by_status,
        mode_boundaries: split.boundaries,
        mode_boundaries_source: split.source.into(),
        cells: cells.cells.len(),
        // A displacement-driven run's tensions were found: the range its designs span.
        tension_range_n: match info.tensions_found {
            true if !designs.is_empty() => {
                [designs.iter().map(|d| d.tension_n).fold(f64::INFINITY, f64::min), designs.iter().map(|d| d.tension_n).fold(0.0, f64::max)]
            }
            true => [0.0, 0.0],
            false => info.tension_range_n,
        },
        radius_mm: info.radius_mm,
        length_mm: info.length_mm,
        run_dir: info.run_dir.clone(),
        spec_hash: info.spec_hash.clone(),
        length_basis: info.length_basis,
        body: info.body.clone(),
    };
    Ok(MapData { summary, cells: cells.cells, modes, designs })
}

/// Refuses options the reduction cannot use, before reading the run.
pub(crate) fn check_options(info: &RunInfo, options: &ReduceOptions) -> Result<(), ReduceError> {
    check_cell_mm(options.cell_mm, info.length_mm)?;
    if info.order < 1 {
        return Err(ReduceError::OrderTooLow);
    }
    if let Some(b) = &options.mode_boundaries {
        b.validate()?;
    }
    Ok(())
}

/// Refuses a cell size that is not positive and finite, or larger than
/// twice the rod's length `length_mm` (the whole reach, ±L about the clamp,
/// in one or two cells per axis): beyond that a map says nothing, and its
/// corners and pictures would overflow to infinity (a 1e308 mm cell hung
/// the drawing of its axes).
pub(crate) fn check_cell_mm(cell_mm: f64, length_mm: f64) -> Result<(), ReduceError> {
    if !(cell_mm.is_finite() && cell_mm > 0.0) {
        return Err(ReduceError::CellSize { cell_mm });
    }
    let largest_cell_mm = 2.0 * length_mm;
    if cell_mm > largest_cell_mm {
        return Err(ReduceError::CellTooLarge { cell_mm, largest_cell_mm });
    }
    Ok(())
}

/// [`ReduceError::MapNotRun`] when `e` says a directory holds no sweep and
/// that directory holds a map: the map was given in its run's place.
pub fn map_given_as_run(e: &SweepError) -> Option<ReduceError> {
    let SweepError::NoRun { dir, .. } = e else { return None };
    tables::recorded_run_dir(dir).map(|run_dir| ReduceError::MapNotRun { dir: dir.clone(), run_dir })
}

/// A sweep error from opening a run directory, told as a map given in the
/// run's place when the directory holds one.
pub fn run_open_error(e: SweepError) -> ReduceError {
    map_given_as_run(&e).unwrap_or(ReduceError::Sweep(e))
}

/// Opens the run of kind `S` in `run_dir`, refusing an unfinished run
/// unless `partial`.
fn open(run_dir: &Path, partial: bool) -> Result<SweepRun, ReduceError> {
    let completeness = if partial { Completeness::AllowPartial } else { Completeness::Complete };
    open_run(run_dir, completeness).map_err(run_open_error)
}

/// The refusal of a run of another kind than `wanted`.
fn other_kind(run: &SweepRun, wanted: RunKind) -> ReduceError {
    let found = run.spec().kind().format().to_string();
    ReduceError::Sweep(SweepError::OtherKind { dir: run.dir().to_path_buf(), found, wanted: wanted.format().to_string() })
}

/// The planar grid of a planar run, else [`SweepError::OtherKind`].
pub(crate) fn planar_grid(run: &SweepRun) -> Result<&PlanarGrid, ReduceError> {
    run.spec().planar().ok_or_else(|| other_kind(run, RunKind::Planar))
}

/// The cables' grid of a cable sweep, else [`SweepError::OtherKind`].
fn cables_grid(run: &SweepRun) -> Result<&CablesGrid, ReduceError> {
    run.spec().cables().ok_or_else(|| other_kind(run, RunKind::Cables))
}

/// Reduces the sweep run in `run_dir` (refusing an unfinished run unless
/// `partial`). Returns the map and the run's spec (for drawing).
pub fn reduce_run(run_dir: &Path, partial: bool, options: &ReduceOptions) -> Result<(MapData, PlanarGrid, SolverOptions), ReduceError> {
    let run = open(run_dir, partial)?;
    let grid = planar_grid(&run)?.clone();
    let map = planar_map(&run, options)?;
    Ok((map, grid, run.spec().solver.clone()))
}

/// The feasibility map of an opened run of any kind whose rows read as
/// planar rows, by [`reduce_batches`].
fn planar_map(run: &SweepRun, options: &ReduceOptions) -> Result<MapData, ReduceError> {
    let spec = run.spec();
    let info = run_info(run);
    let names = planar_columns(spec);
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    reduce_batches(&info, options, || Ok(run.batches_projected(&names)?.map(|b| planar_batch(spec, b?))))
}

/// A cable sweep's map as [`reduce_cable_run`] wrote it.
#[derive(Debug, Clone)]
pub struct ReachMap {
    /// summary.json.
    pub summary: ReachMapSummary,
    /// The planar map and its pictures (planar runs of order ≥ 1).
    pub planar: Option<(MapData, Vec<Picture>)>,
}

/// Reduces the cable sweep in `run_dir` (refusing an unfinished run unless
/// `partial`) into the map directory `out`, written as a whole like a planar
/// map: reach tables and picture, summary.json, and for a planar run the
/// planar map in `out/planar`. `cell_mm` (default: the spec's
/// `output.cell_mm`) sizes the reach cells and the planar map's cells;
/// `options` sets the planar map's modes and designs.
pub fn reduce_cable_run(
    run_dir: &Path,
    partial: bool,
    cell_mm: Option<f64>,
    options: &ReduceOptions,
    out: &Path,
) -> Result<ReachMap, ReduceError> {
    check_map_out(out)?;
    let run = open(run_dir, partial)?;
    let spec = cables_grid(&run)?;
    let output = &run.spec().output;
    let cell_mm = cell_mm.or(output.cell_mm).unwrap_or(super::DEFAULT_CELL_MM);
    check_cell_mm(cell_mm, spec.actuator.rod.length_mm)?;
    let reach = Reach::count(&run, cell_mm)?;
    let planar = if spec.is_planar() && output.order >= 1 {
        let map = planar_map(&run, &ReduceOptions { cell_mm, ..options.clone() })?;
        let cables = MapCables::of_spec(spec, &run.spec().solver, output);
        let drawings = ModeDrawings::of_cables(&map, &cables);
        Some((map, drawings, cables))
    } else {
        None
    };
    let counts = run.status_counts();
    let count = |s: &str| counts.get(s).copied().unwrap_or(0);
    let rows = run.rows_done();
    let layout = run.spec().layout();
    let summary = ReachMapSummary {
        format: tables::MAP_FORMAT.into(),
        kind: "cables".into(),
        run_dir: run_dir.display().to_string(),
        spec_sha256: run.manifest().spec_sha256.clone(),
        cables: spec.actuator.cables.len(),
        routings: layout.routings,
        tension_combinations: layout.tensions,
        rows,
        rows_total: run.rows_total(),
        ok: count(STATUS_OK),
        failed: rows - count(STATUS_OK) - count(STATUS_INVALID_ROUTING),
        invalid_rows: count(STATUS_INVALID_ROUTING),
        planar: spec.is_planar(),
        cell_mm,
        cells: reach.cells(),
        planar_map: planar.is_some().then(|| PLANAR_MAP_DIR.to_string()),
    };
    let planar = write_cable_map(out, &summary, &reach, planar, &spec.actuator.rod)?;
    Ok(ReachMap { summary, planar })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::{drawings, MapBody, ModeBoundaries};
    use crate::shape::LengthBasis;
    use arrow::array::{Array, ArrayRef, Float64Array, Int64Array, StringArray};
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
            tensions_found: false,
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "test".into(),
            spec_hash: "x".into(),
            length_basis: LengthBasis::Rest,
            body: MapBody::default(),
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
    fn the_tables_do_not_depend_on_the_memory_bound() {
        // Bounds from one sample (a partition per cell) to all of them in
        // memory, mirrored and not, quantile and explicit modes.
        let rows = pseudo_rows(3000);
        for mirrored in [false, true] {
            for boundaries in [None, Some(ModeBoundaries { a0: [-0.2, 0.0, 0.2], a1: [-0.1, 0.1] })] {
                let options = |memory_samples| ReduceOptions { memory_samples, mode_boundaries: boundaries, ..Default::default() };
                let reference = format!("{:?}", run(&rows, mirrored, &options(usize::MAX)));
                for memory_samples in [1, 7, 100, 1000] {
                    assert_eq!(format!("{:?}", run(&rows, mirrored, &options(memory_samples))), reference, "memory {memory_samples}");
                }
            }
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
            let original = rows.iter().find(|r| r.0 == *d.routing_mm.mirrored() && r.1 == d.tension_n).unwrap();
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
    #[test]
    fn the_tables_read_back_as_written() {
        let map = run(&pseudo_rows(300), true, &ReduceOptions::default());
        let tmp = tempfile::tempdir().unwrap();
        tables::write_tables(tmp.path(), &map).unwrap();
        let summary = tables::read_summary(tmp.path()).unwrap();
        assert_eq!(serde_json::to_value(&summary).unwrap(), serde_json::to_value(&map.summary).unwrap());
        let cells = tables::read_cells(tmp.path(), summary.order).unwrap();
        assert_eq!(format!("{cells:?}"), format!("{:?}", map.cells));
        assert_eq!(tables::read_designs(tmp.path(), summary.order).unwrap(), map.designs);
        // A table without one of its columns is refused, naming the column.
        let e = tables::read_designs(tmp.path(), 3).unwrap_err();
        assert!(e.to_string().contains("`a3` is missing"), "{e}");
    }

    #[test]
    fn errors_name_the_problem_and_keep_their_source() {
        use std::error::Error as _;
        let tmp = tempfile::tempdir().unwrap();
        let e = reduce_run(tmp.path(), false, &ReduceOptions::default()).unwrap_err();
        assert!(matches!(e, ReduceError::Sweep(crate::sweep::SweepError::NoRun { .. })), "{e:?}");
        assert!(e.source().is_some());
        // A cell too small for the grid: the smallest that works, no flag names.
        let e = reduce_batches(&info(false), &ReduceOptions { cell_mm: 1e-300, ..Default::default() }, || {
            Ok(vec![Ok(batch(&pseudo_rows(40)))].into_iter())
        })
        .unwrap_err();
        match &e {
            ReduceError::CellTooSmall { smallest_cell_mm, .. } => assert!(*smallest_cell_mm > 1e-6 && *smallest_cell_mm < 1e-3),
            other => panic!("{other:?}"),
        }
        // A cell larger than the whole reach (its corners overflowed and hung the drawing).
        let e = reduce_batches(&info(false), &ReduceOptions { cell_mm: 1e308, ..Default::default() }, || {
            Ok(vec![Ok(batch(&pseudo_rows(40)))].into_iter())
        })
        .unwrap_err();
        assert!(matches!(e, ReduceError::CellTooLarge { largest_cell_mm, .. } if largest_cell_mm == 130.0), "{e:?}");
        // One routing cannot be split into modes by quantiles.
        let one: Vec<Row> = (0..5).map(|i| ([0.0, 1.0, 0.0, -1.0, 0.5], 1.0 + 0.1 * i as f64, "ok", 50.0, 2.0, [0.1, 0.2, 0.0])).collect();
        let e = reduce_batches(&info(false), &ReduceOptions::default(), || Ok(vec![Ok(batch(&one))].into_iter())).unwrap_err();
        assert!(matches!(e, ReduceError::ModesNotSplit { .. }), "{e:?}");
        for e in [e.to_string(), ReduceError::CellSize { cell_mm: 0.0 }.to_string()] {
            assert!(!e.contains("--"), "a library message names no flag: {e}");
        }
        // A sweep column of the wrong type keeps Arrow's error as its source.
        let b = batch(&pseudo_rows(3));
        let i = b.schema().index_of("tip_x_mm").unwrap();
        let mut cols = b.columns().to_vec();
        let lists = arrow::array::ListArray::from_iter_primitive::<arrow::datatypes::Float64Type, _, _>((0..3).map(|_| Some(vec![Some(1.0)])));
        let list_type = lists.data_type().clone();
        cols[i] = Arc::new(lists);
        let mut fields: Vec<Field> = b.schema().fields().iter().map(|f| f.as_ref().clone()).collect();
        fields[i] = Field::new("tip_x_mm", list_type, true);
        let bad = RecordBatch::try_new(Arc::new(Schema::new(fields)), cols).unwrap();
        let e = reduce_batches(&info(false), &ReduceOptions::default(), || Ok(vec![Ok(bad.clone())].into_iter())).unwrap_err();
        assert!(matches!(e, ReduceError::ColumnType { .. }) && e.source().is_some(), "{e:?}");
    }

    #[test]
    fn a_representative_that_cannot_be_drawn_is_reported() {
        let mut map = run(&pseudo_rows(200), false, &ReduceOptions::default());
        let actuator = crate::model::Rod::default();
        let m = map.modes.iter().position(|m| m.representative.is_some()).unwrap();
        // Outside the body: the routing is refused, and the drawing says so.
        map.modes[m].representative.as_mut().unwrap().routing_mm[2] = 2.0 * actuator.radius_mm;
        let drawings = drawings::ModeDrawings::of_map(&map, &actuator, &crate::solver::SolverOptions::default());
        assert_eq!(drawings.shapes.len(), MODES);
        assert!(drawings.shapes[m].is_none());
        assert_eq!(drawings.failures.len(), 1);
        let note = drawings.failure_note();
        assert!(note.contains(&format!("mode {m}")) && note.contains("routing"), "{note}");
    }
}
