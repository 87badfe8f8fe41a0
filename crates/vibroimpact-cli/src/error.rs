//! The CLI's error: one line saying what is wrong; `main` prints it and exits
//! non-zero.

/// A user-facing error message.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct CliError(String);

impl CliError {
    /// An error with this message.
    pub fn new(message: impl Into<String>) -> Self {
        Self(message.into())
    }
}

macro_rules! from_display {
    ($($t:ty),*) => {$(
        impl From<$t> for CliError {
            fn from(e: $t) -> Self {
                Self(e.to_string())
            }
        }
    )*};
}

impl From<csv::Error> for CliError {
    fn from(e: csv::Error) -> Self {
        Self(format!("cannot format CSV: {e}"))
    }
}

from_display!(
    std::string::FromUtf8Error,
    vibroimpact::continuation::ContinuationError,
    vibroimpact::continuation::SwitchError,
    vibroimpact::continuation::StudyError,
    vibroimpact::continuation::CurvesError,
    vibroimpact::integrate::IntegrationError,
    vibroimpact::periodic::PeriodicError,
    vibroimpact::simulate::OptionsError,
    crate::output::OutputError,
    crate::plot::PlotError,
    vibroimpact::contact::ContactLawError,
    vibroimpact::impact::ImpactError,
    vibroimpact::identify::IdentifyError,
    vibroimpact::model::ModelError,
    vibroimpact::model::family::FamilyError,
    vibroimpact::identify::measured::TableError,
    vibroimpact::model::file::ModelFileError,
    vibroimpact::maps::sweep::SweepError,
    serde_json::Error
);

/// A library option error in the command line's words: the option
/// `--kebab-case`, then its value.
pub fn option_error(e: &vibroimpact::field_error::FieldError) -> CliError {
    CliError::new(e.spelled(&format!("--{}", e.field.replace('_', "-")), " "))
}

/// A pounding or collapse error in the command line's words: a setting by
/// its option.
pub fn pounding_error(e: vibroimpact::seismic::pounding::PoundingError) -> CliError {
    match e {
        vibroimpact::seismic::pounding::PoundingError::Field(f) => option_error(&f),
        vibroimpact::seismic::pounding::PoundingError::Interrupted => {
            CliError::new("interrupted (Ctrl-C): nothing written")
        }
        other => CliError::new(other.to_string()),
    }
}
