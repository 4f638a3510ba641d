//! `cablemap design`: routing and tension for a target shape (eq. 3.17).

use super::{ActuatorArgs, LengthBasisArgs};
use anyhow::Context;
use cablemap::design::{self, DesignError, DesignRequest, SearchOptions, Target, Weights};
use cablemap::solver::SolverOptions;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `cablemap design`.
#[derive(Debug, Clone, Args)]
pub struct DesignArgs {
    /// Target, any subset of x, y (tip, mm) and a0, a1, … (curvature coefficients, 1/mm),
    /// e.g. x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015.
    #[arg(long, value_name = "K=V,…", allow_hyphen_values = true, required_unless_present = "targets", conflicts_with = "targets")]
    pub target: Option<String>,
    /// Targets file (TOML: [[target]] tables or a [trajectory]; docs/design.md,
    /// "Several cables"): designs the channels of every cable of --actuator and
    /// one actuation per target.
    #[arg(long, value_name = "FILE.toml")]
    pub targets: Option<PathBuf>,
    /// The actuator to design (the `simulate --actuator` file; a [[cable]]
    /// without y_mm/z_mm has a free channel, `free = ["y", "z"]` frees a given one,
    /// `tension_max_n` bounds its tension) [default with --targets: one cable free in y].
    #[arg(long = "actuator", value_name = "FILE.toml", requires = "targets")]
    pub design_actuator: Option<PathBuf>,
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
    /// Largest |y_i| of a control point, mm [default: 0.999 r: the thesis's −r < y_i < r;
    /// with --moulds at most what the moulds can cast]. A channel of diameter d breaks
    /// the surface beyond r − d/2.
    #[arg(long, value_name = "MM")]
    pub max_offset_mm: Option<f64>,
    #[command(flatten)]
    pub basis: LengthBasisArgs,
    /// Number of seeds refined to convergence (3× as many are explored briefly)
    /// [default: 8; with --targets 4].
    #[arg(long)]
    pub starts: Option<usize>,
    /// Most simulator evaluations per converging start.
    #[arg(long, default_value_t = SearchOptions::default().max_evaluations)]
    pub max_evaluations: usize,
    /// A component counts as met when its error is within this many percent.
    /// [default: 5; with --targets, each target's tolerance_pct, else 5]
    #[arg(long)]
    pub tolerance_pct: Option<f64>,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// Write design.json, channel.csv, mould.svg (1:1, mm; uniform bodies only) and shape.png into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: design within the channel offset the moulds can cast (tube and skin,
    /// see `cablemap mould`) and write the printable moulds too (mould1.stl, mould2.stl,
    /// previews, mould.json), with the mould options below.
    #[arg(long, requires = "out")]
    pub moulds: bool,
    #[command(flatten)]
    pub mould: super::mould::MouldParamArgs,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// The design request the arguments describe.
fn request(args: &DesignArgs) -> anyhow::Result<DesignRequest> {
    Ok(DesignRequest {
        rod: args.actuator.resolve()?,
        actuator_file: args.design_actuator.clone(),
        actuator_rod: args.actuator.overrides(),
        options: args.actuator.solver_options(&SolverOptions::default()),
        target: args.target.as_deref().map(Target::parse).transpose().context("--target")?,
        targets: args.targets.clone(),
        weights: args.weights.as_deref().map(Weights::parse).transpose().context("--weights")?,
        tension_min_n: args.tension_min_n,
        tension_max_n: args.tension_max_n,
        max_offset_mm: args.max_offset_mm,
        length_basis: args.basis.length_basis,
        map: args.map.clone(),
        starts: args.starts,
        max_evaluations: args.max_evaluations,
        tolerance_pct: args.tolerance_pct,
        out: args.out.clone(),
        mould: args.mould.params(),
        write_moulds: args.moulds,
    })
}

/// Runs `cablemap design`.
pub fn run(args: &DesignArgs) -> anyhow::Result<()> {
    let request = request(args)?;
    if let Some(bound) = request.mould_bound_exceeded() {
        // Before the search, on stderr (stdout may be --json).
        eprintln!("note: {bound}");
    }
    let done = design::run(&request).map_err(|e| match e {
        DesignError::ExportDir { .. } => anyhow::Error::new(e).context("--out"),
        DesignError::NoStarts => anyhow::Error::new(e).context("--starts"),
        DesignError::ActuatorFile { .. } => anyhow::Error::new(e).context("--actuator"),
        DesignError::TargetsFile { .. } => anyhow::Error::new(e).context("--targets"),
        DesignError::Tolerance { .. } => anyhow::Error::new(e).context("--tolerance-pct"),
        DesignError::Mould(m) => super::mould::with_flag(m),
        e => anyhow::Error::new(e),
    })?;
    if args.json {
        println!("{}", done.to_json());
    } else {
        print!("{done}");
    }
    Ok(())
}
