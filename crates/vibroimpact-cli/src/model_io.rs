//! Model files from disk: reads the text (and any accelerogram file, relative
//! to the model file) and hands it to the library's model-file schema
//! ([`vibroimpact::model::file`]).

use std::path::Path;

use vibroimpact::model::file::{LoadedModel, ModelDocument};
use vibroimpact::model::parameter::ParameterizedModel;

use crate::error::CliError;
use crate::input::read_text;

/// Reads and parses a model file.
pub fn read_document(path: &Path) -> Result<ModelDocument, CliError> {
    Ok(ModelDocument::read(path, &|p| read_text(p))?)
}

/// Reads a model file and builds its model.
pub fn read_model(path: &Path) -> Result<LoadedModel, CliError> {
    Ok(read_document(path)?.build()?)
}

/// Reads a model file and makes `name` (an alias or a dotted key) its
/// parameter.
pub fn read_family(path: &Path, name: &str) -> Result<ParameterizedModel, CliError> {
    Ok(ParameterizedModel::new(read_document(path)?, name)?)
}
