//! Argument types shared by several commands.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use vibroimpact::continuation::{Linear, Start};
use vibroimpact::field_error::FieldError;
use vibroimpact::integrate::Method;
use vibroimpact::model::file::ModelDocument;
use vibroimpact::model::Model;
use vibroimpact::simulate::Integrator;

use crate::error::CliError;

/// Integration method on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodName {
    /// Explicit 8th-order Dormand–Prince (DOP853): impacts, free flight.
    Dop853,
    /// Explicit 5th-order Dormand–Prince (DOPRI5): loose tolerances with
    /// steps limited by a record's samples.
    Dopri5,
    /// Implicit Rosenbrock (RODAS): bodies pressed together for long times.
    Rodas,
    /// DOP853, switching to RODAS when its stiffness test fires.
    Auto,
}

impl MethodName {
    /// The library's method.
    pub fn method(self) -> Method {
        match self {
            MethodName::Dop853 => Method::Dop853,
            MethodName::Dopri5 => Method::Dopri5,
            MethodName::Rodas => Method::Rodas,
            MethodName::Auto => Method::Auto,
        }
    }
}

/// `--impacts`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ImpactsName {
    /// The contact law, integrated through every contact.
    Soft,
    /// Instantaneous velocity jumps with the law's e(U) (docs/theory.md §12).
    Rigid,
}

/// `--impacts` and `--restitution`: every contact's impacts, over the
/// model file's.
#[derive(Args, Debug)]
pub struct ImpactArgs {
    /// Every contact's impacts: `soft` (the law integrated through the
    /// contact) or `rigid` (velocity jumps with the law's e(U));
    /// default: the model file's (`impacts`), else soft.
    #[arg(long, value_enum)]
    pub impacts: Option<ImpactsName>,
    /// For rigid impacts (`--impacts rigid`, or the model file's): a
    /// constant coefficient of restitution in (0, 1] in place of the
    /// law's e(U).
    #[arg(long)]
    pub restitution: Option<f64>,
}

impl ImpactArgs {
    /// `--impacts` as the library spells it.
    fn name(&self) -> Option<&'static str> {
        self.impacts.map(|i| match i {
            ImpactsName::Soft => "soft",
            ImpactsName::Rigid => "rigid",
        })
    }

    /// `model` with the impacts asked for (`--restitution` alone: on the
    /// model file's rigid contacts).
    pub fn apply(&self, model: Model) -> Result<Model, CliError> {
        model
            .with_impact_options(self.name(), self.restitution)
            .map_err(spelled)
    }

    /// The model file at `path`, read, with the impacts asked for in
    /// every model it builds (a sweep's, a branch's).
    pub fn read(&self, path: &std::path::Path) -> Result<ModelDocument, CliError> {
        crate::model_io::read_document(path)?
            .with_impact_options(self.name(), self.restitution)
            .map_err(spelled)
    }
}

/// A refusal of `--impacts` or `--restitution`, naming the option.
fn spelled(e: FieldError) -> CliError {
    CliError::new(e.spelled(&format!("--{}", e.field), " "))
}

/// `--integrator`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IntegratorName {
    /// Local from 16 groups of bodies (joined by springs) up, unless a
    /// record moves the base; global otherwise
    Auto,
    /// Every body integrated at every step.
    Global,
    /// Exact motion between contacts; bodies in touch integrated.
    Local,
}

impl IntegratorName {
    /// The library's integrator.
    pub fn integrator(self) -> Integrator {
        match self {
            IntegratorName::Auto => Integrator::Auto,
            IntegratorName::Global => Integrator::Global,
            IntegratorName::Local => Integrator::Local,
        }
    }
}

/// How each run of a row of buildings under a record is computed
/// (`pounding`, `collapse`).
#[derive(Args, Debug, Clone)]
pub struct RowRunArgs {
    /// Units of the records when their headers do not state them.
    #[arg(long)]
    pub units: Option<String>,
    /// Output sampling of drifts and accelerations (s).
    #[arg(long, default_value_t = 0.0025)]
    pub sample: f64,
    /// Integration tolerance.
    #[arg(long, default_value_t = 1e-8)]
    pub rtol: f64,
    /// Integration method (dopri5: the faster choice at tolerances of 1e-3
    /// to 1e-5, where the record's samples limit the step).
    #[arg(long, value_enum, default_value_t = MethodName::Dop853)]
    pub method: MethodName,
    /// Integrator: `local` moves each frame exactly between poundings, per
    /// record sample.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    pub integrator: IntegratorName,
}

impl RowRunArgs {
    /// The library's settings (a sample step that is not positive and
    /// finite is refused by name); Ctrl-C stops every run.
    pub fn settings(&self) -> Result<vibroimpact::seismic::pounding::RunSettings, CliError> {
        if !(self.sample.is_finite() && self.sample > 0.0) {
            return Err(CliError::new(format!(
                "--sample {}: give a positive step",
                self.sample
            )));
        }
        Ok(vibroimpact::seismic::pounding::RunSettings {
            sample: self.sample,
            rtol: self.rtol,
            method: self.method.method(),
            integrator: self.integrator.integrator(),
            interrupt: Some(crate::interrupt::on_ctrl_c()),
            loops: false,
        })
    }
}

/// Parses `--mass2`: a mass in kg, or `wall`/`inf` for a rigid wall.
pub fn parse_mass2(text: &str) -> Result<f64, CliError> {
    match text.trim() {
        "wall" | "inf" | "infinity" => Ok(f64::INFINITY),
        t => t
            .parse()
            .map_err(|_| CliError::new(format!("--mass2 `{t}` is not a mass in kg or `wall`"))),
    }
}

/// The model file and the parameter range of `sweep` and `continue`.
#[derive(Args, Debug)]
pub struct ParameterRange {
    /// Model file (TOML, see docs/model.md); its excitation must be periodic
    /// with one frequency at every parameter value.
    pub model: PathBuf,
    /// The parameter: `frequency`, `amplitude` (of the excitation) or a
    /// dotted numeric key of the model file such as `row.clearance` or
    /// `body.1.mass`.
    #[arg(long)]
    pub parameter: String,
    /// First parameter value (`continue` starts there from a simulated
    /// guess).
    #[arg(long)]
    pub from: f64,
    /// Last parameter value.
    #[arg(long)]
    pub to: f64,
    #[command(flatten)]
    pub impacts: ImpactArgs,
}

/// How `continue` finds its first periodic orbit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum StartMethod {
    /// A guess by simulation, then the homotopy if its last 24 periods are
    /// neither near repeating with the orbit's period nor settling onto it,
    /// or if Newton does not converge from it.
    Auto,
    /// The state after --guess-periods forcing periods from the model's
    /// initial state.
    Simulate,
    /// A homotopy in the forcing amplitude from the rest state (an exact
    /// periodic orbit at zero forcing): the primary branch at any N.
    Homotopy,
}

impl StartMethod {
    /// The library's start.
    pub fn start(self) -> Start {
        match self {
            StartMethod::Auto => Start::Auto,
            StartMethod::Simulate => Start::Simulate,
            StartMethod::Homotopy => Start::Homotopy,
        }
    }
}

/// Dense or matrix-free linear algebra for periodic orbits and branches
/// (`periodic`, `continue`).
#[derive(Args, Debug)]
pub struct LinearAlgebra {
    /// Matrix-free: Newton–Krylov with Arnoldi multipliers (default from
    /// 200 bodies on; the dense monodromy costs O(N²) memory and work).
    #[arg(long)]
    pub krylov: bool,
    /// Dense monodromy even for large N.
    #[arg(long, conflicts_with = "krylov")]
    pub dense: bool,
    /// Dominant multipliers computed by Arnoldi (matrix-free).
    #[arg(long, default_value_t = 20)]
    pub arnoldi: usize,
}

impl LinearAlgebra {
    /// The library's choice.
    pub fn linear(&self) -> Linear {
        if self.krylov {
            Linear::MatrixFree
        } else if self.dense {
            Linear::Dense
        } else {
            Linear::Auto
        }
    }
}

/// The `points` values of a grid axis `--NAME-from`, `--NAME-to`,
/// `--NAME-points` (of `chart` and `basins`), checked: a finite range and
/// 2 to 100 000 points.
pub fn grid_axis(name: &str, from: f64, to: f64, points: usize) -> Result<Vec<f64>, CliError> {
    if !from.is_finite() || !to.is_finite() || from == to {
        return Err(CliError::new(format!(
            "--{name}-from {from} --{name}-to {to}: give a range of finite values"
        )));
    }
    if !(2..=100_000).contains(&points) {
        return Err(CliError::new(format!(
            "--{name}-points {points}: from 2 to 100000"
        )));
    }
    Ok(vibroimpact::maps::sweep::parameter_values(from, to, points))
}

/// The grid of `chart` (two parameters) and `basins` (two state
/// components): a name and an evenly spaced range per axis.
#[derive(Args, Debug)]
pub struct GridAxes {
    /// What varies along the horizontal axis: a model parameter
    /// (`frequency`, `amplitude`, a dotted key) for `chart`, a state
    /// component (u1, v2, …) for `basins`.
    #[arg(long)]
    pub x: String,
    /// First value of --x.
    #[arg(long, allow_hyphen_values = true)]
    pub x_from: f64,
    /// Last value of --x.
    #[arg(long, allow_hyphen_values = true)]
    pub x_to: f64,
    /// Number of --x values (2 to 100000), evenly spaced, both ends included.
    #[arg(long)]
    pub x_points: usize,
    /// What varies along the vertical axis (different from --x).
    #[arg(long)]
    pub y: String,
    /// First value of --y.
    #[arg(long, allow_hyphen_values = true)]
    pub y_from: f64,
    /// Last value of --y.
    #[arg(long, allow_hyphen_values = true)]
    pub y_to: f64,
    /// Number of --y values (2 to 100000).
    #[arg(long)]
    pub y_points: usize,
}

impl GridAxes {
    /// The values of both axes, checked.
    pub fn values(&self) -> Result<(Vec<f64>, Vec<f64>), CliError> {
        Ok((
            grid_axis("x", self.x_from, self.x_to, self.x_points)?,
            grid_axis("y", self.y_from, self.y_to, self.y_points)?,
        ))
    }
}

/// How every cell of `chart` or start of `basins` is run to its attractor.
#[derive(Args, Debug)]
pub struct AttractorRuns {
    /// Forcing periods simulated and discarded before recording.
    #[arg(long, default_value_t = 100)]
    pub transient: usize,
    /// At most this many forcing periods added to a run's transient while
    /// its Poincaré samples still converge onto an orbit (default 9 ×
    /// --transient; 0: only class it as settling).
    #[arg(long)]
    pub settle: Option<usize>,
    /// Forcing periods recorded (one Poincaré sample at the end of each).
    #[arg(long, default_value_t = 20)]
    pub record: usize,
    /// Relative tolerance (default: the model's [simulation] rtol, else 1e-7).
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Absolute tolerance in m and m/s (default: [simulation] atol, else rtol × 1e-4).
    #[arg(long)]
    pub atol: Option<f64>,
    /// Integration method.
    #[arg(long, value_enum, default_value_t = MethodName::Dop853)]
    pub method: MethodName,
    /// Relative tolerance under which two Poincaré samples are the same
    /// point (default max(1e-5, 1000 rtol), as for a sweep: runs still
    /// settling go on, see --settle).
    #[arg(long)]
    pub cluster_tolerance: Option<f64>,
    /// Integrator of the transients and recorded periods: `local` moves
    /// bodies out of contact exactly.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    pub integrator: IntegratorName,
}

impl AttractorRuns {
    /// The sweep options of these settings.
    pub fn options(
        &self,
        interrupt: vibroimpact::integrate::Interrupt,
    ) -> vibroimpact::maps::sweep::SweepOptions {
        vibroimpact::maps::sweep::SweepOptions {
            transient: self.transient,
            settle: self.settle,
            record: self.record,
            rtol: self.rtol,
            atol: self.atol,
            method: self.method.method(),
            cluster_tolerance: self.cluster_tolerance,
            interrupt: Some(interrupt),
            integrator: self.integrator.integrator(),
            ..vibroimpact::maps::sweep::SweepOptions::default()
        }
    }
}
