//! A family of models in one parameter (or two): the problem that every
//! parameter study takes (continuation, branch switching, the amplitude
//! homotopy, curves of special points), as BifurcationKit's problem with
//! its lens. A model file with one of its keys made the parameter
//! ([`ParameterizedModel`]) is a family; so is a model built in code, by
//! [`of`] (a name and a function of the value).

use std::fmt;

use crate::model::file::ModelFileError;
use crate::model::file::{ModelDocument, SimulationSpec};
use crate::model::parameter::{ModelParameter, ParameterizedModel};
use crate::model::{Model, ModelError};

/// Why a family has no model at a value.
#[derive(Clone, Debug, thiserror::Error)]
pub enum FamilySource {
    /// The model refuses the value (built in code).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The model file refuses the value (its message names the file, the
    /// line and the key, "FILE with NAME = VALUE").
    #[error(transparent)]
    File(#[from] ModelFileError),
}

/// A family could not build its model: the parameter's name and value
/// with the model's error.
#[derive(Clone, Debug, thiserror::Error)]
pub struct FamilyError {
    /// The parameter's name (`frequency`, `row.clearance`, …).
    pub name: String,
    /// The value.
    pub value: f64,
    /// The model's error.
    #[source]
    pub source: FamilySource,
}

impl FamilyError {
    /// `source` for parameter `name` at `value`.
    pub fn new(name: &str, value: f64, source: impl Into<FamilySource>) -> Self {
        Self {
            name: name.to_string(),
            value,
            source: source.into(),
        }
    }
}

impl fmt::Display for FamilyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.source {
            // A file's message already says "FILE with NAME = VALUE:LINE".
            FamilySource::File(e) => write!(f, "{e}"),
            FamilySource::Model(e) => write!(f, "{} = {}: {e}", self.name, self.value),
        }
    }
}

/// Models in one parameter.
pub trait Family {
    /// The parameter's name.
    fn name(&self) -> &str;
    /// The model at parameter value `p`.
    fn model_at(&mut self, p: f64) -> Result<Model, FamilyError>;
    /// Whether the parameter takes whole numbers only (a count): no
    /// branch can follow it.
    fn whole_numbers(&self) -> bool {
        false
    }
    /// The `[simulation]` settings the models come with (tolerances,
    /// impact threshold); none for a model built in code.
    fn simulation(&self) -> SimulationSpec {
        SimulationSpec::default()
    }
    /// The homotopy start's family: the model at parameter value `p` as a
    /// family in its forcing amplitude (everything else fixed), with the
    /// amplitude to reach. None for a family that cannot vary the
    /// amplitude alone (a model built in code); an error when its model
    /// has no forcing amplitude.
    fn amplitude_family(
        &self,
        _p: f64,
    ) -> Option<Result<(ParameterizedModel, f64), ModelFileError>> {
        None
    }
}

/// Models in two parameters (curves of special points: `p` along the
/// branch, `q` the second parameter).
pub trait Family2 {
    /// The two parameters' names.
    fn names(&self) -> [&str; 2];
    /// The model at `(p, q)`.
    fn model_at(&mut self, p: f64, q: f64) -> Result<Model, FamilyError>;
}

impl<T: Family + ?Sized> Family for &mut T {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn model_at(&mut self, p: f64) -> Result<Model, FamilyError> {
        (**self).model_at(p)
    }
    fn whole_numbers(&self) -> bool {
        (**self).whole_numbers()
    }
    fn simulation(&self) -> SimulationSpec {
        (**self).simulation()
    }
    fn amplitude_family(
        &self,
        p: f64,
    ) -> Option<Result<(ParameterizedModel, f64), ModelFileError>> {
        (**self).amplitude_family(p)
    }
}

impl<T: Family2 + ?Sized> Family2 for &mut T {
    fn names(&self) -> [&str; 2] {
        (**self).names()
    }
    fn model_at(&mut self, p: f64, q: f64) -> Result<Model, FamilyError> {
        (**self).model_at(p, q)
    }
}

impl Family for &ParameterizedModel {
    fn name(&self) -> &str {
        &self.parameter().name
    }
    fn model_at(&mut self, p: f64) -> Result<Model, FamilyError> {
        ParameterizedModel::model_at(self, p)
            .map_err(|e| FamilyError::new(&self.parameter().name, p, e))
    }
    fn whole_numbers(&self) -> bool {
        self.parameter().integer
    }
    fn simulation(&self) -> SimulationSpec {
        self.document().simulation()
    }
    fn amplitude_family(
        &self,
        p: f64,
    ) -> Option<Result<(ParameterizedModel, f64), ModelFileError>> {
        let mut document = self.document().clone();
        Some(
            document
                .set(self.parameter(), p)
                .and_then(|()| ParameterizedModel::in_amplitude(document)),
        )
    }
}

/// The owned family is the borrowed one.
impl Family for ParameterizedModel {
    fn name(&self) -> &str {
        &self.parameter().name
    }
    fn model_at(&mut self, p: f64) -> Result<Model, FamilyError> {
        Family::model_at(&mut &*self, p)
    }
    fn whole_numbers(&self) -> bool {
        (&self).whole_numbers()
    }
    fn simulation(&self) -> SimulationSpec {
        (&self).simulation()
    }
    fn amplitude_family(
        &self,
        p: f64,
    ) -> Option<Result<(ParameterizedModel, f64), ModelFileError>> {
        (&self).amplitude_family(p)
    }
}

/// A model built in code as a family: `f(value)` under the name `name`.
#[derive(Clone, Copy, Debug)]
pub struct FnFamily<F> {
    name: &'static str,
    f: F,
}

/// The family `f(value)` of parameter `name` (e.g. `of("amplitude", |a|
/// reference::r2_forced(2, 1e-3, 7.0, a))`).
pub fn of<F: FnMut(f64) -> Result<Model, ModelError>>(name: &'static str, f: F) -> FnFamily<F> {
    FnFamily { name, f }
}

impl<F: FnMut(f64) -> Result<Model, ModelError>> Family for FnFamily<F> {
    fn name(&self) -> &str {
        self.name
    }
    fn model_at(&mut self, p: f64) -> Result<Model, FamilyError> {
        (self.f)(p).map_err(|e| FamilyError::new(self.name, p, e))
    }
}

/// A model built in code in two parameters: `f(p, q)`.
#[derive(Clone, Copy, Debug)]
pub struct FnFamily2<F> {
    names: [&'static str; 2],
    f: F,
}

/// The family `f(p, q)` of parameters `names`.
pub fn of2<F: FnMut(f64, f64) -> Result<Model, ModelError>>(
    names: [&'static str; 2],
    f: F,
) -> FnFamily2<F> {
    FnFamily2 { names, f }
}

impl<F: FnMut(f64, f64) -> Result<Model, ModelError>> Family2 for FnFamily2<F> {
    fn names(&self) -> [&str; 2] {
        self.names
    }
    fn model_at(&mut self, p: f64, q: f64) -> Result<Model, FamilyError> {
        let [a, b] = self.names;
        (self.f)(p, q).map_err(|e| FamilyError::new(&format!("({a}, {b}) at {a}"), p, e))
    }
}

/// A model file with two of its keys made parameters.
#[derive(Clone, Debug)]
pub struct ParameterizedModel2 {
    /// The document.
    pub document: ModelDocument,
    /// The first parameter (along a branch).
    pub p: ModelParameter,
    /// The second parameter.
    pub q: ModelParameter,
}

impl ParameterizedModel2 {
    /// `p` and `q` (aliases or dotted keys) of `document` made the
    /// parameters.
    pub fn new(document: ModelDocument, p: &str, q: &str) -> Result<Self, ModelFileError> {
        Ok(Self {
            p: document.parameter(p)?,
            q: document.parameter(q)?,
            document,
        })
    }
}

impl Family2 for ParameterizedModel2 {
    fn names(&self) -> [&str; 2] {
        [&self.p.name, &self.q.name]
    }
    fn model_at(&mut self, p: f64, q: f64) -> Result<Model, FamilyError> {
        let mut doc = self.document.clone();
        doc.set(&self.q, q)
            .map_err(|e| FamilyError::new(&self.q.name, q, e))?;
        Ok(doc
            .with_parameter(&self.p, p)
            .map_err(|e| FamilyError::new(&self.p.name, p, e))?
            .model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Errors keep the parameter's name and value, in the family's own
    /// words: a file's message as it was, a model built in code prefixed.
    #[test]
    fn errors_name_the_parameter() {
        let text = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.05\nfrequency = 7.0\n";
        let doc = ModelDocument::from_toml(text, "m.toml").unwrap();
        let mut fam = ParameterizedModel::new(doc.clone(), "row.mass").unwrap();
        assert_eq!(Family::name(&fam), "row.mass");
        assert_eq!(
            Family::model_at(&mut fam, 0.3).unwrap().bodies()[0].mass,
            0.3
        );
        let e = Family::model_at(&mut fam, -1.0).unwrap_err();
        assert_eq!((e.name.as_str(), e.value), ("row.mass", -1.0));
        assert!(matches!(e.source, FamilySource::File(_)));
        assert!(
            e.to_string().starts_with("m.toml with row.mass = -1:1:"),
            "{e}"
        );
        let mut built = of("clearance", |c| crate::model::reference::r2(2, c, 7.0));
        assert!(built.model_at(2e-3).is_ok());
        let e = built.model_at(-1.0).unwrap_err();
        assert!(matches!(e.source, FamilySource::Model(_)));
        assert!(e.to_string().starts_with("clearance = -1: "), "{e}");
        let mut two = ParameterizedModel2::new(doc, "frequency", "amplitude").unwrap();
        assert_eq!(two.names(), ["frequency", "amplitude"]);
        let m = two.model_at(6.5, 0.1).unwrap();
        assert_eq!(m.forcing_frequency(), Some(6.5));
        assert_eq!(m.base().peak(), 0.1);
    }
}
