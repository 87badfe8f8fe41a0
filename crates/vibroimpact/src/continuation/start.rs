//! A start on the primary branch that needs no guess: a homotopy in the
//! forcing amplitude from the rest state.
//!
//! Without forcing, the rest state is an exact periodic orbit of any
//! period (every body at u = 0, v = 0, the contacts apart); for a small
//! amplitude the orbit is the small linear response, which shooting from
//! rest finds at once. Continuing in the amplitude from there up to the
//! model's own amplitude (pseudo-arclength, so through folds) reaches the
//! orbit of the primary branch at any N, where a guess by simulation may
//! land on another attractor or none.

use super::{continue_branch, ContinuationError, ContinuationOptions, StopReason};
use crate::model::family::Family;

/// Start of the homotopy, as a fraction of the target amplitude.
const START_FRACTION: f64 = 1e-3;

/// The periodic state (body order) at forcing amplitude `amplitude` on the
/// branch that grows from the rest state. `family(a)` builds the model at
/// forcing amplitude `a` (everything else fixed). Errors if the branch in
/// the amplitude does not reach `amplitude` (it turns back below its start
/// or the corrector fails), saying where it stopped.
pub fn amplitude_homotopy<F>(
    mut family: F,
    amplitude: f64,
    opts: &ContinuationOptions,
) -> Result<Vec<f64>, ContinuationError>
where
    F: Family + Send,
{
    if !(amplitude.is_finite() && amplitude != 0.0) {
        return Err(ContinuationError::Invalid(format!(
            "amplitude homotopy: the target amplitude must be finite and nonzero, got {amplitude}"
        )));
    }
    let a0 = START_FRACTION * amplitude;
    let rest = family.model_at(a0)?;
    // The caller's shooting and step control; its own point budget (the
    // caller's is for the branch that follows).
    let local = ContinuationOptions {
        parameter_scale: Some(amplitude.abs()),
        bounds: None,
        max_points: ContinuationOptions::default().max_points,
        // Only the end matters: no special points located along the way
        // (at 0.9 ω0 a row of 100 spent minutes locating grazings and
        // Neimark–Sacker points of the homotopy), no orbit summaries.
        special_points: false,
        ..opts.clone()
    };
    let x0 = vec![0.0; 2 * rest.bodies().len()];
    // A stop request fails every integration, which the step control would
    // take for a corrector that does not converge: say it was the request.
    let interrupted = || {
        opts.shooting
            .interrupt
            .as_ref()
            .is_some_and(|i| i.requested())
    };
    let branch = continue_branch(&mut family, a0, &x0, amplitude, &local, |_| !interrupted())?;
    match (branch.stop, branch.points.last()) {
        (StopReason::ReachedEnd, Some(last)) if last.parameter == amplitude => {
            Ok(last.state.clone())
        }
        (_, last) if interrupted() => Err(ContinuationError::Invalid(format!(
            "interrupted during the homotopy in the forcing amplitude, at {} of {amplitude}",
            last.map_or(a0, |p| p.parameter)
        ))),
        (stop, last) => Err(ContinuationError::Invalid(format!(
            "the homotopy in the forcing amplitude did not reach {amplitude}: it stopped at {} ({stop})",
            last.map_or(a0, |p| p.parameter)
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::Continuation;
    use crate::model::reference::{self, NATURAL_FREQUENCY as W0};

    /// R2 with N = 4 under the base acceleration `amplitude` sin(ω t).
    fn r2_n4_forced(
        omega: f64,
        amplitude: f64,
    ) -> Result<crate::model::Model, crate::model::ModelError> {
        reference::r2_forced(4, reference::CLEARANCE, omega, amplitude)
    }

    /// R2 with N = 4 at 1.5 ω0: a guess by simulation does not lead
    /// Newton to a periodic orbit there, the homotopy from rest does, and
    /// the orbit it gives is periodic (a continuation can start from it).
    #[test]
    fn homotopy_starts_r2_n4_where_a_simulated_guess_does_not() {
        let w = 1.5 * W0;
        let model = |a: f64| r2_n4_forced(w, a);
        let family = crate::model::family::of("amplitude", model);
        let opts = ContinuationOptions::default();
        let x = amplitude_homotopy(family, reference::BASE_AMPLITUDE, &opts).unwrap();
        let target = model(reference::BASE_AMPLITUDE).unwrap();
        let sol = crate::periodic::shoot(&target, &x, &opts.shooting).unwrap();
        assert!(sol.converged);
        assert!(sol.residual_history[0] < 1e-6, "{:?}", sol.residual_history);
        // The main continuation in the frequency starts from it.
        let freq = crate::model::family::of("frequency", |p: f64| {
            reference::r2(4, reference::CLEARANCE, p)
        });
        let start = Continuation::new(freq, w, &x, 0.5 * W0, &opts);
        assert!(start.is_ok(), "{:?}", start.err());
        assert!(matches!(
            amplitude_homotopy(family, f64::NAN, &opts),
            Err(ContinuationError::Invalid(_))
        ));
    }

    /// A stop requested during the homotopy is reported as such, not as a
    /// corrector that does not converge.
    #[test]
    fn an_interrupted_homotopy_says_so() {
        let interrupt = crate::integrate::Interrupt::default();
        let mut opts = ContinuationOptions::default();
        opts.shooting.interrupt = Some(interrupt.clone());
        let mut calls = 0;
        let family = crate::model::family::of("amplitude", |a: f64| {
            calls += 1;
            if calls == 30 {
                interrupt.request();
            }
            r2_n4_forced(0.9 * W0, a)
        });
        let err = amplitude_homotopy(family, reference::BASE_AMPLITUDE, &opts).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("interrupted during the homotopy"),
            "{err}"
        );
    }
}
