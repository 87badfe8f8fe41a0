//! An orbit study: everything `periodic` does between reading its
//! arguments and writing its documents, for every face alike. It checks
//! the model and the settings, finds the start guess (by simulation, by
//! the homotopy in the forcing amplitude, or given), shoots (dense or
//! matrix-free) and summarises the orbit over its period.

use super::study::{Linear, StudyError, StudyField};
use super::{amplitude_homotopy, is_symmetric_orbit, ContinuationOptions};
use crate::model::file::ModelDocument;
use crate::model::parameter::ParameterizedModel;
use crate::model::Model;
use crate::periodic::{
    forcing_period, guess_by_simulation_with, orbit_summary_by, shoot, shoot_krylov, OrbitSummary,
    PeriodicSolution, ShootingOptions, MIN_ARNOLDI,
};
use crate::simulate::{estimate_work, SimulationOptions, WorkEstimate};

/// Samples of the orbit summary over one period.
const ORBIT_SAMPLES: usize = 512;

/// Newton steps a shooting is priced at in its announcement (the examples
/// converge in 1 to 19; a homotopy's continuation takes about three times
/// as many maps).
const NEWTON_STEPS: f64 = 10.0;

/// Where shooting starts.
#[derive(Clone, Debug, PartialEq)]
pub enum Guess {
    /// The state after the study's guess periods from the model's initial
    /// state.
    Simulate,
    /// The orbit on the branch that grows from rest, by the homotopy in
    /// the forcing amplitude (the primary orbit at any N).
    Homotopy,
    /// A given state (body order, u then v).
    State(Vec<f64>),
}

/// One periodic orbit of a model file.
#[derive(Clone, Debug)]
pub struct OrbitStudy {
    /// The start guess.
    pub guess: Guess,
    /// Forcing periods simulated for [`Guess::Simulate`].
    pub guess_periods: f64,
    /// Dense or matrix-free.
    pub linear: Linear,
    /// The Arnoldi dimension when matrix-free.
    pub arnoldi: usize,
    /// Shooting's options (period multiple, tolerances, half map,
    /// integrator, stop request).
    pub options: ShootingOptions,
}

/// An [`OrbitStudy`] whose checks passed.
#[derive(Clone, Debug)]
pub struct CheckedOrbit {
    /// The study.
    pub study: OrbitStudy,
    /// The document (the homotopy varies its amplitude).
    pub document: ModelDocument,
    /// Its model.
    pub model: Model,
    /// The Arnoldi dimension if matrix-free (by the study's `linear` for
    /// the model's size), else None.
    pub krylov: Option<usize>,
    /// For [`Guess::Homotopy`]: the document as a family in its forcing
    /// amplitude, and that amplitude.
    amplitude: Option<(ParameterizedModel, f64)>,
}

/// What an orbit study computed.
#[derive(Clone, Debug)]
pub struct OrbitOutcome {
    /// Shooting's result (converged or not: `solution.converged`).
    pub solution: PeriodicSolution,
    /// The orbit over its period.
    pub orbit: OrbitSummary,
    /// Whether the orbit is mirror-symmetric.
    pub symmetric: bool,
}

impl OrbitStudy {
    /// The study on `document` after its checks: a periodic forcing with
    /// one frequency, a period multiple ≥ 1, the half map only on a
    /// mirror-symmetric model with an odd multiple, enough Arnoldi
    /// vectors and a given guess of the model's size.
    pub fn check(mut self, document: ModelDocument) -> Result<CheckedOrbit, StudyError> {
        let loaded = document.build()?;
        let model = loaded.model;
        if let Some(scale) = loaded.simulation.displacement_scale {
            self.options.displacement_scale = scale;
        }
        let invalid = |field, message: String| StudyError::Invalid { field, message };
        if model.forcing_frequency().is_none() {
            return Err(StudyError::Model(format!(
                "{}: the model has no periodic forcing with one frequency, so it has no periodic solutions",
                document.source()
            )));
        }
        for (field, v) in [("rtol", self.options.rtol), ("tol", self.options.tol)] {
            crate::field_error::FieldError::tolerance(field, v).map_err(StudyError::Field)?;
        }
        let n = self.options.subharmonic;
        if n == 0 {
            return Err(invalid(StudyField::Subharmonic, "must be >= 1".into()));
        }
        if self.options.symmetric && (!model.is_mirror_symmetric() || n % 2 == 0) {
            return Err(invalid(
                StudyField::Symmetric,
                "needs a mirror-symmetric model (mirrored bodies, contacts, walls and forcing) \
                 and an odd period multiple"
                    .into(),
            ));
        }
        let d = 2 * model.bodies().len();
        let krylov = self.linear.krylov(model.bodies().len(), self.arnoldi);
        let need = MIN_ARNOLDI.min(d);
        if krylov.is_some() && self.arnoldi < need {
            return Err(invalid(
                StudyField::Arnoldi,
                format!("at least {need} Krylov vectors are needed for a stability verdict"),
            ));
        }
        match &self.guess {
            Guess::State(x) if x.len() != d => {
                return Err(invalid(
                    StudyField::Guess,
                    format!("has {} values, the model needs {d} (u then v)", x.len()),
                ));
            }
            _ => {}
        }
        let amplitude = match self.guess {
            Guess::Homotopy => Some(ParameterizedModel::in_amplitude(document.clone()).map_err(
                |e| {
                    invalid(
                        StudyField::Guess,
                        format!("the homotopy needs a forcing amplitude to vary: {e}"),
                    )
                },
            )?),
            _ => None,
        };
        Ok(CheckedOrbit {
            study: self,
            document,
            model,
            krylov,
            amplitude,
        })
    }
}

impl CheckedOrbit {
    /// The estimated work of [`CheckedOrbit::run`] on one core, for the
    /// faces to announce when it is long (`periodic` on a row of 10⁶
    /// bodies said nothing first): the guess's simulation, then about
    /// `NEWTON_STEPS` period maps, each with its columns (dense: 2N,
    /// integrated with the state; matrix-free: the Arnoldi dimension's
    /// products, each priced at a period), and the orbit's summary. None
    /// where a run is refused (the run says why).
    pub fn work(&self) -> Option<WorkEstimate> {
        let (study, model) = (&self.study, &self.model);
        let opts = &study.options;
        let period = forcing_period(model).ok()? * f64::from(opts.subharmonic.max(1));
        let run = |periods: f64, rtol: f64| {
            estimate_work(
                model,
                &SimulationOptions {
                    t_end: periods * period,
                    rtol,
                    atol: rtol * 1e-4,
                    integrator: opts.integrator,
                    interrupt: opts.interrupt.clone(),
                    ..SimulationOptions::default()
                },
            )
        };
        let one = run(1.0, opts.rtol)?;
        let columns = self.krylov.unwrap_or(2 * model.bodies().len()) as f64;
        let (guess, maps) = match study.guess {
            Guess::Simulate => (
                Some(run(study.guess_periods, opts.rtol.max(1e-9))?),
                NEWTON_STEPS,
            ),
            Guess::Homotopy => (None, 4.0 * NEWTON_STEPS),
            Guess::State(_) => (None, NEWTON_STEPS),
        };
        let shooting = one.times(maps * (columns + 1.0)).then(one);
        Some(guess.map_or(shooting, |g| g.then(shooting)))
    }

    /// Shoots from the study's guess and summarises the orbit.
    pub fn run(self) -> Result<OrbitOutcome, StudyError> {
        let (study, model, opts) = (&self.study, &self.model, &self.study.options);
        let guess = match &study.guess {
            Guess::State(x) => x.clone(),
            Guess::Simulate => guess_by_simulation_with(
                model,
                study.guess_periods,
                opts.rtol.max(1e-9),
                opts.interrupt.clone(),
            )
            .map_err(StudyError::Guess)?,
            Guess::Homotopy => {
                let continuation = ContinuationOptions {
                    shooting: ShootingOptions {
                        interrupt: opts.interrupt.clone(),
                        ..ShootingOptions::default()
                    },
                    ..ContinuationOptions::default()
                };
                // Found by check: the document in its forcing amplitude.
                let Some((family, target)) = &self.amplitude else {
                    return Err(StudyError::Invalid {
                        field: StudyField::Guess,
                        message: "the homotopy's family was not checked".into(),
                    });
                };
                amplitude_homotopy(family, *target, &continuation)?
            }
        };
        let solution = match self.krylov {
            Some(arnoldi) => shoot_krylov(model, &guess, opts, arnoldi),
            None => shoot(model, &guess, opts),
        }
        .map_err(StudyError::Shooting)?;
        let orbit = orbit_summary_by(
            model,
            &solution.initial_state,
            (solution.period, ORBIT_SAMPLES),
            opts.rtol,
            opts.integrator,
        )
        .map_err(StudyError::Shooting)?;
        let symmetric = opts.symmetric || is_symmetric_orbit(model, &solution.initial_state, opts);
        Ok(OrbitOutcome {
            solution,
            orbit,
            symmetric,
        })
    }
}
