//! The reach of a cable sweep: its solved tips counted per cell on the
//! three coordinate planes and per 3-D voxel, read chunk by chunk (one
//! entry per occupied cell, so memory does not grow with the rows). The
//! map format (`tables`) writes the counts, `output` draws them.

use super::ReduceError;
use crate::sweep::schema::{TIP_X_MM, TIP_Y_MM, TIP_Z_MM};
use crate::sweep::SweepRun;
use arrow::array::{Array, AsArray};
use arrow::datatypes::Float64Type;
use std::collections::BTreeMap;

/// The three coordinate planes: the tip coordinates each spans (indices
/// into the tip) and their axis names, in the order of the reach tables.
pub(crate) const PLANES: [([usize; 2], [&str; 2]); 3] = [([0, 1], ["x", "y"]), ([0, 2], ["x", "z"]), ([1, 2], ["y", "z"])];
/// Axis names of the 3-D voxels.
pub(crate) const VOXEL_AXES: [&str; 3] = ["x", "y", "z"];

/// Solved rows per cell on the three planes ([`PLANES`]) and per voxel.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Reach {
    /// Cell and voxel size, mm.
    pub cell_mm: f64,
    /// Rows per cell (cell indices along the plane's two axes), per plane.
    pub planes: [BTreeMap<[i32; 2], i64>; 3],
    /// Rows per voxel (cell indices along x, y, z).
    pub voxels: BTreeMap<[i32; 3], i64>,
    /// Solved tips counted.
    pub tips: u64,
}

impl Reach {
    /// Counts the solved tips of every written row, chunk by chunk.
    pub fn count(run: &SweepRun, cell_mm: f64) -> Result<Self, ReduceError> {
        let mut reach = Reach { cell_mm, planes: Default::default(), voxels: BTreeMap::new(), tips: 0 };
        let index = |v: f64| (v / cell_mm).floor() as i32;
        for batch in run.batches_projected(&[TIP_X_MM, TIP_Y_MM, TIP_Z_MM])? {
            let batch = batch?;
            let col = |name: &str| batch.column_by_name(name).expect("projected").as_primitive::<Float64Type>().clone();
            let (x, y, z) = (col(TIP_X_MM), col(TIP_Y_MM), col(TIP_Z_MM));
            for i in 0..batch.num_rows() {
                if x.is_null(i) || y.is_null(i) || z.is_null(i) {
                    continue;
                }
                let c = [x.value(i), y.value(i), z.value(i)].map(index);
                for (k, (axes, _)) in PLANES.iter().enumerate() {
                    *reach.planes[k].entry([c[axes[0]], c[axes[1]]]).or_default() += 1;
                }
                *reach.voxels.entry(c).or_default() += 1;
                reach.tips += 1;
            }
        }
        Ok(reach)
    }

    /// Occupied cells: x–y, x–z, y–z, 3-D voxels.
    pub fn cells(&self) -> [u64; 4] {
        [self.planes[0].len() as u64, self.planes[1].len() as u64, self.planes[2].len() as u64, self.voxels.len() as u64]
    }
}
