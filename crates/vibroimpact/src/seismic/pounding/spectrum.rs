//! Pounding spectra over gap × period ratio, value ranges and quantiles
//! of an ensemble (docs/earthquakes.md).

use super::{PoundingError, Row, RunSettings};
use crate::field_error::FieldError;
use crate::model::record::Record;

/// One cell of a pounding spectrum: a gap and a period ratio, over the
/// records.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumCell {
    /// The gap (m).
    pub gap: f64,
    /// T_left / T_right (the right frame's stiffnesses scaled to it).
    pub period_ratio: f64,
    /// Per record: the largest impact force (N).
    pub impact_force: Vec<f64>,
    /// Per record: the impacts.
    pub impacts: Vec<usize>,
    /// Per record: the largest ratio of a storey drift with pounding to the
    /// same drift of the free frames, over both frames.
    pub drift_amplification: Vec<f64>,
    /// Per record: the gap that avoids contact (m).
    pub required_gap: Vec<f64>,
}

/// The pair with the right frame's stiffnesses scaled so that T_left /
/// T_right = `ratio`. Only a pair of two fixed frames has this spectrum.
pub fn with_period_ratio(row: &Row, ratio: f64) -> Result<Row, PoundingError> {
    if !(ratio.is_finite() && ratio > 0.0) {
        return Err(FieldError::new("ratios", ratio, "give positive period ratios").into());
    }
    row.check()?;
    if row.buildings.len() != 2 || row.buildings.iter().any(|b| b.isolation.is_some()) {
        let message =
            "a period-ratio spectrum is of two fixed frames (a pair file without isolation)";
        return Err(FieldError::about("ratios", message).into());
    }
    let factor = (row.buildings[1].period() * ratio / row.buildings[0].period()).powi(2);
    let mut out = row.clone();
    out.buildings[1]
        .frame
        .stiffnesses
        .iter_mut()
        .for_each(|k| *k *= factor);
    Ok(out)
}

/// The pounding spectrum: every (gap, period ratio) cell over `records`
/// (each with its scale), in parallel, cells gap-major; each record's run
/// as `run` says. The same numbers at any thread count.
pub fn pounding_spectrum(
    pair: &Row,
    records: &[(Record, f64)],
    gaps: &[f64],
    ratios: &[f64],
    run: &RunSettings,
) -> Result<Vec<SpectrumCell>, PoundingError> {
    use rayon::prelude::*;
    for (field, empty) in [
        ("records", records.is_empty()),
        ("gaps", gaps.is_empty()),
        ("ratios", ratios.is_empty()),
    ] {
        if empty {
            let message = "a pounding spectrum needs records, gaps and period ratios";
            return Err(FieldError::about(field, message).into());
        }
    }
    if let Some(g) = gaps.iter().find(|g| !(g.is_finite() && **g >= 0.0)) {
        return Err(FieldError::new("gaps", g, "give finite gaps >= 0").into());
    }
    let pairs: Vec<Row> = ratios
        .iter()
        .map(|&r| with_period_ratio(pair, r))
        .collect::<Result<_, _>>()?;
    let cells: Vec<(usize, usize)> = (0..gaps.len())
        .flat_map(|g| (0..ratios.len()).map(move |r| (g, r)))
        .collect();
    cells
        .par_iter()
        .map(|&(g, r)| {
            let mut p = pairs[r].clone();
            p.joints[0].gap = gaps[g];
            let mut cell = SpectrumCell {
                gap: gaps[g],
                period_ratio: ratios[r],
                impact_force: Vec::new(),
                impacts: Vec::new(),
                drift_amplification: Vec::new(),
                required_gap: Vec::new(),
            };
            for (record, scale) in records {
                let res = p.analyse(record, *scale, run)?;
                let amp = (0..res.pounding.drift.len())
                    .flat_map(|side| {
                        let (a, b) = (&res.pounding.drift[side], &res.free.drift[side]);
                        a.iter()
                            .zip(b)
                            .map(|(x, y)| if *y > 0.0 { x / y } else { 1.0 })
                    })
                    .fold(0.0f64, f64::max);
                cell.impact_force.push(res.pounding.peak_impact_force);
                cell.impacts.push(res.pounding.impacts);
                cell.drift_amplification.push(amp);
                cell.required_gap.push(res.joints[0].required_gap);
            }
            Ok(cell)
        })
        .collect()
}

/// `FROM:TO:N` as N evenly spaced values (N = 1: FROM), the form of the
/// spectrum's gaps and period ratios; `field` names the option.
pub fn value_range(field: &'static str, text: &str) -> Result<Vec<f64>, FieldError> {
    let bad = || FieldError::new(field, text, "give FROM:TO:N, e.g. 0.01:0.1:10");
    let parts: Vec<&str> = text.split(':').collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(bad());
    };
    let a: f64 = a.trim().parse().map_err(|_| bad())?;
    let b: f64 = b.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if n == 0 || !a.is_finite() || !b.is_finite() || (n > 1 && a == b) {
        return Err(bad());
    }
    Ok((0..n)
        .map(|i| {
            if n == 1 {
                a
            } else {
                a + (b - a) * i as f64 / (n - 1) as f64
            }
        })
        .collect())
}

/// The empirical q-quantile (0 ≤ q ≤ 1) of `values` with linear
/// interpolation between order statistics (NaN for none).
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let x = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < v.len() {
        v[i] * (1.0 - f) + v[i + 1] * f
    } else {
        v[i]
    }
}
