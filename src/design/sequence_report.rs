//! What a sequence design returns ([`SequenceRun`]): every cable's channel,
//! each target's actuation and what it achieved against what it asked, a
//! trajectory's path; its JSON (design.json) and the text it prints.

use super::actuator::{ActuationBounds, DesignActuator};
use super::search::StartReport;
use super::sequence::{Achieved, Channel};
use super::targets::{ComponentOutcome, Quantity, ShapeTarget};
use super::trajectory;
use crate::model::Actuator;
use crate::shape::LengthBasis;
use serde_json::json;
use std::fmt;
use std::path::PathBuf;

/// One target's design: its actuation and what it achieves.
#[derive(Debug, Clone)]
pub struct TargetOutcome {
    /// The target.
    pub target: ShapeTarget,
    /// Each cable's actuation (tension N, or displacement mm, as the cable is driven).
    pub actuation: Vec<f64>,
    /// What the solve achieved (its pose holds every cable's tension and displacement).
    pub achieved: Achieved,
    /// Each component.
    pub components: Vec<ComponentOutcome>,
    /// The actuator that reproduces it.
    pub actuator: Actuator,
    /// The `cablemap simulate` command that solves it again.
    pub command: String,
}

impl TargetOutcome {
    /// Distance of the achieved tip from the asked one over the asked components, mm.
    pub fn tip_error_mm(&self) -> Option<f64> {
        let d: Vec<f64> = self.components.iter().filter(|c| matches!(c.quantity, Quantity::TipX | Quantity::TipY | Quantity::TipZ)).map(|c| c.achieved - c.target).collect();
        (!d.is_empty()).then(|| d.iter().map(|v| v * v).sum::<f64>().sqrt())
    }

    /// Angle between the achieved and the asked tip tangent, degrees.
    pub fn tangent_error_deg(&self) -> Option<f64> {
        let asked = self.target.tangent()?;
        let got = self.achieved.pose.tip_tangent();
        let dot: f64 = asked.iter().zip(got).map(|(a, b)| a * b).sum();
        let n: f64 = got.iter().map(|v| v * v).sum::<f64>().sqrt();
        Some((dot / n).clamp(-1.0, 1.0).acos().to_degrees())
    }

    /// Whether every component is met.
    pub fn met(&self) -> bool {
        self.components.iter().all(|c| c.met)
    }

    /// One sentence per component not met: which, by how much.
    pub fn misses(&self) -> Vec<String> {
        self.components
            .iter()
            .filter(|c| !c.met)
            .map(|c| {
                let pct = c.error_pct.map_or(String::new(), |e| format!(", {e:+.2} %"));
                format!(
                    "{}: {} misses by {} (achieved {}, asked {}{pct}; tolerance {} %)",
                    self.target.name,
                    c.quantity.key(),
                    fmt6(c.achieved - c.target),
                    fmt6(c.achieved),
                    fmt6(c.target),
                    self.target.tolerance_pct
                )
            })
            .collect()
    }
}

pub(super) fn fmt6(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// A finished several-cable design.
#[derive(Debug, Clone)]
pub struct SequenceRun {
    /// The actuator designed for.
    pub design: DesignActuator,
    /// Each cable's designed channel (y, z control points, mm).
    pub channels: Vec<Channel>,
    /// One per target, in order.
    pub targets: Vec<TargetOutcome>,
    /// The summed objective.
    pub cost: f64,
    /// Every refined start.
    pub starts: Vec<StartReport>,
    /// Designs simulated to seed the search.
    pub seeds_simulated: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// How the search ran: `planar` (the thesis's one-cable search) or `cables`.
    pub method: &'static str,
    /// The coefficients' basis.
    pub length_basis: LengthBasis,
    /// The tip path between waypoints, for a trajectory.
    pub trajectory: Option<trajectory::PathReport>,
    /// The export directory and the files written into it.
    pub out: Option<PathBuf>,
    /// Files written, in order.
    pub exported: Vec<String>,
    /// The moulds written, when asked for.
    pub moulds: Option<crate::mould::MouldReport>,
}

impl SequenceRun {
    /// Every target met (and, for a trajectory, every intermediate solve and, with `smooth`, no reversal).
    pub fn met(&self) -> bool {
        self.targets.iter().all(TargetOutcome::met) && self.trajectory.as_ref().is_none_or(|t| t.ok())
    }

    /// Why not, one sentence each.
    pub fn unmet(&self) -> Vec<String> {
        let mut v: Vec<String> = self.targets.iter().flat_map(TargetOutcome::misses).collect();
        if let Some(t) = &self.trajectory {
            v.extend(t.problems());
        }
        v
    }

    /// design.json's object (docs/design.md, "Several cables").
    pub fn to_json(&self) -> serde_json::Value {
        let cables: Vec<serde_json::Value> = self
            .channels
            .iter()
            .zip(&self.design.freedom)
            .enumerate()
            .map(|(i, ((y, z), f))| {
                let c = &self.design.actuator.cables[i];
                json!({
                    "y_mm": y,
                    "z_mm": z,
                    "free": f.free(),
                    "max_offset_mm": f.max_offset_mm,
                    "actuation": f.actuation,
                    "anchor_mm": c.anchor_mm,
                    "cable_ea_n": c.cable_ea_n,
                })
            })
            .collect();
        let targets: Vec<serde_json::Value> = self
            .targets
            .iter()
            .map(|t| {
                let p = &t.achieved.pose;
                let mut errors = serde_json::Map::new();
                let mut achieved = serde_json::Map::new();
                for c in &t.components {
                    errors.insert(c.quantity.key(), json!(c.error_pct));
                    achieved.insert(c.quantity.key(), json!(c.achieved));
                }
                json!({
                    "name": t.target.name,
                    "target": t.target.to_json(),
                    "tensions_n": p.tensions_n.to_vec(),
                    "displacements_mm": p.displacements_mm.iter().map(|d| if d.is_finite() { json!(d) } else { serde_json::Value::Null }).collect::<Vec<_>>(),
                    "actuation": t.actuation,
                    "tip_mm": p.tip_mm(),
                    "tip_tangent": p.tip_tangent(),
                    "length_mm": p.length_mm,
                    "a_bend_z": t.achieved.a_bend_z,
                    "a_bend_y": t.achieved.a_bend_y,
                    "a_twist": t.achieved.a_twist,
                    "achieved": achieved,
                    "error_pct": errors,
                    "tip_error_mm": t.tip_error_mm(),
                    "tangent_error_deg": t.tangent_error_deg(),
                    "tolerance_pct": t.target.tolerance_pct,
                    "weights": t.target.components.iter().map(|c| (c.0.key(), json!(c.2))).collect::<serde_json::Map<_, _>>(),
                    "met": t.met(),
                    "unmet": t.misses(),
                    "command": t.command,
                })
            })
            .collect();
        let mut actuator = serde_json::to_value(&self.design.actuator).unwrap_or(serde_json::Value::Null);
        if let Some(obj) = actuator.as_object_mut() {
            // The cables are above; the actuator keeps rod, torsion and gravity.
            obj.remove("cable");
        }
        json!({
            "cables": cables,
            "targets": targets,
            "met": self.met(),
            "unmet": self.unmet(),
            "cost": self.cost,
            "actuator": actuator,
            "length_basis": self.length_basis,
            "method": self.method,
            "starts": self.starts,
            "seeds_simulated": self.seeds_simulated,
            "seconds": self.seconds,
            "trajectory": self.trajectory,
            "moulds": self.moulds,
        })
    }
}

impl fmt::Display for SequenceRun {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (y, z)) in self.channels.iter().enumerate() {
            let list = |v: &[f64; 5]| v.iter().map(|x| format!("{x:.4}")).collect::<Vec<_>>().join(",");
            writeln!(f, "cable {}      y = {}  z = {} mm   ({})", i + 1, list(y), list(z), match self.design.freedom[i].free().as_slice() {
                [] => "fixed".to_string(),
                free => format!("free: {}", free.join(", ")),
            })?;
        }
        for t in &self.targets {
            writeln!(f)?;
            let act: Vec<String> = self.design.freedom.iter().zip(&t.achieved.pose.tensions_n.to_vec()).zip(&t.actuation).map(|((fr, tn), a)| match fr.actuation {
                ActuationBounds::Tension { .. } => format!("{tn:.4} N"),
                ActuationBounds::Displacement { .. } => format!("{a:.4} mm ({tn:.4} N)"),
            }).collect();
            writeln!(f, "{}   actuation [{}]", t.target.name, act.join(", "))?;
            writeln!(f, "  {:<16}{:>14}{:>14}{:>12}", "component", "target", "achieved", "error")?;
            for c in &t.components {
                let e = c.error_pct.map_or("n/a (t=0)".to_string(), |e| format!("{e:.3}%"));
                writeln!(f, "  {:<16}{:>14.6}{:>14.6}{:>12}{}", c.quantity.key(), c.target, c.achieved, e, if c.met { "" } else { "  unmet" })?;
            }
            if let Some(d) = t.tip_error_mm() {
                write!(f, "  tip off by {d:.4} mm")?;
                if let Some(a) = t.tangent_error_deg() {
                    write!(f, ", tangent by {a:.4}°")?;
                }
                writeln!(f)?;
            }
            writeln!(f, "  {}", t.command)?;
        }
        if let Some(tr) = &self.trajectory {
            writeln!(f)?;
            write!(f, "{tr}")?;
        }
        writeln!(f)?;
        writeln!(f, "objective    {:.3e}   ({} seed designs simulated, {} refined, {:.2} s)", self.cost, self.seeds_simulated, self.starts.len(), self.seconds)?;
        let unmet = self.unmet();
        if unmet.is_empty() {
            writeln!(f, "verdict      every target met within its tolerance")?;
        } else {
            writeln!(f, "verdict      NOT REACHABLE as asked; the design above is the closest found (least summed cost):")?;
            for u in unmet {
                writeln!(f, "  - {u}")?;
            }
        }
        if let Some(dir) = &self.out {
            writeln!(f, "exported {} to {}", self.exported.join(", "), dir.display())?;
            if let Some(m) = &self.moulds {
                write!(f, "{}", m.report(dir))?;
            }
        }
        Ok(())
    }
}

