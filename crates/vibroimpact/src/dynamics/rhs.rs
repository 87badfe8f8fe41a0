//! The right-hand side of [`ChainDynamics`] (docs/theory.md §4): the
//! springs, dampers, base and harmonic forces on each body, the couplings,
//! the storeys, and the contacts not screened out (a chain's neighbour
//! pairs first, as windows of the state).

use super::*;

/// Evaluates a contact law at (s, ṡ) and adds its force to the bodies
/// (`-ml F` on the left, `+mr F` on the right; masks 0 for a wall side).
/// Returns the dissipated power `(F(s, ṡ) - F(s, 0)) ṡ` when `energy`,
/// and the law's partial derivatives with the force when `partials` (else
/// zeros: the force alone is the same number).
#[allow(clippy::too_many_arguments)]
#[inline]
fn apply_contact(
    law: &ContactLaw,
    onset_velocity: f64,
    force: &mut [f64],
    (l, r): (usize, usize),
    (ml, mr): (f64, f64),
    s: f64,
    sdot: f64,
    (energy, partials): (bool, bool),
) -> (ContactForce, f64) {
    let c = if partials {
        law.eval(s, sdot, onset_velocity)
    } else {
        ContactForce {
            force: law.force(s, sdot, onset_velocity),
            ..ContactForce::default()
        }
    };
    let f = c.force;
    force[l] -= ml * f;
    force[r] += mr * f;
    let dissipated = if energy {
        (f - law.force(s, 0.0, onset_velocity)) * sdot
    } else {
        0.0
    };
    (c, dissipated)
}

impl ChainDynamics {
    /// The right-hand side; `replay` applies another copy's contact forces,
    /// evaluated at the same `y` ([`OdeSystem::rhs_reforced`]), in its
    /// order, instead of evaluating them; otherwise the evaluated contacts
    /// are kept for [`OdeSystem::jacobian_after_rhs`].
    pub(super) fn rhs_with(
        &mut self,
        t: f64,
        y: &[f64],
        dydt: &mut [f64],
        replay: Option<&[(usize, ContactForce)]>,
    ) {
        // (Whether the partials are kept is chosen once a call, not at
        // every contact: the hot loop over a row's pairs stays as it was.)
        if self.partials {
            self.rhs_keeping::<true>(t, y, dydt, replay);
        } else {
            self.rhs_keeping::<false>(t, y, dydt, replay);
        }
    }

    /// [`rhs_with`](Self::rhs_with), keeping the evaluated contacts'
    /// partial derivatives if `PARTIALS`.
    fn rhs_keeping<const PARTIALS: bool>(
        &mut self,
        t: f64,
        y: &[f64],
        dydt: &mut [f64],
        replay: Option<&[(usize, ContactForce)]>,
    ) {
        let zdd = self.base.at_from(t, &mut self.segment);
        let n = self.n;
        for ((((f, uv), k), c), m) in self
            .force
            .iter_mut()
            .zip(y[..2 * n].chunks_exact(2))
            .zip(&self.stiffness)
            .zip(&self.damping)
            .zip(&self.mass)
        {
            *f = -k * uv[0] - c * uv[1] - m * zdd;
        }
        let mut input = 0.0;
        let mut damper = 0.0;
        let mut contact = 0.0;
        for &(body, p, w, phi) in &self.forces {
            let f = p * (w * t + phi).sin();
            self.force[body] += f;
            input += f * y[2 * body + 1];
        }
        for &(a, b, k, c) in &self.couplings {
            let du = y[2 * b] - y[2 * a];
            let dv = y[2 * b + 1] - y[2 * a + 1];
            let f = k * du + c * dv;
            self.force[a] += f;
            self.force[b] -= f;
            damper += c * dv * dv;
        }
        // (Not called without storeys: a call per right-hand side of a
        // small set costs as much as a body's forces.)
        if !self.storeys.is_empty() {
            self.storeys.apply(y, &mut self.force, dydt);
        }
        let (sc, contacts, onset, force, kept) = (
            &self.screen,
            &self.contacts,
            &self.onset_velocity,
            &mut self.force,
            &mut self.evaluated,
        );
        let energy = self.energy;
        let mut evaluations = 0;
        if let Some(list) = replay {
            for &(k, c) in list {
                force[sc.l[k]] -= sc.ml[k] * c.force;
                force[sc.r[k]] += sc.mr[k] * c.force;
            }
            kept.clear();
            kept.extend_from_slice(list);
        } else {
            kept.clear();
            let nc = sc.l.len();
            let (chain_start, chain_end) = chain_range(sc, n);
            if chain_end > chain_start {
                // Neighbour pairs of a chain: contiguous, no gathers.
                // (Each pair's two states as one window of the state: no
                // index to check.)
                let pairs = y[..2 * n]
                    .windows(4)
                    .step_by(2)
                    .zip(&sc.test[chain_start..chain_end]);
                for (i, (w, &[g, al, boa, lim])) in pairs.enumerate() {
                    let &[ul, vl, ur, vr] = w else { continue };
                    let s = ul - ur - g;
                    let sdot = vl - vr;
                    if al * s + boa * sdot.abs() < lim {
                        continue;
                    }
                    let k = chain_start + i;
                    evaluations += 1;
                    let (c, dissipated) = apply_contact(
                        &contacts[k].law,
                        onset[k],
                        force,
                        (i, i + 1),
                        (1.0, 1.0),
                        s,
                        sdot,
                        (energy, PARTIALS),
                    );
                    if PARTIALS {
                        kept.push((k, c));
                    }
                    contact += dissipated;
                }
            }
            for k in (0..chain_start).chain(chain_end..nc) {
                let (l, r) = (sc.l[k], sc.r[k]);
                let [g, alpha, boa, limit] = sc.test[k];
                let s = sc.ml[k] * y[2 * l] - sc.mr[k] * y[2 * r] - g;
                let sdot = sc.ml[k] * y[2 * l + 1] - sc.mr[k] * y[2 * r + 1];
                if alpha * s + boa * sdot.abs() < limit {
                    continue;
                }
                evaluations += 1;
                let (c, dissipated) = apply_contact(
                    &contacts[k].law,
                    onset[k],
                    force,
                    (l, r),
                    (sc.ml[k], sc.mr[k]),
                    s,
                    sdot,
                    (energy, PARTIALS),
                );
                if PARTIALS {
                    kept.push((k, c));
                }
                contact += dissipated;
            }
        }
        self.contact_evaluations += evaluations;
        let rows = dydt[..2 * n]
            .chunks_exact_mut(2)
            .zip(y[..2 * n].chunks_exact(2));
        for ((d, w), (f, im)) in rows.zip(self.force.iter().zip(&self.inv_mass)) {
            if let ([du, dv], [_, v]) = (d, w) {
                (*du, *dv) = (*v, f * im);
            }
        }
        if self.energy {
            for i in 0..n {
                let v = y[2 * i + 1];
                input -= self.mass[i] * zdd * v;
                damper += self.damping[i] * v * v;
            }
            let m = self.audit_index();
            dydt[m] = input;
            dydt[m + 1] = damper;
            dydt[m + 2] = contact;
        }
    }
}
