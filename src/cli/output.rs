//! Where a command's report and progress lines go, decided once from its
//! `--json` flag.

use cablemap::map::ReduceReport;
use cablemap::study::StudyReport;
use std::fmt::Display;

/// How a command prints: its report as text or as JSON on stdout; its
/// progress lines on stdout beside text, on stderr beside JSON (stdout then
/// holds the JSON alone).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// The report as text (the default).
    Text,
    /// The report as JSON (`--json`).
    Json,
}

impl Output {
    /// The output `--json` asks for.
    pub fn of_json_flag(json: bool) -> Self {
        if json {
            Output::Json
        } else {
            Output::Text
        }
    }

    /// Prints one progress line where it belongs.
    pub fn progress(self, line: &dyn Display) {
        match self {
            Output::Text => println!("{line}"),
            Output::Json => eprintln!("{line}"),
        }
    }

    /// Prints a map's report: its text, or its JSON with the note on stderr.
    pub fn map(self, report: &ReduceReport) -> anyhow::Result<()> {
        match self {
            Output::Text => print!("{report}"),
            Output::Json => {
                println!("{}", serde_json::to_value(report)?);
                if let Some(note) = report.note() {
                    eprintln!("{note}");
                }
            }
        }
        Ok(())
    }

    /// Prints a study's report: the comparison (text or JSON), or the
    /// command that finishes a split study (a progress line).
    pub fn study(self, report: &StudyReport) -> anyhow::Result<()> {
        match (report, self) {
            (StudyReport::TaskDone { .. }, _) => self.progress(&report.to_string().trim_end()),
            (StudyReport::Compared { .. }, Output::Json) => println!("{}", serde_json::to_string(report)?),
            (StudyReport::Compared { .. }, Output::Text) => print!("{report}"),
        }
        Ok(())
    }
}
