//! The curves through a branch's special points: which are followed, in
//! both directions from each, which are skipped and why (`continue
//! --parameter2`, Python's `continue_(parameter2=…)` and the report alike).

use super::CurveStop;
use super::{continue_curve, grazing_margin, starts_grazing, Curve, CurveKind, CurveOptions};
use crate::continuation::{SpecialKind, SpecialPoint};
use crate::field_error::FieldError;
use crate::model::family::{Family2, FamilyError};
use crate::periodic::ShootingOptions;

/// Which curves to follow and how far.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveSelection {
    /// The kinds of special points continued as curves.
    pub kinds: Vec<CurveKind>,
    /// Bounds of the second parameter (None: from 0, or twice its value if
    /// negative, to twice its value, or half if negative).
    pub bounds2: (Option<f64>, Option<f64>),
    /// Largest step along a curve (scaled arclength).
    pub step: f64,
}

impl Default for CurveSelection {
    fn default() -> Self {
        Self {
            kinds: CurveKind::ALL.to_vec(),
            bounds2: (None, None),
            step: 0.05,
        }
    }
}

/// The curve kinds by their short names, `fold`, `bp`, `pd`, `ns` and
/// `grazing` (the CLI's `--curves`, Python's `curves=`).
pub const CURVE_NAMES: [(&str, CurveKind); 5] = [
    ("fold", CurveKind::Fold),
    ("bp", CurveKind::BranchPoint),
    ("pd", CurveKind::PeriodDoubling),
    ("ns", CurveKind::NeimarkSacker),
    ("grazing", CurveKind::Grazing),
];

impl CurveSelection {
    /// The kinds named `names` (short names, [`CURVE_NAMES`]).
    pub fn kinds_named<S: AsRef<str>>(names: &[S]) -> Result<Vec<CurveKind>, FieldError> {
        names
            .iter()
            .map(|n| {
                let n = n.as_ref();
                CURVE_NAMES
                    .iter()
                    .find(|(name, _)| *name == n)
                    .map(|(_, k)| *k)
                    .ok_or_else(|| {
                        let all: Vec<&str> = CURVE_NAMES.iter().map(|(name, _)| *name).collect();
                        FieldError::new("curves", n, format!("give any of {}", all.join(", ")))
                    })
            })
            .collect()
    }

    /// Checks the step (finite, positive).
    pub fn check(&self) -> Result<(), FieldError> {
        if self.step.is_finite() && self.step > 0.0 {
            Ok(())
        } else {
            Err(FieldError::new(
                "curve_step",
                self.step,
                "give a positive step",
            ))
        }
    }

    /// The second parameter's bounds around its value `q0`, checked.
    fn bounds_around(&self, q0: f64) -> Result<(f64, f64), FieldError> {
        let lo = self
            .bounds2
            .0
            .unwrap_or(if q0 >= 0.0 { 0.0 } else { 2.0 * q0 });
        let hi = self
            .bounds2
            .1
            .unwrap_or(if q0 >= 0.0 { 2.0 * q0 } else { 0.5 * q0 });
        if lo < hi && lo <= q0 && q0 <= hi {
            Ok((lo, hi))
        } else {
            Err(FieldError::new(
                "from2",
                format!("{lo} to {hi}"),
                format!("give a range around the second parameter's value {q0}"),
            ))
        }
    }

    /// The curve kind a special point starts, if selected.
    fn kind_of(&self, s: &SpecialPoint) -> Option<CurveKind> {
        let kind = match s.kind {
            SpecialKind::Fold => CurveKind::Fold,
            SpecialKind::BranchPoint if s.symmetry_breaking => CurveKind::BranchPoint,
            SpecialKind::PeriodDoubling => CurveKind::PeriodDoubling,
            SpecialKind::NeimarkSacker => CurveKind::NeimarkSacker,
            SpecialKind::Grazing => CurveKind::Grazing,
            SpecialKind::BranchPoint | SpecialKind::User => return None,
        };
        self.kinds.contains(&kind).then_some(kind)
    }
}

/// The curves of a branch's special points.
#[derive(Debug, Default)]
pub struct Curves {
    /// Each curve with the label of the special point it starts from.
    pub followed: Vec<(String, Curve)>,
    /// Special points without a curve (label, why): a change of the impact
    /// count that is an impact splitting in two, not a grazing, or a kind
    /// with no matrix-free form.
    pub skipped: Vec<(String, String)>,
}

/// Why the curves could not be followed.
#[derive(Debug, thiserror::Error)]
pub enum CurvesError {
    /// An option refused by name.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// The family has no model at a point.
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// A curve failed.
    #[error("the {kind} curve from {label}: {message}")]
    Curve {
        /// The curve's kind.
        kind: &'static str,
        /// The special point it starts from.
        label: String,
        /// Why.
        message: String,
    },
}

/// The branch whose special points start the curves: its special points,
/// whether it is on the half map, its range in the first parameter and the
/// second parameter's value along it.
#[derive(Clone, Copy, Debug)]
pub struct BranchOrigin<'a> {
    /// The special points.
    pub special: &'a [SpecialPoint],
    /// On the half map.
    pub symmetric: bool,
    /// The first parameter's range (start, end).
    pub range: (f64, f64),
    /// The second parameter's value along the branch.
    pub q0: f64,
}

/// Every curve through the selected special points of `branch` (both
/// directions from each, a closed curve once), within the first
/// parameter's range and the second parameter's bounds; `krylov`: the
/// Arnoldi dimension if matrix-free.
pub fn curves_of_branch<F: Family2>(
    mut family: F,
    branch: BranchOrigin<'_>,
    selection: &CurveSelection,
    (shooting, krylov): (&ShootingOptions, Option<usize>),
) -> Result<Curves, CurvesError> {
    let BranchOrigin {
        special,
        symmetric,
        range: (from, to),
        q0,
    } = branch;
    selection.check()?;
    let (lo, hi) = selection.bounds_around(q0)?;
    let opts = CurveOptions {
        shooting: ShootingOptions {
            symmetric,
            ..shooting.clone()
        },
        bounds: [(from.min(to), from.max(to)), (lo, hi)],
        ds_max: selection.step,
        ds: selection.step.min(CurveOptions::default().ds),
        krylov,
        ..CurveOptions::default()
    };
    let mut out: Vec<(String, Curve)> = Vec::new();
    let mut skipped = Vec::new();
    for s in special {
        let Some(kind) = selection.kind_of(s) else {
            continue;
        };
        // A special point that a curve already passed (both BPs of R2 N = 1
        // lie on one closed curve) is not followed again.
        if out
            .iter()
            .any(|(_, c)| c.kind == kind && passes(c, s.parameter, q0))
        {
            continue;
        }
        if krylov.is_some() && matches!(kind, CurveKind::NeimarkSacker | CurveKind::Grazing) {
            skipped.push((
                s.label.clone(),
                format!(
                    "{} curves have no matrix-free form yet (the dense form takes rows up to 2048 bodies)",
                    kind.name()
                ),
            ));
            continue;
        }
        let fail = |message: String| CurvesError::Curve {
            kind: kind.name(),
            label: s.label.clone(),
            message,
        };
        if kind == CurveKind::Grazing {
            let model = family.model_at(s.parameter, q0)?;
            let margin = grazing_margin(&model, &s.state, &opts.shooting).map_err(fail)?;
            if !starts_grazing(margin, &opts.shooting) {
                skipped.push((
                    s.label.clone(),
                    format!("an impact splits in two: no contact's closest approach grazes (margin {margin:.2e} m)"),
                ));
                continue;
            }
        }
        for direction in [1.0, -1.0] {
            let start = (&s.state[..], s.parameter, q0);
            let curve = continue_curve(&mut family, kind, start, direction, &opts).map_err(fail)?;
            let closed = curve.stop == CurveStop::Closed;
            out.push((s.label.clone(), curve));
            if closed {
                break;
            }
        }
    }
    Ok(Curves {
        followed: out,
        skipped,
    })
}

/// Whether the curve crosses the second parameter's value `q0` at the
/// first parameter `p0`: within 1e-4 relative, or a quarter of the chord's
/// extent in p (the chord between two points misses a bending curve).
fn passes(curve: &Curve, p0: f64, q0: f64) -> bool {
    curve.points.windows(2).any(|w| {
        let (a, b) = (&w[0], &w[1]);
        if (a.q - q0) * (b.q - q0) > 0.0 || a.q == b.q {
            return false;
        }
        let p = a.p + (q0 - a.q) / (b.q - a.q) * (b.p - a.p);
        (p - p0).abs() <= (1e-4 * p0.abs()).max(0.25 * (b.p - a.p).abs())
    })
}
