//! Drawing a planned figure on a plotters backend: frame, grid, ticks,
//! series, legend.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::figure::*;
use super::layout::*;
use super::theme::*;

#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Svg,
    Bitmap,
}

/// A backend's scale and text metrics.
#[derive(Clone, Copy)]
pub(super) struct Canvas {
    pub(super) scale: f64,
    pub(super) kind: Kind,
}

pub(super) type DrawResult = Result<(), String>;

pub(super) fn de(e: impl std::fmt::Display) -> String {
    e.to_string()
}

impl Canvas {
    pub(super) fn px(&self, v: f64) -> i32 {
        (v * self.scale).round() as i32
    }

    pub(super) fn pt(&self, (x, y): (f64, f64)) -> (i32, i32) {
        (self.px(x), self.px(y))
    }

    pub(super) fn stroke(&self, color: RGBColor, width: f64) -> ShapeStyle {
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
    pub(super) fn text<DB: DrawingBackend>(
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

    pub(super) fn line<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        pts: &[(f64, f64)],
        style: ShapeStyle,
    ) -> DrawResult {
        let pts: Vec<(i32, i32)> = pts.iter().map(|&p| self.pt(p)).collect();
        area.draw(&PathElement::new(pts, style)).map_err(de)
    }

    /// Draws `marker` at `(x, y)`, its size grown by `grow` (a halo).
    pub(super) fn marker<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        marker: Marker,
        (x, y): (f64, f64),
        color: RGBColor,
        grow: f64,
    ) -> DrawResult {
        let s = MARKER_SIZE + grow;
        match marker {
            Marker::Circle => area
                .draw(&Circle::new(self.pt((x, y)), self.px(s), color.filled()))
                .map_err(de),
            Marker::Dot => area
                .draw(&Circle::new(
                    self.pt((x, y)),
                    self.px(DOT_SIZE + grow).max(1),
                    color.filled(),
                ))
                .map_err(de),
            Marker::Square => {
                let h = 0.85 * MARKER_SIZE + grow;
                area.draw(&Rectangle::new(
                    [self.pt((x - h, y - h)), self.pt((x + h, y + h))],
                    color.filled(),
                ))
                .map_err(de)
            }
            Marker::Triangle => {
                let r = 1.3 * MARKER_SIZE + 2.0 * grow;
                let c = 0.866 * r;
                let pts = vec![
                    self.pt((x, y - r)),
                    self.pt((x + c, y + 0.5 * r)),
                    self.pt((x - c, y + 0.5 * r)),
                ];
                area.draw(&Polygon::new(pts, color.filled())).map_err(de)
            }
            Marker::Cross => {
                let r = 1.1 * MARKER_SIZE + grow;
                let stroke = self.stroke(color, LINE_WIDTH + 2.0 * grow);
                for (a, b) in [
                    ((x - r, y - r), (x + r, y + r)),
                    ((x - r, y + r), (x + r, y - r)),
                ] {
                    self.line(area, &[a, b], stroke)?;
                }
                Ok(())
            }
            Marker::Diamond => {
                let r = 1.3 * MARKER_SIZE + 2.0 * grow;
                let pts = vec![
                    self.pt((x, y - r)),
                    self.pt((x + r, y)),
                    self.pt((x, y + r)),
                    self.pt((x - r, y)),
                ];
                area.draw(&Polygon::new(pts, color.filled())).map_err(de)
            }
        }
    }
}

pub(super) fn series_markers(style: Style) -> Option<Marker> {
    match style {
        Style::Markers(m) => Some(m),
        Style::Rectangles => Some(Marker::Square),
        Style::Line | Style::DashedLine => None,
    }
}

pub(super) fn draw_figure<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    area.fill(&WHITE).map_err(de)?;
    draw_grid(area, plan, cv)?;
    draw_series(area, fig, plan, cv)?;
    draw_frame(area, plan, cv)?;
    draw_labels(area, fig, plan, cv)?;
    draw_legend(area, fig, plan, cv)
}

/// Minor and major grid lines.
fn draw_grid<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    let (l, r, t, b) = (plan.left, plan.right, plan.top, plan.bottom);
    let x_at = |tx: f64| l + plan.x.frac(tx) * (r - l);
    let y_at = |ty: f64| b - plan.y.frac(ty) * (b - t);
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

    Ok(())
}

/// Every series: lines (clipped, dashed where asked) and markers.
fn draw_series<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    for (s, &color) in fig.series.iter().zip(&plan.colors) {
        let style = cv.stroke(color, LINE_WIDTH);
        let lines = match s.style {
            Style::Line => polylines(plan, &s.points),
            Style::DashedLine => polylines(plan, &s.points)
                .iter()
                .flat_map(|p| dashes(p, DASH))
                .collect(),
            Style::Markers(_) => Vec::new(),
            Style::Rectangles => {
                draw_rectangles(area, plan, cv, &s.points, color)?;
                continue;
            }
        };
        if s.halo {
            let halo = cv.stroke(HALO, LINE_WIDTH + 2.0 * HALO_WIDTH);
            for line in &lines {
                cv.line(area, line, halo)?;
            }
        }
        for line in &lines {
            cv.line(area, line, style)?;
        }
        let visible: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter_map(|&p| plan.data_px(p))
            .filter(|&p| plan.inside(p))
            .collect();
        let marker = match series_markers(s.style) {
            Some(m) => Some(m),
            // A line through a single point would be invisible: show a dot.
            None if lines.is_empty() && visible.len() == 1 => Some(Marker::Circle),
            None => None,
        };
        if let Some(m) = marker {
            if s.halo {
                for &p in &visible {
                    cv.marker(area, m, p, HALO, HALO_WIDTH)?;
                }
            }
            for &p in &visible {
                cv.marker(area, m, p, color, 0.0)?;
            }
        }
        // Tags up and to the right of their points.
        for (&p, tag) in s.points.iter().zip(&s.tags) {
            if let Some((x, y)) = plan.data_px(p).filter(|&q| plan.inside(q)) {
                let (dx, dy) = (MARKER_SIZE + 2.0, MARKER_SIZE + 1.0);
                cv.text(area, tag, TAG_EM, x + dx, y - dy, HPos::Left, false)?;
            }
        }
    }

    Ok(())
}

/// Filled rectangles from pairs of opposite corners, clipped to the plot
/// area.
fn draw_rectangles<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plan: &Plan,
    cv: Canvas,
    corners: &[(f64, f64)],
    color: RGBColor,
) -> DrawResult {
    let clip = |(x, y): (f64, f64)| {
        (
            x.clamp(plan.left, plan.right),
            y.clamp(plan.top, plan.bottom),
        )
    };
    for pair in corners.chunks_exact(2) {
        let (Some(a), Some(b)) = (plan.data_px(pair[0]), plan.data_px(pair[1])) else {
            continue;
        };
        area.draw(&Rectangle::new(
            [cv.pt(clip(a)), cv.pt(clip(b))],
            color.filled(),
        ))
        .map_err(de)?;
    }
    Ok(())
}

/// The frame with its ticks and tick labels.
fn draw_frame<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    let (l, r, t, b) = (plan.left, plan.right, plan.top, plan.bottom);
    let x_at = |tx: f64| l + plan.x.frac(tx) * (r - l);
    let y_at = |ty: f64| b - plan.y.frac(ty) * (b - t);
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

    Ok(())
}

/// Axis labels and title.
fn draw_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
    plan: &Plan,
    cv: Canvas,
) -> DrawResult {
    let (l, r, t, b) = (plan.left, plan.right, plan.top, plan.bottom);
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

    Ok(())
}

/// Centre for a text of width `w` near `cx` that keeps it inside the figure.
pub(super) fn centre_within(cx: f64, w: f64) -> f64 {
    let half = 0.5 * w;
    if w >= W - 2.0 * PAD {
        0.5 * W
    } else {
        cx.clamp(PAD + half, W - PAD - half)
    }
}

pub(super) fn draw_legend<DB: DrawingBackend>(
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
            Style::Markers(_) | Style::Rectangles => {}
        }
        if let Some(m) = series_markers(s.style) {
            // A dot is too small to read in a legend: a full marker there.
            let m = if m == Marker::Dot { Marker::Circle } else { m };
            cv.marker(area, m, (0.5 * (sx0 + sx1), yc), *color, 0.0)?;
        }
        let baseline = yc + 0.5 * CAP * em;
        cv.text(area, label, em, sx1 + gap, baseline, HPos::Left, false)?;
    }
    Ok(())
}

/// Top left corner of a `w`×`h` legend box placed in `corner`.
pub(super) fn legend_origin(plan: &Plan, corner: LegendPosition, w: f64, h: f64) -> (f64, f64) {
    let inset = 10.0;
    if corner == LegendPosition::Outside {
        return (plan.right + LEGEND_GAP, plan.top);
    }
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
pub(super) fn best_corner(fig: &Figure, plan: &Plan, w: f64, h: f64) -> LegendPosition {
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
