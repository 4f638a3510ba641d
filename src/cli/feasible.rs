//! `cablemap feasible`: the map's verdict on a target (thesis §4.2).

use cablemap::design::feasible_request::FeasibleRequest;
use cablemap::design::{DesignError, Target, Weights};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap feasible`.
#[derive(Debug, Clone, Args)]
pub struct FeasibleArgs {
    /// Feasibility map directory (`cablemap reduce` output).
    #[arg(long, value_name = "MAP_DIR", required_unless_present = "study", conflicts_with = "study")]
    pub map: Option<PathBuf>,
    /// A study directory (`cablemap study` output): the verdict of every variant's map.
    #[arg(long, value_name = "DIR")]
    pub study: Option<PathBuf>,
    /// Target, any subset of x, y (tip, mm) and a0, a1, … (1/mm),
    /// e.g. x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015.
    #[arg(long, value_name = "K=V,…", allow_hyphen_values = true, required_unless_present = "targets", conflicts_with = "targets")]
    pub target: Option<String>,
    /// A targets file of a several-cable design (`design --targets`): with the
    /// map of a cable sweep, whether its sweep reached each target's tip
    /// (voxels, plane cells) and, in the plane, its coefficient ranges and
    /// nearest designs with every cable.
    #[arg(long, value_name = "FILE.toml", requires = "map")]
    pub targets: Option<PathBuf>,
    /// Weights λ for the distance to the nearest designs [defaults x=1,y=1,a0=100,a1=50,a2=25].
    #[arg(long, value_name = "K=V,…")]
    pub weights: Option<String>,
    /// How many nearest simulated designs to list.
    #[arg(long, default_value_t = 5)]
    pub nearest: usize,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub basis: super::LengthBasisArgs,
}

/// Runs `cablemap feasible`.
pub fn run(args: &FeasibleArgs) -> anyhow::Result<()> {
    let request = FeasibleRequest {
        map: args.map.clone(),
        study: args.study.clone(),
        target: args.target.as_deref().map(Target::parse).transpose()?,
        targets: args.targets.clone(),
        weights: args.weights.as_deref().map(Weights::parse).transpose()?,
        length_basis: args.basis.length_basis,
        nearest: args.nearest,
    };
    let report = cablemap::design::feasible_request::run(&request).map_err(|e| match e {
        DesignError::TargetsFile { .. } => anyhow::Error::new(e).context("--targets"),
        e => anyhow::Error::new(e),
    })?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_value(&report)?)?;
    } else {
        write!(out, "{report}")?;
    }
    Ok(())
}
