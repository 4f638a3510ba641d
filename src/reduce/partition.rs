//! The cells of a run too large to hold: the samples are split by cell
//! range into partition files that each fit in memory, and each partition
//! is tabulated in memory, in cell order. A cell needs only its own
//! samples (`cells`), and a mode's representative is the nearest member to
//! the mode's median whatever order the members come in (`modes::Nearest`),
//! so the result is the same for any partitioning.

use super::cells::{self, CellTable};
use super::grid::Grid;
use super::modes::{ModeSplit, Nearest};
use super::sample::{RowRef, Sample};
use super::spill::{self, Samples, SpillWriter};
use super::{ReduceError, MODES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Buffer of each partition file's writer (many are written at once).
const PARTITION_BUFFER_BYTES: usize = 64 << 10;

/// The cells and the modes' representatives.
pub(crate) struct Tabulated {
    /// The cells, in (ix, iy) order, and their picks.
    pub cells: CellTable,
    /// Per mode, its representative.
    pub representatives: [Option<RowRef>; MODES],
}

/// What tabulating needs besides the samples.
pub(crate) struct CellSetup<'a> {
    /// The grid.
    pub grid: &'a Grid,
    /// The modes.
    pub split: &'a ModeSplit,
    /// Coefficients with statistics.
    pub nk: usize,
    /// Designs kept per cell.
    pub designs_per_cell: usize,
}

/// Tabulates the `total` samples, holding at most `memory_samples` at a
/// time (more only when one cell alone has more), writing partitions to
/// `scratch`.
pub(crate) fn tabulate(
    samples: Samples,
    total: u64,
    setup: &CellSetup,
    memory_samples: usize,
    scratch: &Path,
) -> Result<Tabulated, ReduceError> {
    let mut nearest = Nearest::new(&samples, setup.split)?;
    let mut table = CellTable::default();
    let mut absorb = |samples: &mut Vec<Sample>| {
        for s in samples.iter() {
            nearest.offer(s);
        }
        let part = cells::tabulate(samples, setup.grid, &setup.split.boundaries, setup.nk, setup.designs_per_cell);
        table.cells.extend(part.cells);
        table.picks.extend(part.picks);
        for (sum, n) in table.mode_cells.iter_mut().zip(part.mode_cells) {
            *sum += n;
        }
    };
    let memory_samples = memory_samples.max(1);
    if let Samples::Memory(mut all) = samples {
        absorb(&mut all);
    } else if total <= memory_samples as u64 {
        let mut all = Vec::with_capacity(total as usize);
        samples.for_each(|s| all.push(*s))?;
        absorb(&mut all);
    } else {
        // Counting pass: samples per cell, then cuts between cells so that
        // each partition holds at most `memory_samples`.
        let mut counts: HashMap<(i32, i32), u64> = HashMap::new();
        samples.for_each(|s| *counts.entry(setup.grid.cell_of(s.x_mm, s.y_mm)).or_default() += 1)?;
        let mut keys: Vec<((i32, i32), u64)> = counts.into_iter().collect();
        keys.sort_unstable();
        let mut cuts: Vec<(i32, i32)> = Vec::new();
        let mut held = 0u64;
        for (key, n) in keys {
            if held > 0 && held + n > memory_samples as u64 {
                cuts.push(key);
                held = 0;
            }
            held += n;
        }
        let partitions = cuts.len() + 1;
        // Partition pass.
        let paths: Vec<PathBuf> = (0..partitions).map(|p| scratch.join(format!("partition-{p}"))).collect();
        let mut writers = paths
            .iter()
            .map(|p| SpillWriter::with_buffer(p, PARTITION_BUFFER_BYTES))
            .collect::<Result<Vec<_>, _>>()?;
        let mut failed = None;
        samples.for_each(|s| {
            let key = setup.grid.cell_of(s.x_mm, s.y_mm);
            let p = cuts.partition_point(|c| *c <= key);
            if let Err(e) = writers[p].push(s, false) {
                failed.get_or_insert(e);
            }
        })?;
        if let Some(e) = failed {
            return Err(e);
        }
        let sizes = writers.into_iter().map(|w| w.finish(false)).collect::<Result<Vec<_>, _>>()?;
        for (path, n) in paths.iter().zip(sizes) {
            let mut samples = spill::load(path, n as usize)?;
            let _ = std::fs::remove_file(path);
            absorb(&mut samples);
        }
    }
    Ok(Tabulated {
        cells: table,
        representatives: nearest.representatives(),
    })
}
