//! Model files from disk: reads the text (and any accelerogram file, relative
//! to the model file) and hands it to the library's model-file schema
//! ([`vibroimpact::model_file`]).

use std::path::{Path, PathBuf};

use vibroimpact::model_file::{
    parse_accelerogram_csv, LoadedModel, ModelDocument, ModelFileError, RecordSamples,
};
use vibroimpact::parameter::ParameterizedModel;

use crate::error::CliError;

/// Reads and parses a model file.
pub fn read_document(path: &Path) -> Result<ModelDocument, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::new(format!("{}: cannot read: {e}", path.display())))?;
    let dir = path
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let mut load = |file: &str| -> Result<RecordSamples, ModelFileError> {
        let record = dir.join(file);
        let source = record.display().to_string();
        let text = std::fs::read_to_string(&record)
            .map_err(|e| ModelFileError(format!("{source}: cannot read the accelerogram: {e}")))?;
        parse_accelerogram_csv(&text, &source)
    };
    Ok(ModelDocument::parse(
        &text,
        &path.display().to_string(),
        &mut load,
    )?)
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
