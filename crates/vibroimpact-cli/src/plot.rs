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

// A general figure API: not every style, marker or builder is used by the
// report at any given time.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::output::{commit_temp, temp_path, write_atomic, OutputError};

/// Axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Linear axis.
    #[default]
    Linear,
    /// Base-10 logarithmic axis; non-positive values are not drawn.
    Log,
}

/// Marker shape for scatter points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Filled square.
    Square,
    /// Filled upward triangle.
    Triangle,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Solid line through the points.
    Line,
    /// Dashed line through the points.
    DashedLine,
    /// Markers only.
    Markers(Marker),
}

/// Where the legend box goes (inside the plot area).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// Upper left corner.
    UpperLeft,
    /// Upper right corner (default).
    #[default]
    UpperRight,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
    /// The corner where the legend box covers the least data.
    Best,
    /// No legend.
    None,
}

/// One data series of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text; `None` keeps the series out of the legend.
    pub label: Option<String>,
    /// Data points `(x, y)`. Points with a NaN or infinite coordinate, or a
    /// non-positive coordinate on a log axis, are skipped (a line is broken there).
    pub points: Vec<(f64, f64)>,
    /// How the series is drawn.
    pub style: Style,
    /// Palette index (wraps around); `None` takes the next unused palette colour.
    pub color: Option<usize>,
}

impl Series {
    /// A series with the given style; an empty `label` means no legend entry.
    pub fn new(
        label: impl Into<String>,
        points: impl IntoIterator<Item = (f64, f64)>,
        style: Style,
    ) -> Self {
        let label = label.into();
        Self {
            label: (!label.is_empty()).then_some(label),
            points: points.into_iter().collect(),
            style,
            color: None,
        }
    }

    /// A solid line; an empty `label` means no legend entry.
    pub fn line(label: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(label, points, Style::Line)
    }

    /// A dashed line; an empty `label` means no legend entry.
    pub fn dashed(label: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(label, points, Style::DashedLine)
    }

    /// Markers only (scatter); an empty `label` means no legend entry.
    pub fn markers(
        label: impl Into<String>,
        points: impl IntoIterator<Item = (f64, f64)>,
        marker: Marker,
    ) -> Self {
        Self::new(label, points, Style::Markers(marker))
    }

    /// Sets the palette index of the series colour.
    pub fn with_color(mut self, palette_index: usize) -> Self {
        self.color = Some(palette_index);
        self
    }
}

/// Description of one figure: axes, series and legend.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title above the plot (empty: none).
    pub title: String,
    /// Label of the horizontal axis (empty: none).
    pub x_label: String,
    /// Label of the vertical axis (empty: none).
    pub y_label: String,
    /// Scale of the horizontal axis.
    pub x_scale: Scale,
    /// Scale of the vertical axis.
    pub y_scale: Scale,
    /// Explicit x range `(min, max)`; `None`: from the data with a small margin.
    pub x_range: Option<(f64, f64)>,
    /// Explicit y range `(min, max)`; `None`: from the data with a small margin
    /// (only points inside an explicit x range are considered).
    pub y_range: Option<(f64, f64)>,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Legend placement.
    pub legend: LegendPosition,
}

impl Figure {
    /// A figure with linear axes, automatic ranges, no series and the legend upper right.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            x_range: None,
            y_range: None,
            series: Vec::new(),
            legend: LegendPosition::UpperRight,
        }
    }

    /// Makes the x axis logarithmic.
    pub fn log_x(mut self) -> Self {
        self.x_scale = Scale::Log;
        self
    }

    /// Makes the y axis logarithmic.
    pub fn log_y(mut self) -> Self {
        self.y_scale = Scale::Log;
        self
    }

    /// Fixes the x range.
    pub fn x_range(mut self, min: f64, max: f64) -> Self {
        self.x_range = Some((min, max));
        self
    }

    /// Fixes the y range.
    pub fn y_range(mut self, min: f64, max: f64) -> Self {
        self.y_range = Some((min, max));
        self
    }

    /// Sets the legend position.
    pub fn legend_at(mut self, position: LegendPosition) -> Self {
        self.legend = position;
        self
    }

    /// Adds a series (builder style).
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a series.
    pub fn push(&mut self, series: Series) -> &mut Self {
        self.series.push(series);
        self
    }
}

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

// ---------------------------------------------------------------------------
// Look

/// Logical figure size (the SVG's nominal size); all layout is in these units.
const W: f64 = 900.0;
const H: f64 = 600.0;
/// The SVG is drawn at this scale (finer coordinates) and declared 900×600.
const SVG_SCALE: f64 = 2.0;
/// Final PNG size and supersampling factor.
const PNG_W: u32 = 1200;
const PNG_H: u32 = 800;
const SUPERSAMPLE: u32 = 2;

const TITLE_EM: f64 = 24.0;
const LABEL_EM: f64 = 20.0;
const TICK_EM: f64 = 16.0;
const LEGEND_EM: f64 = 16.0;
/// Height of digits and capitals, and of ascenders/descenders, in em (DejaVu Sans).
const CAP: f64 = 0.73;
const ASCENT: f64 = 0.76;
const DESCENT: f64 = 0.24;

const PAD: f64 = 14.0;
const TICK_LEN: f64 = 6.0;
const MINOR_TICK_LEN: f64 = 3.5;
const TICK_GAP: f64 = 5.0;
const LINE_WIDTH: f64 = 2.0;
const FRAME_WIDTH: f64 = 1.25;
const GRID_WIDTH: f64 = 1.0;
const MARKER_SIZE: f64 = 4.5;
const DASH: (f64, f64) = (9.0, 5.0);

const TEXT: RGBColor = RGBColor(20, 20, 20);
const FRAME: RGBColor = RGBColor(40, 40, 40);
const GRID_MAJOR: RGBColor = RGBColor(218, 218, 218);
const GRID_MINOR: RGBColor = RGBColor(238, 238, 238);
const LEGEND_BORDER: RGBColor = RGBColor(150, 150, 150);

/// Okabe–Ito colour-blind-safe palette, yellow last (weak on white).
const PALETTE: [RGBColor; 8] = [
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
const FONT_FAMILY: &str = "DejaVu Sans, sans-serif";
static FONT_BYTES: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
/// (hhea ascender − descender) / units per em of DejaVu Sans: ab_glyph scales
/// fonts by this height, not by the em.
const FONT_HEIGHT_PER_EM: f64 = 2384.0 / 2048.0;

/// Registers the embedded font once; false if it cannot be parsed.
fn ensure_font() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES).is_ok())
}

fn font(size: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::Name(FONT_FAMILY), size, FontStyle::Normal)
}

/// Advance width of `text` in px at `em` px per em.
fn text_width(text: &str, em: f64) -> f64 {
    const K: f64 = 16.0; // measure large: the layout box is in whole pixels
    match font(em * K * FONT_HEIGHT_PER_EM).box_size(text) {
        Ok((w, _)) => f64::from(w) / K,
        Err(_) => 0.6 * em * text.chars().count() as f64,
    }
}

// ---------------------------------------------------------------------------
// Axes: ranges, ticks, labels

/// Data values beyond this magnitude are treated as invalid.
const MAX_ABS: f64 = 1e300;

fn transform(scale: Scale, v: f64) -> Option<f64> {
    if !v.is_finite() || v.abs() > MAX_ABS {
        return None;
    }
    match scale {
        Scale::Linear => Some(v),
        Scale::Log if v > 0.0 => Some(v.log10()),
        Scale::Log => None,
    }
}

/// Range in transformed space (log10 for log axes).
fn axis_range(
    scale: Scale,
    explicit: Option<(f64, f64)>,
    data: &[f64],
    name: &str,
) -> Result<(f64, f64), String> {
    if let Some((lo, hi)) = explicit {
        let (tlo, thi) = match (transform(scale, lo), transform(scale, hi)) {
            (Some(a), Some(b)) if lo < hi => (a, b),
            _ => {
                let kind = if scale == Scale::Log { "log " } else { "" };
                return Err(format!("invalid {kind}{name} range [{lo}, {hi}]"));
            }
        };
        return Ok(widen_degenerate(scale, tlo, thi));
    }
    let mut it = data.iter().copied();
    let Some(first) = it.next() else {
        return Ok((0.0, 1.0)); // linear 0..1, log 1..10
    };
    let (lo, hi) = it.fold((first, first), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = widen_degenerate(scale, lo, hi);
    let margin = 0.05 * (hi - lo);
    Ok((lo - margin, hi + margin))
}

/// Gives a zero or numerically tiny span a visible extent.
fn widen_degenerate(scale: Scale, lo: f64, hi: f64) -> (f64, f64) {
    let mid = 0.5 * (lo + hi);
    if hi - lo > mid.abs() * 1e-9 && hi - lo > 1e-290 {
        return (lo, hi);
    }
    let half = match scale {
        Scale::Log => 0.5,
        Scale::Linear if mid == 0.0 => 1.0,
        Scale::Linear => mid.abs() * 0.1,
    };
    (mid - half, mid + half)
}

/// A tick: position in transformed space and its label.
type Tick = (f64, String);
/// A point in logical px.
type Pt = (f64, f64);

/// Ticks and labels of one axis, in transformed space.
#[derive(Debug, Clone)]
struct AxisPlan {
    lo: f64,
    hi: f64,
    major: Vec<(f64, String)>,
    minor: Vec<f64>,
}

impl AxisPlan {
    fn frac(&self, t: f64) -> f64 {
        (t - self.lo) / (self.hi - self.lo)
    }
}

/// Does a row of labels (centres `pos`, extents `size` along the axis) fit
/// without overlapping?
fn labels_fit(pos: &[f64], size: &[f64], gap: f64) -> bool {
    pos.windows(2)
        .zip(size.windows(2))
        .all(|(p, s)| (p[1] - p[0]).abs() >= 0.5 * (s[0] + s[1]) + gap)
}

/// Chooses ticks for an axis of `length` px. `vertical`: labels are stacked
/// (their extent is the text height) rather than side by side.
fn plan_axis(scale: Scale, lo: f64, hi: f64, length: f64, vertical: bool) -> AxisPlan {
    let fits = |ticks: &[(f64, String)]| {
        let pos: Vec<f64> = ticks
            .iter()
            .map(|(t, _)| (t - lo) / (hi - lo) * length)
            .collect();
        if vertical {
            let size = vec![TICK_EM * CAP; ticks.len()];
            labels_fit(&pos, &size, TICK_EM * 1.6)
        } else {
            let size: Vec<f64> = ticks.iter().map(|(_, s)| text_width(s, TICK_EM)).collect();
            labels_fit(&pos, &size, TICK_EM)
        }
    };
    let max_n = if vertical { 8 } else { 10 };
    let (major, minor) = match scale {
        Scale::Linear => (linear_choice(lo, hi, max_n, &fits), Vec::new()),
        Scale::Log => log_choice(lo, hi, max_n, &fits),
    };
    AxisPlan {
        lo,
        hi,
        major,
        minor,
    }
}

/// Ticks at multiples of a "nice" step (1, 2, 5 × 10^k) with at most
/// `max_n` ticks in `[lo, hi]`; returns the values and the step.
fn nice_ticks(lo: f64, hi: f64, max_n: usize) -> (Vec<f64>, f64) {
    let span = hi - lo;
    let raw = span / max_n.max(1) as f64;
    let mut mag = 10f64.powf(raw.log10().floor());
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * mag;
            let i0 = (lo / step - 1e-9).ceil();
            let i1 = (hi / step + 1e-9).floor();
            if i1 - i0 + 1.0 <= max_n as f64 {
                let ticks = (i0 as i64..=i1 as i64)
                    .map(|i| i as f64 * step)
                    .map(|v| if v == 0.0 { 0.0 } else { v })
                    .collect();
                return (ticks, step);
            }
        }
        mag *= 10.0;
    }
}

fn linear_choice(
    lo: f64,
    hi: f64,
    max_n: usize,
    fits: &dyn Fn(&[Tick]) -> bool,
) -> Vec<(f64, String)> {
    let mut fallback = Vec::new();
    for n in (2..=max_n).rev() {
        let (values, step) = nice_ticks(lo, hi, n);
        let labels = format_linear(&values, step);
        let ticks: Vec<(f64, String)> = values.into_iter().zip(labels).collect();
        if ticks.len() >= 2 && fits(&ticks) {
            return ticks;
        }
        fallback = ticks;
    }
    fallback
}

/// Number of significant decimals a step needs (0.25 → 2, 0.5 → 1, 20 → 0).
fn step_decimals(step: f64) -> i32 {
    let e = step.log10().floor() as i32;
    let mantissa = step / 10f64.powi(e);
    let extra = i32::from((mantissa - mantissa.round()).abs() > 1e-6);
    -e + extra
}

/// Labels for linear ticks with a common format: fixed point for moderate
/// magnitudes, otherwise compact scientific (`2.5×10⁴`, `1×10⁻⁵`).
fn format_linear(values: &[f64], step: f64) -> Vec<String> {
    let max_abs = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let decimals = step_decimals(step);
    let scientific = max_abs >= 1e5 || (max_abs > 0.0 && max_abs < 1e-3) || decimals > 6;
    values
        .iter()
        .map(|&v| {
            if v == 0.0 {
                "0".to_string()
            } else if scientific {
                let exp = v.abs().log10().floor() as i32;
                let digits = (exp + decimals).clamp(0, 15) as usize;
                compact_sci(v, digits)
            } else {
                fix_minus(format!("{:.*}", decimals.max(0) as usize, v))
            }
        })
        .collect()
}

/// `v` as `m×10ᵏ` with at most `digits` mantissa decimals, trailing zeros trimmed.
fn compact_sci(v: f64, digits: usize) -> String {
    let s = format!("{v:.digits$e}");
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    let exp: i64 = exp.parse().unwrap_or(0);
    fix_minus(format!("{mantissa}\u{00D7}{}", decade_label(exp)))
}

/// Typographic minus sign.
fn fix_minus(s: String) -> String {
    s.replace('-', "\u{2212}")
}

/// `10^k` with superscript digits.
fn decade_label(k: i64) -> String {
    let sup: String = k
        .to_string()
        .chars()
        .map(|c| match c {
            '-' => '\u{207B}',
            '0' => '\u{2070}',
            '1' => '\u{00B9}',
            '2' => '\u{00B2}',
            '3' => '\u{00B3}',
            d => char::from_u32(0x2070 + d.to_digit(10).unwrap_or(0)).unwrap_or(d),
        })
        .collect();
    format!("10{sup}")
}

/// Label of `m × 10^k` (m in 1..=9) on a log axis without (only) decade
/// ticks: plain decimals when the whole axis is moderate (`fixed`), else
/// `10ᵏ` / `m×10ᵏ`.
fn mantissa_label(m: u32, k: i64, fixed: bool) -> String {
    if fixed {
        let v = f64::from(m) * 10f64.powi(k as i32);
        fix_minus(format!("{:.*}", (-k).max(0) as usize, v))
    } else if m == 1 {
        decade_label(k)
    } else {
        format!("{m}\u{00D7}{}", decade_label(k))
    }
}

fn log_choice(
    lo: f64,
    hi: f64,
    max_n: usize,
    fits: &dyn Fn(&[Tick]) -> bool,
) -> (Vec<(f64, String)>, Vec<f64>) {
    let inside = |t: f64| t >= lo - 1e-9 && t <= hi + 1e-9;
    let d0 = (lo - 1e-9).ceil() as i64;
    let d1 = (hi + 1e-9).floor() as i64;
    // Three decades or more in view: decade ticks, every `stride` decades.
    if d1 - d0 >= 2 {
        for stride in [1i64, 2, 3, 4, 5, 10, 20, 25, 50, 100] {
            let major: Vec<(f64, String)> = (d0..=d1)
                .filter(|d| d.rem_euclid(stride) == 0)
                .map(|d| (d as f64, decade_label(d)))
                .collect();
            if major.len() < 2 {
                break;
            }
            if major.len() <= max_n && fits(&major) {
                let minor = if stride == 1 && hi - lo <= 15.0 {
                    (d0 - 1..=d1)
                        .flat_map(|d| (2..=9).map(move |m| d as f64 + f64::from(m).log10()))
                        .filter(|&t| inside(t))
                        .collect()
                } else if stride > 1 && d1 - d0 <= 200 {
                    (d0..=d1)
                        .filter(|d| d.rem_euclid(stride) != 0)
                        .map(|d| d as f64)
                        .collect()
                } else {
                    Vec::new()
                };
                return (major, minor);
            }
        }
    }
    // Fewer decades in view: 1-2-5 or 1…9 mantissas.
    let fixed = lo >= -3.0 - 1e-9 && hi < 5.0;
    let mantissa_ticks = |set: &[u32]| -> Vec<(f64, String)> {
        ((lo.floor() as i64 - 1)..=(hi.ceil() as i64))
            .flat_map(|k| set.iter().map(move |&m| (m, k)))
            .map(|(m, k)| (k as f64 + f64::from(m).log10(), mantissa_label(m, k, fixed)))
            .filter(|(t, _)| inside(*t))
            .collect()
    };
    let all: Vec<u32> = (1..=9).collect();
    let coarse = mantissa_ticks(&[1, 2, 5]);
    let fine = mantissa_ticks(&all);
    let minor_of = |major: &[(f64, String)]| -> Vec<f64> {
        fine.iter()
            .map(|(t, _)| *t)
            .filter(|t| !major.iter().any(|(m, _)| (m - t).abs() < 1e-9))
            .collect()
    };
    if coarse.len() >= 3 && fits(&coarse) {
        let minor = minor_of(&coarse);
        return (coarse, minor);
    }
    if d1 - d0 < 1 && fine.len() >= 3 && fits(&fine) {
        return (fine, Vec::new());
    }
    if coarse.len() >= 2 && fits(&coarse) {
        let minor = minor_of(&coarse);
        return (coarse, minor);
    }
    if d1 - d0 == 1 {
        let major = vec![(d0 as f64, decade_label(d0)), (d1 as f64, decade_label(d1))];
        let minor = minor_of(&major);
        return (major, minor);
    }
    // Very narrow: nice ticks in value space.
    let (vlo, vhi) = (10f64.powf(lo), 10f64.powf(hi));
    let mut fallback = Vec::new();
    for n in (2..=max_n).rev() {
        let (values, step) = nice_ticks(vlo, vhi, n);
        let labels = format_linear(&values, step);
        let ticks: Vec<(f64, String)> = values
            .into_iter()
            .zip(labels)
            .filter(|(v, _)| *v > 0.0)
            .map(|(v, s)| (v.log10(), s))
            .collect();
        if ticks.len() >= 2 && fits(&ticks) {
            return (ticks, Vec::new());
        }
        if ticks.len() >= 2 || fallback.is_empty() {
            fallback = ticks;
        }
    }
    (fallback, Vec::new())
}

// ---------------------------------------------------------------------------
// Layout

/// Everything about a figure that does not depend on the backend, in logical px.
struct Plan {
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    x: AxisPlan,
    y: AxisPlan,
    x_scale: Scale,
    y_scale: Scale,
    title_em: f64,
    x_label_em: f64,
    y_label_em: f64,
    colors: Vec<RGBColor>,
}

impl Plan {
    fn new(fig: &Figure) -> Result<Self, String> {
        let valid: Vec<(f64, f64)> = fig
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter_map(|&(x, y)| Some((transform(fig.x_scale, x)?, transform(fig.y_scale, y)?)))
            .collect();
        let (xlo, xhi) = {
            let in_y: Vec<f64> = valid
                .iter()
                .filter(|(_, y)| in_explicit(fig.y_scale, fig.y_range, *y))
                .map(|p| p.0)
                .collect();
            axis_range(fig.x_scale, fig.x_range, &in_y, "x")?
        };
        let (ylo, yhi) = {
            let in_x: Vec<f64> = valid
                .iter()
                .filter(|(x, _)| in_explicit(fig.x_scale, fig.x_range, *x))
                .map(|p| p.1)
                .collect();
            axis_range(fig.y_scale, fig.y_range, &in_x, "y")?
        };

        let fit_em = |text: &str, em: f64, room: f64| {
            let w = text_width(text, em);
            if w > room {
                (em * room / w).max(8.0)
            } else {
                em
            }
        };
        let has = |s: &str| !s.trim().is_empty();
        let title_em = fit_em(&fig.title, TITLE_EM, W - 2.0 * PAD);
        let x_label_em = fit_em(&fig.x_label, LABEL_EM, W - 2.0 * PAD);

        let mut top = PAD + 0.5 * TICK_EM * CAP + 2.0;
        if has(&fig.title) {
            top += (ASCENT + DESCENT) * title_em + 10.0;
        }
        let mut bottom = H - PAD - (TICK_LEN + TICK_GAP + (ASCENT + DESCENT) * TICK_EM);
        if has(&fig.x_label) {
            bottom -= (ASCENT + DESCENT) * x_label_em + 6.0;
        }
        let y_label_em = fit_em(&fig.y_label, LABEL_EM, bottom - top);
        let y = plan_axis(fig.y_scale, ylo, yhi, bottom - top, true);
        let y_tick_w = y
            .major
            .iter()
            .map(|(_, s)| text_width(s, TICK_EM))
            .fold(0.0, f64::max);
        let mut left = PAD + y_tick_w + TICK_GAP + TICK_LEN;
        if has(&fig.y_label) {
            left += (ASCENT + DESCENT) * y_label_em + 8.0;
        }
        // The last x tick label may stick out to the right: shrink until it fits.
        let mut right = W - PAD - 6.0;
        let mut x = plan_axis(fig.x_scale, xlo, xhi, right - left, false);
        for _ in 0..3 {
            let overhang = x
                .major
                .iter()
                .map(|(t, s)| left + x.frac(*t) * (right - left) + 0.5 * text_width(s, TICK_EM))
                .fold(0.0, f64::max)
                - (W - 6.0);
            if overhang <= 0.0 {
                break;
            }
            right -= overhang;
            x = plan_axis(fig.x_scale, xlo, xhi, right - left, false);
        }

        Ok(Self {
            left,
            right,
            top,
            bottom,
            x,
            y,
            x_scale: fig.x_scale,
            y_scale: fig.y_scale,
            title_em,
            x_label_em,
            y_label_em,
            colors: assign_colors(&fig.series),
        })
    }

    /// Logical px of a point given in transformed space.
    fn to_px(&self, (tx, ty): (f64, f64)) -> (f64, f64) {
        (
            self.left + self.x.frac(tx) * (self.right - self.left),
            self.bottom - self.y.frac(ty) * (self.bottom - self.top),
        )
    }

    /// Logical px of a data point, if it can be drawn.
    fn data_px(&self, (x, y): (f64, f64)) -> Option<(f64, f64)> {
        let p = self.to_px((transform(self.x_scale, x)?, transform(self.y_scale, y)?));
        (p.0.is_finite() && p.1.is_finite()).then_some(p)
    }

    fn inside(&self, (x, y): (f64, f64)) -> bool {
        let e = 1e-6;
        x >= self.left - e && x <= self.right + e && y >= self.top - e && y <= self.bottom + e
    }
}

fn in_explicit(scale: Scale, range: Option<(f64, f64)>, t: f64) -> bool {
    match range {
        None => true,
        Some((lo, hi)) => match (transform(scale, lo), transform(scale, hi)) {
            (Some(a), Some(b)) => t >= a.min(b) && t <= a.max(b),
            _ => true,
        },
    }
}

/// Explicit palette indices are honoured; the others take the next palette
/// colour not used explicitly (as long as there is one).
fn assign_colors(series: &[Series]) -> Vec<RGBColor> {
    let n = PALETTE.len();
    let used: Vec<usize> = series
        .iter()
        .filter_map(|s| s.color)
        .map(|c| c % n)
        .collect();
    let free: Vec<usize> = (0..n).filter(|i| !used.contains(i)).collect();
    let order = if free.is_empty() {
        (0..n).collect()
    } else {
        free
    };
    let mut next = 0;
    series
        .iter()
        .map(|s| match s.color {
            Some(c) => PALETTE[c % n],
            None => {
                let c = PALETTE[order[next % order.len()]];
                next += 1;
                c
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------
// Geometry

/// Clips the segment `p`–`q` to the rectangle (Liang–Barsky); returns the
/// clipped end points and whether each is the original one.
fn clip_segment(
    p: (f64, f64),
    q: (f64, f64),
    (l, t, r, b): (f64, f64, f64, f64),
) -> Option<(Pt, Pt, bool, bool)> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut u0, mut u1) = (0.0f64, 1.0f64);
    for (pk, qk) in [(-dx, p.0 - l), (dx, r - p.0), (-dy, p.1 - t), (dy, b - p.1)] {
        if pk == 0.0 {
            if qk < 0.0 {
                return None;
            }
        } else {
            let u = qk / pk;
            if pk < 0.0 {
                u0 = u0.max(u);
            } else {
                u1 = u1.min(u);
            }
        }
    }
    if u0 > u1 {
        return None;
    }
    let at = |u: f64| (p.0 + u * dx, p.1 + u * dy);
    Some((at(u0), at(u1), u0 == 0.0, u1 == 1.0))
}

/// Splits a series into drawable polylines: broken at invalid points and
/// clipped to the plot area.
fn polylines(plan: &Plan, points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let rect = (plan.left, plan.top, plan.right, plan.bottom);
    let mut out = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut flush = |cur: &mut Vec<(f64, f64)>| {
        if cur.len() >= 2 {
            out.push(std::mem::take(cur));
        }
        cur.clear();
    };
    let mut prev: Option<(f64, f64)> = None;
    for &pt in points {
        let px = plan.data_px(pt);
        match (prev, px) {
            (Some(p), Some(q)) => match clip_segment(p, q, rect) {
                None => flush(&mut cur),
                Some((a, b, a_orig, b_orig)) => {
                    if !a_orig || cur.is_empty() {
                        flush(&mut cur);
                        cur.push(a);
                    }
                    cur.push(b);
                    if !b_orig {
                        flush(&mut cur);
                    }
                }
            },
            _ => flush(&mut cur),
        }
        prev = px;
    }
    flush(&mut cur);
    out
}

/// Cuts a polyline into dashes (`on`, `off` lengths), continuing the pattern
/// across vertices.
fn dashes(line: &[(f64, f64)], (on, off): (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut drawing = true;
    let mut left = on; // length left in the current dash or gap
    if let Some(&first) = line.first() {
        cur.push(first);
    }
    for w in line.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
        let mut pos = 0.0;
        while len - pos > left {
            pos += left;
            let u = pos / len;
            let p = (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1));
            if drawing {
                cur.push(p);
                out.push(std::mem::take(&mut cur));
                left = off;
            } else {
                cur.push(p);
                left = on;
            }
            drawing = !drawing;
        }
        left -= len - pos;
        if drawing {
            cur.push(b);
        }
    }
    if drawing && cur.len() >= 2 {
        out.push(cur);
    }
    out
}

// ---------------------------------------------------------------------------
// Drawing

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Svg,
    Bitmap,
}

/// A backend's scale and text metrics.
#[derive(Clone, Copy)]
struct Canvas {
    scale: f64,
    kind: Kind,
}

type DrawResult = Result<(), String>;

fn de(e: impl std::fmt::Display) -> String {
    e.to_string()
}

impl Canvas {
    fn px(&self, v: f64) -> i32 {
        (v * self.scale).round() as i32
    }

    fn pt(&self, (x, y): (f64, f64)) -> (i32, i32) {
        (self.px(x), self.px(y))
    }

    fn stroke(&self, color: RGBColor, width: f64) -> ShapeStyle {
        let px = width * self.scale;
        let px = match self.kind {
            Kind::Svg => px.round().max(1.0),
            // plotters offsets the edges of straight path sections by a
            // truncated half width and the ends by a rounded one: an even width
            // keeps both equal (no kinks on straight lines).
            Kind::Bitmap => ((0.5 * px).round() * 2.0).max(2.0),
        };
        color.stroke_width(px as u32)
    }

    /// Draws `text` with its baseline at `baseline` and its horizontal anchor
    /// `h` at `x`. With `rotated`, the text runs bottom to top, `x` is the
    /// vertical anchor and `baseline` the horizontal baseline position.
    #[allow(clippy::too_many_arguments)]
    fn text<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        text: &str,
        em: f64,
        x: f64,
        baseline: f64,
        h: HPos,
        rotated: bool,
    ) -> DrawResult {
        if text.is_empty() {
            return Ok(());
        }
        // SVG: font-size = size / 1.24 and dy = 0.76em for a top anchor.
        // ab_glyph: the font is scaled by its ascent-descent height and the
        // baseline lands half a size below a top anchor.
        let (size, offset) = match self.kind {
            Kind::Svg => (em * 1.24, 0.76 * em),
            Kind::Bitmap => (em * FONT_HEIGHT_PER_EM, 0.5 * em * FONT_HEIGHT_PER_EM),
        };
        let mut style = TextStyle::from(font(size * self.scale))
            .color(&TEXT)
            .pos(Pos::new(h, VPos::Top));
        let pos = if rotated {
            style = style.transform(FontTransform::Rotate270);
            (self.px(baseline - offset), self.px(x))
        } else {
            (self.px(x), self.px(baseline - offset))
        };
        area.draw_text(text, &style, pos).map_err(de)
    }

    fn line<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        pts: &[(f64, f64)],
        style: ShapeStyle,
    ) -> DrawResult {
        let pts: Vec<(i32, i32)> = pts.iter().map(|&p| self.pt(p)).collect();
        area.draw(&PathElement::new(pts, style)).map_err(de)
    }

    fn marker<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        marker: Marker,
        (x, y): (f64, f64),
        color: RGBColor,
    ) -> DrawResult {
        let s = MARKER_SIZE;
        match marker {
            Marker::Circle => area
                .draw(&Circle::new(self.pt((x, y)), self.px(s), color.filled()))
                .map_err(de),
            Marker::Square => {
                let h = 0.85 * s;
                area.draw(&Rectangle::new(
                    [self.pt((x - h, y - h)), self.pt((x + h, y + h))],
                    color.filled(),
                ))
                .map_err(de)
            }
            Marker::Triangle => {
                let r = 1.3 * s;
                let c = 0.866 * r;
                let pts = vec![
                    self.pt((x, y - r)),
                    self.pt((x + c, y + 0.5 * r)),
                    self.pt((x - c, y + 0.5 * r)),
                ];
                area.draw(&Polygon::new(pts, color.filled())).map_err(de)
            }
        }
    }
}

fn series_markers(style: Style) -> Option<Marker> {
    match style {
        Style::Markers(m) => Some(m),
        Style::Line | Style::DashedLine => None,
    }
}

fn draw_figure<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    area.fill(&WHITE).map_err(de)?;
    let (l, r, t, b) = (plan.left, plan.right, plan.top, plan.bottom);
    let x_at = |tx: f64| l + plan.x.frac(tx) * (r - l);
    let y_at = |ty: f64| b - plan.y.frac(ty) * (b - t);

    // Grid.
    let minor = cv.stroke(GRID_MINOR, GRID_WIDTH);
    let major = cv.stroke(GRID_MAJOR, GRID_WIDTH);
    for &tx in &plan.x.minor {
        cv.line(area, &[(x_at(tx), t), (x_at(tx), b)], minor)?;
    }
    for &ty in &plan.y.minor {
        cv.line(area, &[(l, y_at(ty)), (r, y_at(ty))], minor)?;
    }
    for (tx, _) in &plan.x.major {
        cv.line(area, &[(x_at(*tx), t), (x_at(*tx), b)], major)?;
    }
    for (ty, _) in &plan.y.major {
        cv.line(area, &[(l, y_at(*ty)), (r, y_at(*ty))], major)?;
    }

    // Series.
    for (s, &color) in fig.series.iter().zip(&plan.colors) {
        let style = cv.stroke(color, LINE_WIDTH);
        let lines = match s.style {
            Style::Line => polylines(plan, &s.points),
            Style::DashedLine => polylines(plan, &s.points)
                .iter()
                .flat_map(|p| dashes(p, DASH))
                .collect(),
            Style::Markers(_) => Vec::new(),
        };
        for line in &lines {
            cv.line(area, line, style)?;
        }
        let visible: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter_map(|&p| plan.data_px(p))
            .filter(|&p| plan.inside(p))
            .collect();
        match series_markers(s.style) {
            Some(m) => {
                for &p in &visible {
                    cv.marker(area, m, p, color)?;
                }
            }
            // A line through a single point would be invisible: show a dot.
            None if lines.is_empty() && visible.len() == 1 => {
                cv.marker(area, Marker::Circle, visible[0], color)?;
            }
            None => {}
        }
    }

    // Frame and ticks.
    let frame = cv.stroke(FRAME, FRAME_WIDTH);
    cv.line(area, &[(l, t), (r, t), (r, b), (l, b), (l, t)], frame)?;
    for &tx in &plan.x.minor {
        cv.line(
            area,
            &[(x_at(tx), b), (x_at(tx), b + MINOR_TICK_LEN)],
            frame,
        )?;
    }
    for &ty in &plan.y.minor {
        cv.line(
            area,
            &[(l - MINOR_TICK_LEN, y_at(ty)), (l, y_at(ty))],
            frame,
        )?;
    }
    let tick_baseline = b + TICK_LEN + TICK_GAP + ASCENT * TICK_EM;
    for (tx, label) in &plan.x.major {
        let x = x_at(*tx);
        cv.line(area, &[(x, b), (x, b + TICK_LEN)], frame)?;
        cv.text(area, label, TICK_EM, x, tick_baseline, HPos::Center, false)?;
    }
    for (ty, label) in &plan.y.major {
        let y = y_at(*ty);
        cv.line(area, &[(l - TICK_LEN, y), (l, y)], frame)?;
        let baseline = y + 0.5 * CAP * TICK_EM;
        let x = l - TICK_LEN - TICK_GAP;
        cv.text(area, label, TICK_EM, x, baseline, HPos::Right, false)?;
    }

    // Axis labels and title.
    let (cx, cy) = (0.5 * (l + r), 0.5 * (t + b));
    let x_label_baseline = H - PAD - DESCENT * plan.x_label_em;
    let x_label_w = text_width(&fig.x_label, plan.x_label_em);
    let x_label_x = centre_within(cx, x_label_w);
    cv.text(
        area,
        &fig.x_label,
        plan.x_label_em,
        x_label_x,
        x_label_baseline,
        HPos::Center,
        false,
    )?;
    let y_label_baseline = PAD + ASCENT * plan.y_label_em;
    cv.text(
        area,
        &fig.y_label,
        plan.y_label_em,
        cy,
        y_label_baseline,
        HPos::Center,
        true,
    )?;
    let title_baseline = PAD + ASCENT * plan.title_em;
    let title_x = centre_within(cx, text_width(&fig.title, plan.title_em));
    cv.text(
        area,
        &fig.title,
        plan.title_em,
        title_x,
        title_baseline,
        HPos::Center,
        false,
    )?;

    draw_legend(area, fig, plan, cv)
}

/// Centre for a text of width `w` near `cx` that keeps it inside the figure.
fn centre_within(cx: f64, w: f64) -> f64 {
    let half = 0.5 * w;
    if w >= W - 2.0 * PAD {
        0.5 * W
    } else {
        cx.clamp(PAD + half, W - PAD - half)
    }
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    if fig.legend == LegendPosition::None {
        return Ok(());
    }
    let entries: Vec<(&Series, RGBColor, &str)> = fig
        .series
        .iter()
        .zip(&plan.colors)
        .filter_map(|(s, &c)| {
            let label = s.label.as_deref().filter(|l| !l.trim().is_empty())?;
            let drawable = s.points.iter().any(|&p| plan.data_px(p).is_some());
            drawable.then_some((s, c, label))
        })
        .collect();
    if entries.is_empty() {
        return Ok(());
    }
    let em = LEGEND_EM;
    let pad = 0.6 * em;
    let sample = 2.4 * em;
    let gap = 0.5 * em;
    let row = 1.45 * em;
    let text_w = entries
        .iter()
        .map(|(_, _, label)| text_width(label, em))
        .fold(0.0, f64::max);
    let w = 2.0 * pad + sample + gap + text_w;
    let h = 2.0 * pad + row * entries.len() as f64 - (row - em);
    let corner = match fig.legend {
        LegendPosition::Best => best_corner(fig, plan, w, h),
        other => other,
    };
    let (x0, y0) = legend_origin(plan, corner, w, h);
    area.draw(&Rectangle::new(
        [cv.pt((x0, y0)), cv.pt((x0 + w, y0 + h))],
        WHITE.filled(),
    ))
    .map_err(de)?;
    area.draw(&Rectangle::new(
        [cv.pt((x0, y0)), cv.pt((x0 + w, y0 + h))],
        cv.stroke(LEGEND_BORDER, 1.0),
    ))
    .map_err(de)?;
    for (i, (s, color, label)) in entries.iter().enumerate() {
        let yc = y0 + pad + 0.5 * em + row * i as f64;
        let (sx0, sx1) = (x0 + pad, x0 + pad + sample);
        let style = cv.stroke(*color, LINE_WIDTH);
        match s.style {
            Style::Line => cv.line(area, &[(sx0, yc), (sx1, yc)], style)?,
            Style::DashedLine => {
                for d in dashes(&[(sx0, yc), (sx1, yc)], (0.9 * DASH.0, 0.6 * DASH.1)) {
                    cv.line(area, &d, style)?;
                }
            }
            Style::Markers(_) => {}
        }
        if let Some(m) = series_markers(s.style) {
            cv.marker(area, m, (0.5 * (sx0 + sx1), yc), *color)?;
        }
        let baseline = yc + 0.5 * CAP * em;
        cv.text(area, label, em, sx1 + gap, baseline, HPos::Left, false)?;
    }
    Ok(())
}

/// Top left corner of a `w`×`h` legend box placed in `corner`.
fn legend_origin(plan: &Plan, corner: LegendPosition, w: f64, h: f64) -> (f64, f64) {
    let inset = 10.0;
    let x0 = match corner {
        LegendPosition::UpperLeft | LegendPosition::LowerLeft => plan.left + inset,
        _ => plan.right - inset - w,
    };
    let y0 = match corner {
        LegendPosition::LowerLeft | LegendPosition::LowerRight => plan.bottom - inset - h,
        _ => plan.top + inset,
    };
    (x0, y0)
}

/// The corner whose legend box is crossed by the fewest line segments and
/// markers (ties: upper right, upper left, lower right, lower left).
fn best_corner(fig: &Figure, plan: &Plan, w: f64, h: f64) -> LegendPosition {
    let corners = [
        LegendPosition::UpperRight,
        LegendPosition::UpperLeft,
        LegendPosition::LowerRight,
        LegendPosition::LowerLeft,
    ];
    let margin = 4.0;
    let mut best = (usize::MAX, LegendPosition::UpperRight);
    for corner in corners {
        let (x0, y0) = legend_origin(plan, corner, w, h);
        let rect = (x0 - margin, y0 - margin, x0 + w + margin, y0 + h + margin);
        let inside = |(x, y): (f64, f64)| x >= rect.0 && x <= rect.2 && y >= rect.1 && y <= rect.3;
        let mut hits = 0;
        for s in &fig.series {
            if series_markers(s.style).is_some() {
                hits += s
                    .points
                    .iter()
                    .filter_map(|&p| plan.data_px(p))
                    .filter(|&p| inside(p))
                    .count();
            }
            if !matches!(s.style, Style::Markers(_)) {
                for line in polylines(plan, &s.points) {
                    hits += line
                        .windows(2)
                        .filter(|seg| clip_segment(seg[0], seg[1], rect).is_some())
                        .count();
                }
            }
        }
        if hits < best.0 {
            best = (hits, corner);
        }
    }
    best.1
}

// ---------------------------------------------------------------------------
// Backends and files

fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

fn render_svg(fig: &Figure, plan: &Plan) -> Result<String, String> {
    let size = ((W * SVG_SCALE) as u32, (H * SVG_SCALE) as u32);
    let mut svg = String::new();
    {
        let area = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let cv = Canvas {
            scale: SVG_SCALE,
            kind: Kind::Svg,
        };
        draw_figure(&area, fig, plan, cv)?;
        area.present().map_err(de)?;
    }
    // Declare the nominal size; the viewBox keeps the finer coordinates.
    let from = format!("width=\"{}\" height=\"{}\"", size.0, size.1);
    let to = format!("width=\"{}\" height=\"{}\"", W as u32, H as u32);
    Ok(svg.replacen(&from, &to, 1))
}

/// The final PNG pixels (RGB, `PNG_W` × `PNG_H`), drawn supersampled.
fn render_png_pixels(fig: &Figure, plan: &Plan) -> Result<Vec<u8>, String> {
    let (w, h) = (PNG_W * SUPERSAMPLE, PNG_H * SUPERSAMPLE);
    let mut big = vec![255u8; (w * h * 3) as usize];
    {
        let area = BitMapBackend::with_buffer(&mut big, (w, h)).into_drawing_area();
        let cv = Canvas {
            scale: f64::from(w) / W,
            kind: Kind::Bitmap,
        };
        draw_figure(&area, fig, plan, cv)?;
        area.present().map_err(de)?;
    }
    Ok(downsample(&big, w, h, SUPERSAMPLE))
}

/// Box filter: averages `k`×`k` blocks of an RGB image.
fn downsample(src: &[u8], w: u32, h: u32, k: u32) -> Vec<u8> {
    let (w, h, k) = (w as usize, h as usize, k as usize);
    let (ow, oh) = (w / k, h / k);
    let n = (k * k) as u32;
    let mut out = vec![0u8; ow * oh * 3];
    for oy in 0..oh {
        for ox in 0..ow {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..k {
                    let row = (oy * k + dy) * w;
                    for dx in 0..k {
                        sum += u32::from(src[(row + ox * k + dx) * 3 + c]);
                    }
                }
                out[(oy * ow + ox) * 3 + c] = ((sum + n / 2) / n) as u8;
            }
        }
    }
    out
}

/// Encodes `pixels` as PNG at `path`: written to a temporary sibling (whose
/// name ends in `.png`, as the encoder picks the format from it), synced, renamed.
fn write_png(pixels: &[u8], path: &Path) -> Result<(), PlotError> {
    let tmp = with_suffix(&temp_path(path), ".png");
    let encoded = (|| {
        let mut backend = BitMapBackend::new(&tmp, (PNG_W, PNG_H));
        backend
            .blit_bitmap((0, 0), (PNG_W, PNG_H), pixels)
            .map_err(de)?;
        backend.present().map_err(de)
    })();
    let synced = encoded.and_then(|()| {
        std::fs::File::open(&tmp)
            .and_then(|f| f.sync_all())
            .map_err(de)
    });
    if let Err(reason) = synced {
        let _ = std::fs::remove_file(&tmp);
        return Err(PlotError::Render {
            path: path.to_path_buf(),
            reason,
        });
    }
    commit_temp(&tmp, path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "vibroimpact-plot-{name}-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn sample_figure() -> Figure {
        let curve: Vec<(f64, f64)> = (0..=100)
            .map(|i| {
                let v = 10f64.powf(-3.0 + 5.0 * f64::from(i) / 100.0);
                (v, 0.9 - 0.3 * (1.0 + v.ln() / 5.0).tanh())
            })
            .collect();
        let scatter: Vec<(f64, f64)> = curve
            .iter()
            .step_by(10)
            .map(|&(v, e)| (v, e + 0.02))
            .collect();
        let reference: Vec<(f64, f64)> = curve.iter().map(|&(v, _)| (v, 0.75)).collect();
        Figure::new(
            "Restitution vs impact velocity",
            "impact velocity V [m/s]",
            "e",
        )
        .log_x()
        .with_series(Series::line("model", curve))
        .with_series(Series::markers("simulation", scatter, Marker::Circle))
        .with_series(Series::dashed("reference", reference))
    }

    fn assert_png(path: &Path) {
        let bytes = std::fs::read(path).unwrap();
        assert!(
            bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            "not a PNG: {path:?}"
        );
        assert!(
            bytes.len() > 10_000,
            "suspiciously small PNG: {}",
            bytes.len()
        );
        // IHDR: width and height.
        assert_eq!(&bytes[12..16], b"IHDR");
        assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), PNG_W);
        assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), PNG_H);
    }

    fn no_temp_files(dir: &Path) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.contains(".tmp"), "temporary file left: {name}");
        }
    }

    #[test]
    fn renders_svg_and_png() {
        let dir = temp_dir("basic");
        let stem = dir.join("fig_restitution");
        render(&sample_figure(), &stem).unwrap();
        let svg = std::fs::read_to_string(dir.join("fig_restitution.svg")).unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("Restitution vs impact velocity"));
        for label in [
            "model",
            "simulation",
            "reference",
            "impact velocity V [m/s]",
        ] {
            assert!(svg.contains(label), "missing {label}");
        }
        assert!(svg.contains("font-family=\"DejaVu Sans, sans-serif\""));
        assert!(svg.contains("width=\"900\" height=\"600\""));
        // Decade labels on the log axis.
        assert!(svg.contains("10\u{207B}\u{00B3}") && svg.contains("10\u{00B2}"));
        assert_png(&dir.join("fig_restitution.png"));
        no_temp_files(&dir);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn png_text_is_rendered() {
        // Same figure with and without text: the text must change the pixels.
        // Dark pixels above the plot area: only the title can be there.
        let dark_above_plot = |fig: &Figure| {
            assert!(ensure_font());
            let plan = Plan::new(fig).unwrap();
            let pixels = render_png_pixels(fig, &plan).unwrap();
            let rows = ((plan.top - TICK_EM) * f64::from(PNG_H) / H) as usize;
            pixels[..PNG_W as usize * 3 * rows]
                .iter()
                .filter(|&&v| v < 128)
                .count()
        };
        let titled = Figure::new("TITLE", "", "").legend_at(LegendPosition::None);
        let blank = Figure::new("", "", "").legend_at(LegendPosition::None);
        let n = dark_above_plot(&titled);
        assert!(n > 300, "title not drawn: {n} dark pixels");
        assert_eq!(dark_above_plot(&blank), 0);
    }

    #[test]
    fn deterministic() {
        let dir = temp_dir("det");
        let fig = sample_figure().log_y();
        render(&fig, &dir.join("a")).unwrap();
        render(&fig, &dir.join("b")).unwrap();
        for ext in ["svg", "png"] {
            let a = std::fs::read(dir.join(format!("a.{ext}"))).unwrap();
            let b = std::fs::read(dir.join(format!("b.{ext}"))).unwrap();
            assert_eq!(a, b, "{ext} differs");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn edge_cases_do_not_panic() {
        let dir = temp_dir("edge");
        let nan = f64::NAN;
        let inf = f64::INFINITY;
        let figures = vec![
            Figure::new("empty", "x", "y"),
            Figure::new("empty series", "x", "y").with_series(Series::line("none", vec![])),
            Figure::new("single point", "x", "y")
                .with_series(Series::line("one", vec![(1.0, 2.0)])),
            Figure::new("single marker", "x", "y")
                .log_x()
                .log_y()
                .with_series(Series::markers("one", vec![(3.0, 3.0)], Marker::Triangle)),
            Figure::new("constant", "x", "y")
                .with_series(Series::line("c", (0..10).map(|i| (f64::from(i), 5.0)))),
            Figure::new("zero constant", "x", "y")
                .with_series(Series::line("c", vec![(0.0, 0.0), (0.0, 0.0)])),
            Figure::new("nan and inf", "x", "y").with_series(Series::line(
                "bad",
                vec![
                    (0.0, 1.0),
                    (nan, 2.0),
                    (1.0, inf),
                    (2.0, 3.0),
                    (3.0, -inf),
                    (4.0, 2.0),
                ],
            )),
            Figure::new("all invalid on log", "x", "y")
                .log_x()
                .with_series(Series::line("neg", vec![(-1.0, 1.0), (0.0, 2.0)])),
            Figure::new("tiny numbers", "x", "y").with_series(Series::markers(
                "tiny",
                (1..20).map(|i| (f64::from(i) * 1e-7, f64::from(i) * 3e-9)),
                Marker::Square,
            )),
            Figure::new("huge numbers", "x", "y").with_series(Series::line(
                "huge",
                (1..20).map(|i| (f64::from(i) * 2.5e4, f64::from(i) * 1e12)),
            )),
            Figure::new("very wide log", "x", "y")
                .log_x()
                .log_y()
                .with_series(Series::line(
                    "wide",
                    (0..50).map(|i| (10f64.powi(i * 6 - 150), 10f64.powi(i - 25))),
                )),
            Figure::new("narrow log", "x", "y")
                .log_x()
                .log_y()
                .with_series(Series::line(
                    "narrow",
                    (0..20).map(|i| (1.0 + f64::from(i) * 1e-4, 2.0 + f64::from(i) * 1e-3)),
                )),
            Figure::new("nearly constant", "x", "y").with_series(Series::line(
                "n",
                (0..20).map(|i| (f64::from(i), 1e16 + f64::from(i))),
            )),
            Figure::new("outside explicit range", "x", "y")
                .x_range(0.0, 1.0)
                .y_range(0.0, 1.0)
                .with_series(Series::markers(
                    "out",
                    vec![
                        (-5.0, 0.5),
                        (0.5, 0.5),
                        (0.5, 9.0),
                        (1e300, -1e300),
                        (0.7, 0.2),
                    ],
                    Marker::Circle,
                )),
            Figure::new("extreme values", "x", "y").with_series(Series::line(
                "x",
                vec![
                    (f64::MAX, 1.0),
                    (-f64::MAX, -1.0),
                    (0.0, 0.0),
                    (1.0, f64::MIN_POSITIVE),
                ],
            )),
            Figure::new("", "", "")
                .legend_at(LegendPosition::LowerLeft)
                .with_series(Series::dashed("d", vec![(0.0, 0.0), (1.0, 1.0)]).with_color(17)),
        ];
        for (i, fig) in figures.iter().enumerate() {
            let stem = dir.join(format!("edge{i}"));
            render(fig, &stem).unwrap_or_else(|e| panic!("{}: {e}", fig.title));
            assert_png(&with_suffix(&stem, ".png"));
        }
        no_temp_files(&dir);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn invalid_explicit_range_is_an_error_naming_the_file() {
        let dir = temp_dir("invalid");
        let stem = dir.join("bad");
        let fig = Figure::new("t", "x", "y").log_x().x_range(0.0, 1.0);
        let err = render(&fig, &stem).unwrap_err();
        assert!(err.to_string().contains("bad.svg"), "{err}");
        let fig = Figure::new("t", "x", "y").y_range(2.0, 1.0);
        assert!(render(&fig, &stem).is_err());
        assert!(std::fs::read_dir(&dir).unwrap().next().is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tick_labels_are_compact() {
        let (v, step) = nice_ticks(0.0, 1e-5, 6);
        let labels = format_linear(&v, step);
        assert_eq!(labels[0], "0");
        assert!(
            labels.contains(&"1\u{00D7}10\u{207B}\u{2075}".to_string()),
            "{labels:?}"
        );
        let (v, step) = nice_ticks(0.0, 1e5, 5);
        let labels = format_linear(&v, step);
        assert_eq!(labels, ["0", "5\u{00D7}10\u{2074}", "1\u{00D7}10\u{2075}"]);
        let labels = format_linear(&[1.5e7, 2.5e7], 5e6);
        assert_eq!(labels, ["1.5\u{00D7}10\u{2077}", "2.5\u{00D7}10\u{2077}"]);
        let (v, step) = nice_ticks(-1.0, 1.0, 5);
        assert_eq!(
            format_linear(&v, step),
            ["\u{2212}1.0", "\u{2212}0.5", "0", "0.5", "1.0"]
        );
        assert_eq!(decade_label(-3), "10\u{207B}\u{00B3}");
        assert_eq!(decade_label(10), "10\u{00B9}\u{2070}");
    }

    #[test]
    fn log_axis_labels_do_not_overlap() {
        assert!(ensure_font());
        for (lo, hi) in [
            (-3.0, 2.0),
            (-30.0, 30.0),
            (0.1, 0.9),
            (0.0, 0.01),
            (-150.0, 150.0),
        ] {
            for length in [200.0, 700.0] {
                let plan = plan_axis(Scale::Log, lo, hi, length, false);
                assert!(plan.major.len() >= 2, "{lo}..{hi}: {:?}", plan.major);
                let pos: Vec<f64> = plan
                    .major
                    .iter()
                    .map(|(t, _)| plan.frac(*t) * length)
                    .collect();
                let size: Vec<f64> = plan
                    .major
                    .iter()
                    .map(|(_, s)| text_width(s, TICK_EM))
                    .collect();
                assert!(
                    labels_fit(&pos, &size, 0.0),
                    "{lo}..{hi} @ {length}: {:?}",
                    plan.major
                );
            }
        }
    }

    #[test]
    fn clipping_and_dashes() {
        let rect = (0.0, 0.0, 10.0, 10.0);
        let (a, b, ao, bo) = clip_segment((-5.0, 5.0), (5.0, 5.0), rect).unwrap();
        assert_eq!((a, b, ao, bo), ((0.0, 5.0), (5.0, 5.0), false, true));
        assert!(clip_segment((-5.0, -5.0), (-1.0, 20.0), rect).is_none());
        let d = dashes(&[(0.0, 0.0), (20.0, 0.0)], (4.0, 2.0));
        assert_eq!(d.len(), 4);
        assert_eq!(d[1], vec![(6.0, 0.0), (10.0, 0.0)]);
    }
}
