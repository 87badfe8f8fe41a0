//! Codimension-two points on a curve of codimension-one points (docs/theory.md
//! §9): where a second multiplier reaches a critical value (two curves
//! meet: fold–flip, 1:1 and 1:2 resonances, …), where the critical pair of a
//! Neimark–Sacker curve reaches the real axis, and cusps of a fold curve.
//! Each is the zero of a test function evaluated at every point; a sign
//! change between two points is located by regula falsi on the arclength.

use nalgebra::Complex;
use serde::Serialize;

use super::CurveKind;

/// A codimension-two point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Codim2Kind {
    /// A cusp of a fold curve: the curve's projection onto the parameter
    /// plane reverses.
    Cusp,
    /// Two multipliers +1 (a fold curve meets a Neimark–Sacker curve, or a
    /// second multiplier crosses +1 on a fold curve).
    #[serde(rename = "resonance-1:1")]
    Resonance11,
    /// Two multipliers −1 (a period-doubling curve meets a Neimark–Sacker
    /// curve).
    #[serde(rename = "resonance-1:2")]
    Resonance12,
    /// Multipliers +1 and −1: fold and period-doubling curves meet.
    FoldFlip,
    /// Fold and symmetry-breaking curves meet (half-map eigenvalues ±1).
    FoldBranchPoint,
    /// A multiplier +1 and a pair on the unit circle.
    FoldNeimarkSacker,
    /// Period-doubling and symmetry-breaking curves meet.
    FlipBranchPoint,
    /// A multiplier −1 and a pair on the unit circle.
    FlipNeimarkSacker,
    /// Two half-map eigenvalues −1.
    DoubleBranchPoint,
    /// A half-map eigenvalue −1 and a pair on the unit circle.
    BranchPointNeimarkSacker,
    /// Two pairs on the unit circle.
    DoubleNeimarkSacker,
    /// A grazing curve meets a fold curve.
    GrazingFold,
    /// A grazing curve meets a period-doubling curve.
    GrazingFlip,
    /// A grazing curve meets a symmetry-breaking curve.
    GrazingBranchPoint,
    /// A grazing curve meets a Neimark–Sacker curve.
    GrazingNeimarkSacker,
}

impl Codim2Kind {
    /// The name used in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Codim2Kind::Cusp => "cusp",
            Codim2Kind::Resonance11 => "resonance-1:1",
            Codim2Kind::Resonance12 => "resonance-1:2",
            Codim2Kind::FoldFlip => "fold-flip",
            Codim2Kind::FoldBranchPoint => "fold-branch-point",
            Codim2Kind::FoldNeimarkSacker => "fold-neimark-sacker",
            Codim2Kind::FlipBranchPoint => "flip-branch-point",
            Codim2Kind::FlipNeimarkSacker => "flip-neimark-sacker",
            Codim2Kind::DoubleBranchPoint => "double-branch-point",
            Codim2Kind::BranchPointNeimarkSacker => "branch-point-neimark-sacker",
            Codim2Kind::DoubleNeimarkSacker => "double-neimark-sacker",
            Codim2Kind::GrazingFold => "grazing-fold",
            Codim2Kind::GrazingFlip => "grazing-flip",
            Codim2Kind::GrazingBranchPoint => "grazing-branch-point",
            Codim2Kind::GrazingNeimarkSacker => "grazing-neimark-sacker",
        }
    }

    /// The point where a curve of kind `a` meets one of kind `b`.
    fn meeting(a: CurveKind, b: CurveKind) -> Codim2Kind {
        use CurveKind::PeriodDoubling as P;
        use CurveKind::{BranchPoint as B, Fold as F, Grazing as G, NeimarkSacker as N};
        match (a, b) {
            (F, F) => Codim2Kind::Resonance11,
            (F, P) | (P, F) => Codim2Kind::FoldFlip,
            (F, B) | (B, F) => Codim2Kind::FoldBranchPoint,
            (F, N) | (N, F) => Codim2Kind::FoldNeimarkSacker,
            (P, P) => Codim2Kind::Resonance12,
            (P, B) | (B, P) => Codim2Kind::FlipBranchPoint,
            (P, N) | (N, P) => Codim2Kind::FlipNeimarkSacker,
            (B, B) => Codim2Kind::DoubleBranchPoint,
            (B, N) | (N, B) => Codim2Kind::BranchPointNeimarkSacker,
            (N, N) => Codim2Kind::DoubleNeimarkSacker,
            (F, G) | (G, F) | (G, G) => Codim2Kind::GrazingFold,
            (P, G) | (G, P) => Codim2Kind::GrazingFlip,
            (B, G) | (G, B) => Codim2Kind::GrazingBranchPoint,
            (N, G) | (G, N) => Codim2Kind::GrazingNeimarkSacker,
        }
    }
}

/// The test functions of a point of a curve of `kind`, from the
/// eigenvalues of the shooting map's Jacobian (DG of the half map when
/// `symmetric`) and κ (Neimark–Sacker curves). The curve's own critical
/// eigenvalues are set aside (those nearest +1, −1, ±i or e^{±iθ}); of the
/// others, Π(1 − λ) changes sign where one crosses +1, Π(1 + λ) where one
/// crosses −1, Π(1 + λ²) where one crosses ±i (a flip of Φ on the half
/// map), Π(1 − |λ|) over the pairs where a pair crosses the circle. On a
/// Neimark–Sacker curve the pair itself reaches the real axis at κ = ±1
/// (and ±i of the half map at κ = 0).
pub(super) fn test_values(
    kind: CurveKind,
    symmetric: bool,
    eigenvalues: &[Complex<f64>],
    kappa: f64,
) -> Vec<(Codim2Kind, f64)> {
    let i = Complex::new(0.0, 1.0);
    let one = Complex::new(1.0, 0.0);
    let critical: Vec<Complex<f64>> = match (kind, symmetric) {
        (CurveKind::Fold, _) => vec![one],
        (CurveKind::BranchPoint, _) | (CurveKind::PeriodDoubling, false) => vec![-one],
        (CurveKind::PeriodDoubling, true) => vec![i, -i],
        (CurveKind::NeimarkSacker, _) => {
            let root = (Complex::new(kappa * kappa - 1.0, 0.0)).sqrt();
            vec![kappa + root, kappa - root]
        }
        (CurveKind::Grazing, _) => vec![],
    };
    let mut others = eigenvalues.to_vec();
    for c in &critical {
        if let Some(k) = (0..others.len())
            .min_by(|&a, &b| (others[a] - c).norm().total_cmp(&(others[b] - c).norm()))
        {
            others.swap_remove(k);
        }
    }
    let product =
        |f: &dyn Fn(Complex<f64>) -> Complex<f64>| others.iter().fold(one, |acc, &l| acc * f(l)).re;
    let minus_kind = if symmetric {
        CurveKind::BranchPoint
    } else {
        CurveKind::PeriodDoubling
    };
    let mut values = vec![
        (
            Codim2Kind::meeting(kind, CurveKind::Fold),
            product(&|l| one - l),
        ),
        (Codim2Kind::meeting(kind, minus_kind), product(&|l| one + l)),
        (
            Codim2Kind::meeting(kind, CurveKind::NeimarkSacker),
            others
                .iter()
                .filter(|l| l.im > 0.0)
                .map(|l| 1.0 - l.norm())
                .product(),
        ),
    ];
    if symmetric {
        values.push((
            Codim2Kind::meeting(kind, CurveKind::PeriodDoubling),
            product(&|l| one + l * l),
        ));
    }
    if kind == CurveKind::NeimarkSacker {
        values.push((Codim2Kind::Resonance11, kappa - 1.0));
        if symmetric {
            values.push((Codim2Kind::DoubleBranchPoint, kappa + 1.0));
            values.push((Codim2Kind::Resonance12, kappa));
        } else {
            values.push((Codim2Kind::Resonance12, kappa + 1.0));
        }
    }
    values
}

/// The index of the test of pairs crossing the circle in
/// [`test_values`]: the one test that can jump (where a pair turns real).
pub(super) const CIRCLE_TEST: usize = 2;

/// Test values below this at both ends of a step are noise, not a sign
/// change: on R2 N = 2 the half map's critical pair of a Neimark–Sacker
/// curve stays at ±i (κ ≈ 1e-12, a double multiplier −1 of Φ) along
/// the whole curve.
const NOISE: f64 = 1e-7;

/// The tests whose sign changed between two points: their indices. A pair
/// of the half map crossing the circle at ±i is a flip of Φ, not a
/// Neimark–Sacker point: where both tests change, only the flip counts.
/// Where a Neimark–Sacker curve's own pair reaches the real axis (κ = ±1,
/// or 0 on the half map), the pair set aside changes from complex to real
/// and the tests of the other eigenvalues are not to be trusted: only the
/// κ test counts. Sign changes between values below [`NOISE`] do not count.
pub(super) fn changed(
    before: &[(Codim2Kind, f64)],
    after: &[(Codim2Kind, f64)],
    symmetric: bool,
) -> Vec<usize> {
    let flips: Vec<usize> = (0..before.len().min(after.len()))
        .filter(|&k| {
            let (a, b) = (before[k].1, after[k].1);
            a * b < 0.0 && a.abs().max(b.abs()) > NOISE
        })
        .collect();
    // Indices as built by `test_values`: 0 +1, 1 −1, 2 the circle, 3 ±i
    // (symmetric), then the κ tests.
    let own = if symmetric { 4 } else { 3 };
    if flips.iter().any(|&k| k >= own) {
        flips.into_iter().filter(|&k| k >= own).collect()
    } else if symmetric && flips.contains(&CIRCLE_TEST) && flips.contains(&3) {
        flips.into_iter().filter(|&k| k != CIRCLE_TEST).collect()
    } else {
        flips
    }
}
