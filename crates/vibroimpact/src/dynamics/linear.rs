//! A chain's linear form `A y + b(t)` where it has one (docs/theory.md
//! §12): every contact rigid (between impacts no contact force acts), no
//! storeys, no energy quadratures, and a forcing of harmonics (a
//! harmonic base or none, harmonic forces, gravity as Ω = 0). The period
//! map of such a chain moves exactly between its impacts
//! ([`crate::integrate::Method::Exact`]).

use nalgebra::DMatrix;

use super::{ChainDynamics, Screen};
use crate::integrate::{Harmonic, LinearForm};
use crate::model::BaseExcitation;

impl ChainDynamics {
    /// The chain as `A y + b(t)` (one block), or None where it is not
    /// linear with harmonic forcing (see the module documentation).
    pub(super) fn linear_form_of(&self) -> Option<LinearForm> {
        let n = self.n;
        let linear = !self.energy
            && self.storeys.is_empty()
            && self
                .contacts
                .iter()
                .all(|c| c.rigid.is_some() && matches!(c.screen, Screen::Never));
        if !linear {
            return None;
        }
        let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(2 * i, 2 * i + 1)] = 1.0;
            a[(2 * i + 1, 2 * i)] = -self.stiffness[i] * self.inv_mass[i];
            a[(2 * i + 1, 2 * i + 1)] = -self.damping[i] * self.inv_mass[i];
        }
        // A coupling's force k Δu + c Δv on a, its opposite on b.
        for &(p, q, k, c) in &self.couplings {
            for (i, j) in [(p, q), (q, p)] {
                let w = self.inv_mass[i];
                a[(2 * i + 1, 2 * i)] -= k * w;
                a[(2 * i + 1, 2 * j)] += k * w;
                a[(2 * i + 1, 2 * i + 1)] -= c * w;
                a[(2 * i + 1, 2 * j + 1)] += c * w;
            }
        }
        // b(t): P sin(Ω t + φ) = P sin φ cos Ω t + P cos φ sin Ω t.
        let mut harmonics: Vec<Harmonic> = Vec::new();
        let mut add = |omega: f64, row: Option<usize>, p: f64, phi: f64| {
            let at = match harmonics.iter().position(|h| h.omega == omega) {
                Some(k) => k,
                None => {
                    harmonics.push(Harmonic {
                        omega,
                        cos: vec![0.0; 2 * n],
                        sin: vec![0.0; 2 * n],
                    });
                    harmonics.len() - 1
                }
            };
            let h = &mut harmonics[at];
            let (s, c) = phi.sin_cos();
            let rows: Vec<usize> = match row {
                Some(i) => vec![i],
                None => (0..n).collect(),
            };
            for i in rows {
                h.cos[2 * i + 1] += p * s;
                h.sin[2 * i + 1] += p * c;
            }
        };
        match self.base {
            BaseExcitation::None => {}
            BaseExcitation::Harmonic {
                amplitude,
                frequency,
                phase,
            } => add(frequency, None, -amplitude, phase),
            _ => return None,
        }
        for &(body, p, w, phi) in &self.forces {
            add(w, Some(body), p * self.inv_mass[body], phi);
        }
        Some(LinearForm {
            a,
            blocks: vec![harmonics],
        })
    }
}
