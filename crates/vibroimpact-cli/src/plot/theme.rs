//! The look of every figure: sizes, fonts, colours.

use plotters::prelude::*;
use plotters::style::register_font;
use std::sync::OnceLock;

// ---------------------------------------------------------------------------
// Look

/// Logical figure size (the SVG's nominal size); all layout is in these units.
pub(super) const W: f64 = 900.0;
pub(super) const H: f64 = 600.0;
/// The SVG is drawn at this scale (finer coordinates) and declared 900×600.
pub(super) const SVG_SCALE: f64 = 2.0;
/// Final PNG size and supersampling factor.
pub(super) const PNG_W: u32 = 1200;
pub(super) const PNG_H: u32 = 800;
pub(super) const SUPERSAMPLE: u32 = 2;

pub(super) const TITLE_EM: f64 = 24.0;
pub(super) const LABEL_EM: f64 = 20.0;
pub(super) const TICK_EM: f64 = 16.0;
pub(super) const LEGEND_EM: f64 = 16.0;
/// Text beside a marker (a special point's label).
pub(super) const TAG_EM: f64 = 12.0;
/// Height of digits and capitals, and of ascenders/descenders, in em (DejaVu Sans).
pub(super) const CAP: f64 = 0.73;
pub(super) const ASCENT: f64 = 0.76;
pub(super) const DESCENT: f64 = 0.24;

pub(super) const PAD: f64 = 14.0;
pub(super) const TICK_LEN: f64 = 6.0;
pub(super) const MINOR_TICK_LEN: f64 = 3.5;
pub(super) const TICK_GAP: f64 = 5.0;
pub(super) const LINE_WIDTH: f64 = 2.0;
pub(super) const FRAME_WIDTH: f64 = 1.25;
pub(super) const GRID_WIDTH: f64 = 1.0;
pub(super) const MARKER_SIZE: f64 = 4.5;
/// Radius of a [`Marker::Dot`](super::Marker::Dot).
pub(super) const DOT_SIZE: f64 = 1.3;
/// Width of a halo on each side of a line or marker, and its colour.
pub(super) const HALO_WIDTH: f64 = 1.5;
pub(super) const HALO: RGBColor = RGBColor(255, 255, 255);
pub(super) const DASH: (f64, f64) = (9.0, 5.0);

pub(super) const TEXT: RGBColor = RGBColor(20, 20, 20);
pub(super) const FRAME: RGBColor = RGBColor(40, 40, 40);
pub(super) const GRID_MAJOR: RGBColor = RGBColor(218, 218, 218);
pub(super) const GRID_MINOR: RGBColor = RGBColor(238, 238, 238);
pub(super) const LEGEND_BORDER: RGBColor = RGBColor(150, 150, 150);

/// Okabe–Ito colour-blind-safe palette, yellow last (weak on white).
pub(super) const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(230, 159, 0),   // orange
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
    RGBColor(240, 228, 66),  // yellow
];

// ---------------------------------------------------------------------------
// Font

/// Family name the font is registered under; also written into the SVG.
pub(super) const FONT_FAMILY: &str = "DejaVu Sans, sans-serif";
pub(super) static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
/// (hhea ascender − descender) / units per em of DejaVu Sans: ab_glyph scales
/// fonts by this height, not by the em.
pub(super) const FONT_HEIGHT_PER_EM: f64 = 2384.0 / 2048.0;

/// Registers the embedded font once; false if it cannot be parsed.
pub(super) fn ensure_font() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES).is_ok())
}

pub(super) fn font(size: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::Name(FONT_FAMILY), size, FontStyle::Normal)
}

/// Advance width of `text` in px at `em` px per em.
pub(super) fn text_width(text: &str, em: f64) -> f64 {
    const K: f64 = 16.0; // measure large: the layout box is in whole pixels
    match font(em * K * FONT_HEIGHT_PER_EM).box_size(text) {
        Ok((w, _)) => f64::from(w) / K,
        Err(_) => 0.6 * em * text.chars().count() as f64,
    }
}

// ---------------------------------------------------------------------------
// Axes: ranges, ticks, labels
