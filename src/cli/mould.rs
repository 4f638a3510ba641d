//! `cablemap mould`: printable moulds (binary STL) for a routing.

use super::{parse_list, ActuatorArgs};
use cablemap::model::{Rod, Routing};
use cablemap::mould::{MouldError, MouldParams, MouldSet};
use anyhow::Context;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Mould parameters shared by `mould` and `design --moulds`.
#[derive(Debug, Clone, Args)]
pub struct MouldParamArgs {
    /// Wall and floor thickness around the cavity, mm.
    #[arg(long, value_name = "MM", allow_hyphen_values = true, default_value_t = MouldParams::default().wall_mm)]
    pub wall_mm: f64,
    /// Outer diameter of the PTFE tube that forms the channel, mm (thesis §5.2: 1).
    #[arg(long, value_name = "MM", allow_hyphen_values = true, default_value_t = MouldParams::default().tube_diameter_mm)]
    pub tube_diameter_mm: f64,
    /// Play between mating printed features (pins in holes, tube notches), mm.
    #[arg(long, value_name = "MM", allow_hyphen_values = true, default_value_t = MouldParams::default().clearance_mm)]
    pub clearance_mm: f64,
    /// Clamp block: body cast before the clamp face (s < 0) for the clamp to hold, mm; 0 for none.
    #[arg(long, value_name = "MM", allow_hyphen_values = true, default_value_t = MouldParams::default().clamp_mm)]
    pub clamp_mm: f64,
    /// Least silicone between the channel and the body surface, mm.
    #[arg(long, value_name = "MM", allow_hyphen_values = true, default_value_t = MouldParams::default().min_skin_mm)]
    pub min_skin_mm: f64,
}

impl MouldParamArgs {
    /// The parameters.
    pub fn params(&self) -> MouldParams {
        MouldParams {
            wall_mm: self.wall_mm,
            tube_diameter_mm: self.tube_diameter_mm,
            clearance_mm: self.clearance_mm,
            clamp_mm: self.clamp_mm,
            min_skin_mm: self.min_skin_mm,
            ..MouldParams::default()
        }
    }
}

/// Arguments of `cablemap mould`.
#[derive(Debug, Clone, Args)]
pub struct MouldArgs {
    /// Control-point offsets y0..y4, mm, e.g. 1,-2,0.5,0,3.
    #[arg(long, value_name = "Y0,..,Y4", allow_hyphen_values = true, conflicts_with = "design", required_unless_present = "design")]
    pub routing: Option<String>,
    /// A design.json written by `cablemap design --out`: its routing and actuator.
    #[arg(long, value_name = "FILE")]
    pub design: Option<PathBuf>,
    /// Directory for mould1.stl, mould2.stl, mould1.png, mould2.png, channel.csv, mould.json: new,
    /// empty or an earlier mould directory, written as a whole (a killed run leaves nothing partial).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Print mould.json instead of a report.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub mould: MouldParamArgs,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// A mould error, with the flag of the parameter it names.
pub fn with_flag(e: MouldError) -> anyhow::Error {
    match &e {
        MouldError::BadParameter { name, .. } if *name != "station_step_mm" => {
            let flag = format!("--{}", name.replace('_', "-"));
            anyhow::Error::new(e).context(flag)
        }
        _ => anyhow::Error::new(e),
    }
}

/// Runs `cablemap mould`.
pub fn run(args: &MouldArgs) -> anyhow::Result<()> {
    let (ys, base) = match (&args.routing, &args.design) {
        (Some(r), _) => (parse_list(r, "--routing")?, Rod::default()),
        (None, Some(d)) => {
            let file = cablemap::design::record::read_design_file(d).context("--design")?;
            (file.routing_mm, file.actuator)
        }
        (None, None) => anyhow::bail!("give --routing y0,..,y4 or --design design.json"),
    };
    let actuator = args.actuator.apply(&base);
    actuator.validate()?;
    cablemap::mould::check_uniform_body(&actuator)?;
    let routing = Routing::new(&ys, actuator.length_mm, actuator.radius_mm)?;
    let summary = MouldSet::new(&routing, actuator.radius_mm, &args.mould.params())
        .and_then(|set| set.write_dir(&args.out))
        .map_err(with_flag)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string(&summary)?)?;
    } else {
        write!(out, "{}", summary.report(&args.out))?;
    }
    Ok(())
}
