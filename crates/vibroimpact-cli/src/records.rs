//! Recorded ground motions as the commands read and report them
//! (`spectrum`, `pounding`; docs/earthquakes.md).

use std::path::Path;

use vibroimpact::model::record::{parse_record, Record, Units};

use crate::error::{option_error, CliError};

/// `--units` parsed (None: the records' headers say).
pub fn units(flag: Option<&str>) -> Result<Option<Units>, CliError> {
    flag.map(Units::parse)
        .transpose()
        .map_err(|e| option_error(&e))
}

/// Reads a record file: AT2, two columns or CSV; errors name the file and
/// line.
pub fn read(path: &Path, units: Option<Units>) -> Result<Record, CliError> {
    let name = path.display().to_string();
    let text = crate::input::read_text(path).map_err(|e| CliError::new(format!("{name}: {e}")))?;
    parse_record(&text, &name, units).map_err(|e| CliError::new(e.to_string()))
}

/// The row (or pair) file at `path`.
pub fn row(path: &Path) -> Result<vibroimpact::seismic::pounding::Row, CliError> {
    let source = path.display().to_string();
    let text =
        crate::input::read_text(path).map_err(|e| CliError::new(format!("{source}: {e}")))?;
    vibroimpact::seismic::pounding::parse_row(&text, &source).map_err(crate::error::pounding_error)
}
