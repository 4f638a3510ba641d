//! Per cell: the count, the percentiles of each coefficient, the mode
//! counts and the designs kept for designs.parquet. A cell needs only its
//! own samples, so cells can be computed range by range.

use super::grid::Grid;
use super::sample::{RowRef, Sample};
use super::stats::quantile_sorted;
use super::{CellStats, CoefficientStats, ModeBoundaries, MODES};

/// A design kept for designs.parquet: which simulation, in which cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pick {
    /// The simulation (its full row is fetched in pass 2).
    pub at: RowRef,
    /// Cell column.
    pub ix: i32,
    /// Cell row.
    pub iy: i32,
}

/// The cells of a map, in (ix, iy) order.
#[derive(Debug, Clone, Default)]
pub(crate) struct CellTable {
    /// Non-empty cells.
    pub cells: Vec<CellStats>,
    /// Designs kept, cell by cell.
    pub picks: Vec<Pick>,
    /// Per mode, the cells where it occurs.
    pub mode_cells: [i64; MODES],
}

/// Computes every cell of `samples` (reordered: by cell, and within a cell
/// by a_0). `nk` coefficients get statistics; `designs_per_cell` designs
/// spanning each cell's a_0 range are picked.
pub(crate) fn tabulate(samples: &mut [Sample], grid: &Grid, boundaries: &ModeBoundaries, nk: usize, designs_per_cell: usize) -> CellTable {
    let key_of = |s: &Sample| grid.cell_of(s.x_mm, s.y_mm);
    samples.sort_unstable_by_key(|s| (key_of(s), s.at));
    let mut table = CellTable::default();
    let mut values = Vec::new();
    for group in samples.chunk_by_mut(|p, q| key_of(p) == key_of(q)) {
        let (ix, iy) = key_of(&group[0]);
        let cell = one_cell(ix, iy, group, grid, boundaries, nk, designs_per_cell, &mut values, &mut table.picks);
        for (m, &c) in cell.modes.iter().enumerate() {
            if c > 0 {
                table.mode_cells[m] += 1;
            }
        }
        table.cells.push(cell);
    }
    table
}

/// The statistics of cell (ix, iy) from its samples `group`; appends its
/// picks. `values` is scratch space.
#[allow(clippy::too_many_arguments)]
fn one_cell(
    ix: i32,
    iy: i32,
    group: &mut [Sample],
    grid: &Grid,
    boundaries: &ModeBoundaries,
    nk: usize,
    designs_per_cell: usize,
    values: &mut Vec<f64>,
    picks: &mut Vec<Pick>,
) -> CellStats {
    let coefficients = (0..nk)
        .map(|k| {
            values.clear();
            values.extend(group.iter().map(|s| s.a[k]));
            values.sort_unstable_by(f64::total_cmp);
            CoefficientStats {
                p10: quantile_sorted(values, 0.1),
                p90: quantile_sorted(values, 0.9),
                min: values[0],
                max: values[values.len() - 1],
            }
        })
        .collect();
    let mut modes = [0i64; MODES];
    for s in group.iter() {
        modes[boundaries.mode(s.a[0], s.a[1])] += 1;
    }
    // Designs spanning the cell's a_0 range.
    group.sort_unstable_by(|p, q| p.a[0].total_cmp(&q.a[0]).then(p.at.row.cmp(&q.at.row)));
    let n = group.len();
    let keep = designs_per_cell.min(n);
    for j in 0..keep {
        let idx = if keep == 1 { n / 2 } else { j * (n - 1) / (keep - 1) };
        picks.push(Pick { at: group[idx].at, ix, iy });
    }
    let (x_mm, y_mm) = grid.centre(ix, iy);
    CellStats { ix, iy, x_mm, y_mm, count: n as i64, coefficients, modes }
}
