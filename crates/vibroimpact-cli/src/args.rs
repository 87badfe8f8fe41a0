//! Argument types shared by several commands.

use clap::ValueEnum;
use vibroimpact::integrate::Method;

use crate::error::CliError;

/// Integration method on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodName {
    /// Explicit 8th-order Dormand–Prince (DOP853): impacts, free flight.
    Dop853,
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
            MethodName::Rodas => Method::Rodas,
            MethodName::Auto => Method::Auto,
        }
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
