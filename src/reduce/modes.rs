//! The characteristic modes: their boundaries (given, or quantiles of the
//! run's a_0 and a_1), each mode's representative simulation and the modes
//! table.

use super::cells::CellTable;
use super::sample::{RowRef, Sample};
use super::select;
use super::spill::Samples;
use super::{Design, ModeBoundaries, ModeStats, ReduceError, MODES};

/// The boundaries used and the spreads that scale distances between modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ModeSplit {
    /// Mode boundaries.
    pub boundaries: ModeBoundaries,
    /// `quantiles` or `explicit`.
    pub source: &'static str,
    /// Interquartile ranges of a_0 and a_1 over the run (at least 1e-12).
    pub spread: [f64; 2],
}

/// Splits the run's simulations into modes: by `explicit` boundaries, or by
/// quantiles of a_0 (25/50/75 %) and a_1 (1/3, 2/3). The samples are read
/// from `samples` (not empty).
pub(crate) fn split(samples: &Samples, explicit: Option<ModeBoundaries>) -> Result<ModeSplit, ReduceError> {
    // Quantiles of a_0 and a_1 over the converged rows, exact (by
    // selection): they give the default mode boundaries and the spreads
    // (interquartile ranges) that scale the distance to a mode's median.
    let requests = [(0, 0.25), (0, 0.5), (0, 0.75), (1, 0.25), (1, 1.0 / 3.0), (1, 2.0 / 3.0), (1, 0.75)];
    let (q, _) = select::quantiles(2, &requests, |f| {
        samples.for_each(|s| {
            f(0, s.a[0]);
            f(1, s.a[1]);
        })
    })?;
    let q: Vec<f64> = q.into_iter().map(|v| v.expect("the run has samples")).collect();
    let (q0, q1) = ([q[0], q[1], q[2]], [q[3], q[4], q[5], q[6]]);
    let spread = [(q0[2] - q0[0]).max(1e-12), (q1[3] - q1[0]).max(1e-12)];
    let (boundaries, source) = match explicit {
        Some(b) => (b, "explicit"),
        None => (ModeBoundaries { a0: [q0[0], q0[1], q0[2]], a1: [q1[1], q1[2]] }, "quantiles"),
    };
    // Quantiles of too few distinct coefficients (a one-routing run) do not
    // split the modes; a map with such boundaries would be refused by
    // `feasible` and `design`, so it is refused here, with the fix.
    if boundaries.validate().is_err() {
        return Err(ReduceError::ModesNotSplit { a0: boundaries.a0, a1: boundaries.a1 });
    }
    Ok(ModeSplit { boundaries, source, spread })
}

/// Per mode, the search for its representative: the simulation nearest the
/// mode's median (a_0, a_1), distances scaled by the spreads, ties to the
/// lowest simulation (so the samples may be offered in any order).
pub(crate) struct Nearest {
    split: ModeSplit,
    medians: [Option<[f64; 2]>; MODES],
    best: [Option<(f64, RowRef)>; MODES],
}

impl Nearest {
    /// Finds the modes' medians (exactly, by selection over `samples`).
    pub fn new(samples: &Samples, split: &ModeSplit) -> Result<Self, ReduceError> {
        let requests: Vec<(usize, f64)> = (0..2 * MODES).map(|g| (g, 0.5)).collect();
        let b = split.boundaries;
        let (q, _) = select::quantiles(2 * MODES, &requests, |f| {
            samples.for_each(|s| {
                let m = b.mode(s.a[0], s.a[1]);
                f(2 * m, s.a[0]);
                f(2 * m + 1, s.a[1]);
            })
        })?;
        let medians = std::array::from_fn(|m| q[2 * m].zip(q[2 * m + 1]).map(|(a0, a1)| [a0, a1]));
        Ok(Self { split: *split, medians, best: [None; MODES] })
    }

    /// Considers sample `s`.
    pub fn offer(&mut self, s: &Sample) {
        let m = self.split.boundaries.mode(s.a[0], s.a[1]);
        let Some([m0, m1]) = self.medians[m] else { return };
        let [s0, s1] = self.split.spread;
        let d = ((s.a[0] - m0) / s0).powi(2) + ((s.a[1] - m1) / s1).powi(2);
        let better = match self.best[m] {
            None => true,
            Some((bd, bat)) => d.total_cmp(&bd).then(s.at.cmp(&bat)).is_lt(),
        };
        if better {
            self.best[m] = Some((d, s.at));
        }
    }

    /// The representatives found.
    pub fn representatives(&self) -> [Option<RowRef>; MODES] {
        self.best.map(|b| b.map(|(_, at)| at))
    }
}

/// The modes table from the cells and the representatives' full rows.
pub(crate) fn table(cells: &CellTable, boundaries: &ModeBoundaries, representatives: [Option<Design>; MODES]) -> Vec<ModeStats> {
    representatives
        .into_iter()
        .enumerate()
        .map(|(m, representative)| {
            let (i, j) = (m / 3, m % 3);
            ModeStats {
                mode: m,
                a0_range: i,
                a1_range: j,
                a0_bounds: ModeBoundaries::bounds(&boundaries.a0, i),
                a1_bounds: ModeBoundaries::bounds(&boundaries.a1, j),
                count: cells.cells.iter().map(|c| c.modes[m]).sum(),
                cells: cells.mode_cells[m],
                representative,
            }
        })
        .collect()
}
