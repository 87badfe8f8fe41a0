//! [`Stepper`]: DOP853, DOPRI5 or RODAS behind one interface, with the
//! automatic switch from DOP853 to RODAS when DOP853's stiffness test
//! fires, and, where asked, the exact flow from every reset at which the
//! system has a linear form ([`Stepper::exact_where_linear`]).

use super::{
    Dop853, Dopri5, Exact, ExactMethod, IntegrationError, IntegratorOptions, Linear, LinearForm,
    OdeSystem, Rodas, Stats,
};

/// Integration method of a [`Stepper`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The explicit [`Dop853`] (non-stiff problems).
    Dop853,
    /// The explicit [`Dopri5`] (non-stiff problems at loose tolerances,
    /// steps limited by breakpoints such as a record's samples).
    Dopri5,
    /// The exact flow [`Exact`] of a system with a
    /// [`linear_form`](super::OdeSystem::linear_form) (the period map of a
    /// chain whose every contact is rigid, between impacts).
    Exact,
    /// The linearly implicit [`Rodas`] (stiff problems).
    Rodas,
    /// Start every integration (every [`Stepper::reset`]) with DOP853 and
    /// switch to RODAS for the rest of it as soon as DOP853's stiffness test
    /// fires ([`Dop853::stiffness_detected`]; needs
    /// [`IntegratorOptions::stiffness_check`], else this is plain DOP853).
    Auto,
}

impl Method {
    /// The method's name as the faces spell it (`dop853`, `dopri5`,
    /// `rodas`, `auto`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Dop853 => "dop853",
            Method::Dopri5 => "dopri5",
            Method::Exact => "exact",
            Method::Rodas => "rodas",
            Method::Auto => "auto",
        }
    }
}

/// The drivers a [`Stepper`] holds. (One stepper serves a whole
/// integration, so the size difference of the variants does not matter.)
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
enum Engines {
    Dop853(Dop853),
    Dopri5(Dopri5),
    Exact(Exact),
    Rodas(Rodas),
    /// DOP853 from every reset, RODAS (`on_rodas`) from the moment DOP853's
    /// stiffness test fired until the next reset.
    Auto {
        dop853: Dop853,
        rodas: Rodas,
        on_rodas: bool,
    },
}

impl Engines {
    fn new(method: Method, dim: usize, opts: &IntegratorOptions) -> Result<Self, IntegrationError> {
        Ok(match method {
            Method::Dop853 => Engines::Dop853(Dop853::new(dim, opts.clone())?),
            Method::Dopri5 => Engines::Dopri5(Dopri5::new(dim, opts.clone())?),
            Method::Exact => Engines::Exact(Exact::new(dim, opts.clone())?),
            Method::Rodas => Engines::Rodas(Rodas::new(dim, opts.clone())?),
            Method::Auto => Engines::Auto {
                dop853: Dop853::new(dim, opts.clone())?,
                rodas: Rodas::new(dim, opts.clone())?,
                on_rodas: false,
            },
        })
    }

    fn stats(&self) -> Stats {
        match self {
            Engines::Dop853(d) => d.stats(),
            Engines::Dopri5(d) => d.stats(),
            Engines::Exact(d) => d.stats(),
            Engines::Rodas(r) => r.stats(),
            Engines::Auto { dop853, rodas, .. } => dop853.stats() + rodas.stats(),
        }
    }

    fn reset_stats(&mut self) {
        match self {
            Engines::Dop853(d) => d.reset_stats(),
            Engines::Dopri5(d) => d.reset_stats(),
            Engines::Exact(d) => d.reset_stats(),
            Engines::Rodas(r) => r.reset_stats(),
            Engines::Auto { dop853, rodas, .. } => {
                dop853.reset_stats();
                rodas.reset_stats();
            }
        }
    }
}

/// Runs `$e` with `$d` bound to the active driver: `active!(self, d => …)`
/// borrows it shared, `active!(mut self, d => …)` mutably.
macro_rules! active {
    (mut $self:ident, $d:ident => $e:expr) => {
        active!(@ &mut $self.engines, $d => $e)
    };
    ($self:ident, $d:ident => $e:expr) => {
        active!(@ &$self.engines, $d => $e)
    };
    (@ $engines:expr, $d:ident => $e:expr) => {
        match $engines {
            Engines::Dop853($d) | Engines::Auto { dop853: $d, on_rodas: false, .. } => $e,
            Engines::Rodas($d) | Engines::Auto { rodas: $d, on_rodas: true, .. } => $e,
            Engines::Dopri5($d) => $e,
            Engines::Exact($d) => $e,
        }
    };
}

/// Any of the integrators behind one interface, with optional automatic
/// switching from DOP853 to RODAS ([`Method::Auto`]).
///
/// The methods have the semantics of the same-named methods of the
/// [`Driver`](super::Driver) and act on the *active* integrator
/// ([`active`](Self::active)).
///
/// With [`Method::Auto`], [`step`](Self::step) checks, *before* taking a
/// step, whether DOP853 has detected stiffness; if so it restarts RODAS at
/// DOP853's current point with DOP853's proposed step (under stiffness
/// limited by stability, which is safe; RODAS then grows it up to 6× per
/// step; one evaluation of `f`) and takes the step with RODAS. Dense output
/// therefore always refers to the last step taken. There is no switch back
/// within an integration: the next [`reset`](Self::reset) (e.g. after an
/// impact) starts with DOP853 again.
#[derive(Clone, Debug)]
pub struct Stepper {
    method: Method,
    opts: IntegratorOptions,
    engines: Engines,
    /// With [`Stepper::exact_where_linear`]: the form the exact flow moves,
    /// and the engine not in use.
    exact: Option<ExactSwitch>,
}

/// The exact flow beside the method of construction: `form` the linear
/// form the exact engine was made for (None: none made yet), `spare` the
/// engine not in use (the exact one while the method of construction
/// runs, and the other way round), `retired` the work of exact engines
/// dropped for another form.
#[derive(Clone, Debug, Default)]
struct ExactSwitch {
    form: Option<LinearForm>,
    spare: Option<Engines>,
    retired: Stats,
}

impl ExactSwitch {
    /// Drops an engine, its work kept in the counters.
    fn retire(&mut self, engines: Engines) {
        self.retired = self.retired + engines.stats();
    }
}

impl Stepper {
    /// Creates a stepper for systems of dimension `dim`, allocating the
    /// integrators the method needs. Fails with
    /// [`IntegrationError::InvalidOptions`] as [`Driver::new`](super::Driver::new) does.
    pub fn new(
        method: Method,
        dim: usize,
        opts: IntegratorOptions,
    ) -> Result<Self, IntegrationError> {
        let engines = Engines::new(method, dim, &opts)?;
        Ok(Self {
            method,
            opts,
            engines,
            exact: None,
        })
    }

    /// A stepper on the exact flow of `linear` (of dimension `dim`), its
    /// steps up to the form's [`step_limit`](super::Linear::step_limit)
    /// (and `opts.h_max`); None where the options refuse it (e.g. an
    /// `h_min` above that limit).
    pub(crate) fn exact(linear: Linear, dim: usize, opts: &IntegratorOptions) -> Option<Self> {
        let h = opts.h_max.min(linear.step_limit());
        let opts = IntegratorOptions {
            h_max: h,
            h_init: Some(h),
            ..opts.clone()
        };
        let engine = Exact::with_method(dim, opts.clone(), ExactMethod::with_form(linear, dim));
        Some(Self {
            method: Method::Exact,
            opts,
            engines: Engines::Exact(engine.ok()?),
            exact: None,
        })
    }

    /// From every [`reset`](Self::reset) at which the system has a
    /// [`linear_form`](OdeSystem::linear_form) that solves, moves it
    /// exactly ([`Method::Exact`], steps up to its
    /// [`step_limit`](super::Linear::step_limit)); elsewhere by the method
    /// of construction. The form is read at each reset (a system that
    /// changes there, e.g. a contact's soft episode starting or ending,
    /// changes method there); the exact engine waits while its form is
    /// gone and takes over again when it is back, its exponentials kept.
    /// (No effect on a stepper built for [`Method::Exact`] itself.)
    pub fn exact_where_linear(mut self) -> Self {
        if self.method != Method::Exact {
            self.exact = Some(ExactSwitch::default());
        }
        self
    }

    /// Puts the engine for `sys`'s form in place (see
    /// [`Stepper::exact_where_linear`]).
    fn choose_engine<S: OdeSystem>(&mut self, sys: &S) -> Result<(), IntegrationError> {
        let Some(sw) = self.exact.as_mut() else {
            return Ok(());
        };
        let form = sys.linear_form();
        let on_exact = matches!(self.engines, Engines::Exact(_));
        // The form the exact engine was made for: it goes on, or takes
        // over again from the spare.
        if form.is_some() && form == sw.form {
            if on_exact {
                return Ok(());
            }
            if let Some(exact) = sw.spare.take() {
                sw.spare = Some(std::mem::replace(&mut self.engines, exact));
                return Ok(());
            }
        }
        let dim = sys.dim();
        // (Options the exact flow cannot take, e.g. an h_min above its
        // step limit, leave the method of construction in place.)
        let exact = match form.clone().and_then(LinearForm::solve) {
            Some(linear) if linear.dim() == dim => {
                Self::exact(linear, dim, &self.opts).map(|st| st.engines)
            }
            _ => None,
        };
        match (on_exact, exact) {
            // Another form: a new exact engine; the old one's work stays
            // counted.
            (true, Some(e)) => {
                sw.retire(std::mem::replace(&mut self.engines, e));
                sw.form = form;
            }
            // The form is gone: the exact engine waits as the spare.
            (true, None) => {
                let back = match sw.spare.take() {
                    Some(back) => back,
                    None => Engines::new(self.method, dim, &self.opts)?,
                };
                sw.spare = Some(std::mem::replace(&mut self.engines, back));
            }
            // A new form: the method of construction waits as the spare
            // (an exact engine of another form there retires).
            (false, Some(e)) => {
                if let Some(old) = sw.spare.take() {
                    sw.retire(old);
                }
                sw.spare = Some(std::mem::replace(&mut self.engines, e));
                sw.form = form;
            }
            // Still no form: nothing changes.
            (false, None) => {}
        }
        Ok(())
    }

    /// The method the stepper was created with.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The integrator in use: [`Method::Dop853`], [`Method::Dopri5`],
    /// [`Method::Exact`] or [`Method::Rodas`].
    pub fn active(&self) -> Method {
        match self.engines {
            Engines::Dopri5(_) => Method::Dopri5,
            Engines::Exact(_) => Method::Exact,
            Engines::Dop853(_)
            | Engines::Auto {
                on_rodas: false, ..
            } => Method::Dop853,
            Engines::Rodas(_) | Engines::Auto { on_rodas: true, .. } => Method::Rodas,
        }
    }

    /// Start (or restart) at `(t0, y0)` with the method of construction
    /// (DOP853 for [`Method::Auto`], also after an earlier switch), or the
    /// exact flow ([`Stepper::exact_where_linear`]).
    pub fn reset<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
    ) -> Result<(), IntegrationError> {
        self.choose_engine(sys)?;
        if let Engines::Auto { on_rodas, .. } = &mut self.engines {
            *on_rodas = false;
        }
        active!(mut self, d => d.reset(sys, t0, y0))
    }

    /// Takes one accepted step; with [`Method::Auto`], first switches to
    /// RODAS if DOP853 has detected stiffness.
    pub fn step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t_bound: f64,
    ) -> Result<(), IntegrationError> {
        if let Engines::Auto {
            dop853,
            rodas,
            on_rodas,
        } = &mut self.engines
        {
            if !*on_rodas && dop853.is_initialised() && dop853.stiffness_detected() {
                rodas.reset_with_step(sys, dop853.t(), dop853.y(), Some(dop853.h_next()))?;
                *on_rodas = true;
            }
        }
        active!(mut self, d => d.step(sys, t_bound))
    }

    /// Time after the last accepted step.
    pub fn t(&self) -> f64 {
        active!(self, d => d.t())
    }

    /// Time before the last accepted step.
    pub fn t_prev(&self) -> f64 {
        active!(self, d => d.t_prev())
    }

    /// State at [`t`](Self::t).
    pub fn y(&self) -> &[f64] {
        active!(self, d => d.y())
    }

    /// `f(t, y)` at the current point.
    pub fn dydt(&self) -> &[f64] {
        active!(self, d => d.dydt())
    }

    /// Size of the last accepted step (before rounding of its end time).
    pub fn h_last(&self) -> f64 {
        active!(self, d => d.h_last())
    }

    /// Step size proposed for the next step.
    pub fn h_next(&self) -> f64 {
        active!(self, d => d.h_next())
    }

    /// Caps the size of the next step of the active integrator at `h`.
    pub fn limit_next_step(&mut self, h: f64) {
        active!(mut self, d => d.limit_next_step(h))
    }

    /// Dense output of the last accepted step, valid in `[t_prev, t]`: 7th
    /// order for DOP853, 4th for DOPRI5, 3rd for RODAS; the first
    /// `out.len()` components ([`super::Driver::dense_output`]).
    ///
    /// # Panics
    /// If `out.len()` exceeds the dimension.
    pub fn dense_output<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]) {
        active!(mut self, d => d.dense_output(sys, t, out))
    }

    /// Shortens the last step to end at `t` inside it where the active
    /// method's dense output is the flow itself (the exact method;
    /// [`Driver::end_step_at`](super::Driver::end_step_at)); false for
    /// another method.
    pub fn end_step_at<S: OdeSystem>(&mut self, sys: &mut S, t: f64) -> bool {
        active!(mut self, d => d.end_step_at(sys, t))
    }

    /// Single component of the dense output.
    ///
    /// # Panics
    /// If `i` is not below the dimension.
    pub fn dense_component<S: OdeSystem>(&mut self, sys: &mut S, i: usize, t: f64) -> f64 {
        active!(mut self, d => d.dense_component(sys, i, t))
    }

    /// Work counters of every integrator together.
    pub fn stats(&self) -> Stats {
        let mut stats = self.engines.stats();
        if let Some(sw) = &self.exact {
            stats = stats + sw.retired;
            if let Some(spare) = &sw.spare {
                stats = stats + spare.stats();
            }
        }
        stats
    }

    /// Sets the work counters of every integrator to zero.
    pub fn reset_stats(&mut self) {
        self.engines.reset_stats();
        if let Some(sw) = &mut self.exact {
            sw.retired = Stats::default();
            if let Some(spare) = &mut sw.spare {
                spare.reset_stats();
            }
        }
    }

    /// The options the stepper was created with.
    pub fn options(&self) -> &IntegratorOptions {
        &self.opts
    }

    /// The Gershgorin bound of RODAS's last Jacobian
    /// ([`Driver::jacobian_bound`](super::Driver::jacobian_bound)) while
    /// RODAS is active, else None.
    pub fn rodas_jacobian_bound(&self) -> Option<f64> {
        match &self.engines {
            Engines::Rodas(r)
            | Engines::Auto {
                rodas: r,
                on_rodas: true,
                ..
            } => Some(r.jacobian_bound()),
            _ => None,
        }
    }

    /// Whether an explicit method is active and its stiffness test currently
    /// reports stiffness ([`Dop853::stiffness_detected`](super::Driver::stiffness_detected));
    /// `false` while RODAS is active.
    pub fn stiffness_detected(&self) -> bool {
        match &self.engines {
            Engines::Dopri5(d) => d.stiffness_detected(),
            Engines::Dop853(d)
            | Engines::Auto {
                dop853: d,
                on_rodas: false,
                ..
            } => d.stiffness_detected(),
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::tests::systems::Harmonic;
    use crate::integrate::BandMatrix;

    /// y' = −λ (y − cos t), with analytic Jacobian.
    struct StiffLinear(f64);
    impl OdeSystem for StiffLinear {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -self.0 * (y[0] - t.cos());
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
            jac.set(0, 0, -self.0);
            true
        }
    }
    fn stiff_exact(lambda: f64, t: f64) -> f64 {
        let a = lambda * lambda / (1.0 + lambda * lambda);
        let b = lambda / (1.0 + lambda * lambda);
        a * t.cos() + b * t.sin() - a * (-lambda * t).exp()
    }

    fn tol(tol: f64) -> IntegratorOptions {
        IntegratorOptions {
            rtol: tol,
            atol: tol,
            ..Default::default()
        }
    }

    fn run_to<S: OdeSystem>(st: &mut Stepper, sys: &mut S, t_end: f64) {
        while st.t() < t_end {
            st.step(sys, t_end).unwrap();
        }
    }

    #[test]
    fn auto_switches_to_rodas_on_stiff_problem() {
        // y' = −1e6 (y − cos t), y(0) = 0, over [0, 10] at tol 1e-8:
        // DOP853 alone needs ~1.56 million steps; Auto detects stiffness
        // after a few dozen DOP853 steps and finishes with RODAS.
        let lambda = 1e6;
        let mut sys = StiffLinear(lambda);
        let mut st = Stepper::new(Method::Auto, 1, tol(1e-8)).unwrap();
        assert_eq!(st.method(), Method::Auto);
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Dop853);
        let mut switched_at = None;
        while st.t() < 10.0 {
            st.step(&mut sys, 10.0).unwrap();
            if switched_at.is_none() && st.active() == Method::Rodas {
                switched_at = Some(st.t_prev());
            }
        }
        let stats = st.stats();
        let err = (st.y()[0] - stiff_exact(lambda, 10.0)).abs();
        // Measured: switch after 34 DOP853 steps (t = 1.4e-4), then 80 RODAS
        // steps; 114 steps, 25 rejected, error 1.0e-9.
        assert!(switched_at.is_some());
        assert!(!st.stiffness_detected(), "false while RODAS is active");
        assert!(err < 1e-7, "error {err:e}");
        assert!(stats.steps < 500, "{stats:?}");
        assert!(stats.jacobian_evaluations > 0 && stats.lu_decompositions > 0);
        // Dense output works across the switch.
        let tm = 0.5 * (st.t_prev() + st.t());
        let v = st.dense_component(&mut sys, 0, tm);
        assert!((v - stiff_exact(lambda, tm)).abs() < 1e-6);
        // reset() starts with DOP853 again.
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Dop853);
        st.reset_stats();
        assert_eq!(st.stats(), Stats::default());
    }

    #[test]
    fn auto_stays_on_dop853_for_non_stiff_problem() {
        let mut st = Stepper::new(Method::Auto, 2, tol(1e-9)).unwrap();
        let mut d = Dop853::new(2, tol(1e-9)).unwrap();
        st.reset(&mut Harmonic::plain(), 0.0, &[1.0, 0.0]).unwrap();
        d.reset(&mut Harmonic::plain(), 0.0, &[1.0, 0.0]).unwrap();
        run_to(&mut st, &mut Harmonic::plain(), 50.0);
        while d.t() < 50.0 {
            d.step(&mut Harmonic::plain(), 50.0).unwrap();
        }
        assert_eq!(st.active(), Method::Dop853);
        assert_eq!(st.y(), d.y(), "identical to plain DOP853");
        assert_eq!(st.stats(), d.stats());
        assert_eq!(st.dydt(), d.dydt());
        assert_eq!(st.h_next(), d.h_next());
    }

    #[test]
    fn fixed_methods_and_manual_switch() {
        // Method::Rodas behaves exactly like a standalone Rodas.
        let lambda = 1e6;
        let mut sys = StiffLinear(lambda);
        let mut st = Stepper::new(Method::Rodas, 1, tol(1e-6)).unwrap();
        let mut r = Rodas::new(1, tol(1e-6)).unwrap();
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        r.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Rodas);
        run_to(&mut st, &mut sys, 1.0);
        while r.t() < 1.0 {
            r.step(&mut sys, 1.0).unwrap();
        }
        assert_eq!(st.y(), r.y());
        assert_eq!(st.stats(), r.stats());
        assert_eq!(st.t_prev(), r.t_prev());
        let mut out = [0.0];
        st.dense_output(&mut sys, 0.5 * (st.t() + st.t_prev()), &mut out);
        assert_eq!(
            out[0],
            r.dense_component(&mut sys, 0, 0.5 * (r.t() + r.t_prev()))
        );

        // Method::Dopri5 behaves exactly like a standalone Dopri5, and
        // reports stiffness through its own test.
        let mut st = Stepper::new(Method::Dopri5, 1, tol(1e-6)).unwrap();
        let mut d = Dopri5::new(1, tol(1e-6)).unwrap();
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        d.reset(&mut sys, 0.0, &[0.0]).unwrap();
        for _ in 0..200 {
            st.step(&mut sys, 1.0).unwrap();
            d.step(&mut sys, 1.0).unwrap();
        }
        assert_eq!(st.active(), Method::Dopri5);
        assert_eq!((st.y(), st.stats()), (d.y(), d.stats()));
        assert!(st.stiffness_detected() && d.stiffness_detected());
        assert_eq!(st.rodas_jacobian_bound(), None);

        // Method::Dop853 never switches, even when its test fires.
        let mut st = Stepper::new(Method::Dop853, 1, tol(1e-6)).unwrap();
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        for _ in 0..200 {
            st.step(&mut sys, 1.0).unwrap();
        }
        assert!(st.stiffness_detected());
        assert_eq!(st.active(), Method::Dop853);
        assert_eq!(st.options().rtol, 1e-6);

        // Auto restarts RODAS at DOP853's current point.
        let mut st = Stepper::new(Method::Auto, 1, tol(1e-6)).unwrap();
        assert!(matches!(
            st.step(&mut sys, 1.0),
            Err(IntegrationError::InvalidOptions(_))
        ));
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        let mut last = (st.t(), st.y()[0]);
        while st.active() == Method::Dop853 {
            last = (st.t(), st.y()[0]);
            st.step(&mut sys, 1.0).unwrap();
        }
        let mut out = [0.0];
        st.dense_output(&mut sys, st.t_prev(), &mut out);
        assert_eq!(
            (st.t_prev(), out[0]),
            last,
            "restarted at the current point"
        );
        run_to(&mut st, &mut sys, 1.0);
        assert!((st.y()[0] - stiff_exact(lambda, 1.0)).abs() < 1e-5);
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Dop853);
    }

    #[test]
    fn stats_add_field_wise() {
        let a = Stats {
            rhs_evaluations: 1,
            steps: 2,
            rejected_steps: 3,
            jacobian_evaluations: 4,
            lu_decompositions: 5,
        };
        let b = a + a;
        assert_eq!(
            b,
            Stats {
                rhs_evaluations: 2,
                steps: 4,
                rejected_steps: 6,
                jacobian_evaluations: 8,
                lu_decompositions: 10,
            }
        );
    }
}
