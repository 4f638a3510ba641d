//! A job spec file, read once and told apart by the tables it has: a
//! planar single-cable sweep (`[grid]`, `[tension]`, … or nothing: the
//! thesis's defaults), a sweep of several or spatial cables (`[[cable]]`
//! tables) or a study over actuator variants (a `[study]` section).
//! `sweep`, `map`, `study` and `status` all take their spec from here, so a
//! spec's kind is decided in one place, from its parsed content.

use crate::io::FileError;
use crate::study::{StudyError, StudySpec};
use crate::sweep::report::SweepReport;
use crate::sweep::{run_status, run_sweep, SweepError, SweepOptions, SweepSpec};
use std::path::{Path, PathBuf};

/// Top-level tables of a planar sweep spec (docs/schema.md).
const PLANAR_TABLES: [&str; 6] = ["actuator", "solver", "grid", "tension", "displacement", "output"];
/// Top-level keys of a cable sweep spec besides `[[cable]]`.
const CABLE_KEYS: [&str; 5] = ["rod", "gj_n_mm2", "gravity_direction", "solver", "output"];

/// The spec a job file holds, by kind.
#[derive(Debug, Clone)]
pub enum JobSpec {
    /// A sweep: a planar single-cable sweep or a sweep of several or
    /// spatial cables ([`SweepSpec::kind`]).
    Sweep(SweepSpec),
    /// A study: one planar sweep and map per actuator variant.
    Study(StudySpec),
}

/// A job: its spec and where it came from.
#[derive(Debug, Clone)]
pub struct Job {
    /// The spec file; `None` for the built-in thesis spec.
    pub path: Option<PathBuf>,
    /// The spec.
    pub spec: JobSpec,
    /// The file sets nothing (blank or comments only): the thesis's defaults run.
    pub blank: bool,
}

/// Why a job spec cannot be read or run.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The file cannot be read.
    #[error(transparent)]
    File(#[from] FileError),
    /// The file is TOML but no kind of job spec.
    #[error(
        "{} is not a job spec: it has none of the tables of a planar sweep ([grid], [tension] or [displacement], [actuator], [solver], [output]), \
         a cable sweep ([[cable]]) or a study ([study]), only {}: give a sweep or study spec (jobs/thesis.toml, jobs/antagonistic-pair.toml, jobs/study.toml)",
        path.display(),
        tables.iter().map(|t| format!("'{t}'")).collect::<Vec<_>>().join(", ")
    )]
    NotAJob {
        /// The file.
        path: PathBuf,
        /// Its top-level keys.
        tables: Vec<String>,
    },
    /// A `[study]` section beside `[[cable]]` tables.
    #[error(
        "{} has both a [study] section and [[cable]] tables: a study varies a planar sweep spec; drop the [[cable]] tables, \
         or the [study] section to run the cable sweep",
        path.display()
    )]
    CableStudy {
        /// The file.
        path: PathBuf,
    },
    /// A study spec given where one sweep is run.
    #[error(
        "{} is a study spec (it has a [study] section): run it with `cablemap study {} --out DIR` or `cablemap map {} --out DIR`",
        path.display(),
        path.display(),
        path.display()
    )]
    StudyNotASweep {
        /// The file.
        path: PathBuf,
    },
    /// A sweep spec is malformed, invalid, or its sweep failed.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// A study spec is malformed or invalid.
    #[error(transparent)]
    Study(#[from] StudyError),
}

impl Job {
    /// The built-in thesis spec (jobs/thesis.toml).
    pub fn thesis() -> Self {
        Self { path: None, spec: JobSpec::Sweep(SweepSpec::thesis()), blank: false }
    }

    /// The spec at `path`, or the built-in thesis spec when `None`.
    pub fn load_or_thesis(path: Option<&Path>) -> Result<Self, JobError> {
        path.map_or_else(|| Ok(Self::thesis()), Self::load)
    }

    /// Reads the spec file at `path` once and decides its kind from its
    /// tables: `[study]` a study, `[[cable]]` a cable sweep, otherwise a
    /// planar sweep (whose parser names a misspelt table). A file with none
    /// of any kind's tables is refused as [`JobError::NotAJob`].
    pub fn load(path: &Path) -> Result<Self, JobError> {
        let text = crate::io::read_text(path, "reading spec")?;
        let origin = path.display().to_string();
        let table = match text.parse::<toml::Table>() {
            Ok(t) => t,
            // Not TOML: worded as the planar parser always has.
            Err(e) => return Err(SweepError::BadSpec { origin, source: crate::sweep::spec::SpecError::Toml(e) }.into()),
        };
        let has = |key: &str| table.contains_key(key);
        let known = |key: &String| PLANAR_TABLES.contains(&key.as_str()) || CABLE_KEYS.contains(&key.as_str()) || key == "cable" || key == "study";
        let spec = if has("study") && has("cable") {
            return Err(JobError::CableStudy { path: path.to_path_buf() });
        } else if has("study") {
            JobSpec::Study(StudySpec::from_table(table, &origin)?)
        } else if !table.is_empty() && !table.keys().any(known) {
            return Err(JobError::NotAJob { path: path.to_path_buf(), tables: table.keys().cloned().collect() });
        } else {
            // `[[cable]]` tables make a cable sweep, else a planar one (whose
            // parser names a misspelt table).
            JobSpec::Sweep(SweepSpec::from_toml(&text, &origin)?)
        };
        Ok(Self { path: Some(path.to_path_buf()), spec, blank: SweepSpec::is_blank_toml(&text) })
    }

    /// What to tell the user about the spec before running it (on stderr):
    /// a file that sets nothing runs the thesis's defaults.
    pub fn note(&self) -> Option<String> {
        let path = self.path.as_ref().filter(|_| self.blank)?;
        Some(format!("note: {} sets nothing: running the built-in thesis sweep (jobs/thesis.toml) with every default", path.display()))
    }

    /// Runs one shard of the job's sweep into `out` and reads the run's
    /// state after it. A study has no single sweep: [`JobError::StudyNotASweep`].
    pub fn sweep(&self, out: &Path, options: &SweepOptions) -> Result<SweepReport, JobError> {
        let JobSpec::Sweep(spec) = &self.spec else {
            return Err(JobError::StudyNotASweep { path: self.path.clone().unwrap_or_default() });
        };
        let summary = run_sweep(spec, out, options)?;
        let status = run_status(out).map_err(|e| SweepError::After { dir: out.to_path_buf(), source: Box::new(e) })?;
        Ok(SweepReport::new(summary, &status))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::RunKind;

    fn load(text: &str) -> Result<Job, JobError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("spec.toml");
        std::fs::write(&path, text).unwrap();
        Job::load(&path)
    }

    #[test]
    fn a_spec_is_told_by_its_tables() {
        let kind = |job: Job| match job.spec {
            JobSpec::Sweep(s) => Some(s.kind()),
            JobSpec::Study(_) => None,
        };
        assert_eq!(kind(load("[grid]\nlevels = 3\n").unwrap()), Some(RunKind::Planar));
        assert_eq!(kind(load("# nothing\n").unwrap()), Some(RunKind::Planar));
        assert!(load("# nothing\n").unwrap().note().is_some_and(|n| n.contains("sets nothing")));
        let cable = "[[cable]]\ny_mm = [1, 1, 1, 1, 1]\ntension_n = { min = 0.0, max = 1.0, count = 2 }\n";
        assert_eq!(kind(load(cable).unwrap()), Some(RunKind::Cables));
        let study = "[grid]\nlevels = 3\n[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [55.0, 65.0]\n";
        assert!(matches!(load(study).unwrap().spec, JobSpec::Study(_)));
    }

    #[test]
    fn a_file_of_no_kind_is_refused_by_name() {
        let e = load("[package]\nname = \"x\"\n").unwrap_err().to_string();
        assert!(e.contains("is not a job spec") && e.contains("'package'"), "{e}");
        let e = load("[study]\n[[cable]]\ny_mm = [1, 1, 1, 1, 1]\n").unwrap_err().to_string();
        assert!(e.contains("both a [study] section and [[cable]] tables"), "{e}");
        // A misspelt planar table beside a real one: the planar parser names it.
        let e = load("[grid]\nlevels = 3\n[tensions]\n").unwrap_err().to_string();
        assert!(e.contains("unknown field `tensions`"), "{e}");
        let e = load("not toml [").unwrap_err().to_string();
        assert!(e.contains("bad sweep spec"), "{e}");
    }

    #[test]
    fn the_shipped_jobs_load_as_their_kind() {
        let jobs = Path::new(env!("CARGO_MANIFEST_DIR")).join("jobs");
        for (name, kind) in [("thesis.toml", "planar"), ("quick.toml", "planar"), ("antagonistic-pair.toml", "cables"), ("spatial-pair.toml", "cables"), ("study.toml", "study")] {
            let job = Job::load(&jobs.join(name)).unwrap();
            let found = match job.spec {
                JobSpec::Sweep(s) if s.planar().is_some() => "planar",
                JobSpec::Sweep(_) => "cables",
                JobSpec::Study(_) => "study",
            };
            assert_eq!(found, kind, "{name}");
        }
    }
}
