//! The sweep spec: what a sweep varies ([`RoutingGrid`]: the thesis's
//! planar grid of one cable's routings, or a grid of several or spatial
//! cables) and what each row stores ([`OutputSpec`]). One [`SweepSpec`]
//! type for every kind; each kind declares itself once, in its `impl
//! RunSpec` ([`planar::PlanarGrid`], `cablemap-sweep/2` runs;
//! [`cables::CablesGrid`], `cablemap-cables/1` runs), and has its own file
//! layout (its TOML tables and the canonical JSON every run records).
//!
//! A spec file's kind follows from its tables: `[[cable]]` tables make a
//! cable sweep, anything else a planar sweep ([`SweepSpec::from_toml`];
//! `job::Job::load` tells a sweep from a study the same way). Every kind
//! keeps the limits every kind shares ([`MAX_CHUNK_ROWS`], [`MAX_ROWS`]).

pub mod cables;
pub mod planar;

pub use super::kind::{MAX_CHUNK_ROWS, MAX_ROWS};
pub use cables::{CableGrid, CablesGrid, PointSweep, ValueGrid, MAX_TENSION_COUNT};
pub use planar::{
    ChunkBytesFix, DisplacementSpec, GridSpec, Ladder, PlanarGrid, TensionSpec, MAX_CHUNK_BYTES, MAX_LEVELS, MAX_ORDER, MAX_STEPS_PER_SPAN,
    MAX_TENSIONS, THESIS_SPEC_TOML,
};

use super::kind::{ChunkLayout, RunKind, RunSpec};
use super::SweepError;
use crate::model::routing::CONTROL_POINTS;
use crate::model::MAX_CABLES;
use crate::shape::LengthBasis;
use crate::solver::spatial::SpatialError;
use crate::solver::SolverOptions;
use arrow::datatypes::SchemaRef;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// A sweep job: the routings it solves and what each row stores.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSpec {
    /// What is swept, and so the kind of the run.
    pub routings: RoutingGrid,
    /// Numerical settings of the solver (the kind's backend reads its own).
    pub solver: SolverOptions,
    /// What each row stores and how rows are grouped into files.
    pub output: OutputSpec,
}

/// What a sweep varies: the kinds of sweep.
#[derive(Debug, Clone, PartialEq)]
pub enum RoutingGrid {
    /// One planar cable over the thesis's grid of routings, through an
    /// actuation ladder.
    Planar(PlanarGrid),
    /// Several or spatial cables, with swept control points and an
    /// actuation grid per cable.
    Cables(CablesGrid),
}

/// What each row stores, and how rows are grouped into chunk files.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputSpec {
    /// Highest Legendre order n stored (a0 … an; a cable sweep stores its
    /// three series to this order).
    pub order: usize,
    /// The length the a_i columns are per unit of: `rest` (the thesis's
    /// basis) or `deformed`.
    pub length_basis: LengthBasis,
    /// Store the centreline of each solve as list columns (planar sweeps).
    pub centreline: bool,
    /// The reach maps' cell size, mm, a cable sweep's map takes by default;
    /// `None` for a planar sweep, whose map sets its own.
    pub cell_mm: Option<f64>,
    /// Routings per chunk file (each chunk is built in memory and written
    /// atomically; a resumed run redoes at most the chunks in progress).
    pub chunk_routings: u32,
}

impl Default for SweepSpec {
    /// The thesis sweep's settings (`jobs/thesis.toml`).
    fn default() -> Self {
        Self { routings: RoutingGrid::Planar(PlanarGrid::default()), solver: SolverOptions::default(), output: planar::Output::default().into() }
    }
}

/// What is wrong with a sweep spec: the section, cable or setting, and what
/// to do.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The TOML text does not parse, has unknown keys or a bad `[[cable]]`.
    #[error("{0}")]
    Toml(#[from] toml::de::Error),
    /// A planar sweep's actuator parameters.
    #[error("[actuator] {0}")]
    Actuator(#[source] crate::model::ParameterError),
    /// Both ladders given.
    #[error("[displacement] give either [tension] or [displacement], not both: the cable is driven by one of them")]
    TensionAndDisplacement,
    /// More steps per span than memory allows.
    #[error(
        "[solver] steps_per_span = {steps} is more than {MAX_STEPS_PER_SPAN}: the solver would need more memory than a machine has, \
         and {resolving} steps already resolve every supported order"
    )]
    StepsPerSpan {
        /// The steps asked for.
        steps: usize,
        /// Steps that resolve the highest supported order.
        resolving: usize,
    },
    /// The solver refuses the settings for this actuator.
    #[error("[solver] {0}")]
    Solver(#[source] crate::solver::SimulateError),
    /// More tensions than a routing may have.
    #[error("[tension] count = {count} is more than {MAX_TENSIONS} tensions per routing")]
    TooManyTensions {
        /// The count asked for.
        count: u32,
    },
    /// No tension, or a lowest tension below 0.
    #[error("[tension] min_n = {min_n} must be a finite tension ≥ 0 N")]
    TensionMin {
        /// The lowest tension, N.
        min_n: f64,
    },
    /// A highest tension below the lowest.
    #[error("[tension] max_n = {max_n} must be finite and ≥ min_n = {min_n}")]
    TensionMax {
        /// The highest tension, N.
        max_n: f64,
        /// The lowest, N.
        min_n: f64,
    },
    /// `count = 0`.
    #[error("[tension] count = 0: at least one tension is needed")]
    NoTensions,
    /// One tension over a range.
    #[error("[tension] count = 1 needs min_n = max_n (or give count ≥ 2)")]
    OneTensionOverARange,
    /// A displacement count out of range.
    #[error("[displacement] count = {count} must be 1 … {MAX_TENSIONS} displacements per routing")]
    DisplacementCount {
        /// The count asked for.
        count: u32,
    },
    /// A smallest displacement below 0.
    #[error("[displacement] min_mm = {min_mm} must be a finite displacement ≥ 0 mm (the length pulled in at the base)")]
    DisplacementMin {
        /// The smallest displacement, mm.
        min_mm: f64,
    },
    /// A largest displacement below the smallest.
    #[error("[displacement] max_mm = {max_mm} must be finite and ≥ min_mm = {min_mm} (equal when count = 1)")]
    DisplacementMax {
        /// The largest displacement, mm.
        max_mm: f64,
        /// The smallest, mm.
        min_mm: f64,
    },
    /// A displacement as long as the rod.
    #[error("{}: a cable cannot be pulled in by its length", DisplacementBeyond { cable: *cable, max_mm: *max_mm, length_mm: *length_mm })]
    DisplacementBeyondRod {
        /// The cable, from 1 (`None`: a planar sweep's one cable).
        cable: Option<usize>,
        /// The largest displacement, mm.
        max_mm: f64,
        /// The rod's length, mm.
        length_mm: f64,
    },
    /// A cable stiffness that is not a stiffness.
    #[error(
        "{} cable_ea_n = {ea_n} must be a finite stiffness > 0 N (leave it out for an inextensible cable)",
        cable.map_or_else(|| "[displacement]".to_string(), |c| format!("cable {c}:"))
    )]
    CableStiffness {
        /// The cable, from 1 (`None`: a planar sweep's one cable).
        cable: Option<usize>,
        /// The stiffness given, N.
        ea_n: f64,
    },
    /// Displacement driving with the method that cannot meet it.
    #[error("{}", DisplacementRk4 { cable: *cable })]
    DisplacementWithRk4 {
        /// The cable, from 1 (`None`: a planar sweep's one cable).
        cable: Option<usize>,
    },
    /// A level count out of range.
    #[error("[grid] levels = {levels} must be between 1 and {MAX_LEVELS}")]
    Levels {
        /// The levels asked for.
        levels: u32,
    },
    /// Levels beyond the body.
    #[error("[grid] extent_r = {extent_r} puts levels beyond ±r (outside the body): use a fraction 0 ≤ extent_r < 1")]
    ExtentR {
        /// The half-width of the levels over r.
        extent_r: f64,
    },
    /// Levels and channel offset together beyond the body.
    #[error("[grid] extent_r = {extent_r} with {} = {offset_mm} puts the channel beyond ±r: reduce one of them", crate::model::effects::CHANNEL_OFFSET.key)]
    ChannelBeyondBody {
        /// The half-width of the levels over r.
        extent_r: f64,
        /// The channel offset, mm.
        offset_mm: f64,
    },
    /// Mirror de-duplication of an actuator that is not mirror-symmetric.
    #[error(
        "[grid] mirror_dedup = true needs a mirror-symmetric actuator ({} = 0 and gravity along the clamp axis): set mirror_dedup = false",
        crate::model::effects::CHANNEL_OFFSET.key
    )]
    MirrorAsymmetric,
    /// An order above the highest stored.
    #[error("[output] order = {order} is above the supported {MAX_ORDER}")]
    Order {
        /// The order asked for.
        order: usize,
    },
    /// An order the planar solver's settings do not resolve.
    #[error("[output] {0}")]
    Resolution(#[source] crate::solver::resolution::OrderError),
    /// An order the 3-D solver's settings do not resolve.
    #[error("{0}")]
    SpatialOrder(#[source] SpatialError),
    /// `chunk_routings = 0`.
    #[error("{}: a chunk needs at least one routing", if *cables { "output.chunk_routings = 0" } else { "[output] chunk_routings = 0" })]
    NoChunkRoutings {
        /// Worded for a cable sweep's spec.
        cables: bool,
    },
    /// More rows per chunk than a chunk may hold (a planar sweep's ladder).
    #[error(
        "[output] chunk_routings = {chunk_routings} × {ladder_table} count = {count} gives {chunk_rows} rows per chunk, more than \
         {MAX_CHUNK_ROWS} (each chunk is built in memory): lower chunk_routings to ≤ {most}"
    )]
    ChunkRows {
        /// Routings per chunk.
        chunk_routings: u32,
        /// The ladder's table, `[tension]` or `[displacement]`.
        ladder_table: &'static str,
        /// Rows per routing.
        count: u32,
        /// Rows per chunk.
        chunk_rows: u64,
        /// The most routings per chunk.
        most: u64,
    },
    /// A chunk would take more memory than a chunk may.
    #[error(
        "[output] chunk_routings = {chunk_routings} × {ladder_table} count = {count} gives {chunk_rows} rows per chunk taking about {} \
         of memory while it is built, more than {} ({}): {fix}",
        crate::io::fmt_bytes(*chunk_bytes),
        crate::io::fmt_bytes(MAX_CHUNK_BYTES),
        planar::centreline_text(*centreline)
    )]
    ChunkBytes {
        /// Routings per chunk.
        chunk_routings: u32,
        /// The ladder's table, `[tension]` or `[displacement]`.
        ladder_table: &'static str,
        /// Rows per routing.
        count: u32,
        /// Rows per chunk.
        chunk_rows: u64,
        /// Memory of a chunk while it is built, bytes.
        chunk_bytes: u64,
        /// With a stored centreline: its points per row and the solver's steps per span.
        centreline: Option<(u64, usize)>,
        /// What to change.
        fix: ChunkBytesFix,
    },
    /// A cable with neither or both of a tension grid and a displacement grid.
    #[error(
        "cable {cable}: give {} of tension_n = {{ min, max, count }} (N) and displacement_mm = {{ min, max, count }} (mm)",
        if *both { "only one" } else { "one" }
    )]
    Actuation {
        /// The cable, from 1.
        cable: usize,
        /// Whether both were given (else neither).
        both: bool,
    },
    /// Too few or too many cables.
    #[error("give 1 to {MAX_CABLES} [[cable]] tables, got {count}")]
    CableCount {
        /// The cables given.
        count: usize,
    },
    /// A cable's grid range.
    #[error("cable {cable}: {key} needs 0 ≤ min ≤ max (finite), got min = {min}, max = {max}")]
    GridRange {
        /// The cable, from 1.
        cable: usize,
        /// `tension_n` or `displacement_mm`.
        key: &'static str,
        /// Its first value.
        min: f64,
        /// Its last value.
        max: f64,
    },
    /// A cable's grid count.
    #[error("cable {cable}: {key}.count = {count} must be 1 … {MAX_TENSION_COUNT}")]
    GridCount {
        /// The cable, from 1.
        cable: usize,
        /// `tension_n` or `displacement_mm`.
        key: &'static str,
        /// The count given.
        count: u32,
    },
    /// An anchor off the rod.
    #[error(
        "cable {cable}: anchor_mm = {} must lie on the rod, in (0, {length_mm}] mm (the rod's length_mm; leave anchor_mm out for the tip)",
        crate::io::fmt_num(*anchor_mm)
    )]
    Anchor {
        /// The cable, from 1.
        cable: usize,
        /// The anchor given, mm.
        anchor_mm: f64,
        /// The rod's length, mm.
        length_mm: f64,
    },
    /// A sweep without finite levels.
    #[error("cable {cable}: a sweep needs at least one finite level in levels_mm")]
    NoLevels {
        /// The cable, from 1.
        cable: usize,
    },
    /// A sweep without control points.
    #[error("cable {cable}: a sweep needs at least one control point in points (0 … {})", CONTROL_POINTS - 1)]
    NoPoints {
        /// The cable, from 1.
        cable: usize,
    },
    /// A control point that does not exist.
    #[error("cable {cable}: control point {point} does not exist (points are 0 … {})", CONTROL_POINTS - 1)]
    NoSuchPoint {
        /// The cable, from 1.
        cable: usize,
        /// The point given.
        point: usize,
    },
    /// A control point swept twice.
    #[error("cable {cable}: {} control point {point} is swept twice", axis.name())]
    SweptTwice {
        /// The cable, from 1.
        cable: usize,
        /// The axis.
        axis: super::schema::Axis,
        /// The point.
        point: usize,
    },
    /// A cell size that is not a length.
    #[error("output.cell_mm = {cell_mm} must be a positive length")]
    CellSize {
        /// The cell size given, mm.
        cell_mm: f64,
    },
    /// More rows per routing than a chunk may hold (a cable sweep's tension combinations).
    #[error(
        "{combinations} tension combinations per routing (the product of the cables' tension_n.count) is more than {MAX_CHUNK_ROWS} \
         rows per chunk: use fewer tensions"
    )]
    TooManyCombinations {
        /// Rows per routing.
        combinations: u64,
    },
    /// More rows per chunk than a chunk may hold (a cable sweep's tension combinations).
    #[error(
        "output.chunk_routings = {chunk_routings} × {combinations} tension combinations gives {chunk_rows} rows per chunk, more than \
         {MAX_CHUNK_ROWS} (each chunk is built in memory): lower chunk_routings to ≤ {most}"
    )]
    CombinationChunkRows {
        /// Routings per chunk.
        chunk_routings: u32,
        /// Rows per routing.
        combinations: u64,
        /// Rows per chunk.
        chunk_rows: u64,
        /// The most routings per chunk.
        most: u64,
    },
    /// A cable sweep's rod parameters.
    #[error("{0}")]
    Rod(#[source] crate::model::ParameterError),
    /// A rod the 3-D solver does not model.
    #[error("[rod] {0}")]
    RodUnsupported(#[source] SpatialError),
    /// The gravity direction.
    #[error("{0}")]
    Gravity(#[source] SpatialError),
}

/// The first part of [`SpecError::DisplacementBeyondRod`]'s sentence.
struct DisplacementBeyond {
    cable: Option<usize>,
    max_mm: f64,
    length_mm: f64,
}

impl std::fmt::Display for DisplacementBeyond {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (max_mm, length_mm) = (self.max_mm, self.length_mm);
        match self.cable {
            None => write!(f, "[displacement] max_mm = {max_mm} is not shorter than the rod ({length_mm} mm)"),
            Some(c) => write!(f, "cable {c}: displacement_mm.max = {max_mm} is not shorter than the rod ({length_mm} mm)"),
        }
    }
}

/// [`SpecError::DisplacementWithRk4`]'s sentence.
struct DisplacementRk4 {
    cable: Option<usize>,
}

impl std::fmt::Display for DisplacementRk4 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.cable {
            None => write!(
                f,
                "[displacement] [solver] method = \"rk4\" does not integrate the cable's path, so it cannot meet a displacement: use the \
                 default collocation"
            ),
            Some(c) => write!(
                f,
                "cable {c} is driven by its displacement: [solver] method = \"rk4\" does not integrate the cables' paths; use the default \
                 collocation"
            ),
        }
    }
}

impl SweepSpec {
    /// The thesis sweep (the built-in default).
    pub fn thesis() -> Self {
        Self::from_toml(THESIS_SPEC_TOML, "built-in thesis spec").expect("jobs/thesis.toml is valid")
    }

    /// Parses and validates a spec of either kind (`[[cable]]` tables: a
    /// cable sweep); `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, SweepError> {
        let bad = |source| SweepError::BadSpec { origin: origin.to_string(), source };
        let has_cables = toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("cable"));
        let spec = if has_cables { cables::from_toml(text) } else { planar::from_toml(text) }.map_err(bad)?;
        spec.validate().map_err(bad)?;
        Ok(spec)
    }

    /// Reads, parses and validates a spec file.
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        let text = crate::io::read_utf8(path).map_err(crate::io::FileError::on("reading spec", path))?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Whether a spec file's text sets nothing (empty, or comments only):
    /// such a spec is the built-in thesis sweep, which the caller should say.
    pub fn is_blank_toml(text: &str) -> bool {
        text.lines().all(|l| {
            let l = l.trim();
            l.is_empty() || l.starts_with('#')
        })
    }

    /// The kind of run the spec makes.
    pub fn kind(&self) -> RunKind {
        match &self.routings {
            RoutingGrid::Planar(_) => PlanarGrid::KIND,
            RoutingGrid::Cables(_) => CablesGrid::KIND,
        }
    }

    /// The planar grid, for a planar sweep.
    pub fn planar(&self) -> Option<&PlanarGrid> {
        match &self.routings {
            RoutingGrid::Planar(p) => Some(p),
            RoutingGrid::Cables(_) => None,
        }
    }

    /// The cables' grid, for a cable sweep.
    pub fn cables(&self) -> Option<&CablesGrid> {
        match &self.routings {
            RoutingGrid::Cables(c) => Some(c),
            RoutingGrid::Planar(_) => None,
        }
    }

    /// Checks every setting; the message names the setting and what to do.
    pub fn validate(&self) -> Result<(), SpecError> {
        match &self.routings {
            RoutingGrid::Planar(p) => p.check(&self.solver, &self.output),
            RoutingGrid::Cables(c) => c.check(&self.solver, &self.output),
        }
    }

    /// Checks the whole sweep's size: more than [`MAX_ROWS`] rows is refused
    /// (a typo like `levels = 99` means 10¹¹ rows) unless `allow_large`,
    /// for a deliberate huge job.
    pub fn check_size(&self, allow_large: bool) -> Result<(), SweepError> {
        let layout = self.layout();
        let rows = layout.routings.saturating_mul(layout.tensions);
        if rows > MAX_ROWS && !allow_large {
            let counted = match &self.routings {
                RoutingGrid::Planar(p) => p.rows_counted(),
                RoutingGrid::Cables(c) => c.rows_counted(),
            };
            return Err(SweepError::TooLarge { rows, routings: layout.routings, per_routing: layout.tensions, counted });
        }
        Ok(())
    }

    /// Routings, rows per routing, chunks.
    pub fn layout(&self) -> ChunkLayout {
        match &self.routings {
            RoutingGrid::Planar(p) => p.layout(&self.output),
            RoutingGrid::Cables(c) => c.layout(&self.output),
        }
    }

    /// The Arrow schema of the rows (docs/schema.md).
    pub fn schema(&self) -> SchemaRef {
        match &self.routings {
            RoutingGrid::Planar(p) => p.schema(&self.output),
            RoutingGrid::Cables(c) => c.schema(&self.output),
        }
    }

    /// Estimated bytes one row takes in memory while its chunk is built
    /// (every copy: solved rows, Arrow batch, encoder buffer).
    pub fn row_bytes(&self) -> u64 {
        match &self.routings {
            RoutingGrid::Planar(p) => p.row_bytes(&self.solver, &self.output),
            RoutingGrid::Cables(c) => c.row_bytes(&self.solver, &self.output),
        }
    }

    /// The spec with every default filled in, as compact JSON in its kind's
    /// layout: what the hash covers and what every output file records.
    pub fn canonical_json(&self) -> String {
        serde_json::to_string(self).expect("spec serialises")
    }

    /// SHA-256 of [`Self::canonical_json`], hex. Two specs with the same
    /// meaning (whatever their formatting) have the same hash.
    pub fn hash_hex(&self) -> String {
        let digest = Sha256::digest(self.canonical_json().as_bytes());
        digest.iter().map(|b| format!("{b:02x}")).collect()
    }

    /// Parses the canonical JSON written by [`Self::canonical_json`].
    pub fn from_canonical_json(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }
}

/// Written in its kind's file layout.
impl Serialize for SweepSpec {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match &self.routings {
            RoutingGrid::Planar(p) => planar::SpecFile::of(p, &self.solver, &self.output).serialize(serializer),
            RoutingGrid::Cables(c) => cables::SpecFile::of(c, &self.solver, &self.output).serialize(serializer),
        }
    }
}

/// Read in the layout of the kind its keys name: `cable` a cable sweep's.
impl<'de> Deserialize<'de> for SweepSpec {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let value = serde_json::Value::deserialize(deserializer)?;
        if value.get("cable").is_some() {
            let file = cables::SpecFile::deserialize(value).map_err(D::Error::custom)?;
            file.into_spec().map_err(D::Error::custom)
        } else {
            Ok(planar::SpecFile::deserialize(value).map_err(D::Error::custom)?.into_spec())
        }
    }
}
