//! What pass 1 keeps of a converged simulation ([`Sample`]) and how later
//! stages name the simulation ([`RowRef`]): the records every stage after
//! pass 1 (scratch files, mirror rule, cells, modes) works on.

use super::CELL_STATS_ORDER;

/// A simulation of the run: a stored row by its number in pass order, or
/// that row's mirror image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct RowRef {
    /// Row number in pass order.
    pub row: u32,
    /// Whether the simulation is the row's mirror image.
    pub mirrored: bool,
}

/// One converged simulation as pass 1 keeps it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sample {
    /// Tip, mm.
    pub x_mm: f64,
    /// Tip, mm.
    pub y_mm: f64,
    /// a_0 … a_min(order, 2) (higher entries 0).
    pub a: [f64; CELL_STATS_ORDER + 1],
    /// Which simulation.
    pub at: RowRef,
}
