//! A model file with one numeric key made a parameter: `frequency`,
//! `amplitude` (of the harmonic excitation) or any numeric key by its dotted
//! path (`row.clearance`, `row.contact.alpha`, `body.2.mass` for the second
//! `[[body]]`, `contact.1.clearance`). Each value re-reads the model from the
//! edited document, so every validation of the model file applies.

use std::path::{Path, PathBuf};

use vibroimpact::model::Model;

use crate::error::CliError;
use crate::model_file::{parse_model, LoadedModel};

/// A model with one parameter.
#[derive(Clone, Debug)]
pub struct ParameterizedModel {
    doc: toml::Table,
    path: Vec<String>,
    /// The parameter's name as given.
    pub name: String,
    source: String,
    base_dir: PathBuf,
    /// The parameter's value in the file.
    pub initial: f64,
    /// Whether the key holds an integer (values must then be whole numbers).
    integer: bool,
}

fn resolve_alias(name: &str) -> &str {
    match name {
        "frequency" => "excitation.frequency",
        "amplitude" => "excitation.amplitude",
        other => other,
    }
}

/// Walks `path` in `doc` (array entries by 1-based index) and returns the value.
fn lookup<'a>(doc: &'a mut toml::Table, path: &[String]) -> Option<&'a mut toml::Value> {
    let (first, rest) = path.split_first()?;
    let mut v = doc.get_mut(first)?;
    for key in rest {
        v = match v {
            toml::Value::Table(t) => t.get_mut(key)?,
            toml::Value::Array(a) => {
                let i: usize = key.parse().ok()?;
                a.get_mut(i.checked_sub(1)?)?
            }
            _ => return None,
        };
    }
    Some(v)
}

impl ParameterizedModel {
    /// Reads `path` and makes `name` (alias or dotted key) the parameter.
    pub fn read(path: &Path, name: &str) -> Result<Self, CliError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| CliError::new(format!("{}: cannot read: {e}", path.display())))?;
        let base_dir = path
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        Self::parse(&text, &path.display().to_string(), &base_dir, name)
    }

    /// From model text; `source` names it in messages.
    pub fn parse(text: &str, source: &str, base_dir: &Path, name: &str) -> Result<Self, CliError> {
        // Validate the file itself first (errors with lines).
        parse_model(text, source, base_dir)?;
        let mut doc: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| CliError::new(format!("{source}: {}", e.message())))?;
        let key = resolve_alias(name);
        let path: Vec<String> = key.split('.').map(str::to_string).collect();
        let value = lookup(&mut doc, &path).ok_or_else(|| {
            CliError::new(format!(
                "{source}: parameter `{name}` does not exist in the model (give frequency, amplitude, or a dotted key such as row.clearance or body.1.mass)"
            ))
        })?;
        let (initial, integer) = match value {
            toml::Value::Float(x) => (*x, false),
            toml::Value::Integer(i) => (*i as f64, true),
            other => {
                return Err(CliError::new(format!(
                    "{source}: parameter `{name}` is not a number (it is {})",
                    other.type_str()
                )))
            }
        };
        Ok(Self {
            doc,
            path,
            name: name.to_string(),
            source: source.to_string(),
            base_dir: base_dir.to_path_buf(),
            initial,
            integer,
        })
    }

    /// The model with the parameter set to `value`.
    pub fn model_at(&self, value: f64) -> Result<Model, CliError> {
        Ok(self.loaded_at(value)?.model)
    }

    /// The model and its file settings with the parameter set to `value`.
    pub fn loaded_at(&self, value: f64) -> Result<LoadedModel, CliError> {
        let mut doc = self.doc.clone();
        let slot =
            lookup(&mut doc, &self.path).ok_or_else(|| CliError::new("parameter vanished"))?;
        *slot = if self.integer {
            if value.fract() != 0.0 || !value.is_finite() {
                return Err(CliError::new(format!(
                    "{}: parameter `{}` takes whole numbers, not {value}",
                    self.source, self.name
                )));
            }
            toml::Value::Integer(value as i64)
        } else {
            toml::Value::Float(value)
        };
        let text =
            toml::to_string(&doc).map_err(|e| CliError::new(format!("{}: {e}", self.source)))?;
        parse_model(
            &text,
            &format!("{} with {} = {value}", self.source, self.name),
            &self.base_dir,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROW: &str = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.05\nfrequency = 7.0\n";

    #[test]
    fn aliases_dotted_keys_and_errors() {
        let p = ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "frequency").unwrap();
        assert_eq!(p.initial, 7.0);
        assert_eq!(p.model_at(6.5).unwrap().forcing_frequency(), Some(6.5));
        let p = ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "row.clearance").unwrap();
        assert_eq!(p.model_at(2e-3).unwrap().contacts()[0].clearance, 2e-3);
        let p = ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "row.count").unwrap();
        assert_eq!(p.model_at(5.0).unwrap().bodies().len(), 5);
        assert!(p.model_at(2.5).is_err());
        let e = ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "row.colour").unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let e = ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "excitation.type")
            .unwrap_err();
        assert!(e.to_string().contains("not a number"), "{e}");
        let p = ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "row.mass").unwrap();
        assert!(
            p.model_at(-1.0).is_err(),
            "values are validated like the file"
        );
    }
}
