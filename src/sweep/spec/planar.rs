//! The planar single-cable sweep spec (`cablemap-sweep/2` runs): a TOML
//! file naming the actuator, the solver settings, the routing grid, the
//! tension ladder and what to store. Unknown fields are rejected so that a
//! typo never silently falls back to a default. Its kind ([`RunSpec`]): one
//! [`Simulator`] per worker, each routing solved through the rising tension
//! ladder ([`solve::planar_routing`]).
//!
//! ```toml
//! [actuator]            # model::Rod; omitted fields keep the thesis values
//! [actuator.gravity]
//! enabled = true
//! [solver]              # crate::solver::SolverOptions
//! steps_per_span = 24
//! [grid]
//! levels = 9            # levels per control point
//! extent_r = 0.8        # levels evenly spaced from −0.8 r to +0.8 r
//! mirror_dedup = true   # keep one routing of each mirror pair
//! [tension]
//! min_n = 1.0
//! max_n = 2.0
//! count = 21
//! # or, driving the cable by its displacement (a motor's position):
//! # [displacement]
//! # min_mm = 0.0
//! # max_mm = 4.0
//! # count = 9
//! # cable_ea_n = 2000.0   # optional: the cable's stiffness (default inextensible)
//! [output]
//! order = 3             # store a0 … a3
//! length_basis = "rest" # a_i per unit rest length (thesis); or "deformed"
//! centreline = false    # store centreline_x_mm / centreline_y_mm lists
//! chunk_routings = 256  # routings per Parquet chunk file
//! ```

use crate::model::{Rod, Routing};
use crate::solver::{Simulator, SolverOptions};
use crate::shape::LengthBasis;
use crate::sweep::enumerate::SweepPlan;
use crate::sweep::kind::{ChunkLayout, InvalidSpec, RowsCounted, RunSpec, MAX_CHUNK_ROWS, MAX_ROWS};
use crate::sweep::schema::{arrow_schema, build_batch, SolvedRouting};
use crate::sweep::solve::{self, Stored};
use crate::sweep::SweepError;
use crate::sweep::spec::ValueGrid;
use arrow::datatypes::SchemaRef;
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// The thesis sweep (thesis Ch. 4, model-notes §5): `jobs/thesis.toml`,
/// built into the binary as the default spec.
pub const THESIS_SPEC_TOML: &str = include_str!("../../../jobs/thesis.toml");

/// Most levels per control point (the grid has levels⁵ routings).
pub const MAX_LEVELS: u32 = 99;
/// Highest Legendre order stored.
pub const MAX_ORDER: usize = 12;
/// Most tensions per routing.
pub const MAX_TENSIONS: u32 = 100_000;
/// Most RK4 steps per span (memory grows with it; 24 is the default).
pub const MAX_STEPS_PER_SPAN: usize = 100_000;
/// Most memory one chunk may take while it is built (its solved rows, the
/// Arrow batch and the Parquet encoder's buffers; [`SweepSpec::row_bytes`]).
/// Chunks are built one per thread at once, so this bounds the sweep's
/// memory per thread whatever the centreline's resolution. Rows without a
/// centreline reach it near [`MAX_CHUNK_ROWS`].
pub const MAX_CHUNK_BYTES: u64 = 2 << 30;
/// Estimated bytes of one row's fixed columns in memory, counted once in
/// each of the copies a chunk passes through ([`ROW_COPIES`]): the solved
/// row (its pose and a_i vector), the Arrow columns, the encoder's buffer.
const ROW_FIXED_BYTES: u64 = 256;
/// Copies of a chunk's rows held at once while it is built: the solved
/// rows, the Arrow batch, the encoded Parquet row group.
const ROW_COPIES: u64 = 3;

/// A complete sweep job. Every section may be omitted (thesis defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct SweepSpec {
    /// Rod parameters and effects.
    pub actuator: Rod,
    /// Numerical settings of the solver.
    pub solver: SolverOptions,
    /// The grid of routings.
    pub grid: GridSpec,
    /// The tension ladder each routing is solved through (unless
    /// `displacement` is given).
    pub tension: TensionSpec,
    /// The displacement ladder each routing is solved through instead of
    /// the tension ladder: the cable driven by its displacement.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displacement: Option<DisplacementSpec>,
    /// What each row stores and how rows are grouped into files.
    pub output: OutputSpec,
}

/// The routing grid: every control point y0…y4 takes one of `levels`
/// values evenly spaced over [−extent_r·r, +extent_r·r].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GridSpec {
    /// Levels per control point (1 gives the straight routing only).
    pub levels: u32,
    /// Half-width of the levels as a fraction of the radius r (< 1: the
    /// channel must stay inside the body).
    pub extent_r: f64,
    /// Keep one routing of each mirror pair (y ↦ −y gives the mirrored
    /// shape, so its row carries no new information). Needs a
    /// mirror-symmetric actuator: no channel offset, gravity along the axis.
    pub mirror_dedup: bool,
}

impl Default for GridSpec {
    fn default() -> Self {
        Self { levels: 9, extent_r: 0.8, mirror_dedup: true }
    }
}

/// Tensions: `count` values evenly spaced from `min_n` to `max_n`, solved in
/// rising order (continuation) for each routing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TensionSpec {
    /// Lowest tension, N.
    pub min_n: f64,
    /// Highest tension, N.
    pub max_n: f64,
    /// Number of tensions (1 needs min_n = max_n).
    pub count: u32,
}

impl Default for TensionSpec {
    fn default() -> Self {
        Self { min_n: 1.0, max_n: 2.0, count: 21 }
    }
}

/// Displacements: `count` values evenly spaced from `min_mm` to `max_mm`,
/// solved in rising order for each routing, each cable's tension found
/// (docs/model.md, "Actuation by displacement").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DisplacementSpec {
    /// Smallest displacement, mm (≥ 0).
    pub min_mm: f64,
    /// Largest displacement, mm.
    pub max_mm: f64,
    /// Number of displacements (1 needs min_mm = max_mm).
    pub count: u32,
    /// The cable's axial stiffness EA, N (its stretch is part of its
    /// displacement); inextensible when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cable_ea_n: Option<f64>,
}

/// The actuation ladder of a planar sweep: each routing is solved through
/// these values in order.
#[derive(Debug, Clone, PartialEq)]
pub enum Ladder {
    /// Tensions, N.
    TensionN(Vec<f64>),
    /// Displacements, mm.
    DisplacementMm(Vec<f64>),
}

/// What is stored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSpec {
    /// Highest Legendre order n: columns a0 … an.
    pub order: usize,
    /// The length the a_i columns are per unit of: `rest` (the thesis's
    /// basis, the default) or `deformed`.
    pub length_basis: LengthBasis,
    /// Store the centreline of each solve as list columns.
    pub centreline: bool,
    /// Routings per chunk file (each chunk is written atomically; a resumed
    /// run redoes at most the chunks that were in progress).
    pub chunk_routings: u32,
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self { order: 3, length_basis: LengthBasis::default(), centreline: false, chunk_routings: 256 }
    }
}

/// What is wrong with a sweep spec: the section and setting, and what to do.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The actuator's parameters.
    #[error("[actuator] {0}")]
    Rod(#[source] crate::model::ParameterError),
    /// The TOML text does not parse or has unknown keys.
    #[error("{0}")]
    Toml(#[from] toml::de::Error),
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
    #[error("[displacement] max_mm = {max_mm} is not shorter than the rod ({length_mm} mm): a cable cannot be pulled in by its length")]
    DisplacementBeyondRod {
        /// The largest displacement, mm.
        max_mm: f64,
        /// The rod's length, mm.
        length_mm: f64,
    },
    /// A cable stiffness that is not a stiffness.
    #[error("[displacement] cable_ea_n = {ea_n} must be a finite stiffness > 0 N (leave it out for an inextensible cable)")]
    CableStiffness {
        /// The stiffness given, N.
        ea_n: f64,
    },
    /// Displacement driving with the method that cannot meet it.
    #[error(
        "[displacement] [solver] method = \"rk4\" does not integrate the cable's path, so it cannot meet a displacement: use the default \
         collocation"
    )]
    DisplacementWithRk4,
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
    /// An order the solver settings do not resolve.
    #[error("[output] {0}")]
    Resolution(#[source] crate::solver::resolution::OrderError),
    /// `chunk_routings = 0`.
    #[error("[output] chunk_routings = 0: a chunk needs at least one routing")]
    NoChunkRoutings,
    /// More rows per chunk than a chunk may hold.
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
        centreline_text(*centreline)
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
}

/// Why a chunk is built in memory as large as it is, for
/// [`SpecError::ChunkBytes`].
fn centreline_text(centreline: Option<(u64, usize)>) -> String {
    match centreline {
        Some((points, steps)) => format!("with centreline = true each row holds {points} centreline points ([solver] steps_per_span = {steps})"),
        None => "each chunk is built in memory".to_string(),
    }
}

/// What to change when a chunk would take too much memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ChunkBytesFix {
    /// One routing's rows alone are too many.
    #[error(
        "one routing's {count} rows alone take {}: lower [solver] steps_per_span or {ladder_table} count, or set centreline = false",
        crate::io::fmt_bytes(*routing_bytes)
    )]
    OneRouting {
        /// Rows per routing.
        count: u32,
        /// Memory of one routing's rows, bytes.
        routing_bytes: u64,
        /// The ladder's table.
        ladder_table: &'static str,
    },
    /// Fewer routings per chunk, with a centreline stored.
    #[error("lower chunk_routings to ≤ {most} (or [solver] steps_per_span, or set centreline = false)")]
    FewerRoutingsOrCentreline {
        /// The most routings per chunk.
        most: u64,
    },
    /// Fewer routings per chunk.
    #[error("lower chunk_routings to ≤ {most}")]
    FewerRoutings {
        /// The most routings per chunk.
        most: u64,
    },
}

impl SweepSpec {
    /// The thesis sweep (the built-in default).
    pub fn thesis() -> Self {
        Self::from_toml(THESIS_SPEC_TOML, "built-in thesis spec").expect("jobs/thesis.toml is valid")
    }

    /// Parses and validates a spec; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, SweepError> {
        let spec: SweepSpec =
            toml::from_str(text).map_err(|e| SweepError::BadSpec { origin: origin.to_string(), source: SpecError::Toml(e) })?;
        // A [tension] table beside [displacement] would be silently unused.
        if spec.displacement.is_some() && toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("tension")) {
            return Err(SweepError::BadSpec {
                origin: origin.to_string(),
                source: SpecError::TensionAndDisplacement,
            });
        }
        spec.validate().map_err(|source| SweepError::BadSpec { origin: origin.to_string(), source })?;
        Ok(spec)
    }

    /// Reads, parses and validates a spec file.
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        let text = crate::io::read_utf8(path)
            .map_err(crate::io::FileError::on("reading spec", path))?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Checks every setting; the message names the field and what to do.
    pub fn validate(&self) -> Result<(), SpecError> {
        self.actuator.validate().map_err(SpecError::Rod)?;
        // Sizes before anything is allocated for them.
        if self.solver.steps_per_span > MAX_STEPS_PER_SPAN {
            let resolving = crate::solver::resolution::REQUIRED_STEPS_PER_SPAN[crate::solver::resolution::MAX_RESOLVED_ORDER];
            return Err(SpecError::StepsPerSpan { steps: self.solver.steps_per_span, resolving });
        }
        if self.tension.count > MAX_TENSIONS {
            return Err(SpecError::TooManyTensions { count: self.tension.count });
        }
        if let Some(d) = &self.displacement {
            if d.count == 0 || d.count > MAX_TENSIONS {
                return Err(SpecError::DisplacementCount { count: d.count });
            }
            if !(d.min_mm.is_finite() && d.min_mm >= 0.0) {
                return Err(SpecError::DisplacementMin { min_mm: d.min_mm });
            }
            if !(d.max_mm.is_finite() && d.max_mm >= d.min_mm) || (d.count == 1 && d.max_mm != d.min_mm) {
                return Err(SpecError::DisplacementMax { max_mm: d.max_mm, min_mm: d.min_mm });
            }
            if d.max_mm >= self.actuator.length_mm {
                return Err(SpecError::DisplacementBeyondRod { max_mm: d.max_mm, length_mm: self.actuator.length_mm });
            }
            if let Some(ea_n) = d.cable_ea_n.filter(|ea| !(ea.is_finite() && *ea > 0.0)) {
                return Err(SpecError::CableStiffness { ea_n });
            }
            if self.solver.method == crate::solver::SolverMethod::Rk4 {
                return Err(SpecError::DisplacementWithRk4);
            }
        }
        crate::solver::Simulator::new(&self.actuator, &self.solver).map_err(SpecError::Solver)?;
        let g = &self.grid;
        if g.levels == 0 || g.levels > MAX_LEVELS {
            return Err(SpecError::Levels { levels: g.levels });
        }
        if !(g.extent_r.is_finite() && g.extent_r >= 0.0 && g.extent_r < 1.0) {
            return Err(SpecError::ExtentR { extent_r: g.extent_r });
        }
        let delta = self.actuator.effects.channel_offset_mm;
        // A tapered body's levels are fractions of its narrowest radius along the cable.
        let r = self.actuator.channel_radius_mm();
        if (g.extent_r * r).abs() + delta.abs() >= r {
            return Err(SpecError::ChannelBeyondBody { extent_r: g.extent_r, offset_mm: delta });
        }
        if g.mirror_dedup {
            let gravity = &self.actuator.gravity;
            let tilted = gravity.enabled && gravity.scale != 0.0 && gravity.direction_rad.sin().abs() > 1e-12;
            if delta != 0.0 || tilted {
                return Err(SpecError::MirrorAsymmetric);
            }
        }
        let t = &self.tension;
        if !(t.min_n.is_finite() && t.min_n >= 0.0) {
            return Err(SpecError::TensionMin { min_n: t.min_n });
        }
        if !(t.max_n.is_finite() && t.max_n >= t.min_n) {
            return Err(SpecError::TensionMax { max_n: t.max_n, min_n: t.min_n });
        }
        if t.count == 0 {
            return Err(SpecError::NoTensions);
        }
        if t.count == 1 && t.max_n != t.min_n {
            return Err(SpecError::OneTensionOverARange);
        }
        let o = &self.output;
        if o.order > MAX_ORDER {
            return Err(SpecError::Order { order: o.order });
        }
        crate::solver::resolution::check_order(o.order, &self.solver).map_err(SpecError::Resolution)?;
        if o.chunk_routings == 0 {
            return Err(SpecError::NoChunkRoutings);
        }
        let count = self.ladder_count();
        let chunk_rows = u64::from(o.chunk_routings) * u64::from(count);
        let chunk_bytes = chunk_rows.saturating_mul(self.row_bytes());
        if chunk_rows <= MAX_CHUNK_ROWS && chunk_bytes > MAX_CHUNK_BYTES {
            return Err(self.chunk_bytes_error(chunk_rows, chunk_bytes));
        }
        if chunk_rows > MAX_CHUNK_ROWS {
            return Err(SpecError::ChunkRows {
                chunk_routings: o.chunk_routings,
                ladder_table: self.ladder_table(),
                count,
                chunk_rows,
                most: (MAX_CHUNK_ROWS / u64::from(count)).max(1),
            });
        }
        Ok(())
    }

    /// Points of each row's stored centreline: the solvers' nodes from
    /// clamp to tip, two knot spans of `steps_per_span` steps (both
    /// methods; docs/schema.md); 0 when no centreline is stored.
    pub fn centreline_points(&self) -> u64 {
        if self.output.centreline {
            2 * self.solver.steps_per_span as u64 + 1
        } else {
            0
        }
    }

    /// Estimated bytes one row takes in memory while its chunk is built,
    /// all copies together ([`ROW_COPIES`]): fixed columns and a_i, and the
    /// centreline's x and y lists when stored.
    pub fn row_bytes(&self) -> u64 {
        let per_copy = ROW_FIXED_BYTES + 8 * (self.output.order as u64 + 1) + 16 * self.centreline_points();
        ROW_COPIES * per_copy
    }

    /// The refusal of a chunk of `chunk_rows` rows that would take
    /// `chunk_bytes` (more than [`MAX_CHUNK_BYTES`]), with what to change.
    fn chunk_bytes_error(&self, chunk_rows: u64, chunk_bytes: u64) -> SpecError {
        let o = &self.output;
        let count = self.ladder_count();
        let routing_bytes = u64::from(count) * self.row_bytes();
        let ladder_table = self.ladder_table();
        let fix = match MAX_CHUNK_BYTES / routing_bytes.max(1) {
            0 => ChunkBytesFix::OneRouting { count, routing_bytes, ladder_table },
            most if o.centreline => ChunkBytesFix::FewerRoutingsOrCentreline { most },
            most => ChunkBytesFix::FewerRoutings { most },
        };
        let centreline = o.centreline.then(|| (self.centreline_points(), self.solver.steps_per_span));
        SpecError::ChunkBytes { chunk_routings: o.chunk_routings, ladder_table, count, chunk_rows, chunk_bytes, centreline, fix }
    }

    /// Checks the size of the whole sweep: more than [`MAX_ROWS`] rows is
    /// refused (a typo like `levels = 99` means 10¹¹ rows) unless
    /// `allow_large`, for a deliberate huge job.
    pub fn check_size(&self, allow_large: bool) -> Result<(), SweepError> {
        let plan = SweepPlan::new(self);
        let rows = plan.total_rows();
        if rows > MAX_ROWS && !allow_large {
            return Err(SweepError::TooLarge {
                rows,
                routings: plan.routings,
                per_routing: plan.tensions,
                counted: RowsCounted::Actuations { ladder_table: self.ladder_table() },
            });
        }
        Ok(())
    }

    /// Whether a spec file's text sets nothing (empty, or comments only):
    /// such a spec is the built-in thesis sweep, which the caller should say.
    pub fn is_blank_toml(text: &str) -> bool {
        text.lines().all(|l| {
            let l = l.trim();
            l.is_empty() || l.starts_with('#')
        })
    }

    /// The actuation ladder: the displacements when given, else the tensions.
    pub fn ladder(&self) -> Ladder {
        match &self.displacement {
            Some(d) => Ladder::DisplacementMm(ValueGrid { min: d.min_mm, max: d.max_mm, count: d.count }.values()),
            None => Ladder::TensionN(self.tensions_n()),
        }
    }

    /// Values of the actuation ladder per routing (rows per routing).
    pub fn ladder_count(&self) -> u32 {
        self.displacement.as_ref().map_or(self.tension.count, |d| d.count)
    }

    /// The spec table holding the ladder, for messages: `[tension]` or `[displacement]`.
    fn ladder_table(&self) -> &'static str {
        if self.displacement.is_some() {
            "[displacement]"
        } else {
            "[tension]"
        }
    }

    /// The tension ladder, N, in rising order.
    pub fn tensions_n(&self) -> Vec<f64> {
        let t = &self.tension;
        ValueGrid { min: t.min_n, max: t.max_n, count: t.count }.values()
    }

    /// The level values of one control point, mm, ascending; symmetric
    /// about 0 bit for bit (level i and levels−1−i are exact negatives).
    pub fn levels_mm(&self) -> Vec<f64> {
        let n = self.grid.levels;
        if n == 1 {
            return vec![0.0];
        }
        let half = self.grid.extent_r * self.actuator.channel_radius_mm();
        let d = f64::from(n - 1);
        (0..n).map(|i| half * (2.0 * f64::from(i) - d) / d).collect()
    }

    /// The spec with every default filled in, as compact JSON: what the
    /// hash covers and what every output file records.
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

/// The planar single-cable sweep: one [`Simulator`] per worker, each
/// routing solved through the rising tension ladder.
impl RunSpec for SweepSpec {
    const FORMAT: &'static str = crate::io::run_markers::PLANAR_FORMAT;
    const KIND: &'static str = "planar single-cable sweep";
    type Worker = Simulator;
    type Solved = SolvedRouting;

    fn check(&self) -> Result<(), InvalidSpec> {
        self.validate().map_err(InvalidSpec::Planar)
    }

    fn check_run_size(&self, allow_large: bool) -> Result<(), SweepError> {
        self.check_size(allow_large)
    }

    fn canonical_json(&self) -> String {
        SweepSpec::canonical_json(self)
    }

    fn hash_hex(&self) -> String {
        SweepSpec::hash_hex(self)
    }

    fn length_basis(&self) -> LengthBasis {
        self.output.length_basis
    }

    fn order(&self) -> usize {
        self.output.order
    }

    fn layout(&self) -> ChunkLayout {
        SweepPlan::new(self).layout()
    }

    fn schema(&self) -> SchemaRef {
        arrow_schema(self.output.order, self.output.centreline)
    }

    fn row_bytes(&self) -> u64 {
        SweepSpec::row_bytes(self)
    }

    fn worker(&self) -> Result<Simulator, SweepError> {
        let mut sim = Simulator::new(&self.actuator, &self.solver)?;
        sim.set_cable_stiffness(self.displacement.as_ref().and_then(|d| d.cable_ea_n));
        Ok(sim)
    }

    fn solve(&self, worker: &mut Simulator, id: u64) -> Result<SolvedRouting, SweepError> {
        // The plan holds only the levels (a few numbers): cheap per routing.
        let routing_mm = SweepPlan::new(self).routing_mm(id);
        let routing = Routing::for_actuator(routing_mm, &self.actuator)?;
        let o = &self.output;
        let stored = Stored { order: o.order, length_basis: o.length_basis, centreline: o.centreline };
        Ok(solve::planar_routing(worker, id, routing_mm, &routing, &self.ladder(), stored))
    }

    fn batch(&self, schema: &SchemaRef, solved: &[SolvedRouting]) -> RecordBatch {
        build_batch(schema, self.output.order, self.output.centreline, solved)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        SweepSpec::from_toml(text, "test").unwrap_err().to_string()
    }

    #[test]
    fn thesis_spec_is_the_default() {
        let s = SweepSpec::thesis();
        assert_eq!(s, SweepSpec::default());
        assert_eq!(s.levels_mm(), vec![-4.0, -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0]);
        let t = s.tensions_n();
        assert_eq!(t.len(), 21);
        assert_eq!((t[0], t[20]), (1.0, 2.0));
        assert!((t[1] - 1.05).abs() < 1e-15);
    }

    #[test]
    fn levels_are_exactly_symmetric() {
        let mut s = SweepSpec::default();
        s.grid.levels = 7;
        s.grid.extent_r = 0.73;
        let l = s.levels_mm();
        for i in 0..7 {
            assert_eq!(l[i], -l[6 - i]);
        }
    }

    #[test]
    fn absurd_sizes_are_refused_before_allocation() {
        assert!(err("[tension]\ncount = 4000000000\n").contains("count = 4000000000"));
        assert!(err("[solver]\nsteps_per_span = 4000000000\n").contains("steps_per_span"));
        // Orders beyond what the solver resolves: collocation at 10 intervals stops at 11.
        assert!(err("[output]\norder = 12\n").contains("[solver] nodes_per_span = 12"));
        assert!(err("[solver]\nmethod = \"rk4\"\n[output]\norder = 9\n").contains("[solver] steps_per_span = 80"));
        assert!(err("[tension]\ncount = 100000\n").contains("chunk_routings"));
        // The chunk limit counts the centreline's points, not rows alone.
        let centreline = "[solver]\nsteps_per_span = 100000\n[output]\ncentreline = true\n";
        let e = err(&format!("{centreline}chunk_routings = 1\n[tension]\ncount = 300\n"));
        assert!(e.contains("200001 centreline points") && e.contains("one routing's 300 rows alone"), "{e}");
        let e = err(&format!("{centreline}chunk_routings = 16\n[tension]\ncount = 20\n"));
        assert!(e.contains("lower chunk_routings to ≤ 11") && e.contains("centreline = false"), "{e}");
        assert!(SweepSpec::from_toml(&format!("{centreline}chunk_routings = 11\n[tension]\ncount = 20\n"), "t").is_ok());
        // Without a centreline the row limit is the one that bites.
        assert!(SweepSpec::from_toml("[tension]\ncount = 7812\n", "t").is_ok());
        let huge = SweepSpec::from_toml("[grid]\nlevels = 99\n", "t").unwrap();
        assert!(huge.check_size(false).unwrap_err().to_string().contains("--allow-large"));
        assert!(huge.check_size(true).is_ok());
        assert!(SweepSpec::thesis().check_size(false).is_ok());
        assert!(SweepSpec::is_blank_toml("\n# nothing\n  \n"));
        assert!(!SweepSpec::is_blank_toml("[grid]\n"));
    }

    #[test]
    fn the_centreline_size_is_the_solvers() {
        for method in ["collocation", "rk4"] {
            let spec =
                SweepSpec::from_toml(&format!("[solver]\nmethod = \"{method}\"\nsteps_per_span = 30\n[output]\ncentreline = true\n"), "t")
                    .unwrap();
            let mut sim = crate::solver::Simulator::new(&spec.actuator, &spec.solver).unwrap();
            sim.set_routing_mm(&[1.0, 2.0, 0.0, -1.0, 1.0]).unwrap();
            sim.solve(1.5).unwrap();
            assert_eq!(sim.centreline().len() as u64, spec.centreline_points(), "{method}");
        }
        assert_eq!(SweepSpec::thesis().centreline_points(), 0);
    }

    #[test]
    fn bad_specs_name_the_problem() {
        assert!(err("[grid]\nlevles = 3\n").contains("unknown field `levles`"));
        assert!(err("[grid]\nextent_r = 1.2\n").contains("beyond ±r"));
        assert!(err("[tension]\nmin_n = -1.0\n").contains("min_n = -1"));
        assert!(err("[tension]\ncount = 0\n").contains("count = 0"));
        assert!(err("[output]\nchunk_routings = 0\n").contains("chunk_routings"));
        assert!(err("[actuator]\nea_n = -3.0\n").contains("ea_n"));
        assert!(err(&format!("[actuator.effects]\n{} = 0.5\n", crate::model::effects::CHANNEL_OFFSET.key)).contains("mirror_dedup"));
        assert!(err("[tension]\nmin_n = 2.0\nmax_n = 1.0\n").contains("max_n"));
    }

    #[test]
    fn hash_ignores_formatting_but_not_meaning() {
        let a = SweepSpec::from_toml("[tension]\ncount = 5\n", "a").unwrap();
        let b = SweepSpec::from_toml("[tension]\n  count   = 5 # five\n", "b").unwrap();
        let c = SweepSpec::from_toml("[tension]\ncount = 6\n", "c").unwrap();
        assert_eq!(a.hash_hex(), b.hash_hex());
        assert_ne!(a.hash_hex(), c.hash_hex());
        assert_eq!(SweepSpec::from_canonical_json(&a.canonical_json()).unwrap(), a);
    }
}
