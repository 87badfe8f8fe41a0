//! The local run's pace (docs/theory.md §10): a set whose steps crawl or
//! whose explicit method turns stiff, and checks that crawl, end the run
//! with the reason, as the global integrator's steps do.

use super::*;

/// The set's pace after its `steps`-th kept step, as the global
/// integrator judges its own: an explicit method whose step stability
/// limits so far that the rest of the run would pass the step limit stops
/// with [`IntegrationError::Stiff`]; any method that crawls (projected
/// steps above `CRAWL_FACTOR` times the limit) with
/// [`IntegrationError::NoProgress`].
pub(super) fn pace(
    set: &ActiveSet,
    method: Method,
    opts: &SimulationOptions,
    steps: u64,
) -> Option<IntegrationError> {
    let (t, limit) = (set.st.t(), opts.max_steps);
    if matches!(method, Method::Dop853 | Method::Dopri5) && set.st.stiffness_detected() {
        let h = t - set.st.t_prev();
        let projected = (opts.t_end - t) / h;
        if projected > limit.saturating_sub(steps) as f64 {
            return Some(IntegrationError::Stiff {
                t,
                h,
                projected,
                limit,
            });
        }
    }
    if steps % PROGRESS_CHECK == 0 {
        let projected = steps as f64 * opts.t_end / t;
        if projected > CRAWL_FACTOR * limit as f64 {
            return Some(IntegrationError::NoProgress {
                t,
                steps,
                projected,
                limit,
            });
        }
    }
    None
}

/// Why the run ends after the set's `steps`-th step (kept or taken
/// again) at `t`, if it does: past the step limit, or its pace.
pub(super) fn counted(
    set: &ActiveSet,
    (method, opts): (Method, &SimulationOptions),
    (t, steps): (f64, u64),
) -> Option<IntegrationError> {
    if steps > opts.max_steps {
        return Some(IntegrationError::TooManySteps { t, steps });
    }
    pace(set, method, opts, steps)
}

/// Why the checks crawl, if they do at `t` after `checks`: the error and
/// the contact checked most since the last look (`before`).
pub(super) fn checks_crawl(
    run: &Run,
    opts: &SimulationOptions,
    (t, checks): (f64, u64),
    before: &[u64],
) -> Option<(IntegrationError, Option<usize>)> {
    let nc = run.checks_per_contact.len();
    let projected = checks as f64 * opts.t_end / t;
    if projected <= CRAWL_FACTOR * (opts.max_steps as f64).max(nc as f64) {
        return None;
    }
    let e = IntegrationError::ChecksCrawl {
        t,
        checks,
        projected,
        limit: opts.max_steps,
    };
    // (A storey's checks crawl: no contact to name.)
    let k = (0..nc).max_by_key(|&k| (run.checks_per_contact[k] - before[k], Reverse(k)));
    Some((e, k.filter(|&k| k < run.model.contacts().len())))
}
