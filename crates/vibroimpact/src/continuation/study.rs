//! A branch study: everything `continue` does between reading its
//! arguments and writing its documents, for every face alike. It checks
//! the range, the period multiple and the parameter, finds the first
//! periodic orbit (by simulation, falling back to the homotopy in the
//! forcing amplitude, or by the homotopy directly), continues the branch
//! and switches at a special point if asked.

use super::{continue_branch, switch_branch, validate_size, Branch, BranchPoint};
use super::{ContinuationError, ContinuationOptions, CurvesError, SwitchError};
use crate::field_error::FieldError;
use crate::model::family::{Family, FamilyError};
use crate::model::file::ModelFileError;
use crate::model::Model;
use crate::periodic::{guess_by_simulation_with, settled_guess, PeriodicError};

/// How a branch study finds its first periodic orbit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Start {
    /// A guess by simulation; where its last samples are neither near
    /// repeating with the orbit's period nor settling onto it
    /// (docs/theory.md §8), or Newton does not converge from it, the
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
        // At most the state's size 2N: its Krylov space is the whole state
        // space, so a larger dimension (the default 20 on a row of three,
        // refused as "between 6 and 6") can give no more.
        free.then_some(arnoldi.min(2 * bodies))
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
    /// The curves' second parameter.
    Parameter2,
    /// An earlier branch document whose special points start the curves.
    SpecialPoints,
    /// The symmetric half map.
    Symmetric,
    /// The Arnoldi dimension.
    Arnoldi,
    /// The start guess.
    Guess,
}

impl StudyField {
    /// The library's spelling: `range`, `from`, `subharmonic`,
    /// `parameter`, `start`, `parameter2`, `special_points`, `symmetric`,
    /// `arnoldi` or `guess`.
    pub fn name(self) -> &'static str {
        match self {
            StudyField::Range => "range",
            StudyField::From => "from",
            StudyField::Subharmonic => "subharmonic",
            StudyField::Parameter => "parameter",
            StudyField::Start => "start",
            StudyField::Parameter2 => "parameter2",
            StudyField::SpecialPoints => "special_points",
            StudyField::Symmetric => "symmetric",
            StudyField::Arnoldi => "arnoldi",
            StudyField::Guess => "guess",
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
    /// The model does not admit the study (the message names its file).
    #[error("{0}")]
    Model(String),
    /// A curve option the study refuses, by its field.
    #[error(transparent)]
    Field(FieldError),
    /// The model file has no such parameter.
    #[error(transparent)]
    File(#[from] ModelFileError),
    /// The family has no model at the start.
    #[error(transparent)]
    Family(#[from] FamilyError),
    /// The guess by simulation failed.
    #[error("start guess: {0}")]
    Guess(PeriodicError),
    /// Shooting (or the orbit's summary) failed.
    #[error(transparent)]
    Shooting(PeriodicError),
    /// The continuation (or the homotopy) failed.
    #[error(transparent)]
    Continuation(#[from] ContinuationError),
    /// A curve of special points failed.
    #[error(transparent)]
    Curves(CurvesError),
}

impl From<CurvesError> for StudyError {
    fn from(e: CurvesError) -> Self {
        match e {
            CurvesError::Field(f) => StudyError::Field(f),
            other => StudyError::Curves(other),
        }
    }
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
    /// The study on `family` after its checks: a finite, nonempty range,
    /// a period multiple ≥ 1, a continuous parameter and a periodic
    /// forcing at the start; the model there and the options for its
    /// size.
    pub fn check<F: Family + Send>(self, mut family: F) -> Result<CheckedBranch<F>, StudyError> {
        let invalid = |field, message: &str| StudyError::Invalid {
            field,
            message: message.into(),
        };
        let shooting = &self.options.shooting;
        for (field, v) in [("rtol", shooting.rtol), ("tol", shooting.tol)] {
            crate::field_error::FieldError::tolerance(field, v).map_err(StudyError::Field)?;
        }
        if !(self.from.is_finite() && self.to.is_finite()) || self.from == self.to {
            return Err(invalid(
                StudyField::Range,
                "the range is empty or not finite",
            ));
        }
        if self.options.shooting.subharmonic == 0 {
            return Err(invalid(StudyField::Subharmonic, "must be >= 1"));
        }
        if family.whole_numbers() {
            return Err(invalid(
                StudyField::Parameter,
                "takes whole numbers: a branch needs a continuous parameter (sweep it instead)",
            ));
        }
        let start_model = family.model_at(self.from)?;
        if start_model.forcing_frequency().is_none() {
            return Err(invalid(
                StudyField::From,
                "the model has no periodic forcing with one frequency there: nothing to continue",
            ));
        }
        let mut options = ContinuationOptions {
            krylov: self.linear.krylov(start_model.bodies().len(), self.arnoldi),
            ..self.options.clone()
        };
        if let Some(scale) = family.simulation().displacement_scale {
            options.shooting.displacement_scale = scale;
        }
        validate_size(&start_model, &options).map_err(|e| match (e, options.krylov) {
            (ContinuationError::Invalid(m), Some(_)) if m.starts_with("Arnoldi") => {
                StudyError::Invalid {
                    field: StudyField::Arnoldi,
                    message: m,
                }
            }
            (e, _) => e.into(),
        })?;
        Ok(CheckedBranch {
            study: self,
            family,
            start_model,
            options,
        })
    }
}

/// A branch study whose checks passed, ready to run.
#[derive(Clone, Debug)]
pub struct CheckedBranch<F> {
    /// The study.
    pub study: BranchStudy,
    /// The family it runs on.
    pub family: F,
    /// The model at the start.
    pub start_model: Model,
    /// The options the branches run with (`krylov` set by the study's
    /// `linear` for the start's size; a face sets its stop request in
    /// `shooting.interrupt`).
    pub options: ContinuationOptions,
}

/// The tolerance of a simulated start guess. Its accuracy never reaches
/// the branch: Newton or the homotopy takes the guess to the orbit at the
/// corrector's tolerance. R2 N = 2 at 0.5 ω0, 200 periods: 37,795 steps at
/// rtol 1e-9, 12,892 at 1e-7; the whole branch 0.38 → 0.32 s with the same
/// 133 points and special points (docs/decisions.md D36). Where the motion
/// is chaotic for long, which orbit a transient ends on depends on any
/// tolerance (at 0.8 ω0 rtol 1e-9 and 1e-8 end on different orbits).
pub(super) const GUESS_RTOL: f64 = 1e-7;

impl<F: Family + Send> CheckedBranch<F> {
    /// The estimated work of the start guess's simulation (`start` auto or
    /// simulate) on one core, for the faces to announce when long: a
    /// continuation with `--guess-periods 100000` ran silently (the
    /// branch's own points are priced by none: each ends its own way).
    pub fn guess_work(&self) -> Option<crate::simulate::WorkEstimate> {
        if self.study.start == Start::Homotopy {
            return None;
        }
        let period = crate::periodic::forcing_period(&self.start_model).ok()?;
        crate::simulate::estimate_work(
            &self.start_model,
            &crate::simulate::SimulationOptions {
                t_end: self.study.guess_periods * period,
                rtol: GUESS_RTOL,
                atol: 1e-4 * GUESS_RTOL,
                interrupt: self.options.shooting.interrupt.clone(),
                ..crate::simulate::SimulationOptions::default()
            },
        )
    }

    /// Runs the study. `on_point` sees every point of both branches and
    /// returns false to stop.
    pub fn run(
        mut self,
        mut on_point: impl FnMut(&BranchPoint) -> bool,
    ) -> Result<BranchOutcome, StudyError> {
        let study = &self.study;
        let opts = &self.options;
        let interrupt = || opts.shooting.interrupt.clone();
        let guess = match study.start {
            Start::Homotopy => homotopy_guess(&self.family, study.from, opts)?,
            Start::Simulate => guess_by_simulation_with(
                &self.start_model,
                study.guess_periods,
                GUESS_RTOL,
                interrupt(),
            )
            .map_err(StudyError::Guess)?,
            Start::Auto => {
                let n = opts.shooting.subharmonic as usize;
                let (guess, worth) = settled_guess(
                    &self.start_model,
                    study.guess_periods,
                    GUESS_RTOL,
                    interrupt(),
                    n,
                )
                .map_err(StudyError::Guess)?;
                if worth {
                    guess
                } else {
                    homotopy_guess(&self.family, study.from, opts)?
                }
            }
        };
        let family = &mut self.family;
        let run =
            |family: &mut F, guess: &[f64], on_point: &mut dyn FnMut(&BranchPoint) -> bool| {
                continue_branch(family, study.from, guess, study.to, opts, on_point)
            };
        let branch = match run(family, &guess, &mut on_point) {
            Err(ContinuationError::StartNotConverged(_)) if study.start == Start::Auto => {
                let guess = homotopy_guess(&*family, study.from, opts)?;
                run(family, &guess, &mut on_point)?
            }
            other => other?,
        };
        let switched = study.switch_at.as_deref().map(|label| {
            switch_branch(
                &mut *family,
                &branch,
                label,
                (study.from, study.to),
                opts,
                &mut on_point,
            )
        });
        Ok(BranchOutcome {
            start_model: self.start_model,
            branch,
            switched,
            options: self.options,
        })
    }
}

/// The orbit at `from` on the branch that grows from rest, by the
/// homotopy in `family`'s forcing amplitude there.
fn homotopy_guess<F: Family>(
    family: &F,
    from: f64,
    opts: &ContinuationOptions,
) -> Result<Vec<f64>, StudyError> {
    let (amplitude, target) = match family.amplitude_family(from) {
        Some(Ok(found)) => found,
        Some(Err(why)) => return Err(no_amplitude(why)),
        None => {
            return Err(StudyError::Invalid {
                field: StudyField::Start,
                message: "a family built in code has no forcing amplitude to vary alone: \
                          start by simulation"
                    .into(),
            })
        }
    };
    Ok(super::amplitude_homotopy(amplitude, target, opts)?)
}

/// The homotopy start refused: the model has no forcing amplitude to vary.
fn no_amplitude(why: ModelFileError) -> StudyError {
    StudyError::Invalid {
        field: StudyField::Start,
        message: format!("the homotopy start needs a forcing amplitude to vary: {why}"),
    }
}
