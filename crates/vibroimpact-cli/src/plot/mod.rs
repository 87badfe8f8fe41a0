//! Figure rendering: one [`Figure`] description becomes an SVG and a PNG file.
//!
//! The figure is drawn on plotters' drawing primitives (no chart builder), so
//! the layout is fully under our control: tick labels are measured with the
//! embedded font and never overlap, log axes get decade labels (`10⁻³`), and
//! both backends put text on the same baselines. The font (DejaVu Sans, see
//! `assets/fonts/`) is compiled into the binary: no system font or font
//! library is needed at build or run time. The PNG is drawn at twice its size
//! and box-filtered down, which anti-aliases lines and markers.
//!
//! Output is deterministic: the same figure always gives the same bytes.

mod axis;
mod draw;
mod figure;
mod layout;
mod raster;
#[cfg(test)]
mod tests;
mod theme;

use std::path::{Path, PathBuf};

pub use figure::{Figure, LegendPosition, Marker, Series};
use layout::Plan;
use raster::{render_png_pixels, render_svg, with_suffix, write_png};
use theme::ensure_font;

use crate::output::{write_atomic, OutputError};

/// Error while rendering or writing a figure; names the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The figure cannot be drawn (invalid explicit range, font or drawing
    /// failure). `path` is the output file being produced.
    #[error("cannot render {path}: {reason}")]
    Render {
        /// The output file being produced.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A rendered file could not be written.
    #[error(transparent)]
    Write(#[from] OutputError),
}

/// Writes `<stem>.svg` and `<stem>.png` (e.g. stem = `dir/fig2_restitution`),
/// each atomically (temporary sibling, then rename).
///
/// The SVG is 900×600 px nominal with text as `<text>` in "DejaVu Sans,
/// sans-serif"; the PNG is 1200×800 px with the same layout.
///
/// # Errors
///
/// [`PlotError::Render`] for an invalid explicit range (reversed, empty, or
/// non-positive on a log axis) or a drawing/encoding failure;
/// [`PlotError::Write`] when a file cannot be written. Both name the file.
pub fn render(fig: &Figure, stem: &Path) -> Result<(), PlotError> {
    let svg_path = with_suffix(stem, ".svg");
    let png_path = with_suffix(stem, ".png");
    let fail = |path: &Path, reason: String| PlotError::Render {
        path: path.to_path_buf(),
        reason,
    };
    if !ensure_font() {
        return Err(fail(&svg_path, "the embedded font cannot be loaded".into()));
    }
    let plan = Plan::new(fig).map_err(|r| fail(&svg_path, r))?;
    let svg = render_svg(fig, &plan).map_err(|r| fail(&svg_path, r))?;
    let png = render_png_pixels(fig, &plan).map_err(|r| fail(&png_path, r))?;
    write_png(&png, &png_path)?;
    write_atomic(&svg_path, svg.as_bytes())?;
    Ok(())
}
