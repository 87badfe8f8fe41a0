//! Printing tables of numbers as aligned text or CSV.

use clap::ValueEnum;
use std::io::Write;

use vibroimpact::model::Model;

use crate::error::CliError;

/// Output format of the commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Aligned columns for reading.
    Table,
    /// Comma-separated values with a header row.
    Csv,
    /// A JSON document.
    Json,
}

/// Output format of the commands that print a summary rather than a table
/// (`simulate`, `periodic`, `identify`): no `csv` (their tables are the
/// CSV files of `--out`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SummaryFormat {
    /// Text for reading.
    Table,
    /// A JSON document.
    Json,
}

/// Formats a number for tables: full precision (shortest round-trip form).
pub fn number(x: Option<f64>) -> String {
    match x {
        Some(v) => format!("{v:e}"),
        None => String::new(),
    }
}

/// CSV written into memory (quoting cells where needed).
pub struct CsvText(csv::Writer<Vec<u8>>);

impl CsvText {
    /// An empty CSV text.
    pub fn new() -> Self {
        Self(csv::Writer::from_writer(Vec::new()))
    }

    /// Appends one record.
    pub fn row<I, T>(&mut self, record: I) -> Result<(), CliError>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        Ok(self.0.write_record(record)?)
    }

    /// The text.
    pub fn finish(self) -> Result<String, CliError> {
        let bytes = self
            .0
            .into_inner()
            .map_err(|e| CliError::new(format!("cannot format CSV: {}", e.error())))?;
        Ok(String::from_utf8(bytes)?)
    }
}

/// CSV text of a numeric table (empty cells for missing values).
pub fn csv_text(columns: &[&str], rows: &[Vec<Option<f64>>]) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row(columns)?;
    for row in rows {
        w.row(row.iter().map(|x| number(*x)))?;
    }
    w.finish()
}

/// Prints a table to standard output as aligned text or CSV.
pub fn print_rows(
    format: Format,
    columns: &[&str],
    rows: &[Vec<Option<f64>>],
) -> Result<(), CliError> {
    let text = match format {
        Format::Csv | Format::Json => csv_text(columns, rows)?,
        Format::Table => {
            let cells: Vec<Vec<String>> = rows
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|x| x.map_or("-".to_string(), |v| format!("{v:.6e}")))
                        .collect()
                })
                .collect();
            let widths: Vec<usize> = (0..columns.len())
                .map(|c| {
                    cells
                        .iter()
                        .map(|r| r[c].len())
                        .chain([columns[c].len()])
                        .max()
                        .unwrap_or(0)
                })
                .collect();
            let mut out = String::new();
            let line = |items: Vec<&str>, out: &mut String| {
                let parts: Vec<String> = items
                    .iter()
                    .zip(&widths)
                    .map(|(s, w)| format!("{s:>w$}"))
                    .collect();
                out.push_str(parts.join("  ").trim_end());
                out.push('\n');
            };
            line(columns.to_vec(), &mut out);
            for r in &cells {
                line(r.iter().map(String::as_str).collect(), &mut out);
            }
            out
        }
    };
    std::io::stdout()
        .write_all(text.as_bytes())
        .map_err(|e| CliError::new(format!("cannot write to standard output: {e}")))
}

/// The columns of a time history: `t, u_<body>…, v_<body>…`.
pub fn history_header(model: &Model) -> Vec<String> {
    let mut columns: Vec<String> = vec!["t".into()];
    columns.extend(model.bodies().iter().map(|b| format!("u_{}", b.name)));
    columns.extend(model.bodies().iter().map(|b| format!("v_{}", b.name)));
    columns
}

/// CSV of sampled states: `t, u_<body>…, v_<body>…` (rows of `states` are
/// `[u.., v..]` at `times`).
pub fn history_csv(model: &Model, times: &[f64], states: &[f64]) -> Result<String, CliError> {
    let n = model.bodies().len();
    let columns = history_header(model);
    let rows: Vec<Vec<Option<f64>>> = times
        .iter()
        .enumerate()
        .map(|(j, &t)| {
            std::iter::once(Some(t))
                .chain(states[j * 2 * n..(j + 1) * 2 * n].iter().map(|&x| Some(x)))
                .collect()
        })
        .collect();
    let cols: Vec<&str> = columns.iter().map(String::as_str).collect();
    csv_text(&cols, &rows)
}
