//! Bounds on a group's exact motion ahead, for the local integrator's
//! checks (docs/theory.md §10).
//!
//! The group's mechanical energy `E` (kinetic and spring, about its rest
//! state) can only grow by the work of the forcing: `d√E/dt ≤ G = ½ Σ_i
//! |f_i|max √(2/m_i)`, so over a horizon `H` every velocity is at most
//! `√(2E_H/m_i)` and every spring force at most `√(2 k E_H)` with `√E_H =
//! √E₀ + G H`. The largest force `|f_i|max` is `m_i |z̈|max + Σ|P|` of the
//! body's harmonic forces, with `|z̈|max` the base's largest over the
//! horizon alone ([`Peaks`]): over a record's quiet stretches the bound is
//! as tight as they are quiet, not as loose as the record's strongest part.
//!
//! A group with modes has a second bound, per quantity ([`Envelope`]): a
//! linear combination `q = Re Σ_k w_k z_k` of its state about rest, each
//! mode driven by the base alone (`ż_k = λ_k z_k + β_k f`, |f| ≤ F), so
//! over a horizon `H`
//!
//! ```text
//! |z_k(t + τ)| ≤ min(max(|z_k|, |β_k| F / σ_k), |z_k| + |β_k| F H),  σ_k = −Re λ_k,
//! ```
//!
//! and `|q − q_rest| ≤ Σ_k |w_k|` times that. It holds for all τ in `[0,
//! H]`, whatever the phases: a storey or gap whose envelope stays clear of
//! its limit is safe over the whole horizon, where the energy bound, which
//! lets every spring take the group's whole energy, crawls.

use super::{FreeMotion, Group, Rows};
use crate::model::BaseExcitation;

/// Samples per block of a record's peak table.
const BLOCK: usize = 16;

/// The largest |z̈| of a base excitation over a stretch of time: a
/// record's block maxima with a sparse table over them (a query costs
/// two partial blocks and one table lookup); a constant otherwise.
#[derive(Clone, Debug)]
pub(super) struct Peaks {
    /// The sample times (empty: not a record).
    times: Vec<f64>,
    /// |z̈| at each sample.
    values: Vec<f64>,
    /// `table[l][b]`: the largest over blocks b .. b + 2^l.
    table: Vec<Vec<f64>>,
    /// The peak of a base that is not a record.
    constant: f64,
}

impl Peaks {
    pub(super) fn new(base: &BaseExcitation) -> Self {
        let BaseExcitation::Record(rec) = base else {
            return Self {
                times: Vec::new(),
                values: Vec::new(),
                table: Vec::new(),
                constant: base.peak(),
            };
        };
        let times = rec.times().to_vec();
        let values: Vec<f64> = times.iter().map(|&t| rec.at(t).abs()).collect();
        let blocks: Vec<f64> = values
            .chunks(BLOCK)
            .map(|c| c.iter().fold(0.0f64, |m, v| m.max(*v)))
            .collect();
        let mut table = vec![blocks];
        while 2 * (1 << (table.len() - 1)) <= table[0].len() {
            let (prev, half) = (table.last().unwrap_or(&table[0]), 1 << (table.len() - 1));
            let next = (0..prev.len() - half)
                .map(|b| prev[b].max(prev[b + half]))
                .collect();
            table.push(next);
        }
        Self {
            times,
            values,
            table,
            constant: 0.0,
        }
    }

    /// The largest |z̈| over `[a, b]`: for a record, the largest of the
    /// samples that bracket the stretch (the interpolant is linear between
    /// samples; beyond the record's ends, where z̈ is zero, its end samples
    /// still count: a bound); otherwise the base's peak.
    pub(super) fn between(&self, a: f64, b: f64) -> f64 {
        if self.times.is_empty() {
            return self.constant;
        }
        let n = self.times.len();
        let i0 = self.times.partition_point(|&s| s <= a).saturating_sub(1);
        let i1 = self.times.partition_point(|&s| s < b).min(n - 1).max(i0);
        let (b0, b1) = (i0.div_ceil(BLOCK), (i1 + 1) / BLOCK);
        if b0 >= b1 {
            return self.values[i0..=i1].iter().fold(0.0f64, |m, v| m.max(*v));
        }
        let head = self.values[i0..b0 * BLOCK].iter();
        let tail = self.values[b1 * BLOCK..=i1].iter();
        let edges = head.chain(tail).fold(0.0f64, |m, v| m.max(*v));
        let level = (usize::BITS - 1 - (b1 - b0).leading_zeros()) as usize;
        let row = &self.table[level];
        edges.max(row[b0]).max(row[b1 - (1 << level)])
    }
}

impl FreeMotion {
    /// The largest |z̈| of the base over `[a, b]` (m/s²).
    pub fn base_peak(&self, a: f64, b: f64) -> f64 {
        self.peaks.between(a, b)
    }

    /// A check's time `until` (after `t`) moved back to the last record
    /// sample after `t`, if there is one: checking earlier is always safe,
    /// and a group checked at samples moves between them by the whole
    /// sample step, computed once, instead of the partial steps' complex
    /// exponentials per mode (a row of 16 buildings under a record: 3.7 µs
    /// a check, a third of it in those exponentials; the run 105 → 68 ms).
    /// Only where that keeps four fifths of the safe interval: checks of a
    /// sample or two, near yield or contact, would come back more often
    /// (at half, the row at full scale took 29 % more storey checks and
    /// 6 % more time; at four fifths 2 % less time). Not a record, or no
    /// such sample: `until`.
    pub fn sample_before(&self, t: f64, until: f64) -> f64 {
        let times = &self.peaks.times;
        let k = times.partition_point(|&s| s <= until);
        match k.checked_sub(1).map(|i| times[i]) {
            Some(s) if s - t >= 0.8 * (until - t) => s,
            _ => until,
        }
    }
}

/// The modal bound of one quantity of a group (module notes): per mode
/// `[|w_k|, |z_k|, |β_k|, σ_k]`.
#[derive(Clone, Debug)]
pub struct Envelope {
    terms: Vec<[f64; 4]>,
}

impl Envelope {
    /// The bound on `|q − q_rest|` over a horizon `horizon` while the
    /// base's |z̈| stays below `zdd`.
    pub fn reach(&self, horizon: f64, zdd: f64) -> f64 {
        self.terms
            .iter()
            .map(|&[w, z, b, sigma]| {
                let drive = b * zdd;
                let growing = z + drive * horizon;
                let settled = if sigma > 0.0 {
                    z.max(drive / sigma)
                } else {
                    f64::INFINITY
                };
                w * growing.min(settled)
            })
            .sum()
    }
}

impl FreeMotion {
    /// Whether group `g` has envelopes ([`FreeMotion::envelopes`]): modes,
    /// and no harmonic terms.
    pub fn has_envelopes(&self, g: usize) -> bool {
        let group = &self.groups[g];
        group.modal.is_some() && group.harmonic().is_empty()
    }

    /// The envelopes of `q = Σ c x_r` over each of `quantities` (rows r
    /// of group `g`'s interleaved state, coefficient c) from the state
    /// `x` (one change to modes for all); None where the group has no
    /// modes or harmonic terms (whose steady state the envelope leaves
    /// out).
    pub fn envelopes<const Q: usize>(
        &self,
        g: usize,
        x: &[f64],
        quantities: [&[(usize, f64)]; Q],
    ) -> Option<[Envelope; Q]> {
        let group = &self.groups[g];
        let modal = group.modal.as_ref()?;
        if !group.harmonic().is_empty() {
            return None;
        }
        let about: Rows = (x.iter().enumerate())
            .map(|(r, a)| a - group.rest(r))
            .collect();
        let mut z = Vec::with_capacity(x.len());
        modal.to_modes(&about, &mut z);
        Some(quantities.map(|rows| {
            let mut terms = Vec::with_capacity(z.len());
            modal.envelope_terms(&z, rows, &mut terms);
            Envelope { terms }
        }))
    }
}

impl Group {
    /// Row r of the rest state (interleaved).
    pub fn rest(&self, r: usize) -> f64 {
        self.terms.as_deref().map_or(0.0, |t| t.rest[r])
    }

    /// Mechanical energy (kinetic and springs, about the rest state) of the
    /// interleaved state `x`.
    pub fn energy(&self, x: &[f64]) -> f64 {
        let u = |i: usize| x[2 * i] - self.rest(2 * i);
        let mut e = 0.0;
        for j in 0..self.mass.len() {
            let v = x[2 * j + 1];
            e += 0.5 * self.mass[j] * v * v + 0.5 * self.stiffness[j] * u(j) * u(j);
        }
        for &(a, b, k, _) in self.couplings() {
            let du = u(b) - u(a);
            e += 0.5 * k * du * du;
        }
        e
    }

    /// The energy bound `E_H = (√E + G H)²` over `horizon` from the
    /// interleaved state `x`, the base's |z̈| below `zdd`.
    pub fn energy_ahead(&self, x: &[f64], horizon: f64, zdd: f64) -> f64 {
        let root = self.energy(x).sqrt() + self.growth(zdd) * horizon;
        root * root
    }

    /// `G` of the module notes while the base's |z̈| stays below `zdd`: `√E`
    /// grows at most this fast (√J/s).
    pub fn growth(&self, zdd: f64) -> f64 {
        (self.mass.iter().enumerate())
            .map(|(j, m)| 0.5 * (m * zdd + self.force_amplitude(j)) * (2.0 / m).sqrt())
            .sum()
    }

    /// Largest |acceleration| of body `j` (index in the group) while the
    /// group's energy stays below `e_max` and the base's |z̈| below `zdd`
    /// (m/s²).
    pub fn acceleration_bound(&self, j: usize, e_max: f64, zdd: f64) -> f64 {
        let speed = |i: usize| (2.0 * e_max / self.mass[i]).sqrt();
        let mut f = (2.0 * self.stiffness[j] * e_max).sqrt()
            + self.damping[j] * speed(j)
            + self.mass[j] * zdd
            + self.force_amplitude(j);
        for &(a, b, k, c) in self.couplings() {
            if a == j || b == j {
                f += (2.0 * k * e_max).sqrt() + c * (speed(a) + speed(b));
            }
        }
        f / self.mass[j]
    }
}
