//! `feasible --map MAP --targets T.toml`: a cable sweep's map's answer for
//! each target of a several-cable design before any search: was the target
//! tip's voxel (all three tip components asked) or cell (two) reached by
//! the sweep, or a neighbour of it; and, with the sweep's planar map
//! (`MAP/planar`, every cable in the x–y plane), the planar verdict on the
//! in-plane tip and `a_bend_z` (the map's coefficient ranges) with the
//! nearest stored designs, every cable of each.

use super::feasible::{self as planar, FeasibilityReport, Verdict};
use super::map::MapDir;
use super::target::{Target, Weights};
use super::DesignError;
use super::targets::{Quantity, ShapeTarget, TargetSet};
use crate::reduce::tables::{read_reach, ReachTables};
use crate::shape::LengthBasis;
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// One target's tip against the reach tables.
#[derive(Debug, Clone, Serialize)]
pub struct TipReach {
    /// The verdict: `feasible` for tips in the target's voxel or cell,
    /// `borderline` for none there and some in a neighbour, `unreachable`
    /// for none there or next to it (not proof: the sweep samples a grid;
    /// `design` will tell), `unchecked` when the target asks for fewer
    /// than two tip components. Written in the reach tables' words
    /// ([`Verdict::reach_word`]).
    #[serde(serialize_with = "reach_word")]
    pub verdict: Verdict,
    /// Which table: `3d` (voxels), `xy`, `xz` or `yz` (plane cells).
    pub table: Option<&'static str>,
    /// The voxel or cell indices of the tip.
    pub cell: Vec<i32>,
    /// Tips in it.
    pub count: i64,
    /// Tips in its neighbours (26 voxels or 8 cells).
    pub neighbours: i64,
}

/// The answer for one target.
#[derive(Debug, Clone, Serialize)]
pub struct TargetFeasibility {
    /// The target's name.
    pub name: String,
    /// Its tip against the reach tables.
    pub tip: TipReach,
    /// With the sweep's planar map and an in-plane target: the planar
    /// verdict, coefficient ranges and nearest designs (every cable).
    pub planar: Option<FeasibilityReport>,
}

/// The map's answer for every target.
#[derive(Debug, Clone, Serialize)]
pub struct TargetsFeasibility {
    /// The map directory.
    pub map: PathBuf,
    /// Cables per actuator of the sweep.
    pub cables: usize,
    /// Reach cell / voxel size, mm.
    pub cell_mm: f64,
    /// One per target, in order.
    pub targets: Vec<TargetFeasibility>,
}

fn reach_word<S: serde::Serializer>(verdict: &Verdict, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(verdict.reach_word())
}

fn tip_reach(reach: &ReachTables, t: &ShapeTarget) -> TipReach {
    let cell = reach.summary.cell_mm;
    let index = |v: f64| (v / cell).floor() as i32;
    let tip = t.tip_mm();
    let given: Vec<usize> = (0..3).filter(|&i| tip[i].is_some()).collect();
    let unchecked = TipReach { verdict: Verdict::Unchecked, table: None, cell: Vec::new(), count: 0, neighbours: 0 };
    let (table, idx, count, neighbours) = match given.as_slice() {
        [0, 1, 2] => {
            let c = [0, 1, 2].map(|i| index(tip[i].expect("given")));
            let at = |d: [i32; 3]| reach.voxels.get(&[c[0] + d[0], c[1] + d[1], c[2] + d[2]]).copied().unwrap_or(0);
            let mut n = 0;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if (dx, dy, dz) != (0, 0, 0) {
                            n += at([dx, dy, dz]);
                        }
                    }
                }
            }
            ("3d", c.to_vec(), at([0, 0, 0]), n)
        }
        [a, b] => {
            let plane = match (a, b) {
                (0, 1) => 0,
                (0, 2) => 1,
                _ => 2,
            };
            let c = [index(tip[*a].expect("given")), index(tip[*b].expect("given"))];
            let at = |d: [i32; 2]| reach.planes[plane].get(&[c[0] + d[0], c[1] + d[1]]).copied().unwrap_or(0);
            let mut n = 0;
            for da in -1..=1 {
                for db in -1..=1 {
                    if (da, db) != (0, 0) {
                        n += at([da, db]);
                    }
                }
            }
            (["xy", "xz", "yz"][plane], c.to_vec(), at([0, 0]), n)
        }
        _ => return unchecked,
    };
    let verdict = if count > 0 {
        Verdict::Feasible
    } else if neighbours > 0 {
        Verdict::Borderline
    } else {
        Verdict::Unreachable
    };
    TipReach { verdict, table: Some(table), cell: idx, count, neighbours }
}

/// The planar target of a target's in-plane tip and `a_bend_z` (none when
/// it asks for nothing in the plane).
fn planar_target(t: &ShapeTarget) -> Option<(Target, Weights)> {
    let key = |q: &Quantity| match q {
        Quantity::BendZ(k) if *k > super::target::MAX_ORDER => None,
        q => q.planar_key(),
    };
    let pairs: Vec<(String, f64, f64)> = t.components.iter().filter_map(|(q, v, w)| key(q).map(|k| (k, *v, *w))).collect();
    if pairs.is_empty() {
        return None;
    }
    let target = Target::parse(&pairs.iter().map(|(k, v, _)| format!("{k}={v}")).collect::<Vec<_>>().join(",")).ok()?;
    let weights = Weights::parse(&pairs.iter().map(|(k, _, w)| format!("{k}={w}")).collect::<Vec<_>>().join(",")).ok()?;
    Some((target, weights))
}

/// The map's answer for every target of `targets`.
pub fn check(map: &Path, targets: &TargetSet, basis: LengthBasis, nearest: usize) -> Result<TargetsFeasibility, DesignError> {
    let reach = read_reach(map)?;
    let planar_map = match &reach.summary.planar_map {
        Some(dir) => Some(MapDir::open(&map.join(dir))?),
        None => None,
    };
    let targets = targets
        .targets
        .iter()
        .map(|t| {
            let planar = match (&planar_map, planar_target(t)) {
                (Some(m), Some((target, weights))) if t.tip_mm()[2].is_none_or(|z| z == 0.0) => Some(planar::check(m, &target, basis, &weights, nearest)?),
                _ => None,
            };
            Ok(TargetFeasibility { name: t.name.clone(), tip: tip_reach(&reach, t), planar })
        })
        .collect::<Result<Vec<_>, DesignError>>()?;
    Ok(TargetsFeasibility { map: map.to_path_buf(), cables: reach.summary.cables, cell_mm: reach.summary.cell_mm, targets })
}

impl fmt::Display for TargetsFeasibility {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "map          {} ({} cables, reach cells of {} mm)", self.map.display(), self.cables, self.cell_mm)?;
        for t in &self.targets {
            writeln!(f)?;
            let r = &t.tip;
            let what = match r.verdict {
                Verdict::Feasible => format!("reached: {} tips in the tip's {} cell {:?}", r.count, r.table.unwrap_or(""), r.cell),
                Verdict::Borderline => format!("borderline: no tip in the {} cell {:?}, {} in its neighbours", r.table.unwrap_or(""), r.cell, r.neighbours),
                Verdict::Unreachable => format!(
                    "not reached by the sweep: no tip in or next to the {} cell {:?} (the sweep samples a grid: `design` will tell)",
                    r.table.unwrap_or(""),
                    r.cell
                ),
                Verdict::Unchecked => "tip unchecked (the target asks for fewer than two tip components)".to_string(),
            };
            writeln!(f, "{}   {what}", t.name)?;
            if let Some(p) = &t.planar {
                writeln!(f, "  in the x–y plane (MAP/planar):")?;
                for line in p.to_string().lines() {
                    writeln!(f, "    {line}")?;
                }
            }
        }
        Ok(())
    }
}
