//! The saltation of a rigid impact (docs/theory.md §12): how a
//! perturbation of the state just before rigid contact k's impact maps to
//! one just after it, for the monodromy of a period map through impacts.
//!
//! The impact happens where the event `h(x) = s = u_l − u_r − c` reaches
//! zero; the jump `x⁺ = g(x⁻)` changes the two velocities by `∓P/m`, with
//! the impulse `P = μ (1 + e(U)) U` and the approach velocity
//! `U = ṡ = v_l − v_r`. A perturbation `w` of `x⁻` moves the impact's time
//! by `−∇h·w / ∇h·f⁻`, so that (`f∓` the right-hand sides on either side)
//!
//! ```text
//! w⁺ = S w,   S = G + (f⁺ − G f⁻) ∇hᵀ / (∇hᵀ f⁻),
//! G = ∂g/∂x = I + b ∇Uᵀ,   b_l = −μ q / m_l,  b_r = μ q / m_r,
//! q = ∂((1 + e) U)/∂U = 1 + e + U de/dU,
//! ```
//!
//! where `∇hᵀ f⁻ = U`: the saltation grows as 1/U toward a grazing impact,
//! the rigid map's square-root singularity. A velocity-dependent law (the
//! seed's eq. (10)) enters through `de/dU`.

use super::ChainDynamics;
use crate::impact::rigid::RigidImpact;
use crate::integrate::OdeSystem;

/// The saltation matrix of one impact, applied to perturbations of the
/// interleaved state (`S w` costs O(dim)).
#[derive(Clone, Debug)]
pub struct Saltation {
    /// State indices of (u_l, v_l, u_r, v_r) (None for a wall).
    indices: [Option<usize>; 4],
    /// `b_l`, `b_r`: the velocities' change per unit change of `U`.
    gain: (f64, f64),
    /// `(f⁺ − G f⁻) / U`.
    delta: Vec<f64>,
}

impl Saltation {
    /// The saltation of contact `k`'s impact `impact` at time `t`, from the
    /// states just `before` and `after` it (interleaved, the system's own
    /// components only).
    pub fn new(
        chain: &mut ChainDynamics,
        k: usize,
        t: f64,
        (before, after): (&[f64], &[f64]),
        impact: &RigidImpact,
    ) -> Self {
        let indices = chain.contact_indices(k);
        let inverse_mass = |i: Option<usize>| i.map_or(0.0, |i| 1.0 / chain.mass(i / 2));
        let mu = 1.0 / (inverse_mass(indices[1]) + inverse_mass(indices[3]));
        let q = 1.0 + impact.restitution + impact.impact_velocity * impact.restitution_slope;
        let gain = (
            -mu * q * inverse_mass(indices[1]),
            mu * q * inverse_mass(indices[3]),
        );
        let d = before.len();
        let mut f_minus = vec![0.0; d];
        let mut delta = vec![0.0; d];
        chain.rhs(t, before, &mut f_minus);
        chain.rhs(t, after, &mut delta);
        let mut salt = Self {
            indices,
            gain,
            delta: Vec::new(),
        };
        // G f⁻, then (f⁺ − G f⁻) / U.
        salt.jump_jacobian(&mut f_minus);
        let u = impact.impact_velocity;
        delta
            .iter_mut()
            .zip(&f_minus)
            .for_each(|(p, m)| *p = (*p - m) / u);
        salt.delta = delta;
        salt
    }

    /// `w ← G w`: the jump's Jacobian at fixed time.
    fn jump_jacobian(&self, w: &mut [f64]) {
        let [_, vl, _, vr] = self.indices;
        let du = vl.map_or(0.0, |i| w[i]) - vr.map_or(0.0, |i| w[i]);
        if let Some(i) = vl {
            w[i] += self.gain.0 * du;
        }
        if let Some(i) = vr {
            w[i] += self.gain.1 * du;
        }
    }

    /// The event's gradient times `w`: `∇h·w = w_{u_l} − w_{u_r}`.
    fn event_gradient(&self, w: &[f64]) -> f64 {
        let [ul, _, ur, _] = self.indices;
        ul.map_or(0.0, |i| w[i]) - ur.map_or(0.0, |i| w[i])
    }

    /// `w ← S w`.
    pub fn apply(&self, w: &mut [f64]) {
        self.apply_shifted(w, 0.0);
    }

    /// `w ← S w + (f⁺ − G f⁻) h_p / U`: a parameter's sensitivity column,
    /// where the event moves by `h_p = ∂h/∂p` (a clearance); the caller adds
    /// the jump's own `∂g/∂p`.
    pub fn apply_shifted(&self, w: &mut [f64], h_p: f64) {
        let moved = self.event_gradient(w) + h_p;
        self.jump_jacobian(w);
        w.iter_mut()
            .zip(&self.delta)
            .for_each(|(a, b)| *a += b * moved);
    }
}
