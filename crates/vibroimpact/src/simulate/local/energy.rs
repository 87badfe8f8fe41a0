//! The energy audit under the local integrator (docs/theory.md §10): the
//! active set integrates the three quadratures of the audit with its state
//! (the work of the excitation, the dampers' and the contacts'
//! dissipation, `dynamics/mod.rs`); a group moving exactly has no contact
//! force, and its work and damper dissipation are integrated on its exact
//! motion by Gauss–Legendre quadrature, just before its reference state
//! moves (as its extrema are scanned), on panels no longer than a
//! sixteenth of its fastest rate's period that end at a record's samples
//! (where the base acceleration has a kink).

use super::*;

/// 8-point Gauss–Legendre nodes and weights on [−1, 1] (exact for
/// polynomials of degree 15).
const GAUSS_LEGENDRE: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// The audit's sums and how far each group's exact motion has entered
/// them.
pub(super) struct LocalEnergy {
    /// Work of the excitation, dissipation of the dampers and of the
    /// contacts so far (J).
    pub(super) sums: [f64; 3],
    /// Per group: its exact motion is in the sums up to this time.
    done: Vec<f64>,
    /// Per group: the longest quadrature panel (s).
    panel: Vec<f64>,
}

impl LocalEnergy {
    /// Nothing summed yet; the panels from every group's fastest rate
    /// (natural, forcing, damping, couplings).
    pub(super) fn new(model: &Model, free: &FreeMotion) -> Self {
        let panel = free
            .groups()
            .iter()
            .map(|g| {
                let mut rate = g.rate();
                for &i in g.bodies() {
                    let b = &model.bodies()[i];
                    rate = rate
                        .max((b.stiffness / b.mass).sqrt())
                        .max(b.damping / b.mass);
                }
                for c in model.couplings() {
                    if g.bodies().contains(&c.a) {
                        let m = model.bodies()[c.a].mass.min(model.bodies()[c.b].mass);
                        rate = rate.max((c.stiffness / m).sqrt()).max(c.damping / m);
                    }
                }
                if rate > 0.0 {
                    std::f64::consts::PI / (8.0 * rate)
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        Self {
            sums: [0.0; 3],
            done: vec![0.0; free.groups().len()],
            panel,
        }
    }
}

impl Run<'_> {
    /// Group `g`'s power input and damper dissipation at `t` in its state
    /// `x` (interleaved, its bodies).
    fn group_power(&self, g: usize, t: f64, x: &[f64]) -> (f64, f64) {
        let model = self.model;
        let zdd = model.base().at(t);
        let bodies = self.free.groups()[g].bodies();
        let (mut input, mut damper) = (0.0, 0.0);
        for (j, &i) in bodies.iter().enumerate() {
            let b = &model.bodies()[i];
            let v = x[2 * j + 1];
            input -= b.mass * zdd * v;
            damper += b.damping * v * v;
        }
        for &f in self.free.forces_in(g) {
            let f = &model.forces()[f];
            let j = bodies.iter().position(|&i| i == f.body).unwrap_or(0);
            input += f.amplitude * (f.frequency * t + f.phase).sin() * x[2 * j + 1];
        }
        for &c in self.free.couplings_in(g) {
            let c = &model.couplings()[c];
            let a = bodies.iter().position(|&i| i == c.a).unwrap_or(0);
            let b = bodies.iter().position(|&i| i == c.b).unwrap_or(0);
            let dv = x[2 * b + 1] - x[2 * a + 1];
            damper += c.damping * dv * dv;
        }
        (input, damper)
    }

    /// Adds group `g`'s exact motion up to `t` to the audit (before its
    /// reference state moves there, or it joins the set).
    pub(super) fn energy_to(&mut self, g: usize, t: f64) {
        let Some(mut energy) = self.energy.take() else {
            return;
        };
        let (t0, x0) = &self.exact[g];
        let from = energy.done[g].max(*t0);
        if t > from {
            // Panels end at the record's samples and are at most `panel`.
            let first = self.breakpoints.partition_point(|&b| b <= from);
            let last = self.breakpoints.partition_point(|&b| b < t);
            let ends = self.breakpoints[first..last].iter().copied().chain([t]);
            let mut a = from;
            let mut x = x0.clone();
            for b in ends {
                let pieces = ((b - a) / energy.panel[g]).ceil().max(1.0);
                let h = (b - a) / pieces;
                for p in 0..pieces as usize {
                    let (lo, hi) = (a + p as f64 * h, a + (p + 1) as f64 * h);
                    let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                    for &(node, weight) in &GAUSS_LEGENDRE {
                        let tn = mid + half * node;
                        x.clone_from(x0);
                        self.free.propagate(g, *t0, tn, &mut x);
                        let (input, damper) = self.group_power(g, tn, &x);
                        energy.sums[0] += weight * half * input;
                        energy.sums[1] += weight * half * damper;
                    }
                }
                a = b;
            }
        }
        energy.done[g] = energy.done[g].max(t);
        self.energy = Some(energy);
    }

    /// A group leaves the set at `t`: its exact motion enters the audit
    /// from there (the set's quadratures covered it so far).
    pub(super) fn energy_from(&mut self, g: usize, t: f64) {
        if let Some(energy) = self.energy.as_mut() {
            energy.done[g] = t;
        }
    }

    /// Adds the set's quadratures (the three components from `at` in its
    /// state `y`) to the audit.
    pub(super) fn energy_of_set(&mut self, y: &[f64], at: usize) {
        if let Some(energy) = self.energy.as_mut() {
            for (s, q) in energy.sums.iter_mut().zip(&y[at..at + 3]) {
                *s += q;
            }
        }
    }
}
