//! Reading measured data files (CSV, see [`vibroimpact::identify::measured`]).

use std::path::Path;

pub use vibroimpact::identify::measured::{parse_csv, Table};

use crate::error::CliError;

/// Reads the named columns from a CSV file.
pub fn read_csv(path: &Path, wanted: &[&str]) -> Result<Table, CliError> {
    let text = crate::input::read_text(path)
        .map_err(|e| CliError::new(format!("{}: cannot read: {e}", path.display())))?;
    Ok(parse_csv(&text, &path.display().to_string(), wanted)?)
}
