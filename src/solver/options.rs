//! The numerical settings of every backend ([`SolverOptions`]), the
//! settings a user gives ([`SolverSettings`]) and which a request gave
//! ([`Given`]), and the two `[solver]` tables a sweep spec writes them as: a planar sweep's
//! ([`planar_table`]) and a cable sweep's ([`spatial_table`]), each with the
//! keys and defaults of the backends it runs, so that the specs' files and
//! the hashes over them read as they always have.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// How the centreline is integrated along each knot span of the routing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SolverMethod {
    /// Spectral collocation on Chebyshev–Lobatto nodes per span (the
    /// default): strains at `nodes_per_span + 1` points per span, integrals
    /// by the exact integral of the interpolating polynomial; gravity's
    /// distal moment by fixed-point sweeps (no shooting), with Newton's
    /// method and continuation in the weight as the fallback for heavy rods.
    #[default]
    Collocation,
    /// The reference method, a plain scheme to check against: classical RK4 with
    /// `steps_per_span` steps per span and secant shooting on gravity's
    /// base moment.
    Rk4,
}

/// Numerical settings of the solver, one set for every backend. A setting
/// whose default differs between the planar and the spatial backends is
/// two fields, named by the backends they tune; a setting given by the
/// user (`--steps-per-span`) sets both ([`SolverSettings::applied_to`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SolverOptions {
    /// Collocation or the RK4 reference, for the planar and the spatial backends.
    pub method: SolverMethod,
    /// Collocation: Chebyshev–Lobatto intervals per knot span (4–64); the
    /// span's integrands are smooth, so the error falls geometrically with it.
    /// With material stiffening the planar backend uses at least
    /// [`super::MIN_NODES_WITH_STIFFENING`].
    pub nodes_per_span: usize,
    /// Planar RK4 steps on each of the routing's two knot spans (even, ≥ 2).
    /// With collocation it sets the centreline's resolution:
    /// 2·steps_per_span + 1 evenly spaced points (planar and spatial).
    pub planar_steps_per_span: usize,
    /// Spatial RK4 steps per knot span of the routing (≥ 2); anchors split
    /// a span and share its steps in proportion to length.
    pub spatial_steps_per_span: usize,
    /// Planar: last Newton step accepted for the cable angle α, rad (the
    /// error left is of the order of its square).
    pub angle_tolerance_rad: f64,
    /// Planar convergence of gravity's moment, N·mm: RK4, the residual at
    /// the tip; collocation, the largest change at a node between the last
    /// sweeps. 1e-8 N·mm leaves a curvature error of about 1e-10 /mm
    /// (δm/EI): far below the solver's discretisation error.
    pub planar_moment_tolerance_n_mm: f64,
    /// Spatial convergence of gravity's distal moment at the tip, N·mm.
    /// 1e-7 N·mm moves the tip by about δm L²/(2 EI) ≈ 2e-6 mm and turns
    /// it by δm L/EI ≈ 6e-8 rad: well below RK4's error at the default steps.
    pub spatial_moment_tolerance_n_mm: f64,
    /// Planar RK4: most shooting passes before giving up. (Collocation has
    /// no shooting: its sweeps hand over to Newton's method when they stall.)
    pub max_shooting_passes: u32,
    /// Spatial RK4: most integration passes per solve (gravity's Broyden iteration).
    pub spatial_max_passes: u32,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            method: SolverMethod::Collocation,
            nodes_per_span: 10,
            planar_steps_per_span: 24,
            spatial_steps_per_span: 10,
            angle_tolerance_rad: 1e-7,
            planar_moment_tolerance_n_mm: 1e-8,
            spatial_moment_tolerance_n_mm: 1e-7,
            max_shooting_passes: 30,
            spatial_max_passes: 40,
        }
    }
}

/// Settings of a request given explicitly (by a flag or a spec key) rather
/// than left at their defaults: a backend that does not read one refuses
/// it instead of ignoring it silently. Defaults every backend may ignore.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Given {
    /// The method (`--method`).
    pub method: bool,
    /// Collocation intervals per span (`--nodes-per-span`).
    pub nodes_per_span: bool,
    /// RK4 steps per span (`--steps-per-span`).
    pub steps_per_span: bool,
    /// A load direction or dwell of the final tension (`--direction`, `--dwell-s`).
    pub hold: bool,
    /// The thesis's coefficient route from a planar centreline (`--coefficients thesis`).
    pub thesis_coefficients: bool,
}

/// The solver settings as a user gives them (`--method`,
/// `--nodes-per-span`, `--steps-per-span`; the `solver` keys of Python's
/// requests), each `None` when left at its default: they make the
/// [`SolverOptions`] and say which settings were given ([`Given`]), so a
/// backend that does not read one can refuse it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSettings {
    /// Collocation or the RK4 reference.
    pub method: Option<SolverMethod>,
    /// Collocation intervals per knot span.
    pub nodes_per_span: Option<usize>,
    /// RK4 steps per knot span (both backends'); collocation's centreline resolution.
    pub steps_per_span: Option<usize>,
}

impl SolverSettings {
    /// The default options with these settings.
    pub fn options(&self) -> SolverOptions {
        self.applied_to(&SolverOptions::default())
    }

    /// `base` with these settings.
    pub fn applied_to(&self, base: &SolverOptions) -> SolverOptions {
        let mut options = base.clone();
        if let Some(n) = self.steps_per_span {
            options.planar_steps_per_span = n;
            options.spatial_steps_per_span = n;
        }
        if let Some(m) = self.nodes_per_span {
            options.nodes_per_span = m;
        }
        if let Some(m) = self.method {
            options.method = m;
        }
        options
    }

    /// Which settings were given (the request's hold and coefficient route aside).
    pub fn given(&self) -> Given {
        Given {
            method: self.method.is_some(),
            nodes_per_span: self.nodes_per_span.is_some(),
            steps_per_span: self.steps_per_span.is_some(),
            ..Given::default()
        }
    }

    /// A request's options from its `solver` object (for
    /// `#[serde(deserialize_with = …)]`).
    pub fn deserialize_options<'de, D: Deserializer<'de>>(deserializer: D) -> Result<SolverOptions, D::Error> {
        Self::deserialize(deserializer).map(|s| s.options())
    }
}

/// The `[solver]` table of a planar sweep spec: the planar backends' keys
/// (`steps_per_span`, `moment_tolerance_n_mm` are the planar ones); for
/// `#[serde(with = "planar_table")]`.
pub mod planar_table {
    use super::*;

    #[derive(Serialize, Deserialize)]
    #[serde(deny_unknown_fields, default)]
    struct Table {
        method: SolverMethod,
        nodes_per_span: usize,
        steps_per_span: usize,
        angle_tolerance_rad: f64,
        moment_tolerance_n_mm: f64,
        max_shooting_passes: u32,
    }

    impl From<&SolverOptions> for Table {
        fn from(o: &SolverOptions) -> Self {
            Self {
                method: o.method,
                nodes_per_span: o.nodes_per_span,
                steps_per_span: o.planar_steps_per_span,
                angle_tolerance_rad: o.angle_tolerance_rad,
                moment_tolerance_n_mm: o.planar_moment_tolerance_n_mm,
                max_shooting_passes: o.max_shooting_passes,
            }
        }
    }

    impl Default for Table {
        fn default() -> Self {
            Self::from(&SolverOptions::default())
        }
    }

    /// Writes the planar table of `o`.
    pub fn serialize<S: Serializer>(o: &SolverOptions, serializer: S) -> Result<S::Ok, S::Error> {
        Table::from(o).serialize(serializer)
    }

    /// Reads a planar table; the spatial settings keep their defaults.
    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<SolverOptions, D::Error> {
        let t = Table::deserialize(deserializer)?;
        Ok(SolverOptions {
            method: t.method,
            nodes_per_span: t.nodes_per_span,
            planar_steps_per_span: t.steps_per_span,
            angle_tolerance_rad: t.angle_tolerance_rad,
            planar_moment_tolerance_n_mm: t.moment_tolerance_n_mm,
            max_shooting_passes: t.max_shooting_passes,
            ..SolverOptions::default()
        })
    }
}

/// The `[solver]` table of a cable sweep spec: the spatial backends' keys
/// (`steps_per_span`, `moment_tolerance_n_mm`, `max_passes` are the spatial
/// ones); for `#[serde(with = "spatial_table")]`.
pub mod spatial_table {
    use super::*;

    #[derive(Serialize, Deserialize)]
    #[serde(deny_unknown_fields, default)]
    struct Table {
        steps_per_span: usize,
        moment_tolerance_n_mm: f64,
        max_passes: u32,
        nodes_per_span: usize,
        method: SolverMethod,
    }

    impl From<&SolverOptions> for Table {
        fn from(o: &SolverOptions) -> Self {
            Self {
                steps_per_span: o.spatial_steps_per_span,
                moment_tolerance_n_mm: o.spatial_moment_tolerance_n_mm,
                max_passes: o.spatial_max_passes,
                nodes_per_span: o.nodes_per_span,
                method: o.method,
            }
        }
    }

    impl Default for Table {
        fn default() -> Self {
            Self::from(&SolverOptions::default())
        }
    }

    /// Writes the spatial table of `o`.
    pub fn serialize<S: Serializer>(o: &SolverOptions, serializer: S) -> Result<S::Ok, S::Error> {
        Table::from(o).serialize(serializer)
    }

    /// Reads a spatial table; the planar settings keep their defaults.
    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<SolverOptions, D::Error> {
        let t = Table::deserialize(deserializer)?;
        Ok(SolverOptions {
            method: t.method,
            nodes_per_span: t.nodes_per_span,
            spatial_steps_per_span: t.steps_per_span,
            spatial_moment_tolerance_n_mm: t.moment_tolerance_n_mm,
            spatial_max_passes: t.max_passes,
            ..SolverOptions::default()
        })
    }
}
