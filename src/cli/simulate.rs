//! `cablemap simulate`: one actuator, one tension.

use super::{parse_list, ActuatorArgs, LengthBasisArgs};
use cablemap::io::SettingNames;
use cablemap::model::{Cable, LoadDirection};
use cablemap::plot::draw_simulation;
use cablemap::solver::request::{CoefficientRoute, SimulateRequest};
use anyhow::Context;
use clap::Args;
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
    #[arg(long, value_enum, default_value_t = CoefficientsArg::Exact)]
    pub coefficients: CoefficientsArg,
    /// Intervals n_d of the thesis route.
    #[arg(long, default_value_t = cablemap::solver::request::DEFAULT_N_D)]
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

/// Which definition of the curvature coefficients to report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CoefficientsArg {
    /// a_i = (2i+1)/ℓ ∫ P_i dθ, exactly (model-notes §4).
    Exact,
    /// The thesis's discrete route (§3.3, eq. 3.12), from the centreline points.
    Thesis,
}

/// Runs `cablemap simulate`: fills the library's request and prints its report.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    // The outputs are checked before the solve, so a path that cannot be
    // written is named before any work is done.
    for (flag, path) in [("--csv", &args.csv), ("--png", &args.png)] {
        if let Some(path) = path {
            cablemap::io::check_regular_or_new(path).with_context(|| format!("{flag} {}", path.display()))?;
        }
    }
    let mut actuator = args.actuator.actuator(args.spatial_actuator.as_deref())?;
    if !args.cable.is_empty() {
        actuator.cables = args.cable.iter().map(|c| c.parse::<Cable>()).collect::<Result<_, _>>().context("--cable")?;
    }
    if let Some(text) = &args.gravity_direction {
        let g = parse_list(text, "--gravity-direction")?;
        let g: [f64; 3] = g.try_into().map_err(|g: Vec<f64>| anyhow::anyhow!("--gravity-direction needs 3 numbers X,Y,Z, got {}", g.len()))?;
        actuator.gravity_direction = Some(g);
    }
    let request = SimulateRequest {
        actuator,
        routing_mm: args.routing.as_deref().map(|r| parse_list(r, "--routing")).transpose()?,
        tension_n: args.tension_n,
        displacement_mm: args.displacement_mm,
        cable_ea_n: args.cable_ea_n,
        order: args.order,
        length_basis: args.basis.length_basis,
        direction: Some(if args.direction == "unload" { LoadDirection::Unload } else { LoadDirection::Load }),
        dwell_s: args.dwell_s,
        solver: args.actuator.solver_settings(),
        coefficients: match args.coefficients {
            CoefficientsArg::Exact => CoefficientRoute::Exact,
            CoefficientsArg::Thesis => CoefficientRoute::Thesis,
        },
        n_d: args.n_d,
    };
    let report = match request.run(SettingNames::Flags) {
        Ok(report) => report,
        Err(e) => {
            // With --json, a failed solve is a record too: its status (the
            // one a sweep stores for it, e.g. `non_finite`, `unresolved`)
            // and the message, on stdout; the error still goes to stderr
            // with a non-zero exit.
            if let (Some(failure), true) = (e.solve_error(), args.json) {
                if let Some(status) = failure.failure_status() {
                    let record = serde_json::json!({ "status": status, "error": failure.to_string() });
                    writeln!(std::io::stdout().lock(), "{record}")?;
                }
            }
            return Err(e.into());
        }
    };
    if let Some(path) = &args.csv {
        report.write_centreline_csv(path).with_context(|| format!("writing centreline CSV {}", path.display()))?;
    }
    if let Some(path) = &args.png {
        draw_simulation(path, &report)?;
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", report.to_json())?;
    } else {
        write!(out, "{report}")?;
    }
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
