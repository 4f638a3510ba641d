//! The planar single-cable sweep spec (`cablemap-sweep/2` runs): a TOML
//! file naming the actuator, the solver settings, the routing grid, the
//! tension ladder and what to store. Unknown fields are rejected so that a
//! typo never silently falls back to a default. Its kind ([`RunSpec`] for
//! [`PlanarGrid`]): one [`Simulator`] per worker, each routing solved
//! through the rising tension ladder ([`solve::planar_routing`]).
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
use crate::sweep::kind::{ChunkLayout, RowsCounted, RunKind, RunSpec, MAX_CHUNK_ROWS};
use crate::sweep::schema::{arrow_schema, build_batch, SolvedRouting};
use crate::sweep::solve::{self, Stored};
use crate::sweep::spec::{OutputSpec, SpecError, SweepSpec, RoutingGrid, ValueGrid};
use crate::sweep::SweepError;
use arrow::datatypes::SchemaRef;
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};

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
/// Arrow batch and the Parquet encoder's buffers; [`PlanarGrid::row_bytes`]).
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

/// The thesis's kind of sweep: one planar cable in a rod, its routings a
/// grid of control-point levels, each solved through an actuation ladder.
/// Every table of its spec file may be omitted (thesis defaults).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlanarGrid {
    /// Rod parameters and effects.
    pub actuator: Rod,
    /// The grid of routings.
    pub grid: GridSpec,
    /// The tension ladder each routing is solved through (unless
    /// `displacement` is given).
    pub tension: TensionSpec,
    /// The displacement ladder each routing is solved through instead of
    /// the tension ladder: the cable driven by its displacement.
    pub displacement: Option<DisplacementSpec>,
}

/// The file layout of a planar sweep spec (its TOML tables, and the key
/// order of the canonical JSON the spec hash covers).
#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub(super) struct SpecFile {
    actuator: Rod,
    #[serde(with = "crate::solver::options::planar_table")]
    solver: SolverOptions,
    grid: GridSpec,
    tension: TensionSpec,
    #[serde(skip_serializing_if = "Option::is_none")]
    displacement: Option<DisplacementSpec>,
    output: Output,
}

/// The `[output]` table of a planar sweep spec.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct Output {
    order: usize,
    length_basis: LengthBasis,
    centreline: bool,
    chunk_routings: u32,
}

impl Default for Output {
    fn default() -> Self {
        Self { order: 3, length_basis: LengthBasis::default(), centreline: false, chunk_routings: 256 }
    }
}

impl From<Output> for OutputSpec {
    fn from(o: Output) -> Self {
        let Output { order, length_basis, centreline, chunk_routings } = o;
        OutputSpec { order, length_basis, centreline, cell_mm: None, chunk_routings }
    }
}

impl SpecFile {
    /// The layout of a planar spec.
    pub(super) fn of(grid: &PlanarGrid, solver: &SolverOptions, output: &OutputSpec) -> Self {
        let PlanarGrid { actuator, grid, tension, displacement } = grid.clone();
        let solver = solver.clone();
        let OutputSpec { order, length_basis, centreline, chunk_routings, cell_mm: _ } = output.clone();
        Self { actuator, solver, grid, tension, displacement, output: Output { order, length_basis, centreline, chunk_routings } }
    }

    /// The spec it lays out.
    pub(super) fn into_spec(self) -> SweepSpec {
        let SpecFile { actuator, solver, grid, tension, displacement, output } = self;
        SweepSpec { routings: RoutingGrid::Planar(PlanarGrid { actuator, grid, tension, displacement }), solver, output: output.into() }
    }
}

/// Parses a planar spec's TOML (unchecked).
pub(super) fn from_toml(text: &str) -> Result<SweepSpec, SpecError> {
    let file: SpecFile = toml::from_str(text)?;
    // A [tension] table beside [displacement] would be silently unused.
    if file.displacement.is_some() && toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("tension")) {
        return Err(SpecError::TensionAndDisplacement);
    }
    Ok(file.into_spec())
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

/// Why a chunk is built in memory as large as it is, for
/// [`SpecError::ChunkBytes`].
pub(super) fn centreline_text(centreline: Option<(u64, usize)>) -> String {
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

impl PlanarGrid {
    /// Checks every setting with the spec's `output`; the error names the
    /// field and what to do.
    fn validate(&self, solver: &SolverOptions, output: &OutputSpec) -> Result<(), SpecError> {
        self.actuator.validate().map_err(SpecError::Actuator)?;
        // Sizes before anything is allocated for them.
        if solver.planar_steps_per_span > MAX_STEPS_PER_SPAN {
            let resolving = crate::solver::resolution::REQUIRED_STEPS_PER_SPAN[crate::solver::resolution::MAX_RESOLVED_ORDER];
            return Err(SpecError::StepsPerSpan { steps: solver.planar_steps_per_span, resolving });
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
                return Err(SpecError::DisplacementBeyondRod { cable: None, max_mm: d.max_mm, length_mm: self.actuator.length_mm });
            }
            if let Some(ea_n) = d.cable_ea_n.filter(|ea| !(ea.is_finite() && *ea > 0.0)) {
                return Err(SpecError::CableStiffness { cable: None, ea_n });
            }
            if solver.method == crate::solver::SolverMethod::Rk4 {
                return Err(SpecError::DisplacementWithRk4 { cable: None });
            }
        }
        crate::solver::Simulator::for_rod(&self.actuator, &solver).map_err(SpecError::Solver)?;
        let g = &self.grid;
        if g.levels == 0 || g.levels > MAX_LEVELS {
            return Err(SpecError::Levels { levels: g.levels });
        }
        if !(g.extent_r.is_finite() && g.extent_r >= 0.0 && g.extent_r < 1.0) {
            return Err(SpecError::ExtentR { extent_r: g.extent_r });
        }
        let delta = (crate::model::effects::CHANNEL_OFFSET.get)(&self.actuator);
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
        let o = output;
        if o.order > MAX_ORDER {
            return Err(SpecError::Order { order: o.order });
        }
        crate::solver::resolution::check_order(o.order, &solver).map_err(SpecError::Resolution)?;
        if o.chunk_routings == 0 {
            return Err(SpecError::NoChunkRoutings { cables: false });
        }
        let count = self.ladder_count();
        let chunk_rows = u64::from(o.chunk_routings) * u64::from(count);
        let chunk_bytes = chunk_rows.saturating_mul(self.row_bytes(solver, o));
        if chunk_rows <= MAX_CHUNK_ROWS && chunk_bytes > MAX_CHUNK_BYTES {
            return Err(self.chunk_bytes_error(solver, o, chunk_rows, chunk_bytes));
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
    pub fn centreline_points(solver: &SolverOptions, output: &OutputSpec) -> u64 {
        if output.centreline {
            2 * solver.planar_steps_per_span as u64 + 1
        } else {
            0
        }
    }

    /// The refusal of a chunk of `chunk_rows` rows that would take
    /// `chunk_bytes` (more than [`MAX_CHUNK_BYTES`]), with what to change.
    fn chunk_bytes_error(&self, solver: &SolverOptions, o: &OutputSpec, chunk_rows: u64, chunk_bytes: u64) -> SpecError {
        let count = self.ladder_count();
        let routing_bytes = u64::from(count) * self.row_bytes(solver, o);
        let ladder_table = self.ladder_table();
        let fix = match MAX_CHUNK_BYTES / routing_bytes.max(1) {
            0 => ChunkBytesFix::OneRouting { count, routing_bytes, ladder_table },
            most if o.centreline => ChunkBytesFix::FewerRoutingsOrCentreline { most },
            most => ChunkBytesFix::FewerRoutings { most },
        };
        let centreline = o.centreline.then(|| (Self::centreline_points(solver, o), solver.planar_steps_per_span));
        SpecError::ChunkBytes { chunk_routings: o.chunk_routings, ladder_table, count, chunk_rows, chunk_bytes, centreline, fix }
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
}

/// The planar single-cable sweep: one [`Simulator`] per worker, each
/// routing solved through the rising actuation ladder.
impl RunSpec for PlanarGrid {
    const KIND: RunKind = RunKind::Planar;
    type Worker = Simulator;
    type Solved = SolvedRouting;

    fn check(&self, solver: &SolverOptions, output: &OutputSpec) -> Result<(), SpecError> {
        self.validate(solver, output)
    }

    fn rows_counted(&self) -> RowsCounted {
        RowsCounted::Actuations { ladder_table: self.ladder_table() }
    }

    fn layout(&self, output: &OutputSpec) -> ChunkLayout {
        SweepPlan::new(self, output).layout()
    }

    fn schema(&self, output: &OutputSpec) -> SchemaRef {
        arrow_schema(output.order, output.centreline)
    }

    /// Fixed columns and a_i, and the centreline's x and y lists when
    /// stored, in each of [`ROW_COPIES`] copies.
    fn row_bytes(&self, solver: &SolverOptions, output: &OutputSpec) -> u64 {
        let per_copy = ROW_FIXED_BYTES + 8 * (output.order as u64 + 1) + 16 * Self::centreline_points(solver, output);
        ROW_COPIES * per_copy
    }

    fn worker(&self, solver: &SolverOptions) -> Result<Simulator, SweepError> {
        let mut sim = Simulator::for_rod(&self.actuator, solver)?;
        sim.set_cable_stiffness(self.displacement.as_ref().and_then(|d| d.cable_ea_n));
        Ok(sim)
    }

    fn solve(&self, _solver: &SolverOptions, output: &OutputSpec, worker: &mut Simulator, id: u64) -> Result<SolvedRouting, SweepError> {
        // The plan holds only the levels (a few numbers): cheap per routing.
        let routing_mm = SweepPlan::new(self, output).routing_mm(id);
        let routing = Routing::for_actuator(routing_mm, &self.actuator)?;
        let stored = Stored { order: output.order, length_basis: output.length_basis, centreline: output.centreline };
        Ok(solve::planar_routing(worker, id, routing_mm, &routing, &self.ladder(), stored))
    }

    fn batch(&self, output: &OutputSpec, schema: &SchemaRef, solved: &[SolvedRouting]) -> RecordBatch {
        build_batch(schema, output.order, output.centreline, solved)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        SweepSpec::from_toml(text, "test").unwrap_err().to_string()
    }

    fn planar(spec: &SweepSpec) -> &PlanarGrid {
        spec.planar().expect("a planar spec")
    }

    #[test]
    fn thesis_spec_is_the_default() {
        let s = SweepSpec::thesis();
        assert_eq!(s, SweepSpec::default());
        let s = planar(&s);
        assert_eq!(s.levels_mm(), vec![-4.0, -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.0]);
        let t = s.tensions_n();
        assert_eq!(t.len(), 21);
        assert_eq!((t[0], t[20]), (1.0, 2.0));
        assert!((t[1] - 1.05).abs() < 1e-15);
    }

    #[test]
    fn levels_are_exactly_symmetric() {
        let mut s = PlanarGrid::default();
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
            let grid = planar(&spec);
            let mut sim = crate::solver::Simulator::for_rod(&grid.actuator, &spec.solver).unwrap();
            sim.set_routing_mm(&[1.0, 2.0, 0.0, -1.0, 1.0]).unwrap();
            sim.solve(1.5).unwrap();
            assert_eq!(sim.centreline().len() as u64, PlanarGrid::centreline_points(&spec.solver, &spec.output), "{method}");
        }
        let thesis = SweepSpec::thesis();
        assert_eq!(PlanarGrid::centreline_points(&thesis.solver, &thesis.output), 0);
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
