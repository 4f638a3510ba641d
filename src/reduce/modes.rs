//! The characteristic modes: their boundaries (given, or quantiles of the
//! run's a_0 and a_1), each mode's representative simulation and the modes
//! table.

use super::cells::CellTable;
use super::samples::{RowRef, Sample};
use super::stats::{quantile_sorted, quantiles};
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
/// quantiles of a_0 (25/50/75 %) and a_1 (1/3, 2/3). `samples` not empty.
pub(crate) fn split(samples: &[Sample], explicit: Option<ModeBoundaries>) -> Result<ModeSplit, ReduceError> {
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

/// Per mode, the simulation nearest the mode's median (a_0, a_1), distances
/// scaled by the spreads; ties go to the lowest simulation.
pub(crate) fn representatives(samples: &[Sample], split: &ModeSplit) -> [Option<RowRef>; MODES] {
    let mut by_mode: Vec<Vec<&Sample>> = vec![Vec::new(); MODES];
    for s in samples {
        by_mode[split.boundaries.mode(s.a[0], s.a[1])].push(s);
    }
    let [s0, s1] = split.spread;
    std::array::from_fn(|m| {
        let members = &by_mode[m];
        if members.is_empty() {
            return None;
        }
        let med = |k: usize| quantiles(&members.iter().map(|s| s.a[k]).collect::<Vec<_>>(), &[0.5])[0];
        let (m0, m1) = (med(0), med(1));
        let d = |s: &Sample| ((s.a[0] - m0) / s0).powi(2) + ((s.a[1] - m1) / s1).powi(2);
        members.iter().min_by(|p, q| d(p).total_cmp(&d(q)).then(p.at.cmp(&q.at))).map(|s| s.at)
    })
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
