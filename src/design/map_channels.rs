//! Starting designs from a feasibility map of several cables
//! (`design --map MAP` with `--targets`): the map's simulated designs
//! nearest to the targets, every cable's channel.

use super::sequence::{Channel, Setup};
use super::targets::Quantity;
use super::map::{map_error, MapDir, MapMismatch};
use super::DesignError;
use std::path::Path;

/// Opens the planar map of a cable sweep's map `dir` (its `planar/` folder, which
/// holds the designs), or `dir` itself.
pub fn open(dir: &Path) -> Result<MapDir, DesignError> {
    let planar = dir.join("planar");
    if planar.join("summary.json").exists() {
        MapDir::open(&planar)
    } else {
        MapDir::open(dir)
    }
}

/// Up to `count` distinct channel sets of the map's designs nearest to the
/// targets (for each target in turn, by the weighted distance over its
/// in-plane tip and a_bend_z components).
pub fn channels(dir: &Path, setup: &Setup, count: usize) -> Result<Vec<Vec<Channel>>, DesignError> {
    let map = open(dir)?;
    let Some(cables) = &map.cables else {
        return Err(map_error(dir, MapMismatch::OnePlanarCable));
    };
    if cables.count() != setup.cables() {
        return Err(map_error(dir, MapMismatch::CableCount { map: cables.count(), actuator: setup.cables() }));
    }
    let mut out: Vec<Vec<Channel>> = Vec::new();
    let per_target = count.div_ceil(setup.targets.len().max(1));
    for t in &setup.targets {
        let score = |d: &super::map::MapDesign| -> f64 {
            t.components
                .iter()
                .map(|(q, v, w)| {
                    let got = match q {
                        Quantity::TipX => d.tip_x_mm,
                        Quantity::TipY => d.tip_y_mm,
                        Quantity::BendZ(k) => d.a.get(*k).copied().unwrap_or(0.0),
                        _ => return 0.0,
                    };
                    w * (got - v).powi(2)
                })
                .sum()
        };
        let mut ranked: Vec<(f64, usize)> = map.designs.iter().enumerate().map(|(i, d)| (score(d), i)).collect();
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut taken = 0;
        for (_, i) in ranked {
            if taken >= per_target || out.len() >= count {
                break;
            }
            let d = &map.designs[i];
            let sign = if d.mirrored { -1.0 } else { 1.0 };
            let set: Vec<Channel> = cables.actuator(d.routing_id).cables.iter().map(|c| (c.y_mm.map(|y| sign * y), c.z_mm)).collect();
            if !out.contains(&set) {
                out.push(set);
                taken += 1;
            }
        }
    }
    Ok(out)
}
