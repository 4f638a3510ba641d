//! The grid of square cells over the reach: its origin is the lower-left
//! corner of the lowest-left tip's cell, on multiples of the cell size.

use super::spill::Extent;
use super::{ReduceError, MAX_CELLS_PER_AXIS};

/// A grid of `nx` × `ny` cells of `cell_mm`, cell (0, 0) with its
/// lower-left corner at (`x_min_mm`, `y_min_mm`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Grid {
    /// Cell size, mm.
    pub cell_mm: f64,
    /// Lower-left corner of cell (0, 0), mm.
    pub x_min_mm: f64,
    /// See `x_min_mm`.
    pub y_min_mm: f64,
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
}

impl Grid {
    /// The grid covering the tips' `extent` (of at least one tip).
    pub fn spanning(extent: &Extent, cell_mm: f64) -> Result<Self, ReduceError> {
        let ([xmin, xmax], [ymin, ymax]) = (extent.x_mm, extent.y_mm);
        let x0 = (xmin / cell_mm).floor() * cell_mm;
        let y0 = (ymin / cell_mm).floor() * cell_mm;
        // Cell indices are i32 in the tables: a cell so small that the reach
        // spans more than MAX_CELLS_PER_AXIS cells would overflow them (and no
        // picture of it could be drawn), so it is refused with the smallest
        // cell that works.
        let (span_x, span_y) = ((xmax - x0) / cell_mm, (ymax - y0) / cell_mm);
        let limit = MAX_CELLS_PER_AXIS as f64;
        if !(x0.is_finite() && y0.is_finite() && span_x < limit && span_y < limit) {
            let reach = (xmax - xmin).max(ymax - ymin);
            return Err(ReduceError::CellTooSmall {
                cell_mm,
                reach_x_mm: xmax - xmin,
                reach_y_mm: ymax - ymin,
                smallest_cell_mm: (reach / (limit - 2.0)).max(f64::MIN_POSITIVE),
            });
        }
        Ok(Self { cell_mm, x_min_mm: x0, y_min_mm: y0, nx: (span_x.floor() as usize) + 1, ny: (span_y.floor() as usize) + 1 })
    }

    /// (column, row) of the cell holding the point (x, y), mm.
    pub fn cell_of(&self, x_mm: f64, y_mm: f64) -> (i32, i32) {
        (((x_mm - self.x_min_mm) / self.cell_mm).floor() as i32, ((y_mm - self.y_min_mm) / self.cell_mm).floor() as i32)
    }

    /// Centre of cell (ix, iy), mm.
    pub fn centre(&self, ix: i32, iy: i32) -> (f64, f64) {
        (self.x_min_mm + (ix as f64 + 0.5) * self.cell_mm, self.y_min_mm + (iy as f64 + 0.5) * self.cell_mm)
    }
}
