//! The targets file of a several-cable design (`design --targets T.toml`):
//! one or more `[[target]]` tables (a sequence of shapes reached by one set
//! of channels, one actuation per target) or a `[trajectory]` of tip
//! waypoints. Each target asks for any of the tip position (any subset of
//! x, y, z), the tip tangent and the three coefficient series of the 3-D
//! solver (`a_bend_z`, `a_bend_y`, `a_twist`, the names `simulate --json`
//! uses), with weights and a tolerance.

use super::DesignError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Highest Legendre order accepted in a target.
pub const MAX_ORDER: usize = 12;

/// Relative error of an achieved value, %, in the thesis's convention
/// (Table 5.1): 100 (achieved − target) / |target|. `None` for a zero target.
pub fn error_pct(achieved: f64, target: f64) -> Option<f64> {
    (target != 0.0).then(|| 100.0 * (achieved - target) / target.abs())
}

/// One scalar a target can ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Quantity {
    /// Tip position along the clamp axis (global x), mm.
    TipX,
    /// Tip position, global y, mm.
    TipY,
    /// Tip position, global z, mm.
    TipZ,
    /// Component 0, 1, 2 (x, y, z) of the unit tip tangent.
    Tangent(usize),
    /// In-plane (x–y) bending coefficient a_bend_z[k], 1/mm.
    BendZ(usize),
    /// Out-of-plane bending coefficient a_bend_y[k], 1/mm.
    BendY(usize),
    /// Twist coefficient a_twist[k], 1/mm.
    Twist(usize),
}

impl Quantity {
    /// The key in design.json (`tip_x_mm`, `tip_tangent_y`, `a_bend_z0`, …).
    pub fn key(&self) -> String {
        match self {
            Quantity::TipX => "tip_x_mm".into(),
            Quantity::TipY => "tip_y_mm".into(),
            Quantity::TipZ => "tip_z_mm".into(),
            Quantity::Tangent(i) => format!("tip_tangent_{}", ["x", "y", "z"][*i]),
            Quantity::BendZ(k) => format!("a_bend_z{k}"),
            Quantity::BendY(k) => format!("a_bend_y{k}"),
            Quantity::Twist(k) => format!("a_twist{k}"),
        }
    }

    /// The default weight λ: 1 per mm² for the tip (eq. 3.17's λ_x = λ_y),
    /// L² for the unit tangent (a tangent off by δ weighs as the tip off by
    /// L δ, about 1.1 mm per degree on the thesis rod), the thesis's
    /// λ_0 = 100, λ_1 = 50, λ_k = 25 for every series.
    pub fn default_weight(&self, length_mm: f64) -> f64 {
        self.thesis_weight().unwrap_or(length_mm * length_mm)
    }

    /// The thesis's weight λ (Ch. 5) of a tip coordinate or a coefficient:
    /// λ_x = λ_y = 1, λ_0 = 100, λ_1 = 50, λ_2 = 25 and λ_2's weight for
    /// higher orders; none for the tangent, whose weight depends on the
    /// rod's length.
    pub fn thesis_weight(&self) -> Option<f64> {
        match self {
            Quantity::TipX | Quantity::TipY | Quantity::TipZ => Some(1.0),
            Quantity::Tangent(_) => None,
            Quantity::BendZ(k) | Quantity::BendY(k) | Quantity::Twist(k) => Some(match k {
                0 => 100.0,
                1 => 50.0,
                _ => 25.0,
            }),
        }
    }

    /// The scale a zero target is judged against (Table 5.1's % needs a
    /// non-zero target): the rod length for the tip, 1 for the tangent,
    /// 1/L for a coefficient (one radian of bending over the rod).
    pub fn natural_scale(&self, length_mm: f64) -> f64 {
        match self {
            Quantity::TipX | Quantity::TipY | Quantity::TipZ => length_mm,
            Quantity::Tangent(_) => 1.0,
            _ => 1.0 / length_mm,
        }
    }

    /// The key of an in-plane quantity in the thesis's `--target` list and
    /// a one-target design.json (`x`, `y`, `a0`, `a1`, …); none for the
    /// quantities out of the plane.
    pub fn planar_key(&self) -> Option<String> {
        match self {
            Quantity::TipX => Some("x".into()),
            Quantity::TipY => Some("y".into()),
            Quantity::BendZ(k) => Some(format!("a{k}")),
            _ => None,
        }
    }

    /// Parses a `--target` key: `x`, `y`, `a0`, `a1`, … (also `x_e`, `y_e`).
    pub fn parse_planar_key(key: &str) -> Option<Self> {
        match key.trim() {
            "x" | "x_e" | "xe" => Some(Quantity::TipX),
            "y" | "y_e" | "ye" => Some(Quantity::TipY),
            k => {
                let digits = k.strip_prefix('a')?;
                if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) {
                    return None;
                }
                // Orders beyond a few dozen are numerically meaningless for a
                // 65 mm rod sampled at ~50 nodes; reject them as typos.
                digits.parse::<usize>().ok().filter(|&k| k <= MAX_ORDER).map(Quantity::BendZ)
            }
        }
    }

    /// Whether it is a coefficient of a series (1/mm).
    pub fn is_coefficient(&self) -> bool {
        matches!(self, Quantity::BendZ(_) | Quantity::BendY(_) | Quantity::Twist(_))
    }

    /// Unit, for tables.
    pub fn unit(&self) -> &'static str {
        match self {
            Quantity::TipX | Quantity::TipY | Quantity::TipZ => "mm",
            Quantity::Tangent(_) => "1",
            _ => "1/mm",
        }
    }
}

impl std::fmt::Display for Quantity {
    /// The thesis's symbol: x_e, y_e, z_e for the tip, a_k for the in-plane
    /// bending coefficients.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Quantity::TipX => write!(f, "x_e"),
            Quantity::TipY => write!(f, "y_e"),
            Quantity::TipZ => write!(f, "z_e"),
            Quantity::Tangent(i) => write!(f, "t_{}", ["x", "y", "z"][*i]),
            Quantity::BendZ(k) => write!(f, "a_{k}"),
            Quantity::BendY(k) => write!(f, "a_bend_y_{k}"),
            Quantity::Twist(k) => write!(f, "a_twist_{k}"),
        }
    }
}

/// One target component, asked vs achieved.
#[derive(Debug, Clone, PartialEq)]
pub struct ComponentOutcome {
    /// Which.
    pub quantity: Quantity,
    /// Asked.
    pub target: f64,
    /// Achieved.
    pub achieved: f64,
    /// 100 (achieved − target)/|target| (None for a zero target).
    pub error_pct: Option<f64>,
    /// Within the target's tolerance.
    pub met: bool,
}

impl ComponentOutcome {
    /// `achieved` against `target`: met when its relative error is within
    /// `tolerance_pct`, a zero target judged against the quantity's natural
    /// scale on a rod of `length_mm` instead.
    pub fn judge(quantity: Quantity, target: f64, achieved: f64, tolerance_pct: f64, length_mm: f64) -> Self {
        let error_pct = error_pct(achieved, target);
        let met = match error_pct {
            Some(e) => e.abs() <= tolerance_pct,
            None => (achieved - target).abs() <= tolerance_pct / 100.0 * quantity.natural_scale(length_mm),
        };
        Self { quantity, target, achieved, error_pct, met }
    }
}

/// One target shape: what is asked, with weights and a tolerance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShapeTarget {
    /// Its name (`name = "…"`, else `target N`).
    pub name: String,
    /// (quantity, target value, weight λ), in the order tip, tangent, series.
    pub components: Vec<(Quantity, f64, f64)>,
    /// A component counts as met within this many percent.
    pub tolerance_pct: f64,
}

impl ShapeTarget {
    /// The asked value of `q`, if asked.
    pub fn get(&self, q: Quantity) -> Option<f64> {
        self.components.iter().find(|c| c.0 == q).map(|c| c.1)
    }

    /// The tip components asked, as [x, y, z] with `None` for those not asked.
    pub fn tip_mm(&self) -> [Option<f64>; 3] {
        [self.get(Quantity::TipX), self.get(Quantity::TipY), self.get(Quantity::TipZ)]
    }

    /// The unit tangent asked, if asked.
    pub fn tangent(&self) -> Option<[f64; 3]> {
        Some([self.get(Quantity::Tangent(0))?, self.get(Quantity::Tangent(1))?, self.get(Quantity::Tangent(2))?])
    }

    /// The highest coefficient order asked (2 when none: the shape is still reported).
    pub fn order(&self) -> usize {
        self.components
            .iter()
            .filter_map(|(q, ..)| match q {
                Quantity::BendZ(k) | Quantity::BendY(k) | Quantity::Twist(k) => Some(*k),
                _ => None,
            })
            .max()
            .unwrap_or(2)
            .max(2)
    }

    /// The target as a JSON object in the file's own terms.
    pub fn to_json(&self) -> serde_json::Value {
        let mut v = serde_json::Map::new();
        let tip: serde_json::Map<String, serde_json::Value> =
            ["x", "y", "z"].iter().zip(self.tip_mm()).filter_map(|(k, t)| t.map(|t| (k.to_string(), serde_json::json!(t)))).collect();
        if !tip.is_empty() {
            v.insert("tip_mm".into(), tip.into());
        }
        if let Some(t) = self.tangent() {
            v.insert("tip_tangent".into(), serde_json::json!(t));
        }
        for (name, of) in [("a_bend_z", Quantity::BendZ as fn(usize) -> Quantity), ("a_bend_y", Quantity::BendY), ("a_twist", Quantity::Twist)] {
            let series: Vec<f64> = (0..=MAX_ORDER).map_while(|k| self.get(of(k))).collect();
            if !series.is_empty() {
                v.insert(name.into(), serde_json::json!(series));
            }
        }
        v.into()
    }
}

/// A tip trajectory: waypoints reached in order, the actuation moving
/// linearly from one to the next.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trajectory {
    /// Samples per leg between consecutive waypoints (the path report).
    pub steps_per_leg: usize,
    /// Whether no cable's tension may reverse inside a leg.
    pub smooth: bool,
}

/// What a targets file asks for.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetSet {
    /// The targets in file order (a trajectory's waypoints, in order).
    pub targets: Vec<ShapeTarget>,
    /// Present when the targets are a trajectory's waypoints.
    pub trajectory: Option<Trajectory>,
}

/// Default tolerance, % (as `design --tolerance-pct`).
pub const DEFAULT_TOLERANCE_PCT: f64 = 5.0;

/// Default samples per trajectory leg.
pub const DEFAULT_STEPS_PER_LEG: usize = 20;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TargetsFile {
    #[serde(default, rename = "target")]
    targets: Vec<TargetTable>,
    trajectory: Option<TrajectoryTable>,
    tolerance_pct: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TargetTable {
    name: Option<String>,
    tip_mm: Option<TipSpec>,
    tip_tangent: Option<Vec<f64>>,
    a_bend_z: Option<Vec<f64>>,
    a_bend_y: Option<Vec<f64>>,
    a_twist: Option<Vec<f64>>,
    weights: Option<WeightsTable>,
    tolerance_pct: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum TipSpec {
    All(Vec<f64>),
    Some(TipTable),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TipTable {
    x: Option<f64>,
    y: Option<f64>,
    z: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct WeightsTable {
    tip: Option<f64>,
    tip_tangent: Option<f64>,
    a_bend_z: Option<Vec<f64>>,
    a_bend_y: Option<Vec<f64>>,
    a_twist: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TrajectoryTable {
    waypoints: Vec<Vec<f64>>,
    tangents: Option<Vec<Vec<f64>>>,
    steps_per_leg: Option<usize>,
    #[serde(default)]
    smooth: bool,
    weights: Option<WeightsTable>,
    tolerance_pct: Option<f64>,
}

fn bad(message: String) -> DesignError {
    DesignError::TargetsFile { path: None, message }
}

impl TargetSet {
    /// Reads a targets file; `length_mm` (the rod's) sets the default weights.
    pub fn read(path: &Path, length_mm: f64) -> Result<Self, DesignError> {
        let in_file = |message| DesignError::TargetsFile { path: Some(path.to_path_buf()), message };
        let text = std::fs::read_to_string(path).map_err(|e| in_file(e.to_string()))?;
        Self::parse(&text, length_mm).map_err(|e| match e {
            DesignError::TargetsFile { path: None, message } => in_file(message),
            e => e,
        })
    }

    /// Parses the TOML text of a targets file.
    pub fn parse(text: &str, length_mm: f64) -> Result<Self, DesignError> {
        let file: TargetsFile = toml::from_str(text).map_err(|e| bad(format!("{e}; see docs/design.md, \"Several cables\"")))?;
        let default_tol = file.tolerance_pct.unwrap_or(DEFAULT_TOLERANCE_PCT);
        match (file.targets.is_empty(), file.trajectory) {
            (true, None) => Err(bad("no targets: give one or more [[target]] tables or a [trajectory] with waypoints".into())),
            (false, Some(_)) => Err(bad("give either [[target]] tables (a sequence of shapes) or a [trajectory], not both".into())),
            (false, None) => {
                let targets = file
                    .targets
                    .into_iter()
                    .enumerate()
                    .map(|(i, t)| target_of(t, i, default_tol, length_mm))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Self { targets, trajectory: None })
            }
            (true, Some(tr)) => {
                if tr.waypoints.len() < 2 {
                    return Err(bad(format!("a trajectory needs at least 2 waypoints, got {}", tr.waypoints.len())));
                }
                if let Some(t) = &tr.tangents {
                    if t.len() != tr.waypoints.len() {
                        return Err(bad(format!("trajectory: {} tangents for {} waypoints: give one per waypoint", t.len(), tr.waypoints.len())));
                    }
                }
                let steps = tr.steps_per_leg.unwrap_or(DEFAULT_STEPS_PER_LEG);
                if !(1..=1000).contains(&steps) {
                    return Err(bad(format!("trajectory: steps_per_leg = {steps} must lie in 1 … 1000")));
                }
                let tol = tr.tolerance_pct.unwrap_or(default_tol);
                let targets = tr
                    .waypoints
                    .iter()
                    .enumerate()
                    .map(|(i, w)| {
                        let table = TargetTable {
                            name: Some(format!("waypoint {}", i + 1)),
                            tip_mm: Some(TipSpec::All(w.clone())),
                            tip_tangent: tr.tangents.as_ref().map(|t| t[i].clone()),
                            a_bend_z: None,
                            a_bend_y: None,
                            a_twist: None,
                            weights: tr.weights.as_ref().map(|w| WeightsTable { tip: w.tip, tip_tangent: w.tip_tangent, ..WeightsTable::default() }),
                            tolerance_pct: Some(tol),
                        };
                        target_of(table, i, default_tol, length_mm)
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Self { targets, trajectory: Some(Trajectory { steps_per_leg: steps, smooth: tr.smooth }) })
            }
        }
    }

    /// The highest coefficient order of any target.
    pub fn order(&self) -> usize {
        self.targets.iter().map(ShapeTarget::order).max().unwrap_or(2)
    }
}

fn finite(what: &str, v: f64) -> Result<f64, DesignError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(bad(format!("{what} = {v} is not a finite number")))
    }
}

fn target_of(t: TargetTable, index: usize, default_tol: f64, length_mm: f64) -> Result<ShapeTarget, DesignError> {
    let name = t.name.unwrap_or_else(|| format!("target {}", index + 1));
    let w = t.weights.unwrap_or_default();
    let weight = |what: &str, v: Option<f64>, default: f64| -> Result<f64, DesignError> {
        match v {
            Some(v) if v.is_finite() && v >= 0.0 => Ok(v),
            Some(v) => Err(bad(format!("{name}: weights.{what} = {v} must be a finite weight ≥ 0"))),
            None => Ok(default),
        }
    };
    let mut components = Vec::new();
    let tip: [Option<f64>; 3] = match t.tip_mm {
        None => [None; 3],
        Some(TipSpec::All(v)) if v.len() == 3 => [Some(v[0]), Some(v[1]), Some(v[2])],
        Some(TipSpec::All(v)) => {
            return Err(bad(format!(
                "{name}: tip_mm has {} numbers; give all three, tip_mm = [x, y, z], or a subset as a table, tip_mm = {{ x = 50, y = 5 }}",
                v.len()
            )))
        }
        Some(TipSpec::Some(t)) => [t.x, t.y, t.z],
    };
    for (q, v) in [Quantity::TipX, Quantity::TipY, Quantity::TipZ].into_iter().zip(tip) {
        if let Some(v) = v {
            let v = finite(&format!("{name}: {}", q.key()), v)?;
            components.push((q, v, weight("tip", w.tip, q.default_weight(length_mm))?));
        }
    }
    if let Some(tan) = t.tip_tangent {
        let n = tan.iter().map(|v| v * v).sum::<f64>().sqrt();
        if tan.len() != 3 || !(n.is_finite() && n > 0.0) {
            return Err(bad(format!("{name}: tip_tangent must be three finite numbers [tx, ty, tz], not all zero (it is normalised)")));
        }
        for (i, v) in tan.iter().enumerate() {
            let q = Quantity::Tangent(i);
            components.push((q, v / n, weight("tip_tangent", w.tip_tangent, q.default_weight(length_mm))?));
        }
    }
    for (series, name_s, of, ws) in [
        (t.a_bend_z, "a_bend_z", Quantity::BendZ as fn(usize) -> Quantity, w.a_bend_z),
        (t.a_bend_y, "a_bend_y", Quantity::BendY, w.a_bend_y),
        (t.a_twist, "a_twist", Quantity::Twist, w.a_twist),
    ] {
        let Some(series) = series else { continue };
        if series.len() > MAX_ORDER + 1 {
            return Err(bad(format!("{name}: {name_s} has {} coefficients; at most {} (orders 0 … {MAX_ORDER})", series.len(), MAX_ORDER + 1)));
        }
        if let Some(ws) = &ws {
            if ws.len() != series.len() {
                return Err(bad(format!("{name}: weights.{name_s} has {} weights for {} coefficients: give one per coefficient", ws.len(), series.len())));
            }
        }
        for (k, v) in series.iter().enumerate() {
            let q = of(k);
            let v = finite(&format!("{name}: {name_s}[{k}]"), *v)?;
            components.push((q, v, weight(name_s, ws.as_ref().map(|w| w[k]), q.default_weight(length_mm))?));
        }
    }
    if components.is_empty() {
        return Err(bad(format!("{name} asks for nothing: give tip_mm, tip_tangent, a_bend_z, a_bend_y or a_twist")));
    }
    if components.iter().all(|c| c.2 == 0.0) {
        return Err(bad(format!("{name}: every weight is zero: nothing to fit")));
    }
    let tolerance_pct = t.tolerance_pct.unwrap_or(default_tol);
    if !(tolerance_pct.is_finite() && tolerance_pct >= 0.0) {
        return Err(bad(format!("{name}: tolerance_pct = {tolerance_pct} must be a finite number ≥ 0 %")));
    }
    Ok(ShapeTarget { name, components, tolerance_pct })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_targets_subsets_weights_and_trajectories() {
        let set = TargetSet::parse(
            "[[target]]\ntip_mm = [50, 5, 1]\ntip_tangent = [0, 0, 2]\n\n[[target]]\nname = \"B\"\ntip_mm = { x = 40 }\na_bend_y = [0.01, -0.02]\nweights = { a_bend_y = [7, 8] }\ntolerance_pct = 1\n",
            65.0,
        )
        .unwrap();
        assert_eq!(set.targets.len(), 2);
        let a = &set.targets[0];
        assert_eq!(a.tip_mm(), [Some(50.0), Some(5.0), Some(1.0)]);
        assert_eq!(a.tangent(), Some([0.0, 0.0, 1.0]));
        assert_eq!(a.components[3].2, 65.0 * 65.0);
        let b = &set.targets[1];
        assert_eq!((b.name.as_str(), b.tip_mm(), b.tolerance_pct), ("B", [Some(40.0), None, None], 1.0));
        assert_eq!(b.components[2], (Quantity::BendY(1), -0.02, 8.0));
        assert_eq!(b.order(), 2);
        let t = TargetSet::parse("[trajectory]\nwaypoints = [[60, 0, 0], [55, 10, 0], [55, -10, 0]]\nsmooth = true\n", 65.0).unwrap();
        assert_eq!(t.targets.len(), 3);
        assert_eq!(t.trajectory, Some(Trajectory { steps_per_leg: 20, smooth: true }));
    }

    #[test]
    fn bad_targets_are_named() {
        for (text, says) in [
            ("", "no targets"),
            ("[[target]]\n", "asks for nothing"),
            ("[[target]]\ntip_mm = [1, 2]\n", "tip_mm has 2 numbers"),
            ("[[target]]\ntip_tangent = [0, 0, 0]\n", "tip_tangent"),
            ("[[target]]\ntip_mm = [1, 2, 3]\ncolour = 1\n", "unknown field"),
            ("[[target]]\na_twist = [0.1]\nweights = { a_twist = [1, 2] }\n", "one per coefficient"),
            ("[trajectory]\nwaypoints = [[1, 2, 3]]\n", "at least 2 waypoints"),
        ] {
            let e = TargetSet::parse(text, 65.0).unwrap_err().to_string();
            assert!(e.contains(says), "{text:?}: {e}");
        }
    }
}
