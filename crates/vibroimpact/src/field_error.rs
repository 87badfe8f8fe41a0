//! An option a study refuses, by name: each face spells the field its own
//! way (`--cluster-tolerance 0: …` on the command line, `cluster_tolerance
//! = 0: …` in Python) from the same error, with no rewritten text.

use std::fmt;

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
