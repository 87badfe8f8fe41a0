//! The [`Continuation`] iterator: one accepted point of the branch per
//! step (predictor, corrector, step control, special points between the
//! points), ending with the reason it stopped.
//!
//! - `mod.rs` — the start, the corrector's steps and the branch's checks;
//! - `handover.rs` — the points handed from the corrector to the finisher,
//!   and the iterator of finished points;
//! - `tests.rs` — the start.

use std::collections::VecDeque;

use crate::model::family::Family;
use nalgebra::{Complex, DMatrix};

use super::events::{BranchEvent, BUILT_IN};
use super::finish::{Corrected, Finisher, Shared};
use super::problem::{period_image, Evaluated, Linear, Problem};
use super::{
    is_symmetric_orbit, BranchPoint, ContinuationError, ContinuationOptions, SpecialPoint,
    StopReason,
};
use crate::model::Model;
use crate::newton::NewtonStop;
use crate::periodic::{shoot_krylov, shoot_orbit, ShootingOptions, MAX_DENSE_DIM, MIN_ARNOLDI};
use crate::simulate::Integrator;

mod handover;
use handover::Step;

/// One step of a [`Continuation`].
#[derive(Clone, Debug)]
pub enum BranchStep {
    /// An accepted point (the first is the start), with the special points
    /// located between it and the point before.
    Point {
        /// The point.
        point: BranchPoint,
        /// Special points located since the previous point, in order.
        special: Vec<SpecialPoint>,
    },
    /// The branch ended; nothing follows.
    Stop(StopReason),
}

/// Pseudo-arclength continuation as an iterator over the steps of a branch
/// ([`BranchStep`]): the caller decides when to stop (a point budget of its
/// own, Ctrl-C, a condition on the points), watches progress, or collects
/// the branch ([`continue_branch`](super::continue_branch)).
///
/// Built-in events are the fold, branch point, period doubling,
/// Neimark–Sacker and grazing tests; [`with_event`](Self::with_event) adds
/// more (e.g. a [`UserEvent`](super::UserEvent)).
pub struct Continuation<F> {
    problem: Problem<Shared<F>>,
    /// The points' orbit summaries and special points (None only while it
    /// works beside the corrector).
    finisher: Option<Finisher<Shared<F>>>,
    /// Points corrected ahead of the one being finished, in order, and the
    /// stop that may end them.
    ahead: VecDeque<Step>,
    /// Points finished and not yet yielded, in order, and the stop that
    /// may end them.
    finished: VecDeque<Result<(Evaluated, Vec<SpecialPoint>), Ending>>,
    /// Whether the corrector has met the end of the branch.
    ended: bool,
    /// Parameter interval the branch stays in.
    bounds: (f64, f64),
    /// The bound the branch starts on, if it starts on one other than
    /// the bound toward `p_end`: leaving by it is
    /// [`StopReason::TurnedBack`] (a branch started inside, a switched
    /// one, ends by either bound).
    start_bound: Option<f64>,
    /// The last point corrected.
    current: Evaluated,
    /// Whether the start is not yet yielded (the finisher adds its orbit
    /// summary beside the corrector's first step).
    start: bool,
    ds: f64,
    /// Points corrected so far (the start included).
    points: usize,
    /// First point and its tangent (closing a loop).
    origin: (Vec<f64>, Vec<f64>),
    /// Mirror images of the points traversed, for asymmetric branches of
    /// a mirror-symmetric row (closing a loop onto the mirror image).
    mirrors: Option<(ShootingOptions, Vec<Vec<f64>>)>,
    symmetric: bool,
    /// The stop reason decided with the last point corrected: the
    /// corrector's next step returns it.
    pending: Option<StopReason>,
    /// The change of the unit tangent per arclength over the last step
    /// (second-order predictor).
    curvature: Option<Vec<f64>>,
    /// The change of the dense Jacobian [Ĵ_x Ĝ_p] per arclength over the
    /// last step: the corrector's chord starts from the Jacobian
    /// extrapolated to the predicted point.
    jacobian_rate: Option<DMatrix<f64>>,
    done: bool,
}

/// Why the branch ends, and whether that was decided together with the
/// point before it (the end of the range, a closed loop:
/// [`Continuation::pending_stop`]).
struct Ending {
    reason: StopReason,
    with_point: bool,
}

impl<F: Family + Send> Continuation<F> {
    /// Starts the branch of nT-periodic solutions at `(x0, p0)` toward
    /// `p_end`: validates the options, refines `x0` by shooting and
    /// corrects the start with the parameter held. `family(p)` builds the
    /// model at parameter p. Symmetric orbits of a mirror-symmetric row are
    /// followed on the half map when `opts.use_symmetry` allows.
    pub fn new(
        family: F,
        p0: f64,
        x0: &[f64],
        p_end: f64,
        opts: &ContinuationOptions,
    ) -> Result<Self, ContinuationError> {
        validate(p0, p_end, opts)?;
        let mut family = Shared::new(family);
        let model = family.model_at(p0)?;
        validate_size(&model, opts)?;
        let opts = &ContinuationOptions {
            shooting: ShootingOptions {
                integrator: branch_integrator(&mut family, &model, (p0, p_end), opts),
                ..opts.shooting.clone()
            },
            ..opts.clone()
        };
        let odd = opts.shooting.subharmonic.max(1) % 2 == 1;
        let halves = opts.use_symmetry && odd && model.is_mirror_symmetric();
        // A guess that is a symmetric orbit already (to 100 tol,
        // `is_symmetric_orbit`) is corrected on the half map below at
        // once: shooting the whole period would only confirm it (the
        // start of R2 N = 2 from its orbit: one map of the period saved).
        let on_half = opts.krylov.is_none()
            && !opts.shooting.symmetric
            && halves
            && is_symmetric_orbit(&model, x0, &opts.shooting);
        // (The start's multipliers are the point's own, evaluated below.)
        let (start, converged, history) = match opts.krylov {
            None if on_half => (x0.to_vec(), true, Vec::new()),
            None => {
                let (_, out) = shoot_orbit(&model, x0, &opts.shooting)?;
                (out.x, out.stop == NewtonStop::Converged, out.history)
            }
            Some(m) => {
                let s = shoot_krylov(&model, x0, &opts.shooting, m)?;
                (s.initial_state, s.converged, s.residual_history)
            }
        };
        if !converged {
            return Err(ContinuationError::StartNotConverged(
                *history.last().unwrap_or(&f64::NAN),
            ));
        }
        let d = x0.len();
        let symmetric = opts.shooting.symmetric
            || on_half
            || (halves && is_symmetric_orbit(&model, &start, &opts.shooting));
        let local = ContinuationOptions {
            shooting: ShootingOptions {
                symmetric,
                ..opts.shooting.clone()
            },
            ..opts.clone()
        };
        let p_scale = parameter_scale(opts, p0, p_end);
        let mut problem = Problem::new(family, local, &model, p_scale);
        let bounds = opts
            .bounds
            .map_or((p0.min(p_end), p0.max(p_end)), |(a, b)| {
                (a.min(b), a.max(b))
            });
        let z0 = problem.scale_state(&start, p0);
        // The start point: corrected with the parameter held (t = e_p).
        let mut dir = vec![0.0; d + 1];
        dir[d] = 1.0;
        let (solved0, _) = problem
            .correct(&z0, &dir, None)
            .ok_or(ContinuationError::StartNotConverged(f64::NAN))?;
        dir[d] = (p_end - p0).signum();
        // (Its orbit summary is the finisher's, beside the first step.)
        let first = problem
            .evaluate_with(solved0, &dir, false)
            .ok_or_else(|| ContinuationError::Invalid("cannot evaluate the start point".into()))?;
        // Closing the loop: the branch is back at its first point, or (for
        // an asymmetric branch of a mirror-symmetric row) at the mirror
        // image S x(nT/2) of a point already traversed, which happens right
        // after it passes a pitchfork on the symmetric branch; the rest
        // would be the mirror image of what is known.
        let mirrors =
            (!symmetric && opts.use_symmetry && odd && model.is_mirror_symmetric()).then(|| {
                let half = ShootingOptions {
                    symmetric: true,
                    ..problem.opts.shooting.clone()
                };
                (half, Vec::new())
            });
        let events: Vec<Box<dyn BranchEvent>> = if opts.special_points {
            BUILT_IN
                .iter()
                .map(|k| Box::new(*k) as Box<dyn BranchEvent>)
                .collect()
        } else {
            Vec::new()
        };
        let finisher = Finisher::new(problem.clone(), events, bounds, first.clone());
        let mut this = Self {
            finisher: Some(finisher),
            ahead: VecDeque::new(),
            finished: VecDeque::new(),
            ended: false,
            bounds,
            start_bound: [bounds.0, bounds.1]
                .into_iter()
                .find(|&b| b == p0 && b != if p_end >= p0 { bounds.1 } else { bounds.0 }),
            origin: (first.solved.z.clone(), first.tangent.clone()),
            start: true,
            current: first,
            ds: opts.ds,
            points: 1,
            mirrors,
            symmetric,
            pending: None,
            curvature: None,
            jacobian_rate: None,
            done: false,
            problem,
        };
        this.remember_mirror();
        Ok(this)
    }

    /// Adds an event to detect and locate between points (after the
    /// built-in ones).
    pub fn with_event(mut self, event: Box<dyn BranchEvent>) -> Self {
        if let Some(f) = &mut self.finisher {
            f.events.push(event);
            f.counts.push(0);
        }
        self
    }

    /// Whether the branch is followed on the symmetric half map.
    pub fn symmetric(&self) -> bool {
        self.symmetric
    }

    /// Period multiple n of the branch.
    pub fn subharmonic(&self) -> u32 {
        self.problem.opts.shooting.subharmonic
    }

    /// The stop reason decided together with the last point yielded (the
    /// end of the range, a closed loop), if any: the next step yields it.
    pub fn pending_stop(&self) -> Option<&StopReason> {
        let next = (self.finished.front().map(|f| f.as_ref().err()))
            .or_else(|| self.ahead.front().map(|a| a.as_ref().err()));
        match next {
            Some(Some(end)) => end.with_point.then_some(&end.reason),
            Some(None) => None,
            None => self.pending.as_ref(),
        }
    }

    /// Records the mirror image of the current point (asymmetric branches
    /// of mirror-symmetric rows).
    fn remember_mirror(&mut self) {
        if let Some((half, list)) = &mut self.mirrors {
            let (x, p) = self.problem.unscale(&self.current.solved.z);
            let image = self
                .problem
                .model(p)
                .ok()
                .and_then(|model| period_image(&model, &x, half));
            list.extend(image.map(|image| self.problem.scale_state(&image, p)));
        }
    }

    /// Predictor and corrector with step `ds` from the current point: the
    /// evaluated point, the corrector iterations and the step factor the
    /// change of the multipliers allows next; or, if the correction failed,
    /// turned too sharply or moved the multipliers too far (two crossings
    /// of the unit circle could cancel in the tests), the factor on `ds`
    /// for the retry.
    fn try_step(&mut self, ds: f64) -> Result<(Evaluated, usize, f64), f64> {
        let fail = self.problem.opts.step.fail;
        let mut pred = self.current.predict(ds);
        if let Some(k) = &self.curvature {
            pred.iter_mut()
                .zip(k)
                .for_each(|(z, k)| *z += 0.5 * ds * ds * k);
        }
        let tangent = self.current.tangent.clone();
        let extrapolated = match (&self.current.solved.linear, &self.jacobian_rate) {
            (Linear::Dense { jac, monodromy }, Some(rate)) => Some(Linear::Dense {
                jac: jac + rate * ds,
                monodromy: monodromy.clone(),
            }),
            _ => None,
        };
        let nearby = Some(extrapolated.as_ref().unwrap_or(&self.current.solved.linear));
        let (solved, iterations) = self.problem.correct(&pred, &tangent, nearby).ok_or(fail)?;
        // Without the orbit summary (an integration): the finisher's.
        let next = self
            .problem
            .evaluate_with(solved, &tangent, false)
            .ok_or(fail)?;
        let cos: f64 = next.tangent.iter().zip(&tangent).map(|(a, b)| a * b).sum();
        if cos <= self.problem.opts.step.min_tangent_cos {
            return Err(fail);
        }
        // The multipliers' change grows about linearly with the step: the
        // next step aims at 0.8 of the largest change allowed.
        let change = spectral_distance(&self.current.point.multipliers, &next.point.multipliers);
        let allowed = self.problem.opts.max_multiplier_change;
        let factor = (0.8 * allowed / change).max(0.1);
        if change > allowed && 0.5 * ds >= self.problem.opts.ds_min {
            return Err(factor.min(fail));
        }
        Ok((next, iterations, factor))
    }

    /// Whether parameter `q` is inside the range (to `locate_tol`).
    fn inside(&self, q: f64) -> bool {
        let (lo, hi) = self.bounds;
        let tol = self.problem.opts.locate_tol;
        q >= lo - tol && q <= hi + tol
    }

    /// Whether a stop was requested (`ShootingOptions::interrupt`).
    fn interrupted(&self) -> bool {
        let interrupt = &self.problem.opts.shooting.interrupt;
        interrupt.as_ref().is_some_and(|i| i.requested())
    }

    /// Why a branch through rigid impacts ends (docs/theory.md §12): at
    /// the current point a rigid contact's slowest impact is below 1e-3 of
    /// the orbit's largest velocity, or its orbit's closest approach to a
    /// contact within 1e-6 of its reach: a grazing, where the period map
    /// is not differentiable (its saltation grows as 1/U).
    fn rigid_grazing(&mut self) -> Option<String> {
        let p = self.current.point.parameter;
        let model = self.problem.model(p).ok()?;
        if !model.has_rigid_impacts() {
            return None;
        }
        let orbit = self.problem.add_orbit(self.current.clone())?;
        let shooting = &self.problem.opts.shooting;
        let period =
            crate::periodic::forcing_period(&model).ok()? * f64::from(shooting.subharmonic.max(1));
        let y0 = crate::dynamics::to_interleaved(&orbit.point.state);
        let int_opts = shooting.integrator_options(crate::periodic::MAX_STEPS, None);
        let largest = |v: &[f64]| v.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        let (speed, reach) = (
            largest(&orbit.point.max_velocity),
            largest(&orbit.point.max_displacement),
        );
        let spectral = orbit.point.spectral_radius();
        let slowest = match crate::periodic::rigid_impacts_over(&model, &y0, period, &int_opts) {
            Ok(found) => found
                .into_iter()
                .filter(|(k, _)| model.impacts(*k).is_rigid())
                .min_by(|a, b| a.1.total_cmp(&b.1)),
            // An impact at or below the absolute tolerance: grazing.
            Err(crate::integrate::IntegrationError::RigidImpact { contact, .. }) => {
                Some((contact, int_opts.atol))
            }
            Err(_) => return None,
        };
        if let Some((k, u)) = slowest.filter(|(_, u)| *u < 1e-3 * speed) {
            return Some(format!(
                ": the rigid impact of contact {} grazes there (impact velocity {u:.3e} m/s, largest multiplier {spectral:.3e}); a rigid impact's period map is not differentiable where it grazes, so the branch of impacting orbits ends (GR); beyond it the orbit does not touch",
                model.contact_name(k),
            ));
        }
        // The orbit's closest approach at the contact (from the side that
        // does not touch, or an impact lost in rounding).
        let margin = orbit.tests.grazing_margin;
        (margin.abs() < 1e-6 * reach).then(|| {
            format!(
                ": the orbit grazes a rigid contact there (closest approach {margin:.3e} m, largest multiplier {spectral:.3e}); the rigid period map is not differentiable where an orbit grazes, so the branch ends there (GR)"
            )
        })
    }

    /// Why a branch through rigid impacts cannot step on where it is not
    /// at a grazing: the rigid period map just beyond the current point
    /// (a step of 10 ds_min) fails, typically because an impact there
    /// would overlap another's estimated duration, where the rigid
    /// idealisation breaks (docs/theory.md §12).
    fn rigid_breaks(&mut self) -> Option<String> {
        let z = self.current.predict(10.0 * self.problem.opts.ds_min);
        let (x, p) = self.problem.unscale(&z);
        let model = self.problem.model(p).ok()?;
        if !model.has_rigid_impacts() {
            return None;
        }
        let shooting = &self.problem.opts.shooting;
        let e =
            crate::periodic::map_image(&model, &x, shooting, crate::periodic::MAX_STEPS).err()?;
        Some(format!(
            ": just beyond it (parameter {p}) the rigid period map fails: {e}"
        ))
    }

    /// The next point corrected, not yet finished, or the reason the
    /// branch ends.
    fn advance(&mut self) -> Result<Corrected, Ending> {
        let step = self.correct_next();
        self.ended |= step.is_err();
        step
    }

    /// [`advance`](Self::advance) itself.
    fn correct_next(&mut self) -> Result<Corrected, Ending> {
        if let Some(reason) = self.pending.take() {
            return Err(Ending {
                reason,
                with_point: true,
            });
        }
        let end = |reason| Ending {
            reason,
            with_point: false,
        };
        if self.points >= self.problem.opts.max_points {
            return Err(end(StopReason::MaxPoints));
        }
        let (next, iterations, factor) = loop {
            match self.try_step(self.ds) {
                Ok(found) => break found,
                // A stop request fails every integration, which would read
                // as a corrector that does not converge at any step.
                Err(_) if self.interrupted() => return Err(end(StopReason::Interrupted)),
                Err(shrink) => self.ds *= shrink,
            }
            if self.ds < self.problem.opts.ds_min {
                let p = self.current.point.parameter;
                if let Some(why) = self.rigid_grazing() {
                    return Err(end(StopReason::Grazing(format!("at parameter {p}{why}"))));
                }
                let grazes = self.rigid_breaks().unwrap_or_default();
                return Err(end(StopReason::CannotContinue(format!(
                    "the corrector does not converge beyond parameter {p} even with step {:e}{grazes}",
                    self.ds
                ))));
            }
        };
        let (ds, after, learnt) = (self.ds, self.points - 1, self.problem.learnt());
        let opts = &self.problem.opts;
        self.ds = opts
            .step
            .next(self.ds, iterations, opts.ds_min, opts.ds_max)
            .min(self.ds * factor)
            .max(opts.ds_min);
        // A step past the end of the range: the last point is the solution
        // at the end itself (the parameter held there), if it converges.
        let p = next.point.parameter;
        let beyond = !self.inside(p);
        let end = if beyond {
            let bound = if p > self.bounds.1 {
                self.bounds.1
            } else {
                self.bounds.0
            };
            match self.problem.end_point(&self.current, &next, bound) {
                Some(end) => Some(end),
                None => return Err(end(self.left_by(bound))),
            }
        } else {
            None
        };
        let reached = end.as_ref().unwrap_or(&next).clone();
        let step = Corrected {
            next,
            end,
            ds,
            after,
            learnt,
        };
        let next = reached;
        self.points += 1;
        let h = dist(&next.solved.z, &self.current.solved.z);
        self.curvature = (h > 0.0).then(|| {
            next.tangent
                .iter()
                .zip(&self.current.tangent)
                .map(|(a, b)| (a - b) / h)
                .collect()
        });
        self.jacobian_rate = match (&next.solved.linear, &self.current.solved.linear) {
            (Linear::Dense { jac: a, .. }, Linear::Dense { jac: b, .. }) if h > 0.0 => {
                Some((a - b) / h)
            }
            _ => None,
        };
        let previous_z = std::mem::replace(&mut self.current, next).solved.z;
        if beyond {
            let bound = if p > self.bounds.1 {
                self.bounds.1
            } else {
                self.bounds.0
            };
            self.pending = Some(self.left_by(bound));
        } else if self.points > 4 && self.closes_loop(&previous_z) {
            self.pending = Some(StopReason::ClosedLoop);
        } else {
            self.remember_mirror();
        }
        Ok(step)
    }

    /// Why a branch that left the range by `bound` stopped: the end, or a
    /// turn back out on the start's side.
    fn left_by(&self, bound: f64) -> StopReason {
        if self.start_bound == Some(bound) {
            StopReason::TurnedBack
        } else {
            StopReason::ReachedEnd
        }
    }

    /// Whether the step just taken (from `previous_z`) passed through the
    /// first point (in the same direction) or a mirror image traversed
    /// before the last two.
    fn closes_loop(&self, previous_z: &[f64]) -> bool {
        let (z0, t0) = &self.origin;
        returns_to(z0, Some(t0), previous_z, &self.current)
            || self.mirrors.as_ref().is_some_and(|(_, list)| {
                list[..list.len().saturating_sub(2)]
                    .iter()
                    .any(|m| returns_to(m, None, previous_z, &self.current))
            })
    }
}

/// The integrator of a whole branch: [`Integrator::Auto`] resolved on the
/// start's model, and global for a parameter beyond the forcing (the local
/// maps carry a column of the forcing's parameters only).
fn branch_integrator<F: Family>(
    family: &mut F,
    model: &Model,
    (p0, p_end): (f64, f64),
    opts: &ContinuationOptions,
) -> Integrator {
    let chosen = opts.shooting.integrator;
    let resolved = chosen.resolve(model);
    if chosen != Integrator::Auto || resolved != Integrator::Local {
        return resolved;
    }
    let near = p0 + 1e-6 * (p_end - p0);
    match family.model_at(near) {
        Ok(other) if model.differs_only_in_forcing(&other) => Integrator::Local,
        _ => Integrator::Global,
    }
}

/// The size checks of [`Continuation::new`], for callers that want them
/// before any work (e.g. a start by simulation): a dense period map of
/// the row must fit (else the remedy is matrix-free continuation), and an
/// Arnoldi dimension must lie between the minimum for a stability verdict
/// and the state's size.
pub fn validate_size(model: &Model, opts: &ContinuationOptions) -> Result<(), ContinuationError> {
    let n = model.bodies().len();
    let d = 2 * n;
    match opts.krylov {
        None if d > MAX_DENSE_DIM => Err(ContinuationError::Invalid(format!(
            "a row of {n} bodies is too large for dense continuation (the monodromy matrix \
             alone has {d}×{d} entries, integrated with {d} variational columns): continue \
             matrix-free (--krylov, ContinuationOptions::krylov)"
        ))),
        Some(m) if m < MIN_ARNOLDI.min(d) || m > d => Err(ContinuationError::Invalid(format!(
            "Arnoldi dimension {m}: between {} (for a stability verdict) and the state's \
             size {d}",
            MIN_ARNOLDI.min(d)
        ))),
        _ => Ok(()),
    }
}

/// The parameter's scale in the arclength of a branch from `p0` towards
/// `p_end`: `opts.parameter_scale` if given, else the start value |p0| or
/// half the range |p_end − p0| if that is larger. With the default a
/// branch may cross its range in 2 / `ds_max` steps (40 at the default
/// `ds_max`) where the state moves little. A frequency branch from 0.5
/// to 1.5 ω0 keeps |p0| (both are equal there); an amplitude branch from
/// zero or nearly zero, whose |p0| made every parameter step a fraction of
/// that tiny start (a row of 100 from 5e-5 to 0.05 m/s² took 1500 points
/// to reach 0.0037), steps on the range's scale instead.
pub(super) fn parameter_scale(opts: &ContinuationOptions, p0: f64, p_end: f64) -> f64 {
    opts.parameter_scale
        .unwrap_or_else(|| p0.abs().max(0.5 * (p_end - p0).abs()))
}

/// The checks of the range and the options before anything runs.
fn validate(p0: f64, p_end: f64, opts: &ContinuationOptions) -> Result<(), ContinuationError> {
    if !(p0.is_finite() && p_end.is_finite()) || p0 == p_end {
        return Err(ContinuationError::Invalid(format!(
            "the range from {p0} to {p_end} is empty or not finite"
        )));
    }
    for (name, value) in [
        ("ds", opts.ds),
        ("ds_min", opts.ds_min),
        ("ds_max", opts.ds_max),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(ContinuationError::Invalid(format!(
                "{name} = {value}: must be finite and > 0"
            )));
        }
    }
    opts.shooting
        .check()
        .map_err(|e| ContinuationError::Invalid(e.to_string()))?;
    if let Some(scale) = opts.parameter_scale {
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(ContinuationError::Invalid(format!(
                "parameter_scale = {scale}: must be finite and > 0"
            )));
        }
    }
    if opts.max_points < 2 {
        return Err(ContinuationError::Invalid(format!(
            "max_points = {}: at least 2",
            opts.max_points
        )));
    }
    opts.step.validate()
}

/// Whether the step from `previous` to `current` (scaled unknowns) passes
/// through the point `origin`: within a quarter step of the chord (a chord
/// of the same curve deviates from it by O(curvature × step²)) and, if the
/// origin's tangent is given, in the same direction.
fn returns_to(z0: &[f64], t0: Option<&[f64]>, previous: &[f64], current: &Evaluated) -> bool {
    let z1 = &current.solved.z;
    let chord: Vec<f64> = z1.iter().zip(previous).map(|(b, a)| b - a).collect();
    let len2: f64 = chord.iter().map(|c| c * c).sum();
    if len2 == 0.0 {
        return false;
    }
    let along: f64 = z0
        .iter()
        .zip(previous)
        .zip(&chord)
        .map(|((z, a), c)| (z - a) * c)
        .sum::<f64>()
        / len2;
    let dist2: f64 = z0
        .iter()
        .zip(previous)
        .zip(&chord)
        .map(|((z, a), c)| (z - a - along.clamp(0.0, 1.0) * c).powi(2))
        .sum();
    let aligned = t0.is_none_or(|t0| {
        t0.iter()
            .zip(&current.tangent)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            > 0.5
    });
    (0.0..=1.0).contains(&along) && dist2 <= 0.0625 * len2 && aligned
}

/// Euclidean distance.
fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Distance between two spectra, as seen by the stability tests: the
/// largest change of log-modulus between the multipliers sorted by
/// modulus, each modulus clamped to `[1/FAR_MULTIPLIER, FAR_MULTIPLIER]`.
/// Crossing the unit circle is a matter of modulus: a multiplier far
/// outside or inside the circle can grow or shrink by any factor, and a
/// complex pair can turn by any angle, without coming near a crossing (on
/// R2 N = 2 the largest multiplier grows from 1 to 600 and back within
/// 0.05 ω0 while a pair at modulus 0.85 turns quickly; a distance in the
/// complex plane resolved both with ~100 points). Spectra of different
/// sizes (the Ritz values of two Arnoldi iterations that ended at
/// different dimensions, which can resolve 4 or 8 multipliers of one
/// cluster) are compared by the
/// Hausdorff distance of their clamped log-moduli: every multiplier of
/// one near some multiplier of the other (R2 N = 100 at 0.6445 ω0: the
/// positions of the sorted lists compared a resolved 0.881 with 0.097
/// and refused every step); an empty one is infinitely far from any
/// other.
pub fn spectral_distance(a: &[Complex<f64>], b: &[Complex<f64>]) -> f64 {
    if a.is_empty() != b.is_empty() {
        return f64::INFINITY;
    }
    let log_moduli = |s: &[Complex<f64>]| {
        let mut m: Vec<f64> = s
            .iter()
            .map(|x| x.norm().clamp(1.0 / FAR_MULTIPLIER, FAR_MULTIPLIER).ln())
            .collect();
        m.sort_by(|x, y| y.total_cmp(x));
        m
    };
    let (a, b) = (log_moduli(a), log_moduli(b));
    if a.len() == b.len() {
        return a.iter().zip(&b).fold(0.0, |m, (x, y)| m.max((x - y).abs()));
    }
    let directed = |from: &[f64], to: &[f64]| {
        from.iter().fold(0.0f64, |m, x| {
            m.max(to.iter().fold(f64::INFINITY, |n, y| n.min((x - y).abs())))
        })
    };
    directed(&a, &b).max(directed(&b, &a))
}

/// Modulus beyond which [`spectral_distance`] sees no change of a
/// multiplier's size.
pub const FAR_MULTIPLIER: f64 = 2.0;

#[cfg(test)]
mod tests;
