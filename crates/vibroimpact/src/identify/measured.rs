//! Measured data as CSV text: a header row naming the columns, `#`
//! comment lines allowed. Every error names the source, the line and what
//! is wrong. (The faces read the files; this parses their text.)

/// A measured table that cannot be read: the message names the source
/// and the line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct TableError(pub String);

#[derive(Debug)]
/// A numeric table read from a CSV file: the requested columns, with the
/// 1-based file line of every row (for error messages).
pub struct Table {
    /// One vector per requested column, in the requested order.
    pub columns: Vec<Vec<f64>>,
    /// File line number of each row.
    pub lines: Vec<usize>,
}

/// 1-based line numbers of byte offsets in `text`, for offsets that come in
/// increasing order (the records of a CSV reader): each call counts only
/// the newlines since the previous one, so a file costs one pass.
struct LineCounter<'a> {
    bytes: &'a [u8],
    at: usize,
    line: usize,
}

impl<'a> LineCounter<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            bytes: text.as_bytes(),
            at: 0,
            line: 1,
        }
    }

    /// Line of the first non-blank byte at or after `byte` (a record's
    /// position may point at the blank lines before it).
    fn line_of(&mut self, byte: usize) -> usize {
        let bytes = self.bytes;
        let mut at = byte.min(bytes.len());
        while at < bytes.len() && (bytes[at] == b'\n' || bytes[at] == b'\r') {
            at += 1;
        }
        if at < self.at {
            // Out of order (not from the reader): count from the start.
            self.at = 0;
            self.line = 1;
        }
        self.line += bytes[self.at..at].iter().filter(|&&b| b == b'\n').count();
        self.at = at;
        self.line
    }
}

/// Reads the named columns (other columns are ignored) from CSV text.
/// `source` names the file in messages.
pub fn parse_csv(text: &str, source: &str, wanted: &[&str]) -> Result<Table, TableError> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header_line = text
        .lines()
        .position(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map_or(1, |i| i + 1);
    let headers = reader
        .headers()
        .map_err(|e| TableError(format!("{source}: cannot read the header: {e}")))?
        .clone();
    let mut index = Vec::with_capacity(wanted.len());
    for name in wanted {
        match headers.iter().position(|h| h == *name) {
            Some(i) => index.push(i),
            None => {
                return Err(TableError(format!(
                    "{source}:{header_line}: wrong header: expected a column named `{name}` (columns needed: {}), found: {}",
                    wanted.join(", "),
                    headers.iter().collect::<Vec<_>>().join(", ")
                )))
            }
        }
    }
    let mut table = Table {
        columns: vec![Vec::new(); wanted.len()],
        lines: Vec::new(),
    };
    let mut lines = LineCounter::new(text);
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| lines.line_of(p.byte() as usize));
            TableError(format!("{source}:{line}: malformed CSV row: {e}"))
        })?;
        // Line from the byte offset (the csv crate's own line count skips blank lines).
        let line = record
            .position()
            .map_or(0, |p| lines.line_of(p.byte() as usize));
        for (k, &i) in index.iter().enumerate() {
            let cell = record.get(i).unwrap_or("");
            let value: f64 = cell.parse().map_err(|_| {
                TableError(format!(
                    "{source}:{line}: column `{}`: `{cell}` is not a number",
                    wanted[k]
                ))
            })?;
            if !value.is_finite() {
                return Err(TableError(format!(
                    "{source}:{line}: column `{}`: {cell} is not a finite number",
                    wanted[k]
                )));
            }
            table.columns[k].push(value);
        }
        table.lines.push(line);
    }
    if table.lines.is_empty() {
        return Err(TableError(format!("{source}: no data rows")));
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_named_columns_with_comments() {
        let t = parse_csv(
            "# made by hand\nrestitution,impact_velocity\n0.9, 0.1\n\n0.8,0.2\n",
            "r.csv",
            &["impact_velocity", "restitution"],
        )
        .unwrap();
        assert_eq!(t.columns, vec![vec![0.1, 0.2], vec![0.9, 0.8]]);
        assert_eq!(t.lines, vec![3, 5]);
    }

    #[test]
    fn errors_name_file_and_line() {
        let e = parse_csv("u,e\n1,2\n", "r.csv", &["impact_velocity"]).unwrap_err();
        assert!(e.to_string().starts_with("r.csv:1: wrong header"), "{e}");
        let e = parse_csv(
            "# c\nimpact_velocity\n0.1\nabc\n",
            "r.csv",
            &["impact_velocity"],
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "r.csv:4: column `impact_velocity`: `abc` is not a number"
        );
        let e = parse_csv("impact_velocity\n", "r.csv", &["impact_velocity"]).unwrap_err();
        assert_eq!(e.to_string(), "r.csv: no data rows");
        let e = parse_csv("a,b\n1,2\n3\n", "r.csv", &["a"]).unwrap_err();
        assert!(
            e.to_string().starts_with("r.csv:3: malformed CSV row"),
            "{e}"
        );
    }
}
