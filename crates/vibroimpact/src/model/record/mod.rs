//! Recorded ground motions (docs/earthquakes.md): PEER NGA `.AT2` files,
//! two-column text (time, acceleration) with its header lines skipped, and
//! CSV, in g, m/s² or cm/s² (gal). A record keeps its source, header, units
//! and time step, and is applied as the piecewise-linear function of its
//! samples (no resampling). The library parses text; the callers read the
//! files.
//!
//! Files: `mod.rs` (reading records), `tests.rs` (AT2, columns, units and
//! bad input).

use std::fmt;

use serde::Serialize;

use crate::field_error::FieldError;

/// Standard gravity (m/s²) for records in g.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Why a record cannot be read: its file (the source it was read from),
/// the line to blame where there is one, and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordError {
    /// The record's source (a file name).
    pub file: String,
    /// The line (1-based), where one line is to blame.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl RecordError {
    /// An error at `line` of `file`.
    pub fn at(file: &str, line: usize, message: impl Into<String>) -> Self {
        Self {
            file: file.to_string(),
            line: Some(line),
            message: message.into(),
        }
    }

    /// An error of `file` as a whole.
    pub fn whole(file: &str, message: impl Into<String>) -> Self {
        Self {
            file: file.to_string(),
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for RecordError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for RecordError {}

/// The units of a record's accelerations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// Multiples of standard gravity.
    G,
    /// m/s².
    MetersPerSecond2,
    /// cm/s² (gal).
    Gal,
}

impl Units {
    /// Parses `g`, `m/s2` (`m/s^2`, `m/s²`) or `gal` (`cm/s2`).
    pub fn parse(text: &str) -> Result<Units, FieldError> {
        match text.trim().to_ascii_lowercase().as_str() {
            "g" => Ok(Units::G),
            "m/s2" | "m/s^2" | "m/s²" | "mps2" => Ok(Units::MetersPerSecond2),
            "gal" | "cm/s2" | "cm/s^2" | "cm/s²" => Ok(Units::Gal),
            other => Err(FieldError::new(
                "units",
                other,
                "give g, m/s2 or gal (cm/s2)",
            )),
        }
    }

    /// The name used in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Units::G => "g",
            Units::MetersPerSecond2 => "m/s2",
            Units::Gal => "gal",
        }
    }

    /// One unit in m/s².
    pub fn to_si(self) -> f64 {
        match self {
            Units::G => STANDARD_GRAVITY,
            Units::MetersPerSecond2 => 1.0,
            Units::Gal => 0.01,
        }
    }
}

/// A record's metadata as results carry it (docs/earthquakes.md).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RecordMetadata {
    /// Where it came from (a file name).
    pub source: String,
    /// The header lines as in the file.
    pub header: Vec<String>,
    /// The units of the file's values (`g`, `m/s2`, `gal`).
    pub units: &'static str,
    /// The time step if uniform (s).
    pub dt: Option<f64>,
    /// The sample count.
    pub samples: usize,
    /// The duration (s).
    pub duration: f64,
    /// The peak ground acceleration of the record as read (m/s²).
    pub pga: f64,
    /// The scale factor applied.
    pub scale: f64,
}

/// A ground-motion record.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Where it came from (a file name), for messages and outputs.
    pub source: String,
    /// The header lines as in the file.
    pub header: Vec<String>,
    /// The units of the file's values.
    pub units: Units,
    /// The time step if uniform (s).
    pub dt: Option<f64>,
    /// Sample times (s), strictly increasing.
    pub times: Vec<f64>,
    /// Accelerations (m/s²).
    pub acceleration: Vec<f64>,
}

impl Record {
    /// Peak ground acceleration max |a| (m/s²).
    pub fn pga(&self) -> f64 {
        self.acceleration.iter().fold(0.0, |m, a| m.max(a.abs()))
    }

    /// Its duration (s).
    pub fn duration(&self) -> f64 {
        match (self.times.first(), self.times.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    /// What every result computed from the record carries about it, with
    /// the scale factor applied.
    pub fn metadata(&self, scale: f64) -> RecordMetadata {
        RecordMetadata {
            source: self.source.clone(),
            header: self.header.clone(),
            units: self.units.name(),
            dt: self.dt,
            samples: self.times.len(),
            duration: self.duration(),
            pga: self.pga(),
            scale,
        }
    }

    /// A record from samples: times (s, strictly increasing) and
    /// accelerations (m/s²), both finite, at least two.
    pub fn from_samples(
        source: &str,
        times: Vec<f64>,
        acceleration: &[f64],
    ) -> Result<Record, RecordError> {
        if times.len() != acceleration.len() {
            return Err(RecordError::whole(
                source,
                format!(
                    "{} times and {} accelerations",
                    times.len(),
                    acceleration.len()
                ),
            ));
        }
        if let Some(k) =
            (0..times.len()).find(|&k| !(times[k].is_finite() && acceleration[k].is_finite()))
        {
            return Err(RecordError::whole(
                source,
                format!("sample {k} is not finite"),
            ));
        }
        if let Some(k) = (1..times.len()).find(|&k| times[k] <= times[k - 1]) {
            return Err(RecordError::whole(
                source,
                format!(
                    "time {} of sample {k} is not after the previous {} (times must increase)",
                    times[k],
                    times[k - 1]
                ),
            ));
        }
        Record::new(
            source,
            Vec::new(),
            Units::MetersPerSecond2,
            times,
            acceleration,
        )
    }

    fn new(
        source: &str,
        header: Vec<String>,
        units: Units,
        times: Vec<f64>,
        values: &[f64],
    ) -> Result<Record, RecordError> {
        if times.len() < 2 {
            return Err(RecordError::whole(
                source,
                format!("{} samples; a record needs at least two", times.len()),
            ));
        }
        // (Plain comparisons: `f64::min` and `max` chain a NaN test a
        // sample; a NaN step is ignored either way.)
        let (lo, hi) = times.windows(2).fold((f64::INFINITY, 0.0f64), |(a, b), w| {
            let s = w[1] - w[0];
            (if s < a { s } else { a }, if s > b { s } else { b })
        });
        let dt = (hi - lo <= 1e-9 * hi).then_some(times[1] - times[0]);
        let acceleration: Vec<f64> = values.iter().map(|v| v * units.to_si()).collect();
        // A finite value in g or gal can overflow in m/s² (1e308 g).
        if let Some(k) = acceleration.iter().position(|a| !a.is_finite()) {
            return Err(RecordError::whole(
                source,
                format!(
                    "sample {} (t = {}): {:e} is not finite in m/s2",
                    k + 1,
                    times[k],
                    values[k]
                ),
            ));
        }
        Ok(Record {
            source: source.to_string(),
            header,
            units,
            dt,
            times,
            acceleration,
        })
    }
}

/// Units named in a header line (`UNITS OF G`, `CM/S/S`, `CM/SEC2`, `M/S2`,
/// `GAL`), if any.
fn units_in(line: &str) -> Option<Units> {
    let l = line.to_ascii_uppercase();
    let words: Vec<&str> = l
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '/' || c == '^'))
        .filter(|w| !w.is_empty())
        .collect();
    if words.iter().any(|w| {
        matches!(
            *w,
            "CM/S/S" | "CM/S2" | "CM/S^2" | "CM/SEC2" | "CM/SEC/SEC" | "GAL"
        )
    }) {
        Some(Units::Gal)
    } else if words
        .iter()
        .any(|w| matches!(*w, "M/S/S" | "M/S2" | "M/S^2" | "M/SEC2" | "M/SEC/SEC"))
    {
        Some(Units::MetersPerSecond2)
    } else if l.contains("UNITS OF G") || words.contains(&"G") {
        Some(Units::G)
    } else {
        None
    }
}

/// Parses a PEER NGA `.AT2` file: four header lines (title; event, date,
/// station, component; `ACCELERATION TIME SERIES IN UNITS OF G`; `NPTS=
/// n, DT= dt SEC` or the older `n dt NPTS, DT`), then n values, any number
/// per line. The first sample is at t = 0. `units` overrides the header's.
pub fn parse_at2(text: &str, source: &str, units: Option<Units>) -> Result<Record, RecordError> {
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() < 4 {
        return Err(RecordError::whole(
            source,
            format!(
                "an AT2 file has four header lines, this has {} lines",
                lines.len()
            ),
        ));
    }
    let header: Vec<String> = lines[..4]
        .iter()
        .map(|l| l.trim_end().to_string())
        .collect();
    let units = units.or_else(|| units_in(lines[2])).ok_or_else(|| {
        RecordError::at(
            source,
            3,
            format!(
                "no units in `{}`; state them (g, m/s2 or gal)",
                lines[2].trim()
            ),
        )
    })?;
    let (npts, dt) = npts_dt(lines[3]).ok_or_else(|| {
        RecordError::at(
            source,
            4,
            format!(
                "expected `NPTS= n, DT= dt SEC`, found `{}`",
                lines[3].trim()
            ),
        )
    })?;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(RecordError::at(
            source,
            4,
            format!("DT = {dt}: give a positive time step"),
        ));
    }
    let mut values = Vec::with_capacity(npts);
    for (i, line) in lines.iter().enumerate().skip(4) {
        for word in line.split_whitespace() {
            let v: f64 = word
                .parse()
                .map_err(|_| RecordError::at(source, i + 1, format!("`{word}` is not a number")))?;
            if !v.is_finite() {
                return Err(RecordError::at(
                    source,
                    i + 1,
                    format!("`{word}` is not finite"),
                ));
            }
            values.push(v);
        }
    }
    if values.len() != npts {
        return Err(RecordError::whole(
            source,
            format!(
                "the header says NPTS = {npts}, the file has {} values",
                values.len()
            ),
        ));
    }
    let times = (0..npts).map(|k| k as f64 * dt).collect();
    let mut r = Record::new(source, header, units, times, &values)?;
    r.dt = Some(dt);
    Ok(r)
}

/// `NPTS= n, DT= dt SEC` or `n dt NPTS, DT`.
fn npts_dt(line: &str) -> Option<(usize, f64)> {
    let upper = line.to_ascii_uppercase();
    let numbers: Vec<&str> = upper
        .split(|c: char| c.is_whitespace() || c == ',' || c == '=')
        .filter(|w| !w.is_empty() && w.parse::<f64>().is_ok())
        .collect();
    if !(upper.contains("NPTS") && upper.contains("DT")) || numbers.len() < 2 {
        return None;
    }
    // The number after NPTS (or the first) is the count.
    let npts: f64 = numbers[0].parse().ok()?;
    let dt: f64 = numbers[1].parse().ok()?;
    let n = npts as usize;
    (npts >= 0.0 && n as f64 == npts).then_some((n, dt))
}

/// Parses two columns (time s, acceleration) separated by white space or a
/// comma; the lines before the first pair of numbers are the header
/// (skipped, kept), `#` lines are comments. Without `units` the header
/// must state them (`g`, `m/s2`, `cm/s2`, `gal`).
pub fn parse_columns(
    text: &str,
    source: &str,
    units: Option<Units>,
) -> Result<Record, RecordError> {
    let mut header = Vec::new();
    let mut times: Vec<f64> = Vec::new();
    let mut values = Vec::new();
    // The file line of every sample, for messages.
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            if times.is_empty() && !l.is_empty() {
                header.push(l.to_string());
            }
            continue;
        }
        let cells: Vec<&str> = l
            .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
            .filter(|c| !c.is_empty())
            .collect();
        let pair = match cells.as_slice() {
            [t, a] => t.parse::<f64>().ok().zip(a.parse::<f64>().ok()),
            _ => None,
        };
        let Some((t, a)) = pair else {
            // A line that starts with a number is data (three columns, a
            // bad number), never taken for a header.
            let data = cells.first().is_some_and(|c| c.parse::<f64>().is_ok());
            if times.is_empty() && !data {
                header.push(l.to_string());
                continue;
            }
            return Err(RecordError::at(
                source,
                i + 1,
                format!("expected two numbers (time, acceleration), found `{l}`"),
            ));
        };
        if !(t.is_finite() && a.is_finite()) {
            return Err(RecordError::at(source, i + 1, "values must be finite"));
        }
        if let Some(&last) = times.last() {
            if t <= last {
                return Err(RecordError::at(
                    source,
                    i + 1,
                    format!("time {t} is not after the previous {last} (times must increase)"),
                ));
            }
        }
        times.push(t);
        values.push(a);
        lines.push(i + 1);
    }
    if times.is_empty() {
        let what = if text.trim().is_empty() {
            "empty: no samples"
        } else {
            "no samples: no line holds two numbers (time, acceleration)"
        };
        return Err(RecordError::whole(source, what));
    }
    let units = units
        .or_else(|| header.iter().find_map(|h| units_in(h)))
        .ok_or_else(|| {
            RecordError::whole(
                source,
                "the header states no units; give them (g, m/s2 or gal)",
            )
        })?;
    check_gaps(&times, &lines, source)?;
    Record::new(source, header, units, times, &values)
}

/// Refuses a step more than 10× the median step: samples are missing
/// (a gap), and the linear interpolation across it would invent motion.
fn check_gaps(times: &[f64], lines: &[usize], source: &str) -> Result<(), RecordError> {
    let steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.len() < 3 {
        return Ok(());
    }
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    if let Some(k) = steps.iter().position(|s| *s > 10.0 * median) {
        return Err(RecordError::at(
            source,
            lines[k + 1],
            format!(
                "a gap of {:.4e} s after t = {} (the median step is {median:.4e} s): samples are missing",
                steps[k],
                times[k]
            ),
        ));
    }
    Ok(())
}

/// Whether the text is an AT2 file: its fourth line has `NPTS` and `DT`,
/// its first line names PEER or `source` ends in `.AT2`.
pub fn is_at2(text: &str, source: &str) -> bool {
    text.lines().nth(3).is_some_and(|l| npts_dt(l).is_some())
        || text
            .lines()
            .next()
            .is_some_and(|l| l.to_ascii_uppercase().contains("PEER"))
        || source.to_ascii_uppercase().ends_with(".AT2")
}

/// A record from text: AT2 ([`is_at2`]), else two columns.
pub fn parse_record(text: &str, source: &str, units: Option<Units>) -> Result<Record, RecordError> {
    if is_at2(text, source) {
        parse_at2(text, source, units)
    } else {
        parse_columns(text, source, units)
    }
}

#[cfg(test)]
mod tests;
