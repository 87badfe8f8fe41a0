//! What finishes a corrected point before the branch yields it: its orbit
//! summary (amplitudes, impacts, grazing margin) and the special points
//! located between it and the point before (docs/theory.md §5).
//!
//! None of this steers the branch: the corrector's path depends on the
//! points, tangents and multipliers alone. (A location's corrections no
//! longer leave their chord history to the corrector's next step, as they
//! did when they ran in turn; they start from the corrector's history at
//! their point.) So a [`Finisher`], with its own copy of the problem,
//! finishes the points corrected so far on one thread while the
//! [`Continuation`](super::Continuation) corrects the points after them on
//! another (docs/decisions.md D38). Each works through its points in order
//! with its own state, so the numbers are the same on any thread count.

use std::sync::{Arc, Mutex, PoisonError};

use crate::model::family::{Family, FamilyError};
use crate::model::file::{ModelFileError, SimulationSpec};
use crate::model::parameter::ParameterizedModel;
use crate::model::Model;

use super::events::BranchEvent;
use super::problem::{Evaluated, Problem};
use super::{SpecialKind, SpecialPoint, StopReason};

/// A corrected point, as the corrector leaves it: without its orbit
/// summary, and before the special points since the point before.
pub(super) struct Corrected {
    /// The point the step reached (its tests decide the special points).
    pub next: Evaluated,
    /// The solution at the range's bound that replaces it when the step
    /// went past the bound.
    pub end: Option<Evaluated>,
    /// The step's arclength.
    pub ds: f64,
    /// Index of the point before.
    pub after: usize,
    /// What the corrections up to this point learnt ([`Problem::learnt`]):
    /// a location starts from it, as it would after this point in turn.
    pub learnt: (u64, f64),
}

/// The orbit summaries and special points of a branch, point by point.
pub(super) struct Finisher<F> {
    problem: Problem<F>,
    pub events: Vec<Box<dyn BranchEvent>>,
    /// Special points found so far, per event (for the labels).
    pub counts: Vec<usize>,
    /// Parameter interval the branch stays in.
    bounds: (f64, f64),
    /// The last point finished.
    previous: Evaluated,
}

impl<F: Family> Finisher<F> {
    /// Finishes `first` ([`start`](Self::start)) and the points after it
    /// with `problem`, a copy of the corrector's.
    pub fn new(
        problem: Problem<F>,
        events: Vec<Box<dyn BranchEvent>>,
        bounds: (f64, f64),
        first: Evaluated,
    ) -> Self {
        Self {
            problem,
            counts: vec![0; events.len()],
            events,
            bounds,
            previous: first,
        }
    }

    /// The start (the point the finisher was made with), with its orbit
    /// summary (the first and last points carry theirs even without
    /// special points): added here, beside the corrector's first step,
    /// not before the branch's threads start.
    pub fn start(&mut self) -> Result<Evaluated, StopReason> {
        self.previous = self.orbit_of(self.previous.clone())?;
        Ok(self.previous.clone())
    }

    /// Whether the points need their orbit summaries (special points, or
    /// an event that reads them).
    pub fn needs_orbit(&self) -> bool {
        self.problem.opts.special_points || self.events.iter().any(|e| e.needs_orbit())
    }

    /// The point `step` reached, with its orbit summary and the special
    /// points since the point before; or why the branch stops (the orbit
    /// could not be integrated, a stop request: a location it cut short
    /// would lose its special point).
    pub fn finish(
        &mut self,
        step: Corrected,
    ) -> Result<(Evaluated, Vec<SpecialPoint>), StopReason> {
        self.problem.learn(step.learnt);
        let orbit = self.needs_orbit();
        let next = if orbit {
            self.orbit_of(step.next)?
        } else {
            step.next
        };
        let special = self.special_points(&next, step.ds, step.after);
        if self.interrupted() {
            return Err(StopReason::Interrupted);
        }
        let shown = match step.end {
            Some(end) => self.orbit_of(end)?,
            None => next,
        };
        self.previous = shown.clone();
        Ok((shown, special))
    }

    /// Whether a stop was requested (`ShootingOptions::interrupt`).
    fn interrupted(&self) -> bool {
        let interrupt = &self.problem.opts.shooting.interrupt;
        interrupt.as_ref().is_some_and(|i| i.requested())
    }

    /// `e` with its orbit summary.
    fn orbit_of(&mut self, e: Evaluated) -> Result<Evaluated, StopReason> {
        let p = e.point.parameter;
        self.problem.add_orbit(e).ok_or_else(|| {
            StopReason::CannotContinue(format!(
                "the orbit at parameter {p} could not be integrated over its period"
            ))
        })
    }

    /// Detects and locates the events between the last point finished and
    /// `next`, reached by a step `ds` after point `after`.
    fn special_points(&mut self, next: &Evaluated, ds: f64, after: usize) -> Vec<SpecialPoint> {
        let ((lo, hi), tol) = (self.bounds, self.problem.opts.locate_tol);
        let inside = |q: f64| q >= lo - tol && q <= hi + tol;
        let mut found = Vec::new();
        for (k, event) in self.events.iter().enumerate() {
            if !event.between(self.previous.observed(), next.observed()) {
                continue;
            }
            let located = self
                .problem
                .locate(event.as_ref(), &self.previous, next, ds);
            let Some(loc) = located.filter(|l| inside(l.point.parameter)) else {
                continue;
            };
            self.counts[k] += 1;
            let kind = event.kind();
            // The special point's own orbit where the points carry theirs:
            // the nearest point's is off the curve (6 µm at BP1 of R2 N = 2).
            let max_displacement = match (&loc.point.max_displacement, &next.point.max_displacement)
            {
                (own, _) if !own.is_empty() => own.clone(),
                (_, theirs) if !theirs.is_empty() => self
                    .problem
                    .add_orbit(loc.clone())
                    .map(|e| e.point.max_displacement)
                    .unwrap_or_default(),
                _ => Vec::new(),
            };
            found.push(SpecialPoint {
                kind,
                label: format!("{}{}", kind.prefix(), self.counts[k]),
                parameter: loc.point.parameter,
                state: loc.point.state.clone(),
                max_displacement,
                multipliers: loc.point.multipliers.clone(),
                tangent: loc.tangent.clone(),
                after_point: after,
                symmetry_breaking: kind == SpecialKind::BranchPoint
                    && self.previous.tests.det_sym.signum() != next.tests.det_sym.signum(),
            });
        }
        found
    }
}

/// A family shared by the corrector and the [`Finisher`] (each builds its
/// models under the lock; a model costs microseconds, a point milliseconds).
pub struct Shared<F> {
    name: String,
    family: Arc<Mutex<F>>,
}

impl<F: Family> Shared<F> {
    /// Shares `family`.
    pub fn new(family: F) -> Self {
        Self {
            name: family.name().to_string(),
            family: Arc::new(Mutex::new(family)),
        }
    }

    fn with<T>(&self, f: impl FnOnce(&mut F) -> T) -> T {
        f(&mut self.family.lock().unwrap_or_else(PoisonError::into_inner))
    }
}

impl<F> Clone for Shared<F> {
    fn clone(&self) -> Self {
        Self {
            name: self.name.clone(),
            family: Arc::clone(&self.family),
        }
    }
}

impl<F: Family> Family for Shared<F> {
    fn name(&self) -> &str {
        &self.name
    }
    fn model_at(&mut self, p: f64) -> Result<Model, FamilyError> {
        self.with(|f| f.model_at(p))
    }
    fn whole_numbers(&self) -> bool {
        self.with(|f| f.whole_numbers())
    }
    fn simulation(&self) -> SimulationSpec {
        self.with(|f| f.simulation())
    }
    fn amplitude_family(
        &self,
        p: f64,
    ) -> Option<Result<(ParameterizedModel, f64), ModelFileError>> {
        self.with(|f| f.amplitude_family(p))
    }
}
