//! `cablemap simulate`: one actuator, one tension.

use super::{parse_list, ActuatorArgs, LengthBasisArgs};
use cablemap::model::record::{self, SimulationRecord};
use cablemap::model::{simulate_held, Hold, LoadDirection, Routing, SolverOptions};
use cablemap::plot::{draw_bodies, BodyDrawing};
use anyhow::Context;
use clap::Args;
use plotters::style::full_palette::BLUE_800;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap simulate`.
#[derive(Debug, Clone, Args)]
pub struct SimulateArgs {
    /// Routing control points y0,y1,y2,y3,y4 in mm (each |y_i| < r).
    #[arg(long, value_name = "Y0,Y1,Y2,Y3,Y4", allow_hyphen_values = true)]
    pub routing: String,
    /// Cable tension, N (≥ 0).
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub tension: f64,
    /// Highest Legendre order n of the curvature coefficients a_0..a_n.
    #[arg(long, default_value_t = 3)]
    pub order: usize,
    /// How a_i are computed: `exact` (the definition, from the solver's
    /// tangent angles) or `thesis` (thesis §3.3: tangent angles resampled at
    /// --n-d equal arc-length intervals, discrete Legendre vectors, eq. 3.12).
    #[arg(long, value_enum, default_value_t = CoefficientRoute::Exact)]
    pub coefficients: CoefficientRoute,
    /// Intervals n_d of the thesis route.
    #[arg(long, default_value_t = 40)]
    pub n_d: usize,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// Write the centreline and cable path as CSV.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Draw the deformed body, channel and tip as PNG.
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// Direction of the last tension change (sign of friction): load or unload.
    #[arg(long, value_name = "DIR", default_value = "load", value_parser = ["load", "unload"])]
    pub direction: String,
    /// Seconds held at the tension before the reading, from a rod with no
    /// load history (creep) [default: --creep-hold-s, else 0].
    #[arg(long, value_name = "S")]
    pub dwell_s: Option<f64>,
    #[command(flatten)]
    pub basis: LengthBasisArgs,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Most resampling intervals of the thesis route.
pub const MAX_N_D: usize = 100_000;

/// Which definition of the curvature coefficients to report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CoefficientRoute {
    /// a_i = (2i+1)/ℓ ∫ P_i dθ, exactly (model-notes §4).
    Exact,
    /// The thesis's discrete route (§3.3, eq. 3.12), from the centreline points.
    Thesis,
}

/// Runs `cablemap simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let actuator = args.actuator.resolve(None)?;
    actuator.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    anyhow::ensure!(
        args.n_d <= MAX_N_D,
        "--n-d {} is more than {MAX_N_D} intervals (the thesis uses 40; the solver has only 2 × steps-per-span nodes to resample)",
        args.n_d
    );
    let y = parse_list(&args.routing, "--routing")?;
    let routing = Routing::for_actuator(&y, &actuator).context("--routing")?;
    let direction = if args.direction == "unload" { LoadDirection::Unload } else { LoadDirection::Load };
    let hold = Hold { direction, dwell_s: args.dwell_s.unwrap_or(actuator.effects.creep_hold_s) };
    // The thesis route computes its own coefficients from the centreline
    // (its order is limited by n_d, checked there), so the solver's exact
    // ones are only needed up to what the steps resolve.
    let exact_order = match args.coefficients {
        CoefficientRoute::Exact => args.order,
        CoefficientRoute::Thesis => args.order.min(cablemap::model::resolution::max_order(&options)),
    };
    let basis = args.basis.length_basis;
    let mut sim = simulate_held(&actuator, &options, &routing, args.tension, exact_order, basis, hold)
        .with_context(|| format!("simulating routing {y:?} at {} N", args.tension))?;
    if args.coefficients == CoefficientRoute::Thesis {
        let points: Vec<[f64; 2]> = sim.centreline.iter().map(|c| [c.x_mm, c.y_mm]).collect();
        sim.a = cablemap::shape::thesis_coefficients(&points, args.order, args.n_d)
            .context("thesis coefficient route")?
            .in_basis(basis, actuator.length_mm)
            .a;
    }
    if let Some(path) = &args.csv {
        record::write_centreline_csv(path, &sim).with_context(|| format!("writing centreline CSV {}", path.display()))?;
    }
    if let Some(path) = &args.png {
        let title = format!("routing [{}] mm, tension {:.3} N", fmt_list(&y), args.tension);
        let drawing = BodyDrawing::of_body(&sim, &actuator, "body (outline at ±r), cable in red".into(), BLUE_800);
        draw_bodies(path, &title, &[drawing], &[])?;
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", SimulationRecord::from(&sim).to_json_line())?;
        return Ok(());
    }
    let p = &sim.pose;
    writeln!(out, "routing        [{}] mm", fmt_list(&y))?;
    writeln!(out, "tension        {:.6} N   (gravity {})", p.tension_n, if actuator.gravity.enabled { "on" } else { "off" })?;
    writeln!(out, "tip            x = {:.6} mm, y = {:.6} mm", p.tip_x_mm, p.tip_y_mm)?;
    writeln!(out, "tip angle      {:.8} rad ({:.4}°)", p.tip_angle_rad, p.tip_angle_rad.to_degrees())?;
    writeln!(out, "base angle     {:.8} rad ({:.4}°)", p.base_angle_rad, p.base_angle_rad.to_degrees())?;
    writeln!(out, "length ℓ       {:.6} mm", p.length_mm)?;
    writeln!(out, "coefficients   a_i {}", basis.describe())?;
    for (i, a) in sim.a.iter().enumerate() {
        writeln!(out, "a_{i:<12} {a:.8e} mm^-1")?;
    }
    writeln!(out, "iterations     {} integration pass(es)", p.iterations)?;
    Ok(())
}

fn fmt_list(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ")
}
