//! The layout of a figure (plot area, axes, colours) and the geometry of
//! its series (clipping, dashes).

use plotters::prelude::*;

use super::axis::*;
use super::figure::*;
use super::theme::*;

/// Everything about a figure that does not depend on the backend, in logical px.
pub(super) struct Plan {
    pub(super) left: f64,
    pub(super) right: f64,
    pub(super) top: f64,
    pub(super) bottom: f64,
    pub(super) x: AxisPlan,
    pub(super) y: AxisPlan,
    pub(super) x_scale: Scale,
    pub(super) y_scale: Scale,
    pub(super) title_em: f64,
    pub(super) x_label_em: f64,
    pub(super) y_label_em: f64,
    pub(super) colors: Vec<RGBColor>,
}

impl Plan {
    pub(super) fn new(fig: &Figure) -> Result<Self, String> {
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
        // The last x tick label may stick out to the right: shrink until it
        // fits (and leave room for a legend outside).
        let outside = match fig.legend {
            LegendPosition::Outside => legend_size(fig).map_or(0.0, |(w, _)| w + LEGEND_GAP),
            _ => 0.0,
        };
        let mut right = W - PAD - 6.0 - outside;
        let mut x = plan_axis(fig.x_scale, xlo, xhi, right - left, false);
        for _ in 0..3 {
            let overhang = x
                .major
                .iter()
                .map(|(t, s)| left + x.frac(*t) * (right - left) + 0.5 * text_width(s, TICK_EM))
                .fold(0.0, f64::max)
                - (W - 6.0 - outside);
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
    pub(super) fn to_px(&self, (tx, ty): (f64, f64)) -> (f64, f64) {
        (
            self.left + self.x.frac(tx) * (self.right - self.left),
            self.bottom - self.y.frac(ty) * (self.bottom - self.top),
        )
    }

    /// Logical px of a data point, if it can be drawn.
    pub(super) fn data_px(&self, (x, y): (f64, f64)) -> Option<(f64, f64)> {
        let p = self.to_px((transform(self.x_scale, x)?, transform(self.y_scale, y)?));
        (p.0.is_finite() && p.1.is_finite()).then_some(p)
    }

    pub(super) fn inside(&self, (x, y): (f64, f64)) -> bool {
        let e = 1e-6;
        x >= self.left - e && x <= self.right + e && y >= self.top - e && y <= self.bottom + e
    }
}

pub(super) fn in_explicit(scale: Scale, range: Option<(f64, f64)>, t: f64) -> bool {
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
pub(super) fn assign_colors(series: &[Series]) -> Vec<RGBColor> {
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
pub(super) fn clip_segment(
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
pub(super) fn polylines(plan: &Plan, points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
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
pub(super) fn dashes(line: &[(f64, f64)], (on, off): (f64, f64)) -> Vec<Vec<(f64, f64)>> {
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

/// Gap between the plot area and a legend outside it.
pub(super) const LEGEND_GAP: f64 = 12.0;

/// The legend's labelled series with a finite point, in order.
pub(super) fn legend_entries(fig: &Figure) -> Vec<(usize, &str)> {
    fig.series
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            let label = s.label.as_deref().filter(|l| !l.trim().is_empty())?;
            let finite = s.points.iter().any(|p| p.0.is_finite() && p.1.is_finite());
            finite.then_some((i, label))
        })
        .collect()
}

/// Width and height of the legend box of `fig` (None: no entries).
pub(super) fn legend_size(fig: &Figure) -> Option<(f64, f64)> {
    let entries = legend_entries(fig);
    if entries.is_empty() {
        return None;
    }
    let em = LEGEND_EM;
    let text_w = entries
        .iter()
        .map(|(_, label)| text_width(label, em))
        .fold(0.0, f64::max);
    let w = 2.0 * 0.6 * em + 2.4 * em + 0.5 * em + text_w;
    let h = 2.0 * 0.6 * em + 1.45 * em * entries.len() as f64 - 0.45 * em;
    Some((w, h))
}
