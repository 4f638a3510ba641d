//! How densely a map's cells are reached, and the note a sparse map gets
//! (`map`'s report and the explorer page).

use super::{CellStats, MapSummary};

/// Above this share of reached cells holding a single simulation, a map
/// reads as speckle rather than regions.
pub const SPARSE_SINGLE_SHARE: f64 = 0.5;
/// Below this share of the reach's bounding box reached, a map reads as
/// scattered dots.
pub const SPARSE_FILLED_SHARE: f64 = 0.1;
/// Largest cell size a sparse map's note suggests, in multiples of its own.
const MAX_SUGGESTED_FACTOR: i64 = 20;

/// How densely a map's cells are reached: a map whose cells mostly hold
/// one simulation, or fill little of the reach's bounding box, shows
/// speckle (e.g. 1 mm cells over a tapered 360 mm body's reach) and wants
/// larger cells (`--cell-mm`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Density {
    /// Cell size, mm.
    pub cell_mm: f64,
    /// Reached cells.
    pub cells: usize,
    /// Share of the reached cells holding one simulation.
    pub single_share: f64,
    /// Reached cells over the cells of the reach's bounding box.
    pub filled_share: f64,
}

impl Density {
    /// The density of the map with `summary` and `cells`.
    pub fn of(summary: &MapSummary, cells: &[CellStats]) -> Self {
        Self::coarsened(summary, cells, 1)
    }

    /// The density the map would have with cells `factor` times larger,
    /// from its own cells: grids lie on multiples of the cell size, so a
    /// cell of `factor`·c is the union of `factor`² cells of c.
    fn coarsened(summary: &MapSummary, cells: &[CellStats], factor: i64) -> Self {
        let c = summary.cell_mm;
        // The grid's origin in cells (a multiple of the cell size).
        let (ox, oy) = ((summary.x_min_mm / c).round() as i64, (summary.y_min_mm / c).round() as i64);
        let mut merged: std::collections::HashMap<(i64, i64), i64> = std::collections::HashMap::new();
        for cell in cells.iter().filter(|cell| cell.count > 0) {
            let key = ((ox + i64::from(cell.ix)).div_euclid(factor), (oy + i64::from(cell.iy)).div_euclid(factor));
            *merged.entry(key).or_default() += cell.count;
        }
        let singles = merged.values().filter(|&&n| n == 1).count();
        let extent = |f: fn(&(i64, i64)) -> i64| merged.keys().map(f).fold((i64::MAX, i64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let ((x0, x1), (y0, y1)) = (extent(|k| k.0), extent(|k| k.1));
        let boxed = if merged.is_empty() { 1.0 } else { ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64 };
        let n = merged.len();
        Self {
            cell_mm: c * factor as f64,
            cells: n,
            single_share: if n == 0 { 0.0 } else { singles as f64 / n as f64 },
            filled_share: n as f64 / boxed,
        }
    }

    /// Whether the map shows speckle rather than regions.
    pub fn is_sparse(&self) -> bool {
        self.cells > 0 && (self.single_share > SPARSE_SINGLE_SHARE || self.filled_share < SPARSE_FILLED_SHARE)
    }

    /// The smallest cell size, a whole multiple of the map's, at which the
    /// map would no longer be sparse (None: not within 20 times its cell).
    pub fn suggested_cell_mm(summary: &MapSummary, cells: &[CellStats]) -> Option<f64> {
        let found = (2..=MAX_SUGGESTED_FACTOR).map(|f| Self::coarsened(summary, cells, f)).find(|d| !d.is_sparse());
        // Rounded, so that 3 × 0.1 mm reads 0.3.
        found.map(|d| (d.cell_mm * 1e6).round() / 1e6)
    }

    /// A sentence saying that the map with `summary` and `cells` is sparse
    /// and which `--cell-mm` to reduce again with; None when it is not sparse.
    pub fn sparse_note(summary: &MapSummary, cells: &[CellStats]) -> Option<String> {
        let d = Self::of(summary, cells);
        if !d.is_sparse() {
            return None;
        }
        let advice = match Self::suggested_cell_mm(summary, cells) {
            Some(mm) => format!("reduce again with --cell-mm {} for regions instead of speckle", crate::io::fmt_num(mm)),
            None => format!(
                "even {} mm cells stay sparse: sweep more levels or tensions, or reduce again with a much larger --cell-mm",
                crate::io::fmt_num(d.cell_mm * MAX_SUGGESTED_FACTOR as f64)
            ),
        };
        Some(format!(
            "sparse map: at {} mm cells {:.0} % of the {} reached cells hold a single simulation and they fill {:.0} % of the reach's bounding box; {advice}",
            crate::io::fmt_num(d.cell_mm),
            100.0 * d.single_share,
            d.cells,
            100.0 * d.filled_share
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::map_frame::tests::{cell, summary};

    #[test]
    fn a_sparse_map_says_so_and_suggests_a_cell_size() {
        let s = summary();
        // One simulation in each cell: speckle; merged by 2 (10 mm cells) every cell holds 4.
        let speckle: Vec<CellStats> = (0..10).flat_map(|ix| (0..16).map(move |iy| cell(ix, iy, 1, 0))).collect();
        let d = Density::of(&s, &speckle);
        assert!(d.is_sparse() && d.single_share == 1.0 && d.filled_share == 1.0, "{d:?}");
        assert_eq!(Density::suggested_cell_mm(&s, &speckle), Some(10.0));
        let note = Density::sparse_note(&s, &speckle).unwrap();
        assert!(note.contains("100 % of the 160 reached cells hold a single simulation") && note.contains("--cell-mm 10"), "{note}");
        // Two busy cells at opposite corners fill 1 % of their box.
        let scattered = [cell(0, 0, 50, 0), cell(9, 15, 50, 0)];
        assert!(Density::of(&s, &scattered).filled_share < SPARSE_FILLED_SHARE);
        assert!(Density::sparse_note(&s, &scattered).is_some_and(|n| n.contains("fill 1 %")));
        // Three simulations per cell everywhere: no note.
        let dense: Vec<CellStats> = (0..10).flat_map(|ix| (0..16).map(move |iy| cell(ix, iy, 3, 0))).collect();
        assert_eq!(Density::sparse_note(&s, &dense), None);
    }
}
