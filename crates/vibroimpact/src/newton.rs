//! One damped Newton method for every nonlinear solve of periodic motion:
//! shooting with the dense monodromy matrix, Newton–Krylov shooting with
//! GMRES on the monodromy operator, and the corrector of continuation.
//!
//! A problem ([`NewtonSystem`]) evaluates its residual at an iterate and
//! supplies the linear solve (the pluggable part: a dense LU of `Φ − I` or
//! of the extended Jacobian, GMRES on matrix-free products `Φ v`). The
//! method ([`damped_newton`]):
//!
//! 1. evaluates the residual at the start; stops when its norm is at most
//!    `tol`;
//! 2. solves for the Newton direction δ (a singular system ends the solve,
//!    [`NewtonStop::Singular`]);
//! 3. damps the step to at most `max_step` (max-norm in the problem's
//!    scaled units): `λ₀ = min(max_step/|δ|, 1)` — a full Newton step can
//!    land deep inside a contact, where `e^{αs}` makes the period map
//!    astronomically stiff;
//! 4. with a line search, halves λ (12 times at most) until the residual
//!    decreases (or is below `tol`); no decrease ends the solve
//!    ([`NewtonStop::NoDecrease`]). Without one, it takes `x + λ₀ δ`;
//! 5. optionally accepts stagnation at the noise floor of the residual: a
//!    step below `stall.0 · tol` with a residual below `stall.1 · tol`
//!    (then the direction at the last iterate of the budget is computed
//!    too, to test it).

/// Options of [`damped_newton`].
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Convergence: residual norm at most `tol`.
    pub tol: f64,
    /// Newton steps at most.
    pub max_iterations: usize,
    /// Largest step, max-norm in scaled units.
    pub max_step: f64,
    /// Halve the damped step until the residual decreases.
    pub line_search: bool,
    /// `Some((s, r))`: converged at a step below `s · tol` with a residual
    /// below `r · tol` (the residual cannot be resolved further).
    pub stall: Option<(f64, f64)>,
}

/// Why [`damped_newton`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NewtonStop {
    /// The residual is below the tolerance (or stalled at its noise floor).
    Converged,
    /// The linear system was singular (e.g. a multiplier at +1).
    Singular,
    /// No step along the Newton direction decreased the residual.
    NoDecrease,
    /// The iteration budget was used.
    MaxIterations,
}

impl NewtonStop {
    /// Name used in files: `converged`, `singular`, `no-decrease`,
    /// `max-iterations`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::Singular => "singular",
            Self::NoDecrease => "no-decrease",
            Self::MaxIterations => "max-iterations",
        }
    }

    /// What the stop means for a user, with a remedy.
    pub fn explanation(self) -> &'static str {
        match self {
            Self::Converged => "converged",
            Self::Singular => {
                "the Newton matrix is singular (a Floquet multiplier at +1: a fold or branch \
                 point nearby); continue the branch through it instead"
            }
            Self::NoDecrease => {
                "no step along the Newton direction reduces the residual: the guess is outside \
                 the basin of the periodic solution; start from a guess by simulation after a \
                 longer transient, or continue from a parameter value where it converges"
            }
            Self::MaxIterations => {
                "the iteration budget ran out before the residual fell below the tolerance \
                 (slow progress or a stall: the guess may lie near a non-periodic or \
                 subharmonic motion); try another guess, the symmetric half map, a \
                 subharmonic, or continue from a parameter value where it converges"
            }
        }
    }
}

/// A nonlinear system for [`damped_newton`].
pub trait NewtonSystem {
    /// What an evaluation at an iterate holds (the residual and what the
    /// linear solve needs, e.g. the monodromy matrix).
    type Point;
    /// Why an evaluation or solve failed.
    type Error;

    /// Evaluates the system at `x`.
    fn evaluate(&mut self, x: &[f64]) -> Result<Self::Point, Self::Error>;

    /// The residual's norm at an evaluated point (scaled max-norm).
    fn residual_norm(&self, point: &Self::Point) -> f64;

    /// The Newton direction δ at `x` (`J δ = −r`), in the units of `x`;
    /// `None` if the system is singular.
    fn direction(
        &mut self,
        x: &[f64],
        point: &Self::Point,
    ) -> Result<Option<Vec<f64>>, Self::Error>;

    /// The size of a direction, max-norm in scaled units.
    fn step_norm(&self, delta: &[f64]) -> f64;

    /// Whether a failed evaluation at a trial step `λ` of the line search
    /// is skipped (the search goes on with `λ/2`) rather than ending the
    /// solve with the error. Default: skipped.
    fn skip_failed_trial(&self, _lambda: f64, _error: &Self::Error) -> bool {
        true
    }
}

/// The outcome of [`damped_newton`].
#[derive(Clone, Debug)]
pub struct NewtonOutcome<P> {
    /// The last accepted iterate.
    pub x: Vec<f64>,
    /// The evaluation there.
    pub point: P,
    /// Why the iteration ended.
    pub stop: NewtonStop,
    /// The residual norm of every accepted iterate (repeated when a step
    /// was refused).
    pub history: Vec<f64>,
    /// Evaluations of accepted iterates (1 if the start converged).
    pub evaluations: usize,
}

impl<P> NewtonOutcome<P> {
    /// Whether it converged.
    pub fn converged(&self) -> bool {
        self.stop == NewtonStop::Converged
    }
}

/// Damped Newton from `x0` (see the module documentation).
pub fn damped_newton<S: NewtonSystem>(
    sys: &mut S,
    x0: &[f64],
    opts: &NewtonOptions,
) -> Result<NewtonOutcome<S::Point>, S::Error> {
    let mut x = x0.to_vec();
    let mut point = sys.evaluate(&x)?;
    let mut norm = sys.residual_norm(&point);
    let mut history = vec![norm];
    let mut evaluations = 1;
    let mut iterations = 0;
    let stop = loop {
        if norm <= opts.tol {
            break NewtonStop::Converged;
        }
        // With a stall test, the direction at the last iterate is still
        // computed: a negligible step there means convergence.
        if iterations >= opts.max_iterations && opts.stall.is_none() {
            break NewtonStop::MaxIterations;
        }
        let Some(delta) = sys.direction(&x, &point)? else {
            break NewtonStop::Singular;
        };
        let step = sys.step_norm(&delta);
        if let Some((s, r)) = opts.stall {
            if step <= s * opts.tol && norm <= r * opts.tol {
                break NewtonStop::Converged;
            }
        }
        if iterations >= opts.max_iterations {
            break NewtonStop::MaxIterations;
        }
        iterations += 1;
        let lambda0 = (opts.max_step / step).min(1.0);
        let trial = |lambda: f64| -> Vec<f64> {
            x.iter().zip(&delta).map(|(a, d)| a + lambda * d).collect()
        };
        let found = if opts.line_search {
            line_search(sys, lambda0, norm, opts.tol, trial)?
        } else {
            let next = trial(lambda0);
            let p = sys.evaluate(&next)?;
            let n = sys.residual_norm(&p);
            Some((next, p, n))
        };
        let Some((next, p, n)) = found else {
            history.push(norm);
            break NewtonStop::NoDecrease;
        };
        (x, point, norm) = (next, p, n);
        evaluations += 1;
        history.push(norm);
    };
    Ok(NewtonOutcome {
        x,
        point,
        stop,
        history,
        evaluations,
    })
}

/// A trial point, its evaluation and its residual norm.
type Trial<P> = (Vec<f64>, P, f64);

/// Backtracking along the Newton direction: tries `λ = λ₀, λ₀/2, …` (12
/// times) and returns the first trial whose residual is below `norm` (or
/// below `tol`).
fn line_search<S: NewtonSystem>(
    sys: &mut S,
    lambda0: f64,
    norm: f64,
    tol: f64,
    trial: impl Fn(f64) -> Vec<f64>,
) -> Result<Option<Trial<S::Point>>, S::Error> {
    let mut lambda = lambda0;
    for _ in 0..12 {
        let x = trial(lambda);
        match sys.evaluate(&x) {
            Ok(p) => {
                let n = sys.residual_norm(&p);
                if n < norm || n <= tol {
                    return Ok(Some((x, p, n)));
                }
            }
            Err(e) if sys.skip_failed_trial(lambda, &e) => {}
            Err(e) => return Err(e),
        }
        lambda *= 0.5;
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f(x) = (x0² + x1² − 4, x0 − x1)`, root (√2, √2), the direction from
    /// the exact Jacobian. Evaluations after the first `fail_after` fail; a
    /// failed trial at `λ > skip_above` is skipped.
    struct Circle {
        evaluations: usize,
        fail_after: usize,
        skip_above: f64,
    }

    impl Circle {
        fn new() -> Self {
            Self {
                evaluations: 0,
                fail_after: usize::MAX,
                skip_above: 1e-3,
            }
        }
    }

    impl NewtonSystem for Circle {
        type Point = [f64; 2];
        type Error = String;
        fn evaluate(&mut self, x: &[f64]) -> Result<[f64; 2], String> {
            self.evaluations += 1;
            if self.evaluations > self.fail_after {
                return Err(format!("no value at {x:?}"));
            }
            Ok([x[0] * x[0] + x[1] * x[1] - 4.0, x[0] - x[1]])
        }
        fn residual_norm(&self, p: &[f64; 2]) -> f64 {
            p[0].abs().max(p[1].abs())
        }
        fn direction(&mut self, x: &[f64], p: &[f64; 2]) -> Result<Option<Vec<f64>>, String> {
            // J = [[2x0, 2x1], [1, -1]].
            let (a, b, c, d) = (2.0 * x[0], 2.0 * x[1], 1.0, -1.0);
            let det = a * d - b * c;
            if det == 0.0 {
                return Ok(None);
            }
            Ok(Some(vec![
                -(d * p[0] - b * p[1]) / det,
                -(-c * p[0] + a * p[1]) / det,
            ]))
        }
        fn step_norm(&self, delta: &[f64]) -> f64 {
            delta.iter().fold(0.0, |m, v| m.max(v.abs()))
        }
        fn skip_failed_trial(&self, lambda: f64, _e: &String) -> bool {
            lambda > self.skip_above
        }
    }

    fn opts(line_search: bool) -> NewtonOptions {
        NewtonOptions {
            tol: 1e-12,
            max_iterations: 50,
            max_step: 0.5,
            line_search,
            stall: None,
        }
    }

    /// Converges to (√2, √2) quadratically once the damping stops: the
    /// residual squares (within a factor) from step to step near the root.
    #[test]
    fn converges_quadratically_with_and_without_line_search() {
        for search in [true, false] {
            let mut sys = Circle::new();
            let out = damped_newton(&mut sys, &[3.0, 0.5], &opts(search)).unwrap();
            assert!(out.converged());
            let r = std::f64::consts::SQRT_2;
            assert!((out.x[0] - r).abs() < 1e-12 && (out.x[1] - r).abs() < 1e-12);
            let h = &out.history;
            let k = h.len();
            assert!(
                h[k - 2] < 1e-5 * h[k - 3].max(1e-30) || h[k - 2] < 1e-10,
                "{h:?}"
            );
            assert_eq!(out.evaluations, k);
        }
    }

    /// The stops: the iteration budget, a singular Jacobian (x0 = −x1 on
    /// the start), a failed evaluation at a small trial step (the error),
    /// failed evaluations that may all be skipped (no decrease).
    #[test]
    fn reports_why_it_stopped() {
        let mut sys = Circle::new();
        let few = NewtonOptions {
            max_iterations: 2,
            ..opts(true)
        };
        let out = damped_newton(&mut sys, &[3.0, 0.5], &few).unwrap();
        assert_eq!(out.stop, NewtonStop::MaxIterations);
        assert_eq!(out.history.len(), 3);
        let out = damped_newton(&mut sys, &[1.0, -1.0], &opts(true)).unwrap();
        assert_eq!(out.stop, NewtonStop::Singular);
        assert!(NewtonStop::Singular.explanation().contains("singular"));
        let mut sys = Circle {
            fail_after: 1,
            ..Circle::new()
        };
        let err = damped_newton(&mut sys, &[3.0, 0.5], &opts(true)).unwrap_err();
        assert!(err.starts_with("no value"), "{err}");
        let mut sys = Circle {
            fail_after: 1,
            skip_above: 0.0,
            ..Circle::new()
        };
        let out = damped_newton(&mut sys, &[3.0, 0.5], &opts(true)).unwrap();
        assert_eq!(out.stop, NewtonStop::NoDecrease);
        assert_eq!((out.x.as_slice(), out.history.len()), (&[3.0, 0.5][..], 2));
        assert_eq!(sys.evaluations, 13, "the start and 12 trials");
    }
}
