//! A numeric key of a model file made a parameter: `frequency`, `amplitude`
//! (of the harmonic excitation) or any numeric key by its dotted path
//! (`row.clearance`, `row.contact.alpha`, `body.2.mass` for the second
//! `[[body]]`, `contact.1.law.stiffness`, `initial.velocity.3`).
//!
//! The name is resolved once into a [`ParameterKey`] (which table, which
//! field); a value is then written straight into the parsed document and the
//! model rebuilt from it, so every validation of the model file applies to
//! every value and nothing is re-read or re-serialised.

use crate::model::file::{
    ExcitationSpec, InitialValues, LawSpec, LoadedModel, ModelDocument, ModelFile, ModelFileError,
};
use crate::model::{BaseExcitation, Model};

/// The table a parameter lives in (indices of array tables are 0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParameterTable {
    /// `[excitation]`.
    Excitation,
    /// `[row]`.
    Row,
    /// `[row] contact = { … }`.
    RowContact,
    /// `[row] coupling = { … }`.
    RowCoupling,
    /// The i-th `[[body]]`.
    Body(usize),
    /// The i-th `[[spring]]`.
    Spring(usize),
    /// The i-th `[[contact]]`.
    Contact(usize),
    /// The law of the i-th `[[contact]]`.
    ContactLaw(usize),
    /// The i-th `[[force]]`.
    Force(usize),
    /// Entry i of `[initial] displacement`.
    InitialDisplacement(usize),
    /// Entry i of `[initial] velocity`.
    InitialVelocity(usize),
    /// `[simulation]`.
    Simulation,
}

/// A resolved parameter: table and field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParameterKey {
    /// Where.
    pub table: ParameterTable,
    /// The field's name (empty for the entries of `[initial]` arrays).
    pub field: &'static str,
}

/// The numeric fields of the schema.
const NUMERIC: [&str; 24] = [
    "frequency",
    "amplitude",
    "phase",
    "scale",
    "count",
    "mass",
    "stiffness",
    "natural_frequency",
    "damping",
    "damping_ratio",
    "clearance",
    "a_over_b",
    "b",
    "alpha",
    "a",
    "exponent",
    "chi",
    "restitution",
    "min_impact_velocity",
    "initial_displacement",
    "initial_velocity",
    "rtol",
    "atol",
    "impact_force_threshold",
];

/// Keys of the schema that hold text, not numbers.
const TEXT: [&str; 7] = ["type", "law", "form", "name", "walls", "file", "body"];

/// Where a value goes.
enum Slot<'a> {
    Real(&'a mut f64),
    Optional(&'a mut Option<f64>),
    Count(&'a mut usize),
}

fn opt(x: &mut Option<f64>) -> Option<Slot<'_>> {
    x.is_some().then_some(Slot::Optional(x))
}

fn law_slot<'a>(law: &'a mut LawSpec, field: &str) -> Option<Slot<'a>> {
    match (law, field) {
        (LawSpec::Exponential { a_over_b: x, .. }, "a_over_b")
        | (LawSpec::Exponential { b: x, .. }, "b")
        | (LawSpec::Exponential { a: x, .. }, "a")
        | (LawSpec::Hertz { exponent: x, .. }, "exponent")
        | (LawSpec::HuntCrossley { exponent: x, .. }, "exponent")
        | (LawSpec::LankaraniNikravesh { exponent: x, .. }, "exponent")
        | (
            LawSpec::LankaraniNikravesh {
                min_impact_velocity: x,
                ..
            },
            "min_impact_velocity",
        ) => opt(x),
        (LawSpec::Exponential { alpha: x, .. }, "alpha")
        | (LawSpec::Hertz { stiffness: x, .. }, "stiffness")
        | (LawSpec::KelvinVoigt { stiffness: x, .. }, "stiffness")
        | (LawSpec::KelvinVoigt { damping: x, .. }, "damping")
        | (LawSpec::HuntCrossley { stiffness: x, .. }, "stiffness")
        | (LawSpec::HuntCrossley { chi: x, .. }, "chi")
        | (LawSpec::LankaraniNikravesh { stiffness: x, .. }, "stiffness")
        | (LawSpec::LankaraniNikravesh { restitution: x, .. }, "restitution") => {
            Some(Slot::Real(x))
        }
        _ => None,
    }
}

fn slot<'a>(file: &'a mut ModelFile, key: &ParameterKey) -> Option<Slot<'a>> {
    use ParameterTable as T;
    let f = key.field;
    match key.table {
        T::Excitation => match (file.excitation.as_mut()?.get_mut(), f) {
            (ExcitationSpec::HarmonicBase { amplitude: x, .. }, "amplitude")
            | (ExcitationSpec::HarmonicBase { frequency: x, .. }, "frequency") => {
                Some(Slot::Real(x))
            }
            (ExcitationSpec::HarmonicBase { phase: x, .. }, "phase")
            | (ExcitationSpec::Accelerogram { scale: x, .. }, "scale") => opt(x),
            _ => None,
        },
        T::Row => {
            let r = file.row.as_mut()?.get_mut();
            match f {
                "count" => Some(Slot::Count(&mut r.count)),
                "mass" => Some(Slot::Real(&mut r.mass)),
                "clearance" => Some(Slot::Real(&mut r.clearance)),
                "stiffness" => opt(&mut r.stiffness),
                "natural_frequency" => opt(&mut r.natural_frequency),
                "damping" => opt(&mut r.damping),
                "damping_ratio" => opt(&mut r.damping_ratio),
                _ => None,
            }
        }
        T::RowContact => law_slot(&mut file.row.as_mut()?.get_mut().contact, f),
        T::RowCoupling => {
            let c = file.row.as_mut()?.get_mut().coupling.as_mut()?;
            match f {
                "stiffness" => opt(&mut c.stiffness),
                "damping" => opt(&mut c.damping),
                _ => None,
            }
        }
        T::Body(i) => {
            let b = file.body.get_mut(i)?.get_mut();
            match f {
                "mass" => Some(Slot::Real(&mut b.mass)),
                "stiffness" => opt(&mut b.stiffness),
                "natural_frequency" => opt(&mut b.natural_frequency),
                "damping" => opt(&mut b.damping),
                "damping_ratio" => opt(&mut b.damping_ratio),
                "initial_displacement" => opt(&mut b.initial_displacement),
                "initial_velocity" => opt(&mut b.initial_velocity),
                _ => None,
            }
        }
        T::Spring(i) => {
            let s = file.spring.get_mut(i)?.get_mut();
            match f {
                "stiffness" => opt(&mut s.stiffness),
                "damping" => opt(&mut s.damping),
                _ => None,
            }
        }
        T::Contact(i) => {
            let c = file.contact.get_mut(i)?.get_mut();
            (f == "clearance").then_some(Slot::Real(&mut c.clearance))
        }
        T::ContactLaw(i) => law_slot(&mut file.contact.get_mut(i)?.get_mut().law, f),
        T::Force(i) => {
            let c = file.force.get_mut(i)?.get_mut();
            match f {
                "amplitude" => Some(Slot::Real(&mut c.amplitude)),
                "frequency" => Some(Slot::Real(&mut c.frequency)),
                "phase" => opt(&mut c.phase),
                _ => None,
            }
        }
        T::InitialDisplacement(i) => {
            match file.initial.as_mut()?.get_mut().displacement.as_mut()? {
                InitialValues::List(v) => v.get_mut(i).map(Slot::Real),
                InitialValues::Named(_) => None,
            }
        }
        T::InitialVelocity(i) => match file.initial.as_mut()?.get_mut().velocity.as_mut()? {
            InitialValues::List(v) => v.get_mut(i).map(Slot::Real),
            InitialValues::Named(_) => None,
        },
        T::Simulation => {
            let s = file.simulation.as_mut()?;
            match f {
                "rtol" => opt(&mut s.rtol),
                "atol" => opt(&mut s.atol),
                "impact_force_threshold" => opt(&mut s.impact_force_threshold),
                _ => None,
            }
        }
    }
}

/// Why a name is not a parameter (None: it does not exist).
enum Unresolved {
    Missing,
    Text,
}

fn resolve(name: &str) -> Result<ParameterKey, Unresolved> {
    use ParameterTable as T;
    let parts: Vec<&str> = match name {
        "frequency" => vec!["excitation", "frequency"],
        "amplitude" => vec!["excitation", "amplitude"],
        other => other.split('.').collect(),
    };
    let index = |s: &str| -> Result<usize, Unresolved> {
        match s.parse::<usize>() {
            Ok(i) if i >= 1 => Ok(i - 1),
            _ => Err(Unresolved::Missing),
        }
    };
    let (table, field) = match parts.as_slice() {
        ["initial", "displacement", i] => (T::InitialDisplacement(index(i)?), ""),
        ["initial", "velocity", i] => (T::InitialVelocity(index(i)?), ""),
        ["excitation", f] => (T::Excitation, *f),
        ["row", "contact", f] => (T::RowContact, *f),
        ["row", "coupling", f] => (T::RowCoupling, *f),
        ["row", f] => (T::Row, *f),
        ["body", i, f] => (T::Body(index(i)?), *f),
        ["spring", i, f] => (T::Spring(index(i)?), *f),
        ["contact", i, "law", f] => (T::ContactLaw(index(i)?), *f),
        ["contact", i, f] => (T::Contact(index(i)?), *f),
        ["force", i, f] => (T::Force(index(i)?), *f),
        ["simulation", f] => (T::Simulation, *f),
        [.., last] if TEXT.contains(last) => return Err(Unresolved::Text),
        _ => return Err(Unresolved::Missing),
    };
    if field.is_empty() {
        return Ok(ParameterKey { table, field: "" });
    }
    match NUMERIC.iter().find(|&&f| f == field) {
        Some(&f) => Ok(ParameterKey { table, field: f }),
        None if TEXT.contains(&field) => Err(Unresolved::Text),
        None => Err(Unresolved::Missing),
    }
}

/// A named numeric key of a document.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelParameter {
    /// The name as given (`frequency`, `row.clearance`, …).
    pub name: String,
    /// Where it lives.
    pub key: ParameterKey,
    /// Its value in the document.
    pub initial: f64,
    /// Whether it takes whole numbers only (`row.count`).
    pub integer: bool,
}

impl ModelDocument {
    /// Resolves `name` (an alias or a dotted key) in this document.
    pub fn parameter(&self, name: &str) -> Result<ModelParameter, ModelFileError> {
        let source = self.source();
        let missing = || {
            ModelFileError(format!(
                "{source}: parameter `{name}` does not exist in the model (give frequency, amplitude, or a dotted key such as row.clearance or body.1.mass)"
            ))
        };
        let key = match resolve(name) {
            Ok(k) => k,
            Err(Unresolved::Missing) => return Err(missing()),
            Err(Unresolved::Text) => {
                return Err(ModelFileError(format!(
                    "{source}: parameter `{name}` is not a number (it is string)"
                )))
            }
        };
        let mut file = self.file.clone();
        let (initial, integer) = match slot(&mut file, &key).ok_or_else(missing)? {
            Slot::Real(x) => (*x, false),
            Slot::Optional(x) => (x.unwrap_or(f64::NAN), false),
            Slot::Count(c) => (*c as f64, true),
        };
        Ok(ModelParameter {
            name: name.to_string(),
            key,
            initial,
            integer,
        })
    }

    /// Writes `value` into the document (the model is not rebuilt: see
    /// [`ModelDocument::build`]).
    pub fn set(&mut self, p: &ModelParameter, value: f64) -> Result<(), ModelFileError> {
        let source = self.source().to_string();
        let whole = |v: f64| -> Result<usize, ModelFileError> {
            if v.fract() == 0.0 && v.is_finite() && v >= 0.0 {
                Ok(v as usize)
            } else {
                Err(ModelFileError(format!(
                    "{source}: parameter `{}` takes whole numbers, not {v}",
                    p.name
                )))
            }
        };
        match slot(&mut self.file, &p.key) {
            Some(Slot::Real(x)) => *x = value,
            Some(Slot::Optional(x)) => *x = Some(value),
            Some(Slot::Count(c)) => *c = whole(value)?,
            None => {
                return Err(ModelFileError(format!(
                    "{source}: parameter `{}` does not exist in the model",
                    p.name
                )))
            }
        }
        Ok(())
    }

    /// The model and its settings with `p` set to `value`; messages name the
    /// document "SOURCE with NAME = VALUE".
    pub fn with_parameter(
        &self,
        p: &ModelParameter,
        value: f64,
    ) -> Result<LoadedModel, ModelFileError> {
        let mut doc = self.clone();
        doc.set(p, value)?;
        doc.build_labelled(&format!("{} with {} = {value}", self.source(), p.name))
    }
}

/// A document with one of its keys made the parameter of a family of models.
#[derive(Clone, Debug)]
pub struct ParameterizedModel {
    document: ModelDocument,
    parameter: ModelParameter,
    /// For the frequency or amplitude of a harmonic base excitation, the
    /// document's own model: a value replaces its excitation alone
    /// ([`Model::reforced`]), without building the document again (a
    /// branch builds two models per period map; R2 N = 2 rigid: 8 % of
    /// the branch).
    reforced: Option<Model>,
}

impl ParameterizedModel {
    /// `name` (an alias or a dotted key) of `document` made the parameter.
    pub fn new(document: ModelDocument, name: &str) -> Result<Self, ModelFileError> {
        let parameter = document.parameter(name)?;
        let excitation = parameter.key.table == ParameterTable::Excitation
            && matches!(parameter.key.field, "frequency" | "amplitude");
        let reforced = excitation
            .then(|| document.build().ok())
            .flatten()
            .map(|loaded| loaded.model)
            .filter(|model| matches!(model.base(), BaseExcitation::Harmonic { .. }));
        Ok(Self {
            document,
            parameter,
            reforced,
        })
    }

    /// The document.
    pub fn document(&self) -> &ModelDocument {
        &self.document
    }

    /// The parameter.
    pub fn parameter(&self) -> &ModelParameter {
        &self.parameter
    }

    /// `document` as a family in its forcing amplitude, with its own
    /// amplitude (the homotopy start's family and the value to reach).
    ///
    /// Rigid impacts are taken soft (docs/theory.md §12): the rigid period
    /// map is not smooth where the growing orbit first grazes, the soft
    /// one is, and the soft orbit at the target starts Newton on the
    /// rigid one.
    pub fn in_amplitude(document: ModelDocument) -> Result<(Self, f64), ModelFileError> {
        let rigid = document
            .build()
            .is_ok_and(|loaded| loaded.model.has_rigid_impacts());
        let document = if rigid {
            document
                .with_impact_options(Some("soft"), None)
                .map_err(|e| ModelFileError(e.to_string()))?
        } else {
            document
        };
        let family = Self::new(document, "amplitude")?;
        let target = family.initial();
        Ok((family, target))
    }

    /// The parameter's name as given.
    pub fn name(&self) -> &str {
        &self.parameter.name
    }

    /// The parameter's value in the document.
    pub fn initial(&self) -> f64 {
        self.parameter.initial
    }

    /// The model with the parameter set to `value`.
    pub fn model_at(&self, value: f64) -> Result<Model, ModelFileError> {
        if let Some(model) = self.reforced_at(value) {
            return Ok(model);
        }
        Ok(self.loaded_at(value)?.model)
    }

    /// The model at `value` by replacing the excitation of the document's
    /// own; None where the parameter is not the excitation's, or the value
    /// is refused (the document's build then names the file and key).
    fn reforced_at(&self, value: f64) -> Option<Model> {
        let model = self.reforced.as_ref()?;
        let BaseExcitation::Harmonic {
            amplitude,
            frequency,
            phase,
        } = *model.base()
        else {
            return None;
        };
        let base = match self.parameter.key.field {
            "frequency" => BaseExcitation::Harmonic {
                amplitude,
                frequency: value,
                phase,
            },
            _ => BaseExcitation::Harmonic {
                amplitude: value,
                frequency,
                phase,
            },
        };
        model.reforced(base).ok()
    }

    /// The model and its settings with the parameter set to `value`.
    pub fn loaded_at(&self, value: f64) -> Result<LoadedModel, ModelFileError> {
        self.document.with_parameter(&self.parameter, value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROW: &str = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.05\nfrequency = 7.0\n";

    fn family(name: &str) -> Result<ParameterizedModel, ModelFileError> {
        ParameterizedModel::new(ModelDocument::from_toml(ROW, "m.toml").unwrap(), name)
    }

    #[test]
    fn aliases_dotted_keys_and_errors() {
        let p = family("frequency").unwrap();
        assert_eq!(p.initial(), 7.0);
        assert_eq!(p.model_at(6.5).unwrap().forcing_frequency(), Some(6.5));
        let p = family("row.clearance").unwrap();
        assert_eq!(p.model_at(2e-3).unwrap().contacts()[0].clearance, 2e-3);
        let p = family("row.contact.alpha").unwrap();
        assert_eq!(p.initial(), 1.3e5);
        let p = family("row.count").unwrap();
        assert_eq!(p.model_at(5.0).unwrap().bodies().len(), 5);
        assert!(p.model_at(2.5).is_err());
        let e = family("row.colour").unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let e = family("row.stiffness").unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let e = family("body.0.mass").unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let e = family("excitation.type").unwrap_err();
        assert!(e.to_string().contains("not a number"), "{e}");
        let p = family("row.mass").unwrap();
        let e = p.model_at(-1.0).unwrap_err().to_string();
        assert!(
            e.starts_with("m.toml with row.mass = -1:1: [row] mass = -1"),
            "values are validated like the file: {e}"
        );
    }

    /// A value set through the typed key gives the same model as the edited
    /// text.
    #[test]
    fn setting_equals_editing_the_text() {
        for (name, value, edited) in [
            (
                "frequency",
                6.25,
                ROW.replace("frequency = 7.0", "frequency = 6.25"),
            ),
            (
                "row.contact.a_over_b",
                0.9,
                ROW.replace("a_over_b = 1.2", "a_over_b = 0.9"),
            ),
            (
                "row.damping_ratio",
                0.02,
                ROW.replace("damping_ratio = 0.013", "damping_ratio = 0.02"),
            ),
        ] {
            let a = family(name).unwrap().model_at(value).unwrap();
            let b = ModelDocument::from_toml(&edited, "e.toml")
                .unwrap()
                .build()
                .unwrap()
                .model;
            assert_eq!(a, b, "{name}");
        }
    }

    /// The excitation's frequency or amplitude replaces the excitation of
    /// the document's own model: the same model as the document built at
    /// that value, soft or rigid; a refused value gets the file's message.
    #[test]
    fn the_excitations_parameters_equal_the_documents_build() {
        let rigid = ROW.replace("alpha = 1.3e5 }", "alpha = 1.3e5 }\nimpacts = \"rigid\"");
        for text in [ROW.to_string(), rigid] {
            let doc = ModelDocument::from_toml(&text, "m.toml").unwrap();
            for (name, values) in [("frequency", [6.25, 9.5]), ("amplitude", [0.0, -0.2])] {
                let p = ParameterizedModel::new(doc.clone(), name).unwrap();
                assert!(p.reforced.is_some(), "{name}");
                for v in values {
                    let built = p.loaded_at(v).unwrap().model;
                    assert_eq!(p.model_at(v).unwrap(), built, "{name} = {v}");
                }
            }
            let p = ParameterizedModel::new(doc.clone(), "frequency").unwrap();
            for bad in [0.0, -1.0, f64::NAN] {
                let e = p.model_at(bad).unwrap_err().to_string();
                assert_eq!(e, p.loaded_at(bad).unwrap_err().to_string());
                assert!(e.starts_with("m.toml with frequency = "), "{e}");
            }
        }
        // Not the excitation's, or no harmonic base: the document's build.
        assert!(family("row.mass").unwrap().reforced.is_none());
        let none = ROW.replace("type = \"harmonic-base\"", "type = \"none\"");
        let doc = ModelDocument::from_toml(&none, "n.toml").unwrap();
        assert!(ParameterizedModel::new(doc, "frequency").map_or(true, |p| p.reforced.is_none()));
    }

    #[test]
    fn explicit_form_keys() {
        let text = "[[body]]\nname = \"a\"\nmass = 1.0\nstiffness = 100.0\n[[body]]\nname = \"b\"\nmass = 2.0\nstiffness = 50.0\n[[contact]]\nbetween = [\"a\", \"b\"]\nclearance = 0.001\nlaw = { law = \"hertz\", stiffness = 1e9 }\n[[force]]\nbody = \"b\"\namplitude = 1.0\nfrequency = 3.0\n";
        let doc = ModelDocument::from_toml(text, "x.toml").unwrap();
        let p = ParameterizedModel::new(doc.clone(), "body.2.mass").unwrap();
        assert_eq!(p.model_at(3.0).unwrap().bodies()[1].mass, 3.0);
        let p = ParameterizedModel::new(doc.clone(), "contact.1.law.stiffness").unwrap();
        assert_eq!(p.initial(), 1e9);
        let p = ParameterizedModel::new(doc.clone(), "contact.1.clearance").unwrap();
        assert_eq!(p.model_at(2e-3).unwrap().contacts()[0].clearance, 2e-3);
        let p = ParameterizedModel::new(doc, "force.1.frequency").unwrap();
        assert_eq!(p.model_at(4.0).unwrap().forcing_frequency(), Some(4.0));
    }
}
