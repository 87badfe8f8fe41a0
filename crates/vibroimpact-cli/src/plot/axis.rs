//! Axis ranges, ticks and tick labels (linear and logarithmic).

use super::figure::*;
use super::theme::*;

/// Data values beyond this magnitude are treated as invalid.
pub(super) const MAX_ABS: f64 = 1e300;

pub(super) fn transform(scale: Scale, v: f64) -> Option<f64> {
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
pub(super) fn axis_range(
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
pub(super) fn widen_degenerate(scale: Scale, lo: f64, hi: f64) -> (f64, f64) {
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
pub(super) type Tick = (f64, String);
/// A point in logical px.
pub(super) type Pt = (f64, f64);

/// Ticks and labels of one axis, in transformed space.
#[derive(Debug, Clone)]
pub(super) struct AxisPlan {
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) major: Vec<(f64, String)>,
    pub(super) minor: Vec<f64>,
}

impl AxisPlan {
    pub(super) fn frac(&self, t: f64) -> f64 {
        (t - self.lo) / (self.hi - self.lo)
    }
}

/// Does a row of labels (centres `pos`, extents `size` along the axis) fit
/// without overlapping?
pub(super) fn labels_fit(pos: &[f64], size: &[f64], gap: f64) -> bool {
    pos.windows(2)
        .zip(size.windows(2))
        .all(|(p, s)| (p[1] - p[0]).abs() >= 0.5 * (s[0] + s[1]) + gap)
}

/// Chooses ticks for an axis of `length` px. `vertical`: labels are stacked
/// (their extent is the text height) rather than side by side.
pub(super) fn plan_axis(scale: Scale, lo: f64, hi: f64, length: f64, vertical: bool) -> AxisPlan {
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
pub(super) fn nice_ticks(lo: f64, hi: f64, max_n: usize) -> (Vec<f64>, f64) {
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

pub(super) fn linear_choice(
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
pub(super) fn step_decimals(step: f64) -> i32 {
    let e = step.log10().floor() as i32;
    let mantissa = step / 10f64.powi(e);
    let extra = i32::from((mantissa - mantissa.round()).abs() > 1e-6);
    -e + extra
}

/// Labels for linear ticks with a common format: fixed point for moderate
/// magnitudes, otherwise compact scientific (`2.5×10⁴`, `1×10⁻⁵`).
pub(super) fn format_linear(values: &[f64], step: f64) -> Vec<String> {
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
pub(super) fn compact_sci(v: f64, digits: usize) -> String {
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
pub(super) fn fix_minus(s: String) -> String {
    s.replace('-', "\u{2212}")
}

/// `10^k` with superscript digits.
pub(super) fn decade_label(k: i64) -> String {
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
pub(super) fn mantissa_label(m: u32, k: i64, fixed: bool) -> String {
    if fixed {
        let v = f64::from(m) * 10f64.powi(k as i32);
        fix_minus(format!("{:.*}", (-k).max(0) as usize, v))
    } else if m == 1 {
        decade_label(k)
    } else {
        format!("{m}\u{00D7}{}", decade_label(k))
    }
}

pub(super) fn log_choice(
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
