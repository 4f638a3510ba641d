//! `cablemap simulate`: one actuator, one tension.

use super::{parse_list, ActuatorArgs, LengthBasisArgs};
use cablemap::solver::record::{self, SimulationRecord};
use cablemap::model::{Actuation, Actuator, Cable, LoadDirection, Routing};
use cablemap::solver::{simulate_actuator, simulate_held, Backend, Given, Hold, SimulateError, SolverOptions};
use cablemap::plot::{draw_bodies, BodyDrawing};
use anyhow::Context;
use clap::Args;
use plotters::style::full_palette::BLUE_800;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap simulate`.
#[derive(Debug, Clone, Args)]
pub struct SimulateArgs {
    /// Routing control points y0,y1,y2,y3,y4 in mm (each |y_i| < r): one planar cable.
    #[arg(long, value_name = "Y0,Y1,Y2,Y3,Y4", allow_hyphen_values = true, conflicts_with_all = ["cable"])]
    pub routing: Option<String>,
    /// Cable tension τ, N (≥ 0), with --routing (`--tension` is the old name).
    #[arg(long = "tension-n", alias = "tension", value_name = "N", allow_hyphen_values = true, requires = "routing")]
    pub tension_n: Option<f64>,
    /// Cable displacement Δℓ, mm (≥ 0), with --routing, in place of
    /// --tension-n: the length pulled in at the base (a motor's position);
    /// the tension is found. A cable longer than its path is slack.
    #[arg(long = "displacement-mm", value_name = "MM", allow_hyphen_values = true, requires = "routing", conflicts_with = "tension_n")]
    pub displacement_mm: Option<f64>,
    /// The cable's axial stiffness EA, N, with --routing (its stretch under
    /// tension is part of its displacement) [default: inextensible].
    #[arg(long = "cable-ea-n", value_name = "N", allow_hyphen_values = true, requires = "routing")]
    pub cable_ea_n: Option<f64>,
    /// One cable of several or spatial cables, repeatable:
    /// "y=Y0,..,Y4 z=Z0,..,Z4 tension=T" (mm, N; z= may be left out for a
    /// planar cable; anchor=S knots it at s = S mm). Solved by the 3-D solver.
    #[arg(long, value_name = "\"y=.. z=.. tension=T\"", allow_hyphen_values = true)]
    pub cable: Vec<String>,
    /// A whole actuator (rod, torsion, gravity direction, cables) as TOML
    /// (docs/schema.md); --cable replaces its cables, rod flags override it.
    #[arg(long = "actuator", value_name = "FILE.toml")]
    pub spatial_actuator: Option<PathBuf>,
    /// Gravity along a global direction X,Y,Z (normalised; the weight per
    /// length still comes from the density). Uses the 3-D solver.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub gravity_direction: Option<String>,
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
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
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
    if !args.cable.is_empty() || args.spatial_actuator.is_some() || args.gravity_direction.is_some() {
        return run_spatial(args);
    }
    let (Some(routing_text), Some(actuation)) = (&args.routing, planar_actuation(args)?) else {
        anyhow::bail!(
            "say what to simulate: --routing Y0,..,Y4 with --tension-n T or --displacement-mm D (one planar cable), --cable \"y=.. z=.. tension=T\" (repeatable), or --actuator FILE.toml"
        );
    };
    let actuator = args.actuator.resolve()?;
    actuator.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    anyhow::ensure!(
        args.n_d <= MAX_N_D,
        "--n-d {} is more than {MAX_N_D} intervals (the thesis uses 40; the solver has only 2 × steps-per-span nodes to resample)",
        args.n_d
    );
    let y = parse_list(routing_text, "--routing")?;
    let routing = Routing::for_actuator(&y, &actuator).context("--routing")?;
    // The one check: a setting the planar backend of --method does not read is refused.
    Backend::check_planar(&actuator, &options, given_settings(args))?;
    let direction = if args.direction == "unload" { LoadDirection::Unload } else { LoadDirection::Load };
    let hold = Hold { direction, dwell_s: args.dwell_s.unwrap_or(actuator.effects.creep_hold_s) };
    // The thesis route computes its own coefficients from the centreline
    // (its order is limited by n_d, checked there), so the solver's exact
    // ones are only needed up to what the steps resolve.
    let exact_order = match args.coefficients {
        CoefficientRoute::Exact => args.order,
        CoefficientRoute::Thesis => args.order.min(cablemap::solver::resolution::max_order(&options)),
    };
    let basis = args.basis.length_basis;
    let mut sim = match actuation {
        Actuation::Tension(t) if args.cable_ea_n.is_none() => {
            let solved = simulate_held(&actuator, &options, &routing, t, exact_order, basis, hold);
            if let (Err(SimulateError::Solve(failure)), true) = (&solved, args.json) {
                print_failure_json(failure.status(), &failure.to_string())?;
            }
            solved.with_context(|| format!("simulating routing {y:?} at {}", describe(actuation)))?
        }
        // A displacement, or a stiffness: the actuator's one cable, checked
        // and solved as every actuator's (the same planar backend).
        _ => {
            let one = Actuator::with_cables(actuator.clone(), vec![routing_cable(actuation, routing.control_points_mm().0, args.cable_ea_n)]);
            let solved = simulate_actuator(&one, &options, given_settings(args), Some(hold), exact_order, basis);
            if let (Err(e), true) = (&solved, args.json) {
                if let Some(status) = e.failure_status() {
                    print_failure_json(status, &e.to_string())?;
                }
            }
            solved.with_context(|| format!("simulating routing {y:?} at {}", describe(actuation)))?
        }
    };
    if args.coefficients == CoefficientRoute::Thesis {
        let points: Vec<[f64; 2]> = sim.centreline.iter().map(|c| [c.x_mm, c.y_mm]).collect();
        sim.a_bend_z = cablemap::shape::thesis_coefficients(&points, args.order, args.n_d)
            .context("thesis coefficient route")?
            .in_basis(basis, actuator.length_mm)
            .a;
    }
    if let Some(path) = &args.csv {
        record::write_planar_centreline_csv(path, &sim).with_context(|| format!("writing centreline CSV {}", path.display()))?;
    }
    if let Some(path) = &args.png {
        let title = format!("routing [{}] mm, tension {:.3} N", fmt_list(&y), sim.pose.tension_n());
        let drawing = BodyDrawing::of_body(&sim, &actuator, "body (outline at ±r)".into(), BLUE_800);
        draw_bodies(path, &title, &[drawing], &[])?;
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", SimulationRecord::from(&sim).to_json_line())?;
        report_png(args);
        return Ok(());
    }
    write!(out, "{}", record::planar_report(&sim))?;
    drop(out);
    report_png(args);
    Ok(())
}

/// Names the picture `--png` wrote, after the results: on stdout with the
/// text report (as `design` names its exports), on stderr with `--json`,
/// whose stdout stays the JSON object alone.
fn report_png(args: &SimulateArgs) {
    if let Some(path) = &args.png {
        let line = format!("wrote {} (the deformed body, cable and tip; axes in mm)", path.display());
        if args.json {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    }
}

/// An actuator given by its cables (`--cable`, `--actuator`, or a routing
/// with spatial flags): solved by the backend that serves it
/// ([`cablemap::solver::Backend::serving`]: the planar fast path for one
/// in-plane cable with gravity in the plane, else the 3-D solver) and
/// reported in the actuator's terms (the spatial record).
fn run_spatial(args: &SimulateArgs) -> anyhow::Result<()> {
    use cablemap::solver::Hold;
    // The rod: the spatial file's [rod], else an --actuator-file, else the
    // thesis's; rod flags override either.
    let mut spatial = match &args.spatial_actuator {
        Some(path) => {
            anyhow::ensure!(
                args.actuator.actuator_file.is_none(),
                "give the rod either in --actuator FILE's [rod] table or by --actuator-file, not both"
            );
            let mut spatial = Actuator::read(path)?;
            spatial.rod = args.actuator.apply(&spatial.rod);
            spatial
        }
        None => Actuator::with_cables(args.actuator.resolve()?, Vec::new()),
    };
    if !args.cable.is_empty() {
        spatial.cables = args.cable.iter().map(|c| c.parse::<Cable>()).collect::<Result<_, _>>().context("--cable")?;
    }
    if let (Some(routing), Some(actuation)) = (&args.routing, planar_actuation(args)?) {
        let y = parse_list(routing, "--routing")?;
        let y: [f64; 5] = y.try_into().map_err(|y: Vec<f64>| anyhow::anyhow!("--routing: a routing needs exactly 5 control points y0..y4 (mm), got {}", y.len()))?;
        spatial.cables = vec![routing_cable(actuation, y, args.cable_ea_n)];
    }
    anyhow::ensure!(
        !spatial.cables.is_empty(),
        "no cables: give --cable \"y=.. z=.. tension=T\" (repeatable), --routing/--tension, or [[cable]] tables in --actuator"
    );
    if let Some(text) = &args.gravity_direction {
        let g = parse_list(text, "--gravity-direction")?;
        let g: [f64; 3] = g.try_into().map_err(|g: Vec<f64>| anyhow::anyhow!("--gravity-direction needs 3 numbers X,Y,Z, got {}", g.len()))?;
        spatial.gravity_direction = Some(g);
    }
    anyhow::ensure!(
        args.n_d <= MAX_N_D,
        "--n-d {} is more than {MAX_N_D} intervals (the thesis uses 40; the solver has only 2 × steps-per-span nodes to resample)",
        args.n_d
    );
    let options = args.actuator.solver_options(&SolverOptions::default());
    let thesis = args.coefficients == CoefficientRoute::Thesis;
    let given = given_settings(args);
    // As the planar `--routing` path holds it.
    let direction = if args.direction == "unload" { LoadDirection::Unload } else { LoadDirection::Load };
    let hold = Hold { direction, dwell_s: args.dwell_s.unwrap_or(spatial.rod.effects.creep_hold_s) };
    let order = if thesis { args.order.min(cablemap::solver::resolution::max_order(&options)) } else { args.order };
    let basis = args.basis.length_basis;
    let solved = simulate_actuator(&spatial, &options, given, Some(hold), order, basis);
    if let (Err(e), true) = (&solved, args.json) {
        if let Some(status) = e.failure_status() {
            print_failure_json(status, &e.to_string())?;
        }
    }
    let mut sim = solved?;
    // The thesis route needs a planar centreline: the one check refused it otherwise.
    if thesis && sim.backend != Backend::SpatialCollocation {
        let points: Vec<[f64; 2]> = sim.centreline.iter().map(|c| [c.x_mm, c.y_mm]).collect();
        sim.a_bend_z = cablemap::shape::thesis_coefficients(&points, args.order, args.n_d)
            .context("thesis coefficient route")?
            .in_basis(basis, spatial.rod.length_mm)
            .a;
        sim.a_bend_y = vec![0.0; sim.a_bend_z.len()];
        sim.a_twist = vec![0.0; sim.a_bend_z.len()];
    }
    if let Some(path) = &args.csv {
        record::write_actuator_centreline_csv(path, &sim).with_context(|| format!("writing centreline CSV {}", path.display()))?;
    }
    if let Some(path) = &args.png {
        let tensions: Vec<String> = spatial.cables.iter().map(|c| format!("{:.3}", c.tension_n)).collect();
        let title = format!("{} cable(s), tensions [{}] N", spatial.cables.len(), tensions.join(", "));
        cablemap::plot::spatial::draw_spatial(path, &title, &sim)?;
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", record::simulation_json(&sim))?;
    } else {
        write!(out, "{}", record::report(&sim))?;
    }
    drop(out);
    report_png(args);
    Ok(())
}

/// `--routing`'s one cable on routing `y_mm`, driven by `actuation`, with stiffness `cable_ea_n`.
fn routing_cable(actuation: Actuation, y_mm: [f64; 5], cable_ea_n: Option<f64>) -> Cable {
    Cable { cable_ea_n, ..Cable::planar(y_mm, 0.0) }.actuated(actuation)
}

/// An actuation in words, for messages.
fn describe(actuation: Actuation) -> String {
    match actuation {
        Actuation::Tension(t) => format!("{} N", cablemap::io::fmt_num(t)),
        Actuation::Displacement(d) => format!("a displacement of {} mm", cablemap::io::fmt_num(d)),
    }
}

/// `--routing`'s actuation: --tension-n or --displacement-mm (clap refuses
/// both); `None` when neither is given.
fn planar_actuation(args: &SimulateArgs) -> anyhow::Result<Option<Actuation>> {
    match (args.tension_n, args.displacement_mm) {
        (Some(t), None) => Ok(Some(Actuation::Tension(t))),
        (None, Some(d)) => Ok(Some(Actuation::Displacement(d))),
        (None, None) if args.routing.is_some() => {
            anyhow::bail!("--routing needs its actuation: --tension-n T (N) or --displacement-mm D (mm, the length pulled in at the base)")
        }
        _ => Ok(None),
    }
}

/// The settings given by flags rather than left at their defaults: the
/// backend serving the request must read each ([`Backend::check`]).
fn given_settings(args: &SimulateArgs) -> Given {
    Given {
        method: args.actuator.method.is_some(),
        nodes_per_span: args.actuator.nodes_per_span.is_some(),
        steps_per_span: args.actuator.steps_per_span.is_some(),
        hold: args.direction != "load" || args.dwell_s.is_some(),
        thesis_coefficients: args.coefficients == CoefficientRoute::Thesis,
    }
}

/// With `--json`, a failed solve is a record too: its status (the one a
/// sweep stores for it, e.g. `non_finite`, `unresolved`) and the message,
/// on stdout; the error itself still goes to stderr with a non-zero exit.
fn print_failure_json(status: &str, message: &str) -> anyhow::Result<()> {
    let record = serde_json::json!({ "status": status, "error": message });
    writeln!(std::io::stdout().lock(), "{record}")?;
    Ok(())
}

fn fmt_list(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ")
}
