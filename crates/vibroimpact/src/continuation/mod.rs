//! Pseudo-arclength continuation of periodic solutions in a parameter, with
//! Floquet stability and detection and location of special points
//! (docs/theory.md §5).
//!
//! ## Files
//! - `problem.rs` — the extended system in scaled variables, corrector, tangent;
//! - `events.rs` — special points as events: test values, location;
//! - `branch/` — the [`Continuation`] iterator over a branch's steps, and
//!   the hand-over of its points from the corrector to the finisher;
//! - `finish.rs` — each point's orbit summary and the special points before
//!   it, beside the corrector;
//! - `switching.rs` — starts on crossing and period-doubled branches;
//! - `start.rs` — the homotopy start on the primary branch;
//! - `krylov.rs` — the matrix-free extended system for long rows;
//! - `curve/` — two-parameter curves of special points;
//! - `study.rs`, `continue_study.rs`, `orbit_study.rs` — the studies every
//!   face runs (a branch on any family; a branch of a model file with its
//!   curves; one periodic orbit);
//! - `tests.rs` — the linear limit, R2 branches against AUTO-07p's points.
//!
//! ## Formulation
//! Unknowns `z = (x, p)`: the state at t = 0 of an nT-periodic orbit and the
//! parameter, in scaled variables (`x̂ = x / scale`, displacement scale and
//! ×Ω for velocities, `p̂ = p / σ` with σ = |p0| or half the range if
//! larger, or the option `parameter_scale`). The branch solves `G(x, p) =
//! P_p(x) - x = 0`; its Jacobian is `[Φ - I, ∂G/∂p]` (Φ from the variational
//! equations, `∂G/∂p` by a forward difference of the period map).
//!
//! - Predictor: `z + ds t` along the unit tangent t.
//! - Corrector: Newton on `G(z) = 0, t·(z - z_pred) = 0`.
//! - Tangent: `[J; t_old] t_new = e`, normalised, oriented along t_old.
//! - Step control ([`StepControl`]): ds grows (×1.6) after easy
//!   corrections (<= 2 Newton iterations), shrinks (×0.7) after hard ones
//!   (>= 5) and halves on failure; the branch stops when ds < ds_min.
//!
//! ## Special points (test functions between consecutive points)
//! - fold: the parameter component of the tangent changes sign;
//! - branch point: `det [J; t]` changes sign (it does not at a fold):
//!   a multiplier crosses +1 where the parameter does not turn;
//! - period doubling: `det(Φ + I)` changes sign (a real multiplier
//!   crosses -1);
//! - Neimark–Sacker: the number of multipliers outside the unit circle
//!   changes while no real multiplier crosses +1 or -1 (a complex pair
//!   crossed);
//! - grazing: the number of impacts per period changes.
//!
//! - user conditions: a sign change of a function of the point
//!   ([`UserEvent`]).
//!
//! Each is an [`BranchEvent`], located by bisection of the arclength
//! between the two points (re-correcting from the earlier point), until the
//! parameter is known to `locate_tol`.

mod branch;
mod continue_study;
mod curve;
mod events;
mod finish;
mod krylov;
mod orbit_study;
mod problem;
mod start;
mod study;
mod switching;
#[cfg(test)]
mod tests;

pub use branch::{spectral_distance, validate_size, BranchStep, Continuation};
pub use continue_study::{
    BranchSpecialPoints, CheckedContinue, ContinueOutcome, ContinueStudy, CurvesRequest,
};
pub use curve::{
    continue_curve, curves_of_branch, grazing_margin, starts_grazing, BranchOrigin, Codim2Kind,
    Curve, CurveKind, CurveOptions, CurvePoint, CurveSelection, CurveSpecial, CurveStop, Curves,
    CurvesError, CURVE_NAMES,
};
pub use events::{BranchEvent, Observed, TestValues, UserEvent};
pub use orbit_study::{CheckedOrbit, Guess, OrbitOutcome, OrbitStudy};
pub use start::amplitude_homotopy;
pub use study::{
    BranchOutcome, BranchStudy, CheckedBranch, Linear, Start, StudyError, StudyField,
    AUTO_KRYLOV_BODIES,
};
pub use switching::{
    branch_switch_start, is_symmetric_orbit, period_doubled_start, switch_branch, SwitchError,
};

use nalgebra::Complex;

use crate::model::family::{Family, FamilyError};
use crate::periodic::{PeriodicError, ShootingOptions};

/// Kinds of special points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecialKind {
    /// Turning point of the branch (saddle-node).
    Fold,
    /// A multiplier crosses +1 without a turn: branches cross.
    BranchPoint,
    /// A real multiplier crosses -1.
    PeriodDoubling,
    /// A complex pair crosses the unit circle (torus).
    NeimarkSacker,
    /// The number of impacts per period changes.
    Grazing,
    /// A user condition ([`UserEvent`]) changes sign.
    User,
}

impl SpecialKind {
    /// Every kind.
    pub const ALL: [SpecialKind; 6] = [
        SpecialKind::Fold,
        SpecialKind::BranchPoint,
        SpecialKind::PeriodDoubling,
        SpecialKind::NeimarkSacker,
        SpecialKind::Grazing,
        SpecialKind::User,
    ];

    /// Name used in files: `fold`, `branch-point`, `period-doubling`,
    /// `neimark-sacker`, `grazing`, `user`.
    pub fn name(self) -> &'static str {
        match self {
            SpecialKind::Fold => "fold",
            SpecialKind::BranchPoint => "branch-point",
            SpecialKind::PeriodDoubling => "period-doubling",
            SpecialKind::NeimarkSacker => "neimark-sacker",
            SpecialKind::Grazing => "grazing",
            SpecialKind::User => "user",
        }
    }

    /// Label prefix: LP, BP, PD, NS, GR, UZ.
    pub fn prefix(self) -> &'static str {
        match self {
            SpecialKind::Fold => "LP",
            SpecialKind::BranchPoint => "BP",
            SpecialKind::PeriodDoubling => "PD",
            SpecialKind::NeimarkSacker => "NS",
            SpecialKind::Grazing => "GR",
            SpecialKind::User => "UZ",
        }
    }
}

/// Options of a continuation.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationOptions {
    /// Shooting options (subharmonic n, tolerances, scales).
    pub shooting: ShootingOptions,
    /// Initial arclength step (scaled units).
    pub ds: f64,
    /// Smallest step before giving up.
    pub ds_min: f64,
    /// Largest step.
    pub ds_max: f64,
    /// Points at most.
    pub max_points: usize,
    /// Corrector iterations at most.
    pub max_corrector: usize,
    /// How the arclength step adapts.
    pub step: StepControl,
    /// Location tolerance of special points in the parameter.
    pub locate_tol: f64,
    /// Largest change of the Floquet multipliers between consecutive points
    /// ([`spectral_distance`]); a larger change halves the step, so that two
    /// crossings of the unit circle do not hide in one step.
    pub max_multiplier_change: f64,
    /// Parameter interval the branch must stay in (default: between the
    /// start and the end value).
    pub bounds: Option<(f64, f64)>,
    /// Follow symmetric orbits of a mirror-symmetric model on the half map
    /// (see [`ShootingOptions::symmetric`]) when the start orbit is
    /// symmetric: half the cost, and symmetry-breaking pitchforks are
    /// regular points of the half map, found by its eigenvalue -1 instead
    /// of a singular extended Jacobian.
    pub use_symmetry: bool,
    /// Scale of the parameter in the arclength (default: the start value
    /// `|p0|`, or half the range `|p_end − p0|` if larger, so that a start
    /// at or near zero does not make every step tiny): steps change the
    /// parameter by at most about `ds_max · scale`.
    pub parameter_scale: Option<f64>,
    /// Matrix-free continuation with this Arnoldi dimension (None: dense).
    /// The corrector and the tangent solve their bordered systems by GMRES
    /// on products Ĵ_x v (one integration of the state and one tangent
    /// column each), the multipliers are the Ritz values of this many
    /// Arnoldi vectors, and the test functions are taken from them (a
    /// multiplier outside the Arnoldi space is not seen). Memory
    /// O(N · dimension) instead of O(N²); for rows of hundreds of bodies.
    pub krylov: Option<usize>,
    /// Detect and locate the built-in special points and summarise each
    /// point's orbit (default true). Off, the branch is only a path to its
    /// end: no built-in special points, and the points between the first
    /// and the last come without amplitudes (empty) and with 0 impacts per period
    /// unless an added event reads them (the amplitude homotopy of
    /// [`amplitude_homotopy`], whose points
    /// serve only to reach the model's own amplitude).
    pub special_points: bool,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            // The period map with impacts is accurate to ~1e-8 (scaled) at
            // rtol 1e-10; a corrector tolerance above that noise floor (the
            // final free Newton step takes the state below it). R2 N = 2:
            // the special points move by at most 7e-9 ω0 from rtol 1e-11
            // (docs/decisions.md D15).
            shooting: ShootingOptions {
                rtol: 1e-10,
                tol: 1e-7,
                ..ShootingOptions::default()
            },
            ds: 0.01,
            ds_min: 1e-7,
            ds_max: 0.05,
            max_points: 2000,
            max_corrector: 8,
            step: StepControl::default(),
            locate_tol: 1e-8,
            max_multiplier_change: 0.25,
            bounds: None,
            use_symmetry: true,
            parameter_scale: None,
            krylov: None,
            special_points: true,
        }
    }
}

/// Adaptation of the arclength step and the corrector's damping.
#[derive(Clone, Debug, PartialEq)]
pub struct StepControl {
    /// Factor on ds after an easy correction (default 1.6).
    pub grow: f64,
    /// Factor on ds after a hard correction (default 0.7).
    pub shrink: f64,
    /// Factor on ds after a failed correction (default 0.5).
    pub fail: f64,
    /// At most this many corrector iterations is easy (default 2).
    pub easy_iterations: usize,
    /// At least this many corrector iterations is hard (default 5).
    pub hard_iterations: usize,
    /// Smallest cosine between consecutive unit tangents; a sharper turn is
    /// a jump to another branch and is refused (default 0.8, about 37°).
    pub min_tangent_cos: f64,
    /// Largest corrector step (max-norm, scaled units); longer Newton steps
    /// are damped to it (default 0.5).
    pub corrector_max_step: f64,
}

impl Default for StepControl {
    fn default() -> Self {
        Self {
            grow: 1.6,
            shrink: 0.7,
            fail: 0.5,
            easy_iterations: 2,
            hard_iterations: 5,
            min_tangent_cos: 0.8,
            corrector_max_step: 0.5,
        }
    }
}

impl StepControl {
    /// The next step after a correction that took `iterations`, within
    /// `[ds_min, ds_max]`.
    pub fn next(&self, ds: f64, iterations: usize, ds_min: f64, ds_max: f64) -> f64 {
        if iterations <= self.easy_iterations {
            (ds * self.grow).min(ds_max)
        } else if iterations >= self.hard_iterations {
            (ds * self.shrink).max(ds_min)
        } else {
            ds
        }
    }

    /// Checks the factors: `grow >= 1`, `0 < shrink <= 1`, `0 < fail < 1`,
    /// `easy_iterations < hard_iterations`, `min_tangent_cos` in `(-1, 1)`,
    /// `corrector_max_step > 0`.
    fn validate(&self) -> Result<(), ContinuationError> {
        let ok = self.grow >= 1.0
            && self.grow.is_finite()
            && self.shrink > 0.0
            && self.shrink <= 1.0
            && self.fail > 0.0
            && self.fail < 1.0
            && self.easy_iterations < self.hard_iterations
            && self.min_tangent_cos > -1.0
            && self.min_tangent_cos < 1.0
            && self.corrector_max_step > 0.0
            && self.corrector_max_step.is_finite();
        if ok {
            Ok(())
        } else {
            Err(ContinuationError::Invalid(format!(
                "step control {self:?}: needs grow >= 1, 0 < shrink <= 1, 0 < fail < 1, \
                 easy_iterations < hard_iterations, -1 < min_tangent_cos < 1, corrector_max_step > 0"
            )))
        }
    }
}

/// One point of a branch.
#[derive(Clone, Debug)]
pub struct BranchPoint {
    /// Parameter value.
    pub parameter: f64,
    /// State at t = 0 (body order).
    pub state: Vec<f64>,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// max |u_i| over the period (m).
    pub max_displacement: Vec<f64>,
    /// max |v_i| over the period (m/s).
    pub max_velocity: Vec<f64>,
    /// Impacts per period (all contacts).
    pub impacts_per_period: usize,
    /// Special-point label at this point (e.g. `LP1`), if it is one.
    pub label: Option<String>,
}

impl BranchPoint {
    /// Largest |multiplier|.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }
}

/// A located special point.
#[derive(Clone, Debug)]
pub struct SpecialPoint {
    /// Kind.
    pub kind: SpecialKind,
    /// Label, e.g. `PD1`.
    pub label: String,
    /// Parameter value (to `locate_tol`).
    pub parameter: f64,
    /// State at t = 0 (body order).
    pub state: Vec<f64>,
    /// max |u_i| over the orbit there, body order (m): its own orbit, so a
    /// figure marks it on the curve (empty where the branch's points carry
    /// no amplitudes, and in special points read back from a file).
    pub max_displacement: Vec<f64>,
    /// Multipliers there.
    pub multipliers: Vec<Complex<f64>>,
    /// Unit tangent of the branch there (scaled variables, x then p).
    pub tangent: Vec<f64>,
    /// Index of the branch point after which it lies.
    pub after_point: usize,
    /// A branch point where a symmetric orbit loses its symmetry (an
    /// eigenvalue -1 of the half map's Jacobian): a pitchfork whose
    /// crossing branch is a pair of mirror-image asymmetric orbits.
    pub symmetry_breaking: bool,
}

/// Why a continuation ended.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// The parameter left the requested range.
    ReachedEnd,
    /// The point budget was used.
    MaxPoints,
    /// The caller asked to stop (e.g. Ctrl-C).
    Interrupted,
    /// The corrector failed down to the smallest step: where and why.
    CannotContinue(String),
    /// A branch through rigid impacts reached a grazing impact, where the
    /// rigid period map is not differentiable (docs/theory.md §12): the
    /// branch of impacting orbits ends there, labelled GR; where and why.
    Grazing(String),
    /// The branch returned to its first point (a closed loop, e.g. the
    /// asymmetric branch between two symmetry-breaking points and its
    /// mirror image); it is not traversed again.
    ClosedLoop,
    /// It turned back (a fold) and left the range on the side it started
    /// from: the far end was not reached (a homotopy start at 11.1 that
    /// folded back at 10.387 read "from 11.1 to 11.1 (ReachedEnd)").
    TurnedBack,
}

impl StopReason {
    /// A stable name: `ReachedEnd`, `MaxPoints`, `Interrupted`,
    /// `CannotContinue`, `Grazing`, `ClosedLoop` or `TurnedBack` (the
    /// documents' `stop`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::ReachedEnd => "ReachedEnd",
            Self::MaxPoints => "MaxPoints",
            Self::Interrupted => "Interrupted",
            Self::CannotContinue(_) => "CannotContinue",
            Self::Grazing(_) => "Grazing",
            Self::ClosedLoop => "ClosedLoop",
            Self::TurnedBack => "TurnedBack",
        }
    }

    /// Where and why a branch could not continue or ended at a grazing
    /// (the documents' `stop_detail`); None for the other stops.
    pub fn detail(&self) -> Option<&str> {
        match self {
            Self::CannotContinue(why) | Self::Grazing(why) => Some(why),
            _ => None,
        }
    }
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::ReachedEnd => write!(f, "reached the end of the range"),
            Self::MaxPoints => write!(f, "used the point budget"),
            Self::Interrupted => write!(f, "interrupted"),
            Self::CannotContinue(why) => write!(f, "cannot continue: {why}"),
            Self::Grazing(why) => write!(f, "ends at a grazing (GR): {why}"),
            Self::ClosedLoop => write!(
                f,
                "closed loop (back at its first point or its mirror image)"
            ),
            Self::TurnedBack => write!(
                f,
                "turned back and left the range on the side it started from: the far end was not reached"
            ),
        }
    }
}

/// A computed branch.
#[derive(Clone, Debug)]
pub struct Branch {
    /// Points in order along the branch.
    pub points: Vec<BranchPoint>,
    /// Special points in order along the branch.
    pub special: Vec<SpecialPoint>,
    /// Why it ended.
    pub stop: StopReason,
    /// Period multiple n of the branch.
    pub subharmonic: u32,
    /// Whether the branch was followed on the symmetric half map (its
    /// orbits satisfy `x(t + nT/2) = S x(t)`).
    pub symmetric: bool,
}

/// Errors before a branch exists.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ContinuationError {
    /// The family could not build a model at a parameter value.
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// Shooting failed.
    #[error(transparent)]
    Periodic(#[from] PeriodicError),
    /// The start did not converge.
    #[error("no periodic solution at the start: Newton stopped at scaled residual {0:e}")]
    StartNotConverged(f64),
    /// Invalid options or range.
    #[error("{0}")]
    Invalid(String),
    /// An integration failed.
    #[error("integration failed: {0}")]
    Integration(#[from] crate::integrate::IntegrationError),
}

/// Continues the branch of nT-periodic solutions from `(x0, p0)` toward
/// `p_end`, collecting the steps of [`Continuation`] into a [`Branch`].
/// `family(p)` builds the model at parameter p; `on_point` sees every
/// accepted point and returns false to stop (the branch so far is returned,
/// [`StopReason::Interrupted`]). `x0` need not be converged: it is refined
/// by shooting first.
pub fn continue_branch<F, C>(
    family: F,
    p0: f64,
    x0: &[f64],
    p_end: f64,
    opts: &ContinuationOptions,
    mut on_point: C,
) -> Result<Branch, ContinuationError>
where
    F: Family + Send,
    C: FnMut(&BranchPoint) -> bool,
{
    let mut steps = Continuation::new(family, p0, x0, p_end, opts)?;
    let (subharmonic, symmetric) = (steps.subharmonic(), steps.symmetric());
    let (mut points, mut special) = (Vec::new(), Vec::new());
    let stop = loop {
        match steps.next() {
            Some(BranchStep::Point {
                point,
                special: found,
            }) => {
                special.extend(found);
                let go_on = on_point(&point);
                points.push(point);
                if !go_on {
                    break steps
                        .pending_stop()
                        .cloned()
                        .unwrap_or(StopReason::Interrupted);
                }
            }
            Some(BranchStep::Stop(reason)) => break reason,
            None => break StopReason::Interrupted,
        }
    };
    // A rigid branch's grazing end is its last point, labelled GR.
    if let (StopReason::Grazing(_), Some(last)) = (&stop, points.last_mut()) {
        let n = 1 + special
            .iter()
            .filter(|s: &&SpecialPoint| s.kind == SpecialKind::Grazing)
            .count();
        let label = format!("{}{n}", SpecialKind::Grazing.prefix());
        last.label = Some(label.clone());
        special.push(SpecialPoint {
            kind: SpecialKind::Grazing,
            label,
            parameter: last.parameter,
            state: last.state.clone(),
            max_displacement: last.max_displacement.clone(),
            multipliers: last.multipliers.clone(),
            tangent: Vec::new(),
            after_point: points.len() - 1,
            symmetry_breaking: false,
        });
    }
    Ok(Branch {
        points,
        special,
        stop,
        subharmonic,
        symmetric,
    })
}
