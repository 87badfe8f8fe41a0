//! A shear frame (docs/earthquakes.md): floor masses, storey stiffnesses
//! and laws, Rayleigh damping on the initial stiffnesses, its modes.

use nalgebra::{DMatrix, SymmetricEigen};

use crate::model::hysteresis::{StoreyLaw, StoreySpec};
use crate::model::record::STANDARD_GRAVITY;

/// A shear frame: floors from the ground up.
#[derive(Clone, Debug, PartialEq)]
pub struct ShearFrame {
    /// Floor masses (kg), from the first floor up.
    pub masses: Vec<f64>,
    /// Storey stiffnesses (N/m): storey i joins floor i − 1 (the ground for
    /// i = 1) to floor i.
    pub stiffnesses: Vec<f64>,
    /// Rayleigh damping ratio in the first two modes (on the initial
    /// stiffnesses).
    pub damping_ratio: f64,
    /// The storeys' laws, from the ground up (empty: all elastic; a law's
    /// elastic stiffness is the storey's in `stiffnesses`).
    pub storeys: Vec<StoreySpec>,
    /// The storeys' heights (m), from the ground up (empty: not given, and
    /// no drift ratios).
    pub heights: Vec<f64>,
    /// The gravity loads acting through the drifts (P-Δ), if any.
    pub gravity: Gravity,
}

/// P-Δ: the gravity load above each storey, P_i = Σ_{j ≥ i} (m_j g + L_j)
/// with L_j a leaning column's load at floor j, acts through its drift as
/// the shear −(P_i/h_i)·d_i (docs/theory.md §11).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Gravity {
    /// Whether P-Δ acts (it needs the storeys' heights).
    pub p_delta: bool,
    /// A leaning column's gravity load per floor (N; empty: none), from
    /// the first floor up.
    pub leaning_loads: Vec<f64>,
}

impl ShearFrame {
    /// Checks the frame: as many storeys as floors, masses and stiffnesses
    /// positive and finite, a damping ratio in [0, 1).
    pub fn check(&self, name: &str) -> Result<(), String> {
        if self.masses.is_empty() || self.masses.len() != self.stiffnesses.len() {
            return Err(format!(
                "{name}: {} masses and {} storey stiffnesses; give one of each per floor",
                self.masses.len(),
                self.stiffnesses.len()
            ));
        }
        for (i, (m, k)) in self.masses.iter().zip(&self.stiffnesses).enumerate() {
            if !(m.is_finite() && *m > 0.0 && k.is_finite() && *k > 0.0) {
                return Err(format!(
                    "{name}: floor {}: mass {m} and stiffness {k} must be positive and finite",
                    i + 1
                ));
            }
        }
        if !(self.damping_ratio.is_finite() && (0.0..1.0).contains(&self.damping_ratio)) {
            return Err(format!(
                "{name}: damping ratio {}: give a value in [0, 1)",
                self.damping_ratio
            ));
        }
        if !self.storeys.is_empty() && self.storeys.len() != self.masses.len() {
            return Err(format!(
                "{name}: {} storey laws for {} storeys; give one per storey (or none: elastic)",
                self.storeys.len(),
                self.masses.len()
            ));
        }
        if !self.heights.is_empty() && self.heights.len() != self.masses.len() {
            return Err(format!(
                "{name}: heights: {} heights for {} storeys; give one per storey",
                self.heights.len(),
                self.masses.len()
            ));
        }
        if let Some((i, h)) = self
            .heights
            .iter()
            .enumerate()
            .find(|(_, h)| !(h.is_finite() && **h > 0.0))
        {
            return Err(format!(
                "{name}: heights: storey {}: height {h} m must be positive and finite",
                i + 1
            ));
        }
        self.check_gravity(name)?;
        self.laws().map(|_| ()).map_err(|e| format!("{name}: {e}"))
    }

    /// P-Δ needs heights; leaning loads need P-Δ, one per floor, finite and
    /// ≥ 0; each storey's P/h must stay below its elastic stiffness (else
    /// it is unstable at zero drift).
    fn check_gravity(&self, name: &str) -> Result<(), String> {
        let g = &self.gravity;
        if !g.leaning_loads.is_empty() && !g.p_delta {
            return Err(format!(
                "{name}: leaning_loads: given without p_delta = true; set it (the loads act only through P-Δ)"
            ));
        }
        if !g.p_delta {
            return Ok(());
        }
        if self.heights.is_empty() {
            return Err(format!(
                "{name}: p_delta: needs the storeys' heights (heights = [...], m)"
            ));
        }
        if !g.leaning_loads.is_empty() && g.leaning_loads.len() != self.masses.len() {
            return Err(format!(
                "{name}: leaning_loads: {} loads for {} floors; give one per floor (N)",
                g.leaning_loads.len(),
                self.masses.len()
            ));
        }
        if let Some((i, l)) = g
            .leaning_loads
            .iter()
            .enumerate()
            .find(|(_, l)| !(l.is_finite() && **l >= 0.0))
        {
            return Err(format!(
                "{name}: leaning_loads: floor {}: load {l} N must be finite and ≥ 0",
                i + 1
            ));
        }
        for (i, (kg, k)) in self
            .geometric_stiffnesses()
            .iter()
            .zip(&self.stiffnesses)
            .enumerate()
        {
            if kg >= k {
                return Err(format!(
                    "{name}: p_delta: storey {}: P/h = {kg:.6e} N/m is not below its stiffness {k:.6e} N/m: the storey is unstable under its gravity load at zero drift",
                    i + 1
                ));
            }
        }
        Ok(())
    }

    /// Each storey's gravity load P_i (N): the weights of the floors at and
    /// above it and their leaning loads; zeros without P-Δ.
    pub fn gravity_loads(&self) -> Vec<f64> {
        let n = self.masses.len();
        if !self.gravity.p_delta {
            return vec![0.0; n];
        }
        let mut p = vec![0.0; n];
        let mut above = 0.0;
        for i in (0..n).rev() {
            above += self.masses[i] * STANDARD_GRAVITY
                + self.gravity.leaning_loads.get(i).copied().unwrap_or(0.0);
            p[i] = above;
        }
        p
    }

    /// Each storey's P-Δ geometric stiffness P_i/h_i (N/m); zeros without
    /// P-Δ.
    pub fn geometric_stiffnesses(&self) -> Vec<f64> {
        self.gravity_loads()
            .iter()
            .enumerate()
            .map(|(i, p)| self.heights.get(i).map_or(0.0, |h| p / h))
            .collect()
    }

    /// The storey drift ratios of `drifts` (m, one per storey): each over
    /// its storey's height; None without heights.
    pub fn drift_ratios(&self, drifts: &[f64]) -> Option<Vec<f64>> {
        (!self.heights.is_empty()).then(|| {
            drifts
                .iter()
                .zip(&self.heights)
                .map(|(d, h)| d / h)
                .collect()
        })
    }

    /// The storeys' laws with their elastic stiffnesses (all elastic
    /// without `storeys`); an error names the storey and the key.
    pub fn laws(&self) -> Result<Vec<StoreyLaw>, String> {
        (0..self.masses.len())
            .map(|i| {
                let spec = self
                    .storeys
                    .get(i)
                    .copied()
                    .unwrap_or(StoreySpec::Elastic {});
                spec.law(self.stiffnesses[i])
                    .map_err(|e| format!("storey {}: {e}", i + 1))
            })
            .collect()
    }

    /// Whether any storey yields (is not elastic).
    pub fn inelastic(&self) -> bool {
        self.storeys.iter().any(|s| *s != StoreySpec::Elastic {})
    }

    /// The stiffness matrix K (tridiagonal), each storey's stiffness less
    /// its P-Δ stiffness.
    pub(super) fn stiffness_matrix(&self) -> DMatrix<f64> {
        let n = self.masses.len();
        let k: Vec<f64> = self
            .stiffnesses
            .iter()
            .zip(self.geometric_stiffnesses())
            .map(|(k, g)| k - g)
            .collect();
        DMatrix::from_fn(n, n, |r, c| {
            if r == c {
                k[r] + k.get(r + 1).copied().unwrap_or(0.0)
            } else if r + 1 == c {
                -k[c]
            } else if c + 1 == r {
                -k[r]
            } else {
                0.0
            }
        })
    }

    /// The natural circular frequencies (rad/s), lowest first: the
    /// eigenvalues of M^{-1/2} K M^{-1/2}.
    pub fn natural_frequencies(&self) -> Vec<f64> {
        let k = self.stiffness_matrix();
        let s: Vec<f64> = self.masses.iter().map(|m| 1.0 / m.sqrt()).collect();
        let n = s.len();
        let a = DMatrix::from_fn(n, n, |r, c| s[r] * k[(r, c)] * s[c]);
        let mut w: Vec<f64> = SymmetricEigen::new(a)
            .eigenvalues
            .iter()
            .map(|l| l.max(0.0).sqrt())
            .collect();
        w.sort_by(f64::total_cmp);
        w
    }

    /// The fundamental mode shape φ₁ (floor displacements, the roof's 1),
    /// of the stiffnesses less their P-Δ.
    pub fn first_mode(&self) -> Vec<f64> {
        let k = self.stiffness_matrix();
        let s: Vec<f64> = self.masses.iter().map(|m| 1.0 / m.sqrt()).collect();
        let n = s.len();
        let a = DMatrix::from_fn(n, n, |r, c| s[r] * k[(r, c)] * s[c]);
        let eig = SymmetricEigen::new(a);
        let lowest = (0..n)
            .min_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]))
            .unwrap_or(0);
        let phi: Vec<f64> = (0..n)
            .map(|r| s[r] * eig.eigenvectors[(r, lowest)])
            .collect();
        let roof = phi[n - 1];
        phi.iter().map(|p| p / roof).collect()
    }

    /// The fundamental period T1 (s).
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.natural_frequencies()[0]
    }

    /// Rayleigh's (α, β) with ζ in modes 1 and 2 (one storey: β = 0, α = 2ζω).
    pub fn rayleigh(&self) -> (f64, f64) {
        let w = self.natural_frequencies();
        let z = self.damping_ratio;
        match w.as_slice() {
            [w1] => (2.0 * z * w1, 0.0),
            [w1, w2, ..] => {
                let alpha = 2.0 * z * w1 * w2 / (w1 + w2);
                (alpha, 2.0 * z / (w1 + w2))
            }
            [] => (0.0, 0.0),
        }
    }
}
