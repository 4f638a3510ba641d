//! Numbering of routings, their grouping into chunks and the assignment of
//! chunks to shards. Everything here is arithmetic on indices: nothing is
//! materialised, so any grid size costs no memory.
//!
//! **Routing id.** A routing is the tuple of level indices (d0, …, d4) of its
//! control points y0…y4; its id is that tuple read as a base-`levels` number
//! with d0 the most significant digit: id = Σ dᵢ·levels^(4−i). Ids order
//! routings lexicographically.
//!
//! **Mirror de-duplication.** The mirror of a routing (y ↦ −y) has digits
//! levels−1−dᵢ, so its id is N−1−id (N = levels⁵). A routing is kept when
//! id ≤ N−1−id, i.e. when it is lexicographically no greater than its
//! mirror: the ids 0 ..= (N−1)/2. The self-mirror routing (all zeros, odd
//! levels) is kept once. 9 levels: (59,049 + 1)/2 = 29,525 routings.
//!
//! **Chunks.** The kept routings, in id order, are cut into chunks of
//! `chunk_routings`; chunk c holds ids [c·C, min((c+1)·C, R)). Chunks do not
//! depend on the shard count.
//!
//! **Shards.** Shard s of S owns the chunks c with c mod S = s (round robin,
//! which spreads easy and hard regions of the grid over shards).
//!
//! Each routing is solved cold through its tension ladder, so results do not
//! depend on the order routings are visited in (a Gray-code walk would only
//! help if warm starts crossed routings, which would make a row depend on
//! its neighbours and on the sharding).

use super::kind::ChunkLayout;
use super::spec::{OutputSpec, PlanarGrid};
use crate::model::routing::{ControlPoints, CONTROL_POINTS};
use std::ops::Range;

/// The sweep's index arithmetic, derived from a spec.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPlan {
    levels_mm: Vec<f64>,
    /// Routings kept (ids 0..routings).
    pub routings: u64,
    /// Tensions per routing.
    pub tensions: u64,
    /// Routings per chunk.
    pub chunk_routings: u64,
    /// Number of chunks.
    pub chunks: u64,
}

impl SweepPlan {
    /// The plan of a (validated) planar spec's grid and output.
    pub fn new(spec: &PlanarGrid, output: &OutputSpec) -> Self {
        let levels = u64::from(spec.grid.levels);
        let grid = levels.pow(CONTROL_POINTS as u32);
        let routings = if spec.grid.mirror_dedup { grid.div_ceil(2) } else { grid };
        let chunk_routings = u64::from(output.chunk_routings);
        Self {
            levels_mm: spec.levels_mm(),
            routings,
            tensions: u64::from(spec.ladder_count()),
            chunk_routings,
            chunks: routings.div_ceil(chunk_routings),
        }
    }

    /// Rows of the whole sweep (routings × tensions).
    pub fn total_rows(&self) -> u64 {
        self.routings * self.tensions
    }

    /// Level indices (d0…d4) of routing `id`.
    pub fn digits(&self, id: u64) -> [usize; CONTROL_POINTS] {
        let levels = self.levels_mm.len() as u64;
        let mut rest = id;
        let mut d = [0usize; CONTROL_POINTS];
        for slot in d.iter_mut().rev() {
            *slot = (rest % levels) as usize;
            rest /= levels;
        }
        d
    }

    /// Control points y0…y4 of routing `id`, mm.
    pub fn routing_mm(&self, id: u64) -> ControlPoints {
        ControlPoints(self.digits(id).map(|d| self.levels_mm[d]))
    }

    /// The chunk and shard arithmetic of this plan (shared by every kind of sweep).
    pub fn layout(&self) -> ChunkLayout {
        ChunkLayout { routings: self.routings, tensions: self.tensions, chunk_routings: self.chunk_routings, chunks: self.chunks }
    }

    /// Routing ids of chunk `chunk`.
    pub fn chunk_ids(&self, chunk: u64) -> Range<u64> {
        self.layout().chunk_ids(chunk)
    }

    /// Rows in chunk `chunk`.
    pub fn chunk_rows(&self, chunk: u64) -> u64 {
        self.layout().chunk_rows(chunk)
    }

    /// Chunks owned by shard `shard` of `shards` (ascending).
    pub fn shard_chunks(&self, shard: u64, shards: u64) -> impl Iterator<Item = u64> {
        self.layout().shard_chunks(shard, shards)
    }

    /// Which shard of `shards` owns `chunk`.
    pub fn chunk_shard(&self, chunk: u64, shards: u64) -> u64 {
        self.layout().chunk_shard(chunk, shards)
    }

    /// Rows owned by shard `shard` of `shards`.
    pub fn shard_rows(&self, shard: u64, shards: u64) -> u64 {
        self.layout().shard_rows(shard, shards)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::SweepSpec;
    use proptest::prelude::*;
    use std::collections::HashSet;

    #[test]
    fn thesis_grid_has_the_thesis_count() {
        let thesis = SweepSpec::thesis();
        let plan = SweepPlan::new(thesis.planar().unwrap(), &thesis.output);
        assert_eq!(plan.routings, 29_525);
        assert_eq!(plan.total_rows(), 620_025);
        // The last kept routing is the self-mirror straight one.
        assert_eq!(plan.routing_mm(plan.routings - 1), [0.0; 5]);
        assert_eq!(plan.routing_mm(0), [-4.0; 5]);
    }

    /// The lexicographically smaller of a routing and its mirror, as bits
    /// (−0.0 folded into 0.0).
    fn canonical(y: [f64; 5]) -> [u64; 5] {
        let y = y.map(|v| v + 0.0);
        let m = y.map(|v| -v + 0.0);
        let smaller = if y.iter().zip(&m).map(|(a, b)| a.total_cmp(b)).find(|o| o.is_ne()) == Some(std::cmp::Ordering::Greater) { m } else { y };
        smaller.map(f64::to_bits)
    }

    #[test]
    fn mirror_dedup_keeps_exactly_one_of_each_pair() {
        for levels in 1..=6u32 {
            let (mut spec, output) = (PlanarGrid::default(), SweepSpec::default().output);
            spec.grid.levels = levels;
            spec.grid.mirror_dedup = false;
            let full = SweepPlan::new(&spec, &output);
            spec.grid.mirror_dedup = true;
            let kept = SweepPlan::new(&spec, &output);
            let pairs: HashSet<[u64; 5]> = (0..full.routings).map(|id| canonical(full.routing_mm(id).0)).collect();
            let ours: HashSet<[u64; 5]> = (0..kept.routings)
                .map(|id| {
                    let y = kept.routing_mm(id).0;
                    assert_eq!(canonical(y), y.map(|v| (v + 0.0).to_bits()), "levels {levels}: kept {y:?} is not the smaller of its pair");
                    canonical(y)
                })
                .collect();
            assert_eq!(ours.len() as u64, kept.routings, "levels {levels}: kept routings are distinct");
            assert_eq!(ours, pairs, "levels {levels}: one of each mirror pair");
        }
    }

    proptest! {
        /// Every row (routing, tension) of the sweep belongs to exactly one
        /// shard, whatever the grid, chunk size and shard count.
        #[test]
        fn shards_partition_rows(levels in 1u32..6, dedup: bool, tensions in 1u32..4, chunk in 1u32..40, shards in 1u64..20) {
            let (mut spec, mut output) = (PlanarGrid::default(), SweepSpec::default().output);
            spec.grid.levels = levels;
            spec.grid.mirror_dedup = dedup;
            spec.tension.count = tensions;
            spec.tension.max_n = if tensions == 1 { spec.tension.min_n } else { 2.0 };
            output.chunk_routings = chunk;
            let plan = SweepPlan::new(&spec, &output);
            let mut seen = HashSet::new();
            let mut rows = 0u64;
            for s in 0..shards {
                let mut shard_rows = 0;
                for c in plan.shard_chunks(s, shards) {
                    prop_assert_eq!(plan.chunk_shard(c, shards), s);
                    for id in plan.chunk_ids(c) {
                        for t in 0..plan.tensions {
                            prop_assert!(seen.insert((id, t)), "row ({}, {}) twice", id, t);
                            shard_rows += 1;
                        }
                    }
                }
                prop_assert_eq!(shard_rows, plan.shard_rows(s, shards));
                rows += shard_rows;
            }
            prop_assert_eq!(rows, plan.total_rows());
            let grid = u64::from(levels).pow(5);
            prop_assert_eq!(plan.routings, if dedup { grid.div_ceil(2) } else { grid });
            for id in 0..plan.routings {
                prop_assert!(seen.contains(&(id, 0)));
            }
        }
    }
}
