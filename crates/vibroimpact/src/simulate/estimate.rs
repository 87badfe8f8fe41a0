//! The work of a run, estimated before it starts, so that a legal run
//! that will take long says so up front instead of running silently for
//! minutes or hours (the faces print or warn; the run still goes).
//!
//! A first bound comes from the model alone: the integrator takes at
//! least `STEPS_PER_CYCLE` steps per cycle of the fastest time scale (the
//! forcing, a body's natural frequency or damping rate, a record's
//! samples). Where that bound already exceeds `PROBE_FROM` seconds, the
//! first part of the run is simulated as a probe (about `PROBE_SECONDS`
//! of work by the bound, and at most the steps the bound prices at that)
//! and its steps and time are scaled to the whole duration, which counts
//! the impacts the bound cannot see.

use std::f64::consts::PI;
use std::time::Instant;

use super::global::check_run;
use super::{effective_method, simulate_streaming, Integrator, SimulationOptions, CRAWL_FACTOR};
use crate::model::{BaseExcitation, Model};

/// DOP853's steps per cycle of the fastest scale at rtol 1e-8 (a damped
/// linear pair of R2 bodies: 11.2 steps per forcing period over 3000
/// periods); the count grows as rtol^(-1/8).
pub const STEPS_PER_CYCLE: f64 = 11.0;

/// Seconds per step and per body or contact of the global integrator
/// (R2 N = 2, 3 contacts: 1.2 µs a step with impacts).
const SECONDS_PER_STEP_AND_PART: f64 = 0.25e-6;

/// Seconds per output sample and per body taken by a streaming consumer
/// (a pounding study's peaks: 2.3 s for 2.5e7 samples of a pair of five
/// floors at `--sample 1e-6`).
const SECONDS_PER_SAMPLE_AND_BODY: f64 = 20e-9;

/// From this bound (s) on, a probe measures the run.
pub const PROBE_FROM: f64 = 1.0;

/// The probe's work (s, by the bound).
pub const PROBE_SECONDS: f64 = 0.05;

/// The least share of the run the local integrator's probe covers.
const LOCAL_PROBE_SHARE: f64 = 0.01;

/// The least step budget of a probe by the local integrator.
const LOCAL_PROBE_STEPS: u64 = 1000;

/// Runs estimated to take longer than this (s) are announced (issue 38:
/// no run over 10 s without a word first).
pub const LONG_RUN: f64 = 10.0;

/// A run's estimated work.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkEstimate {
    /// Integration steps.
    pub steps: f64,
    /// Seconds on one core.
    pub seconds: f64,
    /// The simulated time the probe ran (s), 0 for the bound alone.
    pub probed: f64,
    /// The step budget the run has.
    pub max_steps: u64,
}

impl WorkEstimate {
    /// Whether the run is long enough to say so ([`LONG_RUN`]).
    pub fn is_long(&self) -> bool {
        self.seconds > LONG_RUN
    }

    /// Whether the run will reach its step budget before its end.
    pub fn exceeds_step_limit(&self) -> bool {
        self.steps > self.max_steps as f64
    }

    /// This run and `other` one after the other (the smaller step budget,
    /// the longer probe).
    pub fn then(self, other: Self) -> Self {
        Self {
            steps: self.steps + other.steps,
            seconds: self.seconds + other.seconds,
            probed: self.probed.max(other.probed),
            max_steps: self.max_steps.min(other.max_steps),
        }
    }

    /// `runs` such runs one after the other, each with its own step
    /// budget.
    pub fn times(self, runs: f64) -> Self {
        Self {
            steps: self.steps * runs,
            seconds: self.seconds * runs,
            max_steps: (self.max_steps as f64 * runs.max(1.0)).min(u64::MAX as f64) as u64,
            ..self
        }
    }

    /// The announcement: steps and time, how they were estimated, and the
    /// step limit where the run will stop.
    pub fn describe(&self) -> String {
        let how = if self.probed > 0.0 {
            format!("scaled from its first {:.3e} s", self.probed)
        } else {
            "by the fastest time scale".to_string()
        };
        // A row moving freely may take no step at all (the local
        // integrator's exact motion): its time is then its samples'
        // ("about 0.00e0 integration steps, about 5 min" for N = 10⁶).
        let steps = if self.steps >= 1.0 {
            format!("about {:.2e} integration steps, ", self.steps)
        } else {
            "no integration steps but its samples, ".to_string()
        };
        let mut text = format!(
            "a long run: {steps}about {} on one core ({how})",
            duration(self.seconds)
        );
        if self.steps > CRAWL_FACTOR * self.max_steps as f64 {
            text += &format!(
                "; far beyond the step limit of {:e}: it stops as soon as its pace shows (no progress)",
                self.max_steps as f64
            );
        } else if self.exceeds_step_limit() {
            text += &format!(
                "; the step limit of {:e} ends it after about {}",
                self.max_steps as f64,
                duration(self.seconds * self.max_steps as f64 / self.steps)
            );
        }
        text
    }
}

/// Seconds in words: s, min, h or days.
fn duration(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else if s < 2.0 * 86400.0 {
        format!("{:.1} h", s / 3600.0)
    } else {
        format!("{:.0} days", s / 86400.0)
    }
}

/// The fastest rate of `model` (rad/s): its forcing, its bodies' free
/// flight, a record's sampling.
fn fastest_rate(model: &Model) -> f64 {
    let mut rate = model.free_flight_rate().rate;
    match model.base() {
        BaseExcitation::Harmonic { frequency, .. } => rate = rate.max(*frequency),
        BaseExcitation::Record(r) => {
            let t = r.times();
            if t.len() > 1 {
                let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
                rate = rate.max(2.0 * PI / dt / STEPS_PER_CYCLE);
            }
        }
        BaseExcitation::None => {}
    }
    model.forces().iter().fold(rate, |r, f| r.max(f.frequency))
}

/// The work of simulating `model` with `opts`: the bound from its fastest
/// time scale, or a probe of the run's first part where the bound exceeds
/// `PROBE_FROM` seconds. None for a run its checks refuse (the run itself
/// says why).
pub fn estimate_work(model: &Model, opts: &SimulationOptions) -> Option<WorkEstimate> {
    check_run(model, opts).ok()?;
    effective_method(model, opts).ok()?;
    let cycles = opts.t_end * fastest_rate(model) / (2.0 * PI);
    let per_cycle = STEPS_PER_CYCLE * (1e-8 / opts.rtol.clamp(1e-14, 1e-2)).powf(0.125);
    let parts = (model.bodies().len() + model.contacts().len()) as f64;
    let steps = cycles * per_cycle;
    // The output samples cost time of their own, whatever the steps.
    let samples = opts.output_step.map_or(0.0, |h| opts.t_end / h);
    let sampling = samples * model.bodies().len() as f64 * SECONDS_PER_SAMPLE_AND_BODY;
    let bound = WorkEstimate {
        steps,
        seconds: steps * parts * SECONDS_PER_STEP_AND_PART + sampling,
        probed: 0.0,
        max_steps: opts.max_steps,
    };
    if bound.seconds.is_nan() || bound.seconds - sampling <= PROBE_FROM {
        return Some(bound);
    }
    // The probe runs to the bound's share of PROBE_SECONDS, or as many
    // steps as the bound prices at PROBE_SECONDS if impacts make it
    // slower (the local integrator's steps cost its set, not the row: at
    // least `LOCAL_PROBE_STEPS` of them), and scales from the time it
    // reached.
    // The bound prices the global integrator: the local one moves free
    // bodies exactly, so its probe covers at least a hundredth of the run.
    let local = opts.integrator.resolve_run(model, opts) == Integrator::Local;
    let priced = (PROBE_SECONDS / (parts * SECONDS_PER_STEP_AND_PART)).ceil() as u64;
    let mut t_probe = opts.t_end * PROBE_SECONDS / (bound.seconds - sampling);
    if local {
        t_probe = t_probe.max(LOCAL_PROBE_SHARE * opts.t_end);
    }
    let probe = SimulationOptions {
        t_end: t_probe,
        // Two samples, at the start and the end: the clock at the first.
        output_step: Some(t_probe),
        output_from: 0.0,
        extrema_window: None,
        energy: false,
        max_steps: if local {
            priced.max(LOCAL_PROBE_STEPS)
        } else {
            priced
        },
        interrupt: opts.interrupt.clone(),
        ..opts.clone()
    };
    // The wall clock at the probe's samples tells the run's setup (a row
    // of 10⁶ bodies checks every contact once first) from its pace: the
    // setup scaled with the time said "2 days" for what takes minutes.
    let clock = Instant::now();
    let mut first: Option<f64> = None;
    let sim = simulate_streaming(model, &probe, |_, _| {
        first.get_or_insert_with(|| clock.elapsed().as_secs_f64());
        true
    });
    let elapsed = clock.elapsed().as_secs_f64();
    // (The local integrator may take no step at all in free flight: the
    // probe's time still scales.)
    Some(match sim {
        Ok(sim) if sim.final_time > 0.0 => {
            let setup = first.unwrap_or(0.0).min(elapsed);
            let pace = (elapsed - setup) / sim.final_time;
            WorkEstimate {
                steps: sim.stats.steps as f64 * opts.t_end / sim.final_time,
                seconds: setup + pace * opts.t_end + sampling,
                probed: sim.final_time,
                max_steps: opts.max_steps,
            }
        }
        _ => bound,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::reference;
    use crate::simulate::simulate;

    /// A run that takes no step (a free row moved exactly) but writes its
    /// samples is told as such, not as "about 0.00e0 integration steps";
    /// many runs each keep their own step budget (a 40 × 40 basins grid
    /// was said to end at one run's limit).
    #[test]
    fn the_announcement_says_what_the_work_is() {
        let samples = WorkEstimate {
            steps: 0.0,
            seconds: 300.0,
            probed: 1.0,
            max_steps: 1000,
        };
        assert!(samples.describe().starts_with(
            "a long run: no integration steps but its samples, about 5 min on one core"
        ));
        let grid = WorkEstimate {
            steps: 600.0,
            seconds: 1.0,
            ..samples
        }
        .times(1600.0);
        assert!(!grid.exceeds_step_limit() && grid.is_long(), "{grid:?}");
    }

    /// R2 N = 2 at 0.95 ω0: the bound stays below the steps a run takes
    /// (impacts add steps), a probe of a long run scales to within a
    /// factor 2 of a run's own count, and 1e7 periods are announced with
    /// the step limit that ends them.
    #[test]
    fn estimates_bound_and_scale_the_steps() {
        let w = 0.95 * reference::NATURAL_FREQUENCY;
        let model = reference::r2(2, reference::CLEARANCE, w).unwrap();
        let period = 2.0 * PI / w;
        let opts = |periods: f64| SimulationOptions {
            t_end: periods * period,
            ..SimulationOptions::default()
        };
        let short = estimate_work(&model, &opts(200.0)).unwrap();
        let run = simulate(&model, &opts(200.0)).unwrap();
        assert_eq!(short.probed, 0.0);
        assert!(!short.is_long());
        assert!(
            short.steps < run.stats.steps as f64,
            "bound {} steps, run {}",
            short.steps,
            run.stats.steps
        );
        let long = estimate_work(&model, &opts(1e7)).unwrap();
        assert!(long.probed > 0.0 && long.probed < 1000.0 * period);
        let per_period = long.steps / 1e7;
        let measured = run.stats.steps as f64 / 200.0;
        assert!(
            per_period > 0.5 * measured && per_period < 2.0 * measured,
            "probe {per_period} steps a period, run {measured}"
        );
        assert!(long.is_long() && long.exceeds_step_limit());
        assert!(
            long.describe().contains("step limit"),
            "{}",
            long.describe()
        );
    }
}
