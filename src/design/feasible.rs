//! The map's verdict on a target before any optimisation (thesis §4.2):
//! is the tip cell reachable, do the target coefficients lie within what
//! the sweep saw there, which characteristic mode the target falls in, and
//! which simulated designs are nearest.

use super::map::{Cell, MapDir, NearDesign, CELL_STATS_ORDER, MODES};
use super::target::{Component, Target, Weights};
use super::DesignError;
use crate::shape::LengthBasis;
use serde::Serialize;

/// The three verdicts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The tip cell was reached and every checked coefficient lies within the
    /// cell's 10th–90th percentiles, in a mode the cell has seen.
    Feasible,
    /// Reached only at the edge: the tip cell is empty but a neighbour is
    /// not, or a coefficient lies outside the cell's percentiles but within
    /// the extremes of the cell and its 8 neighbours, or the target's mode
    /// was not seen in the tip cell.
    Borderline,
    /// Not reached by any of the map's designs: none put the tip in or next
    /// to the cell, or a coefficient lies outside the range its designs
    /// reached there. The map samples a grid of routings, so this does not
    /// prove the target unreachable: `design` may still meet it between the
    /// grid points (Table 5.1's Target I on the thesis map). Serialised
    /// `unreachable`, the key JSON outputs have always used.
    Unreachable,
}

impl Verdict {
    /// The machine-readable key: `feasible`, `borderline` or `unreachable`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "unreachable",
        }
    }

    /// The verdict in words, for people: what the map saw, not more (the
    /// explorer page, `assets/explorer.html`, uses the same words).
    pub fn label(&self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "not reached by any of the map's designs",
        }
    }
}

/// The cells a target's tip selects.
#[derive(Debug, Clone, Serialize)]
pub struct TipCell {
    /// Column (None when the target gives no x).
    pub ix: Option<i32>,
    /// Row (None when the target gives no y).
    pub iy: Option<i32>,
    /// Simulations in the selected cell(s).
    pub count: i64,
    /// Simulations in the selected cell(s) and their neighbours.
    pub neighbourhood_count: i64,
}

/// How one target coefficient compares with the map.
#[derive(Debug, Clone, Serialize)]
pub struct CoefficientCheck {
    /// `a0`, `a1`, ….
    pub component: String,
    /// Target value, 1/mm.
    pub target: f64,
    /// The tip cell's 10th and 90th percentiles (single tip cell only).
    pub cell_p10: Option<f64>,
    /// See `cell_p10`.
    pub cell_p90: Option<f64>,
    /// Smallest value seen in the cell(s) and their neighbours.
    pub neighbourhood_min: Option<f64>,
    /// Largest value seen in the cell(s) and their neighbours.
    pub neighbourhood_max: Option<f64>,
    /// Within the 10th–90th percentiles of some selected cell.
    pub within_percentiles: bool,
    /// Within the neighbourhood's extremes.
    pub within_extremes: bool,
}

/// The characteristic mode of the target (map's `mode_boundaries`).
#[derive(Debug, Clone, Serialize)]
pub struct ModeCheck {
    /// Mode index 3·i + j, when both a0 and a1 are given.
    pub mode: Option<usize>,
    /// The modes consistent with the given a0 / a1 (all 12 when neither is given).
    pub candidates: Vec<usize>,
    /// Simulations of the tip cell in each candidate mode (single tip cell only).
    pub count_in_cell: Option<i64>,
}

/// The full answer of `feasible`.
#[derive(Debug, Clone, Serialize)]
pub struct FeasibilityReport {
    /// The verdict.
    pub verdict: Verdict,
    /// Why, one sentence per finding.
    pub reasons: Vec<String>,
    /// The tip cell(s).
    pub tip_cell: TipCell,
    /// Per target coefficient the map has statistics for.
    pub coefficients: Vec<CoefficientCheck>,
    /// Target components the map cannot judge (coefficients above order 2 or the map's order).
    pub unchecked: Vec<String>,
    /// The target's characteristic mode.
    pub mode: ModeCheck,
    /// Nearest simulated designs (weighted distance), nearest first.
    pub nearest: Vec<NearDesign>,
    /// The length the coefficients (target, map, designs) are per unit of.
    pub length_basis: LengthBasis,
}

/// Judges `target` against `map`; `nearest` designs are listed. The
/// target's coefficients are per unit of `basis`; a map made in the other
/// basis is refused when the target has coefficients ([`MapDir::check_length_basis`]).
pub fn check(map: &MapDir, target: &Target, basis: LengthBasis, weights: &Weights, nearest: usize) -> Result<FeasibilityReport, DesignError> {
    map.check_length_basis(basis, target)?;
    let x = target.get(Component::TipX);
    let y = target.get(Component::TipY);
    let column = map.column_of(x);
    let row = map.row_of(y);
    let within = |c: &Cell, reach: i32| {
        column.is_none_or(|ix| (c.ix - ix).abs() <= reach) && row.is_none_or(|iy| (c.iy - iy).abs() <= reach)
    };
    let selected: Vec<&Cell> = map.cells.iter().filter(|c| within(c, 0) && c.count > 0).collect();
    let neighbourhood: Vec<&Cell> = map.cells.iter().filter(|c| within(c, 1) && c.count > 0).collect();
    let single = x.is_some() && y.is_some();
    let tip_cell = TipCell {
        ix: column,
        iy: row,
        count: selected.iter().map(|c| c.count).sum(),
        neighbourhood_count: neighbourhood.iter().map(|c| c.count).sum(),
    };
    let where_ = match (x, y) {
        (Some(x), Some(y)) => format!("tip cell ({}, {}) at x = {x} mm, y = {y} mm", column.unwrap(), row.unwrap()),
        (Some(x), None) => format!("cells at x = {x} mm"),
        (None, Some(y)) => format!("cells at y = {y} mm"),
        (None, None) => "any cell".to_string(),
    };
    let mut reasons = Vec::new();
    let stats_order = map.summary.order.min(CELL_STATS_ORDER);
    let mut unchecked = Vec::new();
    let mut checked: Vec<(usize, f64)> = Vec::new();
    for (c, v) in &target.components {
        if let Component::A(k) = c {
            if *k <= stats_order {
                checked.push((*k, *v));
            } else {
                unchecked.push(c.key());
            }
        }
    }
    if !unchecked.is_empty() {
        reasons.push(format!(
            "the map has statistics for a0…a{stats_order} only: {} not checked",
            unchecked.join(", ")
        ));
    }
    let in_percentiles = |c: &Cell, k: usize, v: f64| c.coefficients[k].p10 <= v && v <= c.coefficients[k].p90;
    let coefficients: Vec<CoefficientCheck> = checked
        .iter()
        .map(|&(k, v)| {
            let lo = neighbourhood.iter().map(|c| c.coefficients[k].min).fold(f64::INFINITY, f64::min);
            let hi = neighbourhood.iter().map(|c| c.coefficients[k].max).fold(f64::NEG_INFINITY, f64::max);
            let cell = if single { selected.first().map(|c| c.coefficients[k]) } else { None };
            CoefficientCheck {
                component: format!("a{k}"),
                target: v,
                cell_p10: cell.map(|s| s.p10),
                cell_p90: cell.map(|s| s.p90),
                neighbourhood_min: lo.is_finite().then_some(lo),
                neighbourhood_max: hi.is_finite().then_some(hi),
                within_percentiles: selected.iter().any(|c| in_percentiles(c, k, v)),
                within_extremes: lo <= v && v <= hi,
            }
        })
        .collect();
    // Jointly within percentiles in one selected cell (not just each in some cell).
    let joint = selected.iter().any(|c| checked.iter().all(|&(k, v)| in_percentiles(c, k, v)));
    let mode = mode_check(map, target, if single { selected.first().copied() } else { None });

    let verdict = if tip_cell.neighbourhood_count == 0 {
        reasons.insert(0, format!("no simulation of the map put the tip in or next to the {where_}: outside the area the map's designs reach"));
        Verdict::Unreachable
    } else if let Some(out) = coefficients.iter().find(|c| !c.within_extremes) {
        reasons.insert(
            0,
            format!(
                "{} = {} is outside the range the map's designs reached in and around the {where_} ([{:.5}, {:.5}]); \
                 the map samples a grid of designs, so a design between its grid points may still reach it: `design` will tell",
                out.component,
                out.target,
                out.neighbourhood_min.unwrap_or(f64::NAN),
                out.neighbourhood_max.unwrap_or(f64::NAN)
            ),
        );
        Verdict::Unreachable
    } else {
        let mut edge = Vec::new();
        if tip_cell.count == 0 {
            edge.push(format!("the {where_} was never reached, but a neighbouring cell was (edge of the reach)"));
        }
        for c in coefficients.iter().filter(|c| !c.within_percentiles) {
            edge.push(format!(
                "{} = {} is outside the 10th–90th percentiles of the {where_} but within the extremes of it and its neighbours",
                c.component, c.target
            ));
        }
        if edge.is_empty() && !joint {
            edge.push(format!("each coefficient is within some cell's percentiles, but no single cell of the {where_} holds all of them"));
        }
        if let (Some(m), Some(0)) = (mode.mode, mode.count_in_cell) {
            edge.push(format!("the target's mode {m} was never seen in the tip cell (its percentile range spans other modes)"));
        }
        if edge.is_empty() {
            reasons.insert(0, format!("the {where_} was reached {} times and every checked coefficient lies within its 10th–90th percentiles", tip_cell.count));
            Verdict::Feasible
        } else {
            reasons.splice(0..0, edge);
            Verdict::Borderline
        }
    };
    let length = map.summary.length_mm;
    if x.is_some_and(|x| x.abs() > length) {
        reasons.push(format!("the rod is {length} mm long: no tip lies {} mm from the clamp along its axis", x.unwrap_or(0.0)));
    }
    Ok(FeasibilityReport {
        verdict,
        reasons,
        tip_cell,
        coefficients,
        unchecked,
        mode,
        nearest: map.nearest_designs(target, weights, nearest)?,
        length_basis: map.summary.length_basis,
    })
}

fn mode_check(map: &MapDir, target: &Target, cell: Option<&Cell>) -> ModeCheck {
    let b = &map.summary.mode_boundaries;
    // The reducer's ranges() takes both coefficients; a missing one gets a
    // placeholder whose range is then ignored.
    let i = target.get(Component::A(0)).map(|a0| b.ranges(a0, 0.0).0);
    let j = target.get(Component::A(1)).map(|a1| b.ranges(0.0, a1).1);
    let candidates: Vec<usize> =
        (0..MODES).filter(|m| i.is_none_or(|i| m / 3 == i) && j.is_none_or(|j| m % 3 == j)).collect();
    let mode = match (i, j) {
        (Some(i), Some(j)) => Some(3 * i + j),
        _ => None,
    };
    let count_in_cell = cell.map(|c| candidates.iter().map(|&m| c.modes[m]).sum());
    ModeCheck { mode, candidates, count_in_cell }
}
