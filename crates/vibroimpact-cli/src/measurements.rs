//! Measured impacts for an identification: the restitution and
//! acceleration data sets read from CSV, with file and line for every
//! message.

use std::path::Path;

use vibroimpact::identify::{
    identify, AccelerationSample, Identification, IdentifyError, RestitutionSample,
};
use vibroimpact::impact::TwoBodies;

use crate::data::{parse_csv, read_csv, Table};
use crate::error::CliError;

/// Measured data sets of an identification, with their sources for messages.
pub struct Measurements {
    restitution: Option<(Vec<RestitutionSample>, Table, String)>,
    acceleration: Option<(Vec<AccelerationSample>, Table, String)>,
}

impl Measurements {
    /// Parses the two data sets from CSV text (either may be absent).
    pub fn parse(
        restitution: Option<(&str, &str)>,
        acceleration: Option<(&str, &str)>,
    ) -> Result<Self, CliError> {
        let restitution = restitution
            .map(|(text, source)| {
                let t = parse_csv(text, source, &["impact_velocity", "restitution"])?;
                Ok::<_, CliError>((to_restitution(&t), t, source.to_string()))
            })
            .transpose()?;
        let acceleration = acceleration
            .map(|(text, source)| {
                let t = parse_csv(text, source, &["impact_velocity", "peak_acceleration"])?;
                Ok::<_, CliError>((to_acceleration(&t), t, source.to_string()))
            })
            .transpose()?;
        Ok(Self {
            restitution,
            acceleration,
        })
    }

    pub fn read(restitution: Option<&Path>, acceleration: Option<&Path>) -> Result<Self, CliError> {
        let restitution = restitution
            .map(|p| {
                let t = read_csv(p, &["impact_velocity", "restitution"])?;
                Ok::<_, CliError>((to_restitution(&t), t, p.display().to_string()))
            })
            .transpose()?;
        let acceleration = acceleration
            .map(|p| {
                let t = read_csv(p, &["impact_velocity", "peak_acceleration"])?;
                Ok::<_, CliError>((to_acceleration(&t), t, p.display().to_string()))
            })
            .transpose()?;
        Ok(Self {
            restitution,
            acceleration,
        })
    }
}

fn to_restitution(t: &Table) -> Vec<RestitutionSample> {
    t.columns[0]
        .iter()
        .zip(&t.columns[1])
        .map(|(&u, &e)| RestitutionSample {
            impact_velocity: u,
            restitution: e,
        })
        .collect()
}

fn to_acceleration(t: &Table) -> Vec<AccelerationSample> {
    t.columns[0]
        .iter()
        .zip(&t.columns[1])
        .map(|(&u, &a)| AccelerationSample {
            impact_velocity: u,
            peak_acceleration: a,
        })
        .collect()
}

impl Measurements {
    /// The restitution and acceleration samples (empty when absent).
    pub fn samples(&self) -> (&[RestitutionSample], &[AccelerationSample]) {
        (
            self.restitution.as_ref().map_or(&[][..], |r| &r.0),
            self.acceleration.as_ref().map_or(&[][..], |a| &a.0),
        )
    }

    /// Maps a library error to a message naming the file and line.
    fn locate(&self, e: IdentifyError) -> CliError {
        let find = |what: &str| match what {
            "restitution" => self.restitution.as_ref().map(|(_, t, s)| (t, s)),
            _ => self.acceleration.as_ref().map(|(_, t, s)| (t, s)),
        };
        let located = match &e {
            IdentifyError::InvalidSample {
                what,
                index,
                reason,
            } => find(what).map(|(t, source)| format!("{source}:{}: {reason}", t.lines[*index])),
            IdentifyError::TooFewPoints { what, .. } => {
                find(what).map(|(_, source)| format!("{source}: {e}"))
            }
            _ => None,
        };
        located.map_or_else(|| e.into(), CliError::new)
    }

    /// Runs the identification the options ask for.
    pub fn identify(
        &self,
        bodies: TwoBodies,
        a_over_b: Option<f64>,
        joint: bool,
    ) -> Result<Identification, CliError> {
        if self.restitution.is_none() && self.acceleration.is_none() {
            return Err(CliError::new(
                "nothing to identify: give --restitution and/or --acceleration",
            ));
        }
        let (restitution, acceleration) = self.samples();
        identify(restitution, acceleration, bodies, a_over_b, joint).map_err(|e| self.locate(e))
    }
}
