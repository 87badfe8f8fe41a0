//! `vibroimpact.Model`: a model file's document and the model built from it.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use vibroimpact::model::file::{LoadedModel, ModelDocument};

use crate::convert::value_error;

/// A model of bodies, springs, contacts and excitation (the model-file
/// schema of `docs/model.md`). Build it with `Model.load(path)`,
/// `Model.from_toml(text)` or `Model.from_dict(d)`; change it with
/// `model.with_(frequency=..., **{"row.clearance": ...})`. Immutable and
/// picklable (any accelerogram travels inline).
#[pyclass(name = "Model", module = "vibroimpact._core", frozen)]
pub struct PyModel {
    pub(crate) document: ModelDocument,
    pub(crate) loaded: Arc<LoadedModel>,
}

impl PyModel {
    fn new(document: ModelDocument) -> PyResult<Self> {
        let loaded = Arc::new(document.build().map_err(value_error)?);
        Ok(Self { document, loaded })
    }
}

/// Python data as TOML values; `path` names the key in messages.
fn to_toml(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    let at = |what: String| {
        value_error(if path.is_empty() {
            what
        } else {
            format!("{path}: {what}")
        })
    };
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                at(format!(
                    "keys must be strings, not {}",
                    k.repr().map_or_else(|_| "?".into(), |r| r.to_string())
                ))
            })?;
            let sub = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            table.insert(key, to_toml(&v, &sub)?);
        }
        return Ok(toml::Value::Table(table));
    }
    if obj.is_instance_of::<pyo3::types::PyBool>() {
        return Ok(toml::Value::Boolean(obj.extract()?));
    }
    if let Ok(s) = obj.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    if let Ok(i) = obj.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(x) = obj.extract::<f64>() {
        if !x.is_finite() {
            return Err(at(format!("{x} is not a finite number")));
        }
        return Ok(toml::Value::Float(x));
    }
    // numpy arrays and scalars, tuples, lists: their plain Python form.
    let plain = if obj.hasattr("tolist")? {
        obj.call_method0("tolist")?
    } else {
        obj.clone()
    };
    if let Ok(items) = plain.try_iter() {
        let values = items
            .enumerate()
            .map(|(i, item)| to_toml(&item?, &format!("{path}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(values));
    }
    if !plain.is(obj) {
        return to_toml(&plain, path);
    }
    Err(at(format!(
        "{} is not a number, string, list or dict",
        obj.get_type()
            .name()
            .map_or_else(|_| "?".into(), |n| n.to_string())
    )))
}

#[pymethods]
impl PyModel {
    /// Reads a model file (TOML); an accelerogram file is read relative to
    /// it. Raises ValueError naming the file, line and key.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        if let Err(e) = std::fs::metadata(&path) {
            return Err(pyo3::exceptions::PyOSError::new_err(format!(
                "{}: cannot read: {e}",
                path.display()
            )));
        }
        // Regular files of at most MAX_INPUT_BYTES (as the CLI): a FIFO
        // would block, a device never end, a huge record exhaust memory.
        use vibroimpact::model::file::MAX_INPUT_BYTES;
        let regular = |p: &std::path::Path| match std::fs::metadata(p) {
            Ok(m) if !m.is_file() => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file (a directory, FIFO or device cannot be read as input)",
            )),
            Ok(m) if m.len() > MAX_INPUT_BYTES => Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "{} bytes, more than the input limit of {MAX_INPUT_BYTES} bytes",
                    m.len()
                ),
            )),
            _ => std::fs::read_to_string(p),
        };
        let doc = ModelDocument::read(&path, &regular).map_err(value_error)?;
        Self::new(doc)
    }

    /// A model from TOML text; `source` names it in messages.
    #[staticmethod]
    #[pyo3(signature = (text, source = "<string>"))]
    fn from_toml(text: &str, source: &str) -> PyResult<Self> {
        Self::new(ModelDocument::from_toml(text, source).map_err(value_error)?)
    }

    /// A model from a dict in the model-file schema (as `tomllib` reads a
    /// model file), e.g. `{"row": {"count": 3, ...}, "excitation": {...}}`;
    /// lists may be numpy arrays. Errors name the key.
    #[staticmethod]
    #[pyo3(signature = (document, source = "<dict>"))]
    fn from_dict(document: &Bound<'_, PyAny>, source: &str) -> PyResult<Self> {
        let table = match to_toml(document, "")? {
            toml::Value::Table(t) => t,
            _ => return Err(value_error(format!("{source}: expected a dict"))),
        };
        let text = toml::to_string(&table)
            .map_err(|e| value_error(format!("{source}: not a model document: {e}")))?;
        Self::from_toml(&text, source)
    }

    /// The model as a dict in the model-file schema (any record inline).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let table: toml::Table = toml::from_str(&self.document.to_toml()).map_err(value_error)?;
        let json = serde_json::to_value(table).map_err(value_error)?;
        crate::convert::to_python(py, &json)
    }

    /// The model with numeric keys set: `with_(frequency=6.5)`,
    /// `with_({"row.clearance": 2e-3, "body.2.mass": 0.3})`; names as in
    /// `vibroimpact sweep --parameter`. Raises ValueError naming the key.
    #[pyo3(signature = (values = None, **kwargs))]
    fn with_(
        &self,
        values: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut doc = self.document.clone();
        for d in [values, kwargs].into_iter().flatten() {
            for (k, v) in d.iter() {
                let name: String = k.extract()?;
                let value: f64 = v.extract().map_err(|_| {
                    value_error(format!(
                        "{name}: a number is needed, not {}",
                        v.repr().map_or_else(|_| "?".into(), |r| r.to_string())
                    ))
                })?;
                let p = doc.parameter(&name).map_err(value_error)?;
                doc.set(&p, value).map_err(value_error)?;
            }
        }
        Self::new(doc)
    }

    /// The model with every contact's impacts set: `impacts` "soft" or
    /// "rigid" (None: the file's), `restitution` a Newton coefficient for
    /// rigid impacts (alone: on the file's rigid contacts), as
    /// `--impacts` and `--restitution` set them. Raises ValueError naming
    /// the argument.
    #[pyo3(signature = (impacts = None, restitution = None))]
    fn with_impacts(&self, impacts: Option<&str>, restitution: Option<f64>) -> PyResult<Self> {
        let doc = self
            .document
            .clone()
            .with_impact_options(impacts, restitution)
            .map_err(|e| value_error(e.spelled(e.field, " = ")))?;
        Self::new(doc)
    }

    /// The value of a numeric key (`frequency`, `row.clearance`, …).
    fn get(&self, name: &str) -> PyResult<f64> {
        Ok(self.document.parameter(name).map_err(value_error)?.initial)
    }

    /// The model as TOML text (any accelerogram inline).
    fn to_toml(&self) -> String {
        self.document.to_toml()
    }

    /// Body names, in order along the line.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        self.loaded
            .model
            .bodies()
            .iter()
            .map(|b| b.name.clone())
            .collect()
    }

    /// Contact names (`wall|p1`, `p1|p2`, …).
    #[getter]
    fn contacts(&self) -> Vec<String> {
        let m = &self.loaded.model;
        (0..m.contacts().len()).map(|k| m.contact_name(k)).collect()
    }

    /// The forcing frequency Ω (rad/s) of a periodic excitation with one
    /// frequency, else None.
    #[getter]
    fn forcing_frequency(&self) -> Option<f64> {
        self.loaded.model.forcing_frequency()
    }

    /// Whether the row is mirror-symmetric (bodies, contacts, walls and
    /// forcing), so that symmetric orbits exist.
    #[getter]
    fn mirror_symmetric(&self) -> bool {
        self.loaded.model.is_mirror_symmetric()
    }

    /// The name of the model's source in messages.
    #[getter]
    fn source(&self) -> &str {
        self.document.source()
    }

    fn __len__(&self) -> usize {
        self.loaded.model.bodies().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model({} bodies, {} contacts, from {})",
            self.loaded.model.bodies().len(),
            self.loaded.model.contacts().len(),
            self.document.source()
        )
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.loaded.model == other.loaded.model
    }

    /// Pickling: the TOML text with any record inline, rebuilt by
    /// `Model.from_toml` (models travel to Dask workers this way).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let ctor = py.get_type::<PyModel>().getattr("from_toml")?;
        let args = (self.document.to_toml(), self.document.source().to_string());
        (ctor, args).into_pyobject(py)
    }
}
