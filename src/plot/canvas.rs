//! The drawing surface every picture shares: the bundled font (DejaVu
//! Sans, see `assets/README.md`, so pictures never depend on the machine's
//! fonts), the PNG backend behind the output checks, and its error.

use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

/// Font family name every figure uses.
pub const FONT: &str = "sans-serif";

static FONT_BYTES: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Registers the bundled font with plotters (idempotent).
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for style in [FontStyle::Normal, FontStyle::Bold, FontStyle::Italic, FontStyle::Oblique] {
            if plotters::style::register_font(FONT, style, FONT_BYTES).is_err() {
                panic!("the bundled font assets/DejaVuSans.ttf is not valid TrueType");
            }
        }
    });
}

/// Error of a drawing backend, as text (plotters' errors are generic).
#[derive(Debug, thiserror::Error)]
#[error("drawing {path}: {message}")]
pub struct PlotError {
    /// File being drawn.
    pub path: String,
    /// What went wrong.
    pub message: String,
}

impl PlotError {
    /// Wraps any displayable backend error for `path`.
    pub fn new(path: &Path, e: impl std::fmt::Display) -> Self {
        Self { path: path.display().to_string(), message: e.to_string() }
    }
}

/// The bitmap a PNG is drawn into at `path`, after the checks every output
/// file gets ([`crate::io::write_atomic`]'s): never over a symbolic link,
/// FIFO, device or directory, never inside a sweep run directory. plotters
/// writes the file itself when the drawing is presented, so the checks
/// come first here.
pub fn png_backend(path: &Path, size_px: (u32, u32)) -> Result<BitMapBackend<'_>, PlotError> {
    crate::io::check_regular_or_new(path).map_err(|e| PlotError::new(path, e))?;
    crate::io::check_outside_run_dir(path, "the picture").map_err(|e| PlotError::new(path, e))?;
    Ok(BitMapBackend::new(path, size_px))
}
