//! An option a study refuses, by name: each face spells the field its own
//! way (`--cluster-tolerance 0: …` on the command line, `cluster_tolerance
//! = 0: …` in Python) from the same error, with no rewritten text.

use std::fmt;

/// A number as a user types it: 1e-20, not 0.00000000000000000001.
pub fn shown(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() < 1e-4 || v.abs() >= 1e6) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// The open range of a tolerance ([`FieldError::tolerance`]).
pub const TOLERANCES: (f64, f64) = (1e-15, 0.1);

/// A refused option: the field (the library's spelling, snake case, as
/// the options' struct field and the Python keyword), its value as given,
/// and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldError {
    /// The option's field.
    pub field: &'static str,
    /// The value, if one is worth showing.
    pub value: Option<String>,
    /// What is wrong with it.
    pub message: String,
}

impl FieldError {
    /// `field` = `value`: `message`.
    pub fn new(field: &'static str, value: impl fmt::Display, message: impl Into<String>) -> Self {
        Self {
            field,
            value: Some(value.to_string()),
            message: message.into(),
        }
    }

    /// `field`: `message` (no value shown).
    pub fn about(field: &'static str, message: impl Into<String>) -> Self {
        Self {
            field,
            value: None,
            message: message.into(),
        }
    }

    /// `v` as the tolerance `field` (relative, or a Newton tolerance on a
    /// scaled residual), or why not: inside ([`TOLERANCES`]). A looser
    /// one controls no error (an impact integrated at rtol 1 gave a
    /// restitution of 1.0967; a periodic orbit at tol 1 was "converged"
    /// with a residual of 0.196), a tighter one is below double
    /// precision (rtol 1e-20 ran into the step cap).
    pub fn tolerance(field: &'static str, v: f64) -> Result<f64, Self> {
        let (lo, hi) = TOLERANCES;
        if v > lo && v < hi {
            Ok(v)
        } else {
            Err(Self::new(
                field,
                shown(v),
                format!(
                    "give a tolerance in ({lo:e}, {hi}): a looser one controls no error, a tighter one is below double precision"
                ),
            ))
        }
    }

    /// The error with the field spelled `name` and its value joined by
    /// `join` (` = ` in the library's and Python's words, a space for a
    /// command-line option).
    pub fn spelled(&self, name: &str, join: &str) -> String {
        match &self.value {
            Some(v) => format!("{name}{join}{v}: {}", self.message),
            None => format!("{name}: {}", self.message),
        }
    }
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.spelled(self.field, " = "))
    }
}

impl std::error::Error for FieldError {}
