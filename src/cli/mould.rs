//! `cablemap mould`: printable moulds (binary STL) for a routing or any actuator.

use super::{parse_list, ActuatorArgs};
use cablemap::model::{Actuator, Cable, Rod, Routing};
use cablemap::mould::{MouldError, MouldOptions, MouldParams, MouldSettings, MouldStyle};
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
        MouldSettings {
            wall_mm: Some(self.wall_mm),
            tube_diameter_mm: Some(self.tube_diameter_mm),
            clearance_mm: Some(self.clearance_mm),
            clamp_mm: Some(self.clamp_mm),
            min_skin_mm: Some(self.min_skin_mm),
        }
        .params()
    }
}

/// Which moulds `mould` makes (`--style`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum StyleArg {
    /// Two-part moulds for channels all in the bending plane on a uniform body, else lumens.
    #[default]
    Auto,
    /// The thesis's tray, lid (a protrusion per channel) and cover.
    TwoPart,
    /// A printable body with a lumen per channel and the lumens' castable cores.
    Lumens,
}

impl StyleArg {
    /// The library's style.
    pub fn style(self) -> MouldStyle {
        match self {
            StyleArg::Auto => MouldStyle::Auto,
            StyleArg::TwoPart => MouldStyle::TwoPart,
            StyleArg::Lumens => MouldStyle::Lumens,
        }
    }
}

/// Arguments of `cablemap mould`.
#[derive(Debug, Clone, Args)]
pub struct MouldArgs {
    /// Control-point offsets y0..y4, mm, e.g. 1,-2,0.5,0,3.
    #[arg(long, value_name = "Y0,..,Y4", allow_hyphen_values = true, conflicts_with_all = ["design", "spatial_actuator", "cable"], required_unless_present_any = ["design", "spatial_actuator", "cable"])]
    pub routing: Option<String>,
    /// A design.json written by `cablemap design --out`: its routing and actuator.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["spatial_actuator", "cable"])]
    pub design: Option<PathBuf>,
    /// A whole actuator as TOML (the file of `simulate --actuator`: [rod] and 1–8 [[cable]]
    /// tables): moulds for every cable's channel, in the style --style picks.
    #[arg(long = "actuator", value_name = "FILE.toml")]
    pub spatial_actuator: Option<PathBuf>,
    /// A cable "y=Y0,..,Y4 [z=Z0,..,Z4] tension=T" (repeatable; replaces --actuator's cables).
    #[arg(long, value_name = "SPEC")]
    pub cable: Vec<String>,
    /// Two-part moulds (planar channels on a uniform body), a printed body with lumens and its
    /// cores, or auto (two-part when the channels allow it).
    #[arg(long, value_enum, default_value_t = StyleArg::Auto)]
    pub style: StyleArg,
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
        // station_step_mm and channels have no flag.
        MouldError::BadParameter { name, .. } if !matches!(*name, "station_step_mm" | "channels") => {
            let flag = format!("--{}", name.replace('_', "-"));
            anyhow::Error::new(e).context(flag)
        }
        _ => anyhow::Error::new(e),
    }
}

/// Runs `cablemap mould`: one library request ([`cablemap::mould::build`])
/// for every cable's channel; a routing is the actuator with that one
/// planar cable.
pub fn run(args: &MouldArgs) -> anyhow::Result<()> {
    let actuator = moulded_actuator(args)?;
    let options = MouldOptions { params: args.mould.params(), style: args.style.style() };
    let report = cablemap::mould::build(&actuator, &options).and_then(|m| m.write_dir(&args.out)).map_err(with_flag)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_string(&report)?)?;
    } else {
        write!(out, "{}", report.report(&args.out))?;
    }
    debug_assert!(report.style() != MouldStyle::Auto);
    Ok(())
}

/// The actuator whose channels are moulded, as the flags give it: a routing
/// (`--routing`, or a design's) is one planar cable on the rod of the flags
/// (or the design's), checked like any cable's channel.
fn moulded_actuator(args: &MouldArgs) -> anyhow::Result<Actuator> {
    let (ys, base) = match (&args.routing, &args.design) {
        (Some(r), _) => (parse_list(r, "--routing")?, Rod::default()),
        (None, Some(d)) => {
            let file = cablemap::design::record::read_design_file(d).context("--design")?;
            (file.routing_mm, file.actuator)
        }
        (None, None) => {
            let mut actuator = args.actuator.actuator(args.spatial_actuator.as_deref())?;
            if !args.cable.is_empty() {
                actuator.cables = args.cable.iter().map(|c| c.parse::<Cable>()).collect::<Result<_, _>>().context("--cable")?;
            }
            return Ok(actuator);
        }
    };
    let rod = args.actuator.apply(&base);
    rod.validate()?;
    let routing = Routing::new(&ys, rod.length_mm, rod.radius_mm)?;
    Ok(Actuator::with_cables(rod, vec![Cable::planar(routing.control_points_mm().0, 0.0)]))
}
