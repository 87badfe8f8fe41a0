//! Special points of a branch as events: test functions evaluated at every
//! point ([`TestValues`]), the [`BranchEvent`] trait that says whether an
//! event lies between two consecutive points (the built-in kinds — fold,
//! branch point, period doubling, Neimark–Sacker, grazing — and user
//! conditions on a point, [`UserEvent`]). Their location on the arclength
//! is the problem's (`Problem::locate` in `problem.rs`).

use nalgebra::{Complex, DMatrix};

use super::{BranchPoint, SpecialKind};

/// The values of the built-in test functions at a point of a branch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TestValues {
    /// Parameter component of the unit tangent (changes sign at a fold).
    pub tangent_p: f64,
    /// `det [J; t]` of the extended system (changes sign at a branch point).
    pub det_ext: f64,
    /// det(DG + I) of the symmetric half map (an eigenvalue -1 of DG is a
    /// symmetry-breaking pitchfork); 1 off the half map.
    pub det_sym: f64,
    /// det(Φ + I) (changes sign at a period doubling).
    pub det_pd: f64,
    /// Multipliers outside the unit circle.
    pub outside: usize,
    /// Π (1 − |μ|) over the complex multipliers with Im μ > 0: changes sign
    /// when a complex pair crosses the unit circle, and not when a pair is
    /// born inside it (1 without such pairs).
    pub complex_margin: f64,
    /// Impacts per period.
    pub impacts: usize,
    /// The impact margin (max (s − s_on) over the period) of the contact
    /// nearest to grazing (smallest |margin|), signed: it crosses zero
    /// where an impact appears or vanishes. NaN until the orbit is
    /// summarised or without contacts.
    pub grazing_margin: f64,
}

impl TestValues {
    /// The test values from dominant eigenvalues (matrix-free
    /// continuation): `map_eigenvalues` of Φ (or DG of the half map),
    /// `multipliers` those of Φ. det(−Ĵ_x) = Π(1 − λ) over the map's
    /// eigenvalues, and det [J; t] = det(Ĵ_x) / t_p for a unit tangent;
    /// likewise det(DG + I) and det(Φ + I) as products over the dominant
    /// eigenvalues. A factor 1 − λ (or 1 + λ) of a real eigenvalue inside
    /// the circle, or of a complex pair, is positive: the sign changes only
    /// where an eigenvalue crosses 1 (or −1), and not where the set of
    /// converged Ritz values gains or loses an eigenvalue inside the circle.
    pub(super) fn from_spectrum(
        tangent_p: f64,
        map_eigenvalues: &[Complex<f64>],
        multipliers: &[Complex<f64>],
        symmetric: bool,
    ) -> TestValues {
        let one = Complex::new(1.0, 0.0);
        let product =
            |s: &[Complex<f64>], sign: f64| s.iter().fold(one, |acc, l| acc * (one + l * sign)).re;
        TestValues {
            tangent_p,
            det_ext: product(map_eigenvalues, -1.0) / tangent_p,
            det_sym: if symmetric {
                product(map_eigenvalues, 1.0)
            } else {
                1.0
            },
            det_pd: product(multipliers, 1.0),
            ..Self::from_multipliers(multipliers, 0)
        }
    }

    /// The test values from the extended Jacobian `jac`, the tangent `t`,
    /// the monodromy matrix (of the half map if `symmetric`), its
    /// multipliers and the impacts per period.
    pub(super) fn at(
        jac: &DMatrix<f64>,
        t: &[f64],
        monodromy: &DMatrix<f64>,
        multipliers: &[Complex<f64>],
        impacts: usize,
        symmetric: bool,
    ) -> TestValues {
        let d = jac.nrows();
        let mut a = DMatrix::zeros(d + 1, d + 1);
        a.view_mut((0, 0), (d, d + 1)).copy_from(jac);
        for c in 0..=d {
            a[(d, c)] = t[c];
        }
        let identity = DMatrix::<f64>::identity(d, d);
        // Φ + I; on the half map Φ = DG².
        let (det_sym, pd) = if symmetric {
            (
                (monodromy + &identity).determinant(),
                monodromy * monodromy + &identity,
            )
        } else {
            (1.0, monodromy + &identity)
        };
        TestValues {
            tangent_p: t[d],
            det_ext: a.determinant(),
            det_sym,
            det_pd: pd.determinant(),
            ..Self::from_multipliers(multipliers, impacts)
        }
    }

    /// The values read from the multipliers alone (the count outside the
    /// circle, the complex margin) and the impacts; the determinants and
    /// the tangent left neutral for the callers to set.
    fn from_multipliers(multipliers: &[Complex<f64>], impacts: usize) -> TestValues {
        TestValues {
            tangent_p: 1.0,
            det_ext: 1.0,
            det_sym: 1.0,
            det_pd: 1.0,
            outside: multipliers.iter().filter(|m| m.norm() > 1.0).count(),
            complex_margin: multipliers
                .iter()
                .filter(|m| m.im > 0.0)
                .map(|m| 1.0 - m.norm())
                .product(),
            impacts,
            grazing_margin: f64::NAN,
        }
    }
}

/// A point of a branch as an event sees it.
#[derive(Clone, Copy, Debug)]
pub struct Observed<'a> {
    /// The built-in test values.
    pub tests: &'a TestValues,
    /// The point itself (parameter, state, amplitudes, multipliers).
    pub point: &'a BranchPoint,
}

/// A condition whose occurrence between consecutive points of a branch is
/// detected and then located (to the continuation's `locate_tol` in the
/// parameter) by bisection of the arclength.
pub trait BranchEvent: Send {
    /// The kind reported (and the label prefix).
    fn kind(&self) -> SpecialKind;
    /// Whether the event lies between the points `a` and `b`.
    fn between(&self, a: Observed<'_>, b: Observed<'_>) -> bool;

    /// Whether deciding the event needs the orbit summary of a point (its
    /// amplitudes and impacts per period), an integration more per
    /// bisection step; default true.
    fn needs_orbit(&self) -> bool {
        true
    }

    /// A continuous test function that changes sign at the event between
    /// `a` and `b`, if there is one: location then samples where its
    /// secant through the bracket vanishes (Illinois' regula falsi) instead
    /// of halving the bracket. Default None (bisection).
    fn scalar(&self, _a: Observed<'_>, _b: Observed<'_>) -> Option<fn(&TestValues) -> f64> {
        None
    }
}

/// The built-in special points, from the test values.
impl BranchEvent for SpecialKind {
    fn kind(&self) -> SpecialKind {
        *self
    }

    /// Only grazing (impacts per period) and user conditions read the
    /// orbit summary.
    fn needs_orbit(&self) -> bool {
        matches!(self, SpecialKind::Grazing | SpecialKind::User)
    }

    /// Folds: the tangent's parameter component; branch points: det(DG + I)
    /// of the half map where it changes sign, else det [J; t]; period
    /// doublings: det(Φ + I); Neimark–Sacker points: the product of
    /// 1 − |μ| over the complex pairs; grazings: the impact margin of the
    /// contact nearest to grazing (the count decides the bracket; an
    /// impact that splits in two does not change the margin's sign, and
    /// the location falls back to bisection).
    fn scalar(&self, a: Observed<'_>, b: Observed<'_>) -> Option<fn(&TestValues) -> f64> {
        match self {
            SpecialKind::Fold => Some(|t| t.tangent_p),
            SpecialKind::BranchPoint if a.tests.det_sym.signum() != b.tests.det_sym.signum() => {
                Some(|t| t.det_sym)
            }
            SpecialKind::BranchPoint => Some(|t| t.det_ext),
            SpecialKind::PeriodDoubling => Some(|t| t.det_pd),
            SpecialKind::NeimarkSacker => Some(|t| t.complex_margin),
            SpecialKind::Grazing => Some(|t| t.grazing_margin),
            SpecialKind::User => None,
        }
    }

    fn between(&self, a: Observed<'_>, b: Observed<'_>) -> bool {
        match self {
            SpecialKind::Fold => a.tests.tangent_p.signum() != b.tests.tangent_p.signum(),
            SpecialKind::BranchPoint => {
                (a.tests.det_ext.signum() != b.tests.det_ext.signum()
                    && a.tests.tangent_p.signum() == b.tests.tangent_p.signum())
                    || a.tests.det_sym.signum() != b.tests.det_sym.signum()
            }
            SpecialKind::PeriodDoubling => a.tests.det_pd.signum() != b.tests.det_pd.signum(),
            // A change of the number of multipliers outside the circle that no
            // real crossing at +1 (fold, branch point) or -1 (period doubling)
            // explains: a complex pair crossed. (Two real multipliers that
            // collide and turn complex outside the circle change nothing.)
            SpecialKind::NeimarkSacker => {
                a.tests.outside != b.tests.outside
                    && a.tests.det_pd.signum() == b.tests.det_pd.signum()
                    && a.tests.det_ext.signum() == b.tests.det_ext.signum()
                    && a.tests.det_sym.signum() == b.tests.det_sym.signum()
                    && a.tests.tangent_p.signum() == b.tests.tangent_p.signum()
            }
            SpecialKind::Grazing => a.tests.impacts != b.tests.impacts,
            // User conditions are events of their own (UserEvent).
            SpecialKind::User => false,
        }
    }
}

/// A user condition: an event where `g(point)` changes sign, e.g. an
/// amplitude reaching a level (`|u_1| = 5 mm`) or the parameter passing a
/// value of interest. Reported as [`SpecialKind::User`] (labels `UZ1`, …).
pub struct UserEvent<G>(pub G);

impl<G: Fn(&BranchPoint) -> f64 + Send> BranchEvent for UserEvent<G> {
    fn kind(&self) -> SpecialKind {
        SpecialKind::User
    }

    fn between(&self, a: Observed<'_>, b: Observed<'_>) -> bool {
        (self.0)(a.point).signum() != (self.0)(b.point).signum()
    }
}

/// The built-in events, in the order they are reported within a step.
pub(super) const BUILT_IN: [SpecialKind; 5] = [
    SpecialKind::Fold,
    SpecialKind::BranchPoint,
    SpecialKind::PeriodDoubling,
    SpecialKind::NeimarkSacker,
    SpecialKind::Grazing,
];
