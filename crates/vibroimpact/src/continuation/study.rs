//! A branch study: everything `continue` does between reading its
//! arguments and writing its documents, for every face alike. It checks
//! the range, the period multiple and the parameter, finds the first
//! periodic orbit (by simulation, falling back to the homotopy in the
//! forcing amplitude, or by the homotopy directly), continues the branch
//! and switches at a special point if asked.

use super::{continue_branch, switch_branch, validate_size, Branch, BranchPoint};
use super::{ContinuationError, ContinuationOptions, SwitchError};
use crate::family::{Family, FamilyError};
use crate::model::Model;
use crate::periodic::{guess_by_simulation_with, PeriodicError};

/// How a branch study finds its first periodic orbit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Start {
    /// A guess by simulation; where Newton does not converge from it, the
    /// homotopy. (The simulated guess, where it converges, is the attractor
    /// a simulation shows; the homotopy's orbit lies on the branch that
    /// grows from rest, which at a given value may be another one.)
    #[default]
    Auto,
    /// The state after the guess periods from the model's initial state.
    Simulate,
    /// The homotopy in the forcing amplitude from the rest state (an exact
    /// periodic orbit at zero forcing): the primary branch at any N.
    Homotopy,
}

impl Start {
    /// `auto`, `simulate` or `homotopy`.
    pub fn name(self) -> &'static str {
        match self {
            Start::Auto => "auto",
            Start::Simulate => "simulate",
            Start::Homotopy => "homotopy",
        }
    }
}

impl std::str::FromStr for Start {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(Start::Auto),
            "simulate" => Ok(Start::Simulate),
            "homotopy" => Ok(Start::Homotopy),
            other => Err(format!(
                "start = {other:?}: must be auto, simulate or homotopy"
            )),
        }
    }
}

/// Dense or matrix-free linear algebra for periodic orbits and branches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Linear {
    /// Dense below [`AUTO_KRYLOV_BODIES`] bodies, matrix-free from there
    /// (the dense monodromy costs O(N²) memory and work).
    #[default]
    Auto,
    /// The dense monodromy matrix at any size.
    Dense,
    /// Newton–Krylov with the dominant multipliers by Arnoldi.
    MatrixFree,
}

/// Rows of at least this many bodies are matrix-free under [`Linear::Auto`].
pub const AUTO_KRYLOV_BODIES: usize = 200;

impl Linear {
    /// The choice of the two switches `krylov` and `dense` (both: an
    /// error).
    pub fn from_switches(krylov: bool, dense: bool) -> Result<Self, String> {
        match (krylov, dense) {
            (true, true) => Err("krylov = True, dense = True: choose one".into()),
            (true, false) => Ok(Linear::MatrixFree),
            (false, true) => Ok(Linear::Dense),
            (false, false) => Ok(Linear::Auto),
        }
    }

    /// The Arnoldi dimension `arnoldi` if matrix-free for `bodies`, else
    /// None (dense).
    pub fn krylov(self, bodies: usize, arnoldi: usize) -> Option<usize> {
        let free = match self {
            Linear::Auto => bodies >= AUTO_KRYLOV_BODIES,
            Linear::Dense => false,
            Linear::MatrixFree => true,
        };
        free.then_some(arnoldi)
    }
}

/// The study's settings a face may spell its own way (an option, a
/// keyword): the field an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StudyField {
    /// The range `from`, `to`.
    Range,
    /// The start value `from`.
    From,
    /// The period multiple.
    Subharmonic,
    /// The parameter.
    Parameter,
    /// The start method.
    Start,
}

impl StudyField {
    /// The library's spelling: `range`, `from`, `subharmonic`,
    /// `parameter` or `start`.
    pub fn name(self) -> &'static str {
        match self {
            StudyField::Range => "range",
            StudyField::From => "from",
            StudyField::Subharmonic => "subharmonic",
            StudyField::Parameter => "parameter",
            StudyField::Start => "start",
        }
    }
}

/// Why a branch study did not run or ended without a branch.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A setting the study refuses; `field` names it (each face spells it
    /// its own way before the message).
    #[error("{}: {message}", field.name())]
    Invalid {
        /// The setting.
        field: StudyField,
        /// What is wrong with it.
        message: String,
    },
    /// The family has no model at the start.
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// The guess by simulation failed.
    #[error("start guess: {0}")]
    Guess(PeriodicError),
    /// The continuation (or the homotopy) failed.
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
}

/// A branch of nT-periodic orbits from `from` to `to`.
#[derive(Clone, Debug)]
pub struct BranchStudy {
    /// First parameter value (the start).
    pub from: f64,
    /// Last parameter value.
    pub to: f64,
    /// How the first orbit is found.
    pub start: Start,
    /// Forcing periods simulated for the start guess.
    pub guess_periods: f64,
    /// A special point's label (`BP1`, `PD1`) to switch at after the
    /// branch.
    pub switch_at: Option<String>,
    /// Dense or matrix-free (sets `options.krylov` for the start's size).
    pub linear: Linear,
    /// The Arnoldi dimension when matrix-free.
    pub arnoldi: usize,
    /// The continuation's options (the period multiple, the integrator and
    /// the stop request in `shooting`).
    pub options: ContinuationOptions,
}

/// What a branch study computed.
#[derive(Debug)]
pub struct BranchOutcome {
    /// The model at the start.
    pub start_model: Model,
    /// The branch.
    pub branch: Branch,
    /// The switched branch, when a switch was asked for (a failed switch
    /// keeps the branch).
    pub switched: Option<Result<Branch, SwitchError>>,
    /// The options the branches ran with (`krylov` set by `linear`).
    pub options: ContinuationOptions,
}

impl BranchStudy {
    /// The model at the start and the options for its size after the
    /// study's checks: a finite, nonempty
    /// range, a period multiple ≥ 1, a continuous parameter and a periodic
    /// forcing at the start.
    pub fn check<F: Family>(
        &self,
        family: &mut F,
    ) -> Result<(Model, ContinuationOptions), StudyError> {
        let invalid = |field, message: String| StudyError::Invalid { field, message };
        if !(self.from.is_finite() && self.to.is_finite()) || self.from == self.to {
            return Err(invalid(
                StudyField::Range,
                "the range is empty or not finite".into(),
            ));
        }
        if self.options.shooting.subharmonic == 0 {
            return Err(invalid(StudyField::Subharmonic, "must be >= 1".into()));
        }
        if family.whole_numbers() {
            return Err(invalid(
                StudyField::Parameter,
                "takes whole numbers: a branch needs a continuous parameter (sweep it instead)"
                    .into(),
            ));
        }
        let model = family.model_at(self.from)?;
        if model.forcing_frequency().is_none() {
            return Err(invalid(
                StudyField::From,
                "the model has no periodic forcing with one frequency there: nothing to continue"
                    .into(),
            ));
        }
        let options = ContinuationOptions {
            krylov: self.linear.krylov(model.bodies().len(), self.arnoldi),
            ..self.options.clone()
        };
        validate_size(&model, &options)?;
        Ok((model, options))
    }

    /// Runs the study on `family`. `homotopy` is the family in the forcing
    /// amplitude at the start (everything else fixed) with the amplitude
    /// to reach, needed by the homotopy start. `on_point` sees every point
    /// of both branches and returns false to stop.
    pub fn run<F: Family>(
        &self,
        mut family: F,
        mut homotopy: Option<(&mut dyn Family, f64)>,
        mut on_point: impl FnMut(&BranchPoint) -> bool,
    ) -> Result<BranchOutcome, StudyError> {
        let (start_model, options) = self.check(&mut family)?;
        let opts = &options;
        let mut by_homotopy = || match homotopy.as_mut() {
            Some((h, amplitude)) => Ok(super::amplitude_homotopy(h, *amplitude, opts)?),
            None => Err(StudyError::Invalid {
                field: StudyField::Start,
                message: "the homotopy start needs the family in the forcing amplitude".into(),
            }),
        };
        let guess = match self.start {
            Start::Homotopy => by_homotopy()?,
            Start::Auto | Start::Simulate => guess_by_simulation_with(
                &start_model,
                self.guess_periods,
                1e-9,
                opts.shooting.interrupt.clone(),
                opts.shooting.integrator,
            )
            .map_err(StudyError::Guess)?,
        };
        let mut run = |guess: &[f64], on_point: &mut dyn FnMut(&BranchPoint) -> bool| {
            continue_branch(&mut family, self.from, guess, self.to, opts, on_point)
        };
        let branch = match run(&guess, &mut on_point) {
            Err(ContinuationError::StartNotConverged(_)) if self.start == Start::Auto => {
                run(&by_homotopy()?, &mut on_point)?
            }
            other => other?,
        };
        let switched = self.switch_at.as_deref().map(|label| {
            switch_branch(
                &mut family,
                &branch,
                label,
                (self.from, self.to),
                opts,
                &mut on_point,
            )
        });
        Ok(BranchOutcome {
            start_model,
            branch,
            switched,
            options,
        })
    }
}
