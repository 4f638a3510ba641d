//! `cablemap design`: routing and tension for a target shape (eq. 3.17).

use super::{ActuatorArgs, LengthBasisArgs};
use cablemap::design::{self, compare, map::MapDir, optimise, Bounds, ComponentResult, DesignOutcome, Objective, SearchOptions, Target, Weights};
use cablemap::model::{Actuator, SolverOptions};
use clap::Args;
use serde_json::json;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap design`.
#[derive(Debug, Clone, Args)]
pub struct DesignArgs {
    /// Target, any subset of x, y (tip, mm) and a0, a1, … (curvature coefficients, 1/mm),
    /// e.g. x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015.
    #[arg(long, value_name = "K=V,…", allow_hyphen_values = true)]
    pub target: String,
    /// Weights λ of eq. 3.17 for target components, e.g. a2=50
    /// [defaults x=1,y=1,a0=100,a1=50,a2=25, higher orders 25].
    #[arg(long, value_name = "K=V,…")]
    pub weights: Option<String>,
    /// Feasibility map directory (`cablemap reduce` output): seeds the search with
    /// its nearest designs and supplies the tension bounds.
    #[arg(long, value_name = "MAP_DIR")]
    pub map: Option<PathBuf>,
    /// Lower tension bound τ_l, N [default: 1.0, or the map's].
    #[arg(long, value_name = "N")]
    pub tension_min_n: Option<f64>,
    /// Upper tension bound τ_u, N [default: 2.0, or the map's].
    #[arg(long, value_name = "N")]
    pub tension_max_n: Option<f64>,
    /// Largest |y_i| of a control point, mm [default: 0.999 r: the thesis's −r < y_i < r].
    /// A channel of diameter d breaks the surface beyond r − d/2.
    #[arg(long, value_name = "MM")]
    pub max_offset_mm: Option<f64>,
    #[command(flatten)]
    pub basis: LengthBasisArgs,
    /// Number of seeds refined to convergence (3× as many are explored briefly).
    #[arg(long, default_value_t = 8)]
    pub starts: usize,
    /// Most simulator evaluations per converging start.
    #[arg(long, default_value_t = SearchOptions::default().max_evaluations)]
    pub max_evaluations: usize,
    /// A component counts as met when its error is within this many percent.
    #[arg(long, default_value_t = 5.0)]
    pub tolerance_pct: f64,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// Write design.json, channel.csv, mould.svg (1:1, mm) and shape.png into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: also write the printable moulds (mould1.stl, mould2.stl, previews,
    /// mould.json; see `cablemap mould`), with the mould options below.
    #[arg(long, requires = "out")]
    pub moulds: bool,
    #[command(flatten)]
    pub mould: super::mould::MouldParamArgs,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Builds the objective from the arguments (and the map's tension range when given).
fn objective(args: &DesignArgs, map: Option<&MapDir>) -> anyhow::Result<Objective> {
    let actuator = args.actuator.apply(&Actuator::default());
    actuator.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    let target = Target::parse(&args.target)?;
    let weights = match &args.weights {
        Some(w) => Weights::parse(w)?,
        None => Weights::default(),
    };
    let (map_lo, map_hi) = map.map_or((1.0, 2.0), |m| (m.summary.tension_range_n[0], m.summary.tension_range_n[1]));
    let mut bounds = Bounds::thesis(
        actuator.radius_mm,
        args.tension_min_n.unwrap_or(map_lo),
        args.tension_max_n.unwrap_or(map_hi),
    );
    if let Some(y) = args.max_offset_mm {
        bounds.max_offset_mm = y;
    }
    if !(args.tolerance_pct.is_finite() && args.tolerance_pct >= 0.0) {
        anyhow::bail!("--tolerance-pct must be a finite number ≥ 0, got {}", args.tolerance_pct);
    }
    if args.starts == 0 {
        anyhow::bail!("--starts must be at least 1");
    }
    Ok(Objective::new(actuator, options, target, weights, bounds)?.with_length_basis(args.basis.length_basis))
}

/// The JSON object of a design (also written as design.json).
pub fn design_json(objective: &Objective, outcome: &DesignOutcome, results: &[ComponentResult]) -> serde_json::Value {
    let e = &outcome.best;
    let unmet: Vec<String> = results.iter().filter(|r| !r.met).map(|r| r.component.key()).collect();
    json!({
        "routing_mm": e.routing_mm,
        "tension_n": e.tension_n,
        "tip_x_mm": e.pose.tip_x_mm,
        "tip_y_mm": e.pose.tip_y_mm,
        "tip_angle_rad": e.pose.tip_angle_rad,
        "base_angle_rad": e.pose.base_angle_rad,
        "length_mm": e.pose.length_mm,
        "a": e.a,
        "target": objective.target.to_json(),
        "weights": serde_json::Value::Object(objective.target.components.iter()
            .map(|(c, _)| (c.key(), json!(objective.weights.get(*c)))).collect()),
        "achieved": serde_json::Value::Object(results.iter().map(|r| (r.component.key(), json!(r.achieved))).collect()),
        "error_pct": serde_json::Value::Object(results.iter().map(|r| (r.component.key(), json!(r.error_pct))).collect()),
        "met": unmet.is_empty(),
        "unmet": unmet,
        "cost": outcome.cost,
        "bounds": objective.bounds,
        "length_basis": objective.length_basis,
        "actuator": objective.actuator,
        "seeds_simulated": outcome.seeds_simulated,
        "starts": outcome.starts,
        "seconds": outcome.seconds,
    })
}

/// Runs `cablemap design`.
pub fn run(args: &DesignArgs) -> anyhow::Result<()> {
    if let Some(dir) = &args.out {
        // Before the search, not after it.
        cablemap::io::check_not_in_run_dir(dir, "--out").map_err(anyhow::Error::msg)?;
    }
    let map = args.map.as_deref().map(MapDir::open).transpose()?;
    let objective = objective(args, map.as_ref())?;
    if let Some(m) = &map {
        m.check_actuator(&objective.actuator)?;
    }
    // With a map: its verdict first (reported, not enforced: the optimiser
    // still returns the closest design), and its nearest designs as seeds.
    let feasibility = match &map {
        Some(m) => Some(design::feasible::check(m, &objective.target, objective.length_basis, &objective.weights, 2 * args.starts)?),
        None => None,
    };
    let seeds: Vec<design::Seed> =
        feasibility.iter().flat_map(|f| f.nearest.iter().map(|d| d.seed())).collect();
    let search = SearchOptions { starts: args.starts, max_evaluations: args.max_evaluations, ..SearchOptions::default() };
    let outcome = optimise::design(&objective, &search, &seeds)?;
    let results = compare(&objective, &outcome.best, args.tolerance_pct);
    let mut value = design_json(&objective, &outcome, &results);
    if let Some(f) = &feasibility {
        value["feasibility"] = serde_json::json!({ "verdict": f.verdict, "reasons": f.reasons, "map": args.map });
    }
    let mut moulds = None;
    if let Some(dir) = &args.out {
        design::export::write_all(dir, &objective, &outcome.best, &value)?;
        if args.moulds {
            let act = &objective.actuator;
            let routing = cablemap::model::Routing::new(&outcome.best.routing_mm, act.length_mm, act.radius_mm)?;
            moulds = Some(super::mould::write_moulds(dir, &routing, act.radius_mm, &args.mould)?);
        }
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{value}")?;
        return Ok(());
    }
    if let Some(f) = &feasibility {
        writeln!(out, "map verdict  {}: {}\n", f.verdict.as_str(), f.reasons.join("; "))?;
    }
    write!(out, "{}", report(&objective, &outcome, &results, args.tolerance_pct))?;
    if let Some(dir) = &args.out {
        writeln!(out, "exported design.json, channel.csv, mould.svg, shape.png to {}", dir.display())?;
    }
    if let (Some(dir), Some(summary)) = (&args.out, &moulds) {
        write!(out, "{}", super::mould::report(dir, summary))?;
    }
    Ok(())
}

/// The text report: a table in the form of the thesis's Table 5.1, the design,
/// and which components (if any) could not be met.
pub fn report(objective: &Objective, outcome: &DesignOutcome, results: &[ComponentResult], tolerance_pct: f64) -> String {
    let mut s = String::new();
    let col = 14;
    s.push_str(&format!("{:<10}", ""));
    for r in results {
        s.push_str(&format!("{:>col$}", format!("{} [{}]", r.component, r.component.unit())));
    }
    s.push('\n');
    let digits = |r: &ComponentResult| if matches!(r.component, design::Component::A(_)) { 6 } else { 4 };
    s.push_str(&format!("{:<10}", "Target"));
    for r in results {
        s.push_str(&format!("{:>col$.*}", digits(r), r.target));
    }
    s.push('\n');
    s.push_str(&format!("{:<10}", "Achieved"));
    for r in results {
        s.push_str(&format!("{:>col$.*}", digits(r), r.achieved));
    }
    s.push('\n');
    s.push_str(&format!("{:<10}", "Error"));
    for r in results {
        let e = r.error_pct.map_or("n/a (t=0)".to_string(), |e| format!("{e:.3}%"));
        s.push_str(&format!("{e:>col$}"));
    }
    s.push('\n');
    let e = &outcome.best;
    s.push('\n');
    // Pasteable into `simulate` and `design`: --routing takes a plain comma list.
    s.push_str(&format!(
        "routing      y0..y4 (mm): --routing {} --tension {:.4}\n",
        e.routing_mm.iter().map(|y| format!("{y:.4}")).collect::<Vec<_>>().join(","),
        e.tension_n
    ));
    s.push_str(&format!(
        "tension      {:.4} N   (bounds {} … {} N)\n",
        e.tension_n, objective.bounds.tension_min_n, objective.bounds.tension_max_n
    ));
    s.push_str(&format!("shape        a = [{}] 1/mm\n", e.a.iter().map(|a| format!("{a:.6}")).collect::<Vec<_>>().join(", ")));
    s.push_str(&format!("basis        a_i {} (--length-basis {})\n", objective.length_basis.describe(), objective.length_basis));
    s.push_str(&format!(
        "objective    {:.3e}   ({} seed designs simulated, {} refined, {:.2} s)\n",
        outcome.cost,
        outcome.seeds_simulated,
        outcome.starts.len(),
        outcome.seconds
    ));
    let unmet: Vec<&ComponentResult> = results.iter().filter(|r| !r.met).collect();
    if unmet.is_empty() {
        s.push_str(&format!("verdict      every component met within {tolerance_pct}%\n"));
    } else {
        s.push_str(&format!(
            "verdict      NOT REACHABLE as asked: {} could not be met within {tolerance_pct}%; the design above is the closest achievable (least eq. 3.17 cost)\n",
            unmet.iter().map(|r| r.component.to_string()).collect::<Vec<_>>().join(", ")
        ));
    }
    s
}
