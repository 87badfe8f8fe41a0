//! When a contact matters to the local integrator: its activation gap at
//! the run's tolerance, and the first step of a contact that enters the
//! integrated set (docs/theory.md §10).

use super::*;

/// The gap at which a contact's force stops being negligible.
#[derive(Clone, Copy, Debug)]
pub(super) enum Activation {
    /// Compact support, active at any positive approach (Kelvin–Voigt:
    /// its damping force acts from the first touch).
    Compact,
    /// `F <= k s^n (1 + factor |ṡ|)` for s > 0 (Hertz, Hunt–Crossley,
    /// Lankarani–Nikravesh): active where that bound exceeds `f_neg`, the
    /// force that changes the lighter of the contact's bodies' velocity by
    /// less than `atol` over the whole run.
    Power {
        k: f64,
        n: f64,
        factor: f64,
        f_neg: f64,
    },
    /// The exponential law `(a + b ṡ) e^{αs}`: active where
    /// `α s + (b/a)|ṡ| >= ln(F_neg/a)`, `F_neg = 1e-3 rtol F_ref`.
    Exponential { alpha: f64, boa: f64, limit: f64 },
}

impl Activation {
    /// Every contact's activation, in contact order; a contact like the
    /// one before it (`like`, [`like_previous`]) takes its activation (a
    /// row of a thousand like pairs computes one).
    pub(super) fn all(model: &Model, opts: &SimulationOptions, like: &[bool]) -> Vec<Self> {
        let contacts = model.contacts();
        let mut out: Vec<Self> = Vec::with_capacity(contacts.len());
        for (k, c) in contacts.iter().enumerate() {
            let a = match out.last() {
                Some(&a) if like[k] => a,
                _ => {
                    let s_on = c.law.onset_approach(opts.impact_force_threshold);
                    Self::new(model, k, opts, s_on)
                }
            };
            out.push(a);
        }
        out
    }

    pub(super) fn new(model: &Model, k_index: usize, opts: &SimulationOptions, s_on: f64) -> Self {
        let rtol = opts.rtol;
        let c = &model.contacts()[k_index];
        match *c.law.kind() {
            LawKind::Exponential { a, b, alpha } => {
                let f_ref = model.contact_force_scale(k_index).unwrap_or(a);
                // Never later than the impact threshold.
                let limit = ((1e-3 * rtol * f_ref) / a).ln().min(alpha * s_on);
                Activation::Exponential {
                    alpha,
                    boa: b / a,
                    limit,
                }
            }
            LawKind::Hertz { k, n } => Self::power(model, k_index, (k, n, 0.0), opts),
            LawKind::HuntCrossley { k, n, chi } => Self::power(model, k_index, (k, n, chi), opts),
            LawKind::LankaraniNikravesh {
                k,
                n,
                restitution,
                min_impact_velocity,
            } => {
                let factor = 0.75 * (1.0 - restitution * restitution) / min_impact_velocity;
                Self::power(model, k_index, (k, n, factor), opts)
            }
            LawKind::KelvinVoigt { .. } => Activation::Compact,
        }
    }

    pub(super) fn power(
        model: &Model,
        contact: usize,
        law: (f64, f64, f64),
        opts: &SimulationOptions,
    ) -> Self {
        let c = &model.contacts()[contact];
        let lighter = [c.pair.left(), c.pair.right()]
            .into_iter()
            .flatten()
            .map(|i| model.bodies()[i].mass)
            .fold(f64::INFINITY, f64::min);
        let (k, n, factor) = law;
        Activation::Power {
            k,
            n,
            factor,
            f_neg: lighter * opts.atol / opts.t_end,
        }
    }

    /// The largest gap that is surely inactive while |ṡ| <= `speed`.
    pub(super) fn gap(&self, speed: f64) -> f64 {
        match *self {
            Activation::Compact => 0.0,
            Activation::Power {
                k,
                n,
                factor,
                f_neg,
            } => (f_neg / (k * (1.0 + factor * speed))).powf(1.0 / n),
            Activation::Exponential { alpha, boa, limit } => (limit - boa * speed) / alpha,
        }
    }

    /// Positive where the contact is active at (s, ṡ).
    pub(super) fn margin(&self, s: f64, sdot: f64) -> f64 {
        match *self {
            Activation::Compact => s,
            Activation::Power { .. } => s - self.gap(sdot.abs()),
            Activation::Exponential { alpha, boa, limit } => s + (boa * sdot.abs() - limit) / alpha,
        }
    }
}

/// Whether contact `k` (k > 0) is like the one before it: the same law and
/// clearance, walls on the same sides, and bodies of the same mass and
/// stiffness, so that whatever the run derives from a contact alone (its
/// activation, its force scale, its judging gap) is the same.
pub(super) fn like_previous(model: &Model, k: usize) -> bool {
    let Some(j) = k.checked_sub(1) else {
        return false;
    };
    let (a, b) = (&model.contacts()[j], &model.contacts()[k]);
    let body = |i: Option<usize>| i.map(|i| &model.bodies()[i]).map(|b| (b.mass, b.stiffness));
    a.law == b.law
        && a.clearance == b.clearance
        && body(a.pair.left()) == body(b.pair.left())
        && body(a.pair.right()) == body(b.pair.right())
}

/// The largest `h <= h_max` (to a factor 2) with `impulse(h) <= limit`,
/// for an impulse that grows with `h`; `h_max` if it stays below.
pub(super) fn first_step(impulse: impl Fn(f64) -> f64, limit: f64, h_max: f64) -> f64 {
    let mut h = h_max;
    // 60 halvings reach 1e-18 of the proposed step.
    for _ in 0..60 {
        if impulse(h) <= limit {
            return h;
        }
        h *= 0.5;
    }
    h
}
