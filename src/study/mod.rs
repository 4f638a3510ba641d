//! Studies over actuator variants (thesis §4.1: an actuator's specification
//! is chosen from maps of many variants). A study spec is a sweep spec with
//! a `[study]` section whose axes vary actuator parameters, the tension
//! range or the effects; every combination of the axes' values is one
//! variant, with its own resumable sweep and map:
//!
//! ```toml
//! [grid]                       # the base sweep spec, as for `cablemap sweep`
//! levels = 3
//! [study]
//! name = "length × stiffness"
//! [[study.axis]]
//! name = "length_mm"           # absolute values …
//! values = [55.0, 65.0, 75.0]
//! [[study.axis]]
//! name = "ei_n_mm2"            # … or factors on the base spec's value
//! scale = [0.8, 1.0, 1.25]
//! ```
//!
//! Axes: `length_mm`, `radius_mm`, `ei_n_mm2`, `ea_n`, `ga_n`,
//! `density_g_cm3` (numbers, or `scale`), `tension_n` (pairs [min, max] in
//! N), `effects` (tables of `[actuator.effects]` settings, laid over the
//! base spec's), and each effect parameter of the registry by its path
//! (`effects.KEY`, `gravity.scale`: numbers; see [`crate::model::effects`]). Variants are numbered with the first axis
//! slowest.
//!
//! A study directory holds `study.json` (the study and its variants),
//! `v{i}/run` and `v{i}/map` per variant (each exactly what `cablemap map`
//! of the variant's spec, `v{i}/spec.toml`, writes), and once every
//! variant is mapped the comparison: `comparison.csv`, `comparison.json`
//! and `index.html` (the variants' maps side by side).
//!
//! - [`axes`]: the axes a study may vary and how each value changes a
//!   variant's spec (effect parameters from the registry).
//! - [`spec`]: the study spec and its variants (every combination).
//! - [`record`]: the study directory: `study.json`, each `v{i}/spec.toml`.
//! - [`comparison`]: the variants' maps compared (`comparison.csv`/`.json`).
//! - [`page`]: `index.html`, the maps side by side, and its pictures.
//! - [`run`](mod@run): the workflow, request → report; one variant's sweep and map.
//! - [`error`]: what can go wrong.

pub mod axes;
pub mod comparison;
pub mod error;
pub mod page;
pub mod record;
pub mod run;
pub mod spec;

pub use axes::{AxisError, NUMBER_AXES};
pub use comparison::{compare, Comparison, VariantRow, COMPARISON_CSV, COMPARISON_JSON};
pub use error::{SpecProblem, StudyError};
pub use page::{reach_picture_file, PagePicture, PagePictures, MODES_SHOWN_MAX_W, PAGE_FILE, STUDY_REACH_PLOT_W};
pub use record::{mapped_variants, STUDY_FILE, STUDY_FORMAT};
pub use run::{run, run_variant, StudyProgress, StudyReport, StudyRequest, StudyTask, VariantRun};
pub use spec::{Setting, StudySpec, Variant, MAX_VARIANTS};
