//! Model files from disk: reads the text (and any accelerogram file, relative
//! to the model file) and hands it to the library's model-file schema
//! ([`vibroimpact::model::file`]).

use std::path::Path;

use vibroimpact::model::file::ModelDocument;

use crate::error::CliError;
use crate::input::read_text;

/// Reads and parses a model file.
pub fn read_document(path: &Path) -> Result<ModelDocument, CliError> {
    Ok(ModelDocument::read(path, &|p| read_text(p))?)
}
