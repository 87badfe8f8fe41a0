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

from_display!(
    crate::output::OutputError,
    crate::plot::PlotError,
    vibroimpact::contact::ContactLawError,
    vibroimpact::impact::ImpactError,
    vibroimpact::identify::IdentifyError,
    vibroimpact::model::ModelError,
    vibroimpact::model_file::ModelFileError,
    vibroimpact::sweep::SweepError,
    serde_json::Error
);
