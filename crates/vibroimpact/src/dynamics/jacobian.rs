//! The row's Jacobian `∂f/∂y` (docs/theory.md §5): analytic and banded
//! for the integrators and the variational equations, and recorded
//! compactly for tangent replay. After a right-hand side at the same state
//! the contacts' partial derivatives are those that call evaluated (the
//! same numbers, one evaluation of each law instead of two).

use super::ChainDynamics;
use crate::contact::ContactForce;
use crate::integrate::{BandMatrix, RecordedJacobian};

impl ChainDynamics {
    /// The contacts the last right-hand side evaluated, with their forces
    /// and partial derivatives, in contact order (as
    /// [`evaluated_contacts`](Self::evaluated_contacts) lists them; the
    /// right-hand side takes a chain's neighbour pairs first).
    fn last_evaluated(&self) -> impl Iterator<Item = (usize, ContactForce)> + '_ {
        let (start, end) = super::chain_range(&self.screen, self.n);
        let list = &self.evaluated;
        let part = move |keep: fn(usize, usize, usize) -> bool| {
            list.iter()
                .copied()
                .filter(move |&(k, _)| keep(k, start, end))
        };
        part(|k, start, _| k < start)
            .chain(part(|k, start, end| (start..end).contains(&k)))
            .chain(part(|k, _, end| k >= end))
    }

    /// [`OdeSystem::jacobian`]; `after_rhs` takes the contacts' partial
    /// derivatives from the last right-hand side, which was at `y`
    /// ([`OdeSystem::jacobian_after_rhs`]).
    pub(super) fn jacobian_from(&self, y: &[f64], jac: &mut BandMatrix, after_rhs: bool) -> bool {
        // The storeys' hysteretic terms are left to finite differences.
        if self.energy || !self.storeys.is_empty() {
            return false;
        }
        for i in 0..self.n {
            let im = self.inv_mass[i];
            jac.set(2 * i, 2 * i + 1, 1.0);
            jac.add(2 * i + 1, 2 * i, -self.stiffness[i] * im);
            jac.add(2 * i + 1, 2 * i + 1, -self.damping[i] * im);
        }
        let pair = |jac: &mut BandMatrix, a: usize, b: usize, ds: f64, dv: f64| {
            // Force +(ds Δu + dv Δv) on a, -(…) on b, with Δ = (b) - (a).
            let (ia, ib) = (self.inv_mass[a], self.inv_mass[b]);
            jac.add(2 * a + 1, 2 * a, -ds * ia);
            jac.add(2 * a + 1, 2 * b, ds * ia);
            jac.add(2 * a + 1, 2 * a + 1, -dv * ia);
            jac.add(2 * a + 1, 2 * b + 1, dv * ia);
            jac.add(2 * b + 1, 2 * a, ds * ib);
            jac.add(2 * b + 1, 2 * b, -ds * ib);
            jac.add(2 * b + 1, 2 * a + 1, dv * ib);
            jac.add(2 * b + 1, 2 * b + 1, -dv * ib);
        };
        for &(a, b, k, c) in &self.couplings {
            pair(jac, a, b, k, c);
        }
        let mut contact = |k: usize, c: ContactForce| {
            match (self.contacts[k].left, self.contacts[k].right) {
                // -F on l, +F on r, F = F(u_l - u_r - g, v_l - v_r): the same
                // shape as a coupling of stiffness ∂F/∂s between r and l.
                (Some(l), Some(r)) => pair(jac, l, r, c.d_ds, c.d_dsdot),
                (Some(l), None) => {
                    jac.add(2 * l + 1, 2 * l, -c.d_ds * self.inv_mass[l]);
                    jac.add(2 * l + 1, 2 * l + 1, -c.d_dsdot * self.inv_mass[l]);
                }
                (None, Some(r)) => {
                    // s = -u_r - g: ∂(+F)/∂u_r = -∂F/∂s.
                    jac.add(2 * r + 1, 2 * r, -c.d_ds * self.inv_mass[r]);
                    jac.add(2 * r + 1, 2 * r + 1, -c.d_dsdot * self.inv_mass[r]);
                }
                (None, None) => {}
            }
        };
        if after_rhs {
            self.last_evaluated().for_each(|(k, c)| contact(k, c));
        } else {
            self.evaluated_contacts(y).for_each(|(k, c)| contact(k, c));
        }
        true
    }
}

/// The Jacobian recorded for tangent replay: springs, dampers and
/// couplings are the model's (constant); each contact not screened out
/// contributes its index and its force's partial derivatives
/// `(∂F/∂s, ∂F/∂ṡ)`, as in [`crate::integrate::OdeSystem::jacobian`].
impl RecordedJacobian for ChainDynamics {
    type Entry = (u32, f64, f64);

    fn record_jacobian(&self, y: &[f64], out: &mut Vec<(u32, f64, f64)>) {
        out.extend(
            self.evaluated_contacts(y)
                .map(|(k, c)| (k as u32, c.d_ds, c.d_dsdot)),
        );
    }

    fn record_jacobian_after_rhs(&self, y: &[f64], out: &mut Vec<(u32, f64, f64)>) {
        if !self.partials {
            return self.record_jacobian(y, out);
        }
        out.extend(
            self.last_evaluated()
                .map(|(k, c)| (k as u32, c.d_ds, c.d_dsdot)),
        );
    }

    fn apply_recorded(&self, entries: &[(u32, f64, f64)], v: &[f64], out: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            out[2 * i] = v[2 * i + 1];
            out[2 * i + 1] = -self.stiffness[i] * v[2 * i] - self.damping[i] * v[2 * i + 1];
        }
        for &(a, b, k, c) in &self.couplings {
            let f = k * (v[2 * b] - v[2 * a]) + c * (v[2 * b + 1] - v[2 * a + 1]);
            out[2 * a + 1] += f;
            out[2 * b + 1] -= f;
        }
        let sc = &self.screen;
        for &(k, d_ds, d_dsdot) in entries {
            let k = k as usize;
            let (l, r, ml, mr) = (sc.l[k], sc.r[k], sc.ml[k], sc.mr[k]);
            let ds = ml * v[2 * l] - mr * v[2 * r];
            let dsdot = ml * v[2 * l + 1] - mr * v[2 * r + 1];
            let f = d_ds * ds + d_dsdot * dsdot;
            out[2 * l + 1] -= ml * f;
            out[2 * r + 1] += mr * f;
        }
        for i in 0..n {
            out[2 * i + 1] *= self.inv_mass[i];
        }
    }
}
