//! The built-in default study and its report folder: every figure as SVG and
//! PNG, the data behind each figure as CSV, `summary.json` with the key
//! numbers, and `index.html` showing it all with captions.
//!
//! Every file is written atomically; `index.html` is written last. The
//! report's content is deterministic (timings go to the terminal only).
//!
//! One file per section; each computes its data with library calls
//! (`compute`) and writes it separately (`render`), so the numbers of a
//! section are tested on their own.

mod frequency_response;
mod identification;
mod impacts;
mod maps;
mod peer_speed;
mod time_history;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use vibroimpact::identify::Estimate;

use crate::error::CliError;
use crate::format::csv_text;
use crate::output::{ensure_dir, write_atomic, OutputError, Pending};
use crate::plot::{render, Figure};

/// A CSV file behind a figure.
struct DataFile {
    name: String,
    columns: Vec<&'static str>,
    rows: Vec<Vec<Option<f64>>>,
}

impl DataFile {
    fn new(name: &str, columns: Vec<&'static str>, rows: Vec<Vec<f64>>) -> Self {
        Self {
            name: name.to_string(),
            columns,
            rows: rows
                .into_iter()
                .map(|r| r.into_iter().map(Some).collect())
                .collect(),
        }
    }
}

struct FigureEntry {
    stem: String,
    caption: String,
    data: Vec<String>,
}

struct Section {
    title: String,
    html: String,
    figures: Vec<FigureEntry>,
}

/// A report being written: into a staging folder beside the target, which
/// replaces the target only when the report is complete (an interrupted or
/// failed run leaves the previous report as it was, never a mix).
pub struct Report {
    /// The staging folder every file is written into.
    dir: PathBuf,
    /// The report folder it becomes.
    target: PathBuf,
    /// Registered for removal by a hard stop; None once committed.
    staging: Option<Pending>,
    title: String,
    sections: Vec<Section>,
    summary: serde_json::Map<String, serde_json::Value>,
}

impl Drop for Report {
    /// An unfinished report's staging folder is removed.
    fn drop(&mut self) {
        if self.staging.take().is_some() {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

/// `dir` with `suffix` appended to its name (a sibling).
fn sibling(dir: &Path, suffix: &str) -> PathBuf {
    let mut name = dir.file_name().unwrap_or_default().to_os_string();
    name.push(suffix);
    dir.with_file_name(name)
}

/// Escapes text for HTML.
pub fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

impl Report {
    /// Starts a report that will become the folder `dir`: refused up front
    /// if `dir` exists and is not a report folder (a file, or a folder with
    /// other content and no `index.html`), since it is replaced whole.
    pub fn new(dir: &Path, title: &str) -> Result<Self, CliError> {
        if dir.exists() {
            let is_report = dir.join("index.html").is_file();
            let empty = std::fs::read_dir(dir).map(|mut d| d.next().is_none());
            if !dir.is_dir() || !(is_report || matches!(empty, Ok(true))) {
                return Err(CliError::new(format!(
                    "{}: exists and is not a report folder (no index.html); the report replaces its folder whole, so choose another --out",
                    dir.display()
                )));
            }
        }
        let staging = sibling(dir, &format!(".partial{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&staging);
        let pending = Pending::new(&staging);
        ensure_dir(&staging)?;
        Ok(Self {
            dir: staging,
            target: dir.to_path_buf(),
            staging: Some(pending),
            title: title.to_string(),
            sections: Vec::new(),
            summary: serde_json::Map::new(),
        })
    }

    /// Replaces the target folder by the complete staging folder.
    fn commit(&mut self) -> Result<(), CliError> {
        let fail = |path: &Path, source| {
            CliError::from(OutputError {
                path: path.to_path_buf(),
                source,
            })
        };
        let old = sibling(&self.target, &format!(".old{}", std::process::id()));
        let had_old = self.target.exists();
        if had_old {
            std::fs::rename(&self.target, &old).map_err(|e| fail(&self.target, e))?;
        }
        if let Err(e) = std::fs::rename(&self.dir, &self.target) {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(fail(&self.target, e));
        }
        self.staging = None;
        if had_old {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }

    /// Starts a section; `html` is its introduction (already HTML).
    pub fn section(&mut self, title: &str, html: String) {
        self.sections.push(Section {
            title: title.to_string(),
            html,
            figures: Vec::new(),
        });
    }

    /// Appends HTML to the current section.
    pub fn append_html(&mut self, html: &str) {
        if let Some(s) = self.sections.last_mut() {
            s.html.push_str(html);
        }
    }

    /// Records a key number (or object) in `summary.json`.
    pub fn summary(&mut self, key: &str, value: serde_json::Value) {
        self.summary.insert(key.to_string(), value);
    }

    /// Renders a figure (SVG + PNG) with its data files into the current section.
    fn figure(
        &mut self,
        fig: &Figure,
        stem: &str,
        caption: &str,
        data: Vec<DataFile>,
    ) -> Result<(), CliError> {
        render(fig, &self.dir.join(stem))?;
        let mut names = Vec::new();
        for d in data {
            write_atomic(
                &self.dir.join(&d.name),
                csv_text(&d.columns, &d.rows)?.as_bytes(),
            )?;
            names.push(d.name);
        }
        if let Some(s) = self.sections.last_mut() {
            s.figures.push(FigureEntry {
                stem: stem.to_string(),
                caption: caption.to_string(),
                data: names,
            });
        }
        Ok(())
    }

    /// Writes `summary.json` and then `index.html`, and puts the report in
    /// place of its target folder.
    pub fn finish(mut self) -> Result<PathBuf, CliError> {
        let summary = serde_json::to_string_pretty(&serde_json::Value::Object(std::mem::take(
            &mut self.summary,
        )))?;
        write_atomic(&self.dir.join("summary.json"), summary.as_bytes())?;
        let mut h = String::new();
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{t}</title>\n<style>\n\
             body {{ font-family: 'DejaVu Sans', Helvetica, Arial, sans-serif; max-width: 1000px; margin: 2em auto; padding: 0 1em; color: #222; line-height: 1.45; }}\n\
             figure {{ margin: 1.5em 0; }} figure img {{ width: 100%; border: 1px solid #ddd; }}\n\
             figcaption {{ font-size: 0.95em; color: #333; }}\n\
             table {{ border-collapse: collapse; margin: 1em 0; font-size: 0.92em; }}\n\
             th, td {{ border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }} th {{ background: #f0f0f0; }}\n\
             td.l, th.l {{ text-align: left; }} code {{ background: #f4f4f4; padding: 0 0.2em; }}\n\
             </style>\n</head>\n<body>\n<h1>{t}</h1>\n",
            t = html_escape(&self.title)
        );
        h.push_str("<nav><ol>\n");
        for (i, s) in self.sections.iter().enumerate() {
            let _ = writeln!(
                h,
                "<li><a href=\"#s{}\">{}</a></li>",
                i + 1,
                html_escape(&s.title)
            );
        }
        h.push_str("</ol></nav>\n");
        let mut n = 0;
        for (i, s) in self.sections.iter().enumerate() {
            let _ = writeln!(
                h,
                "<section id=\"s{}\">\n<h2>{}. {}</h2>\n{}",
                i + 1,
                i + 1,
                html_escape(&s.title),
                s.html
            );
            for f in &s.figures {
                n += 1;
                let data: Vec<String> = f
                    .data
                    .iter()
                    .map(|d| format!("<a href=\"{0}\">{0}</a>", html_escape(d)))
                    .collect();
                let _ = writeln!(
                    h,
                    "<figure id=\"{stem}\">\n<a href=\"{stem}.svg\"><img src=\"{stem}.png\" alt=\"Figure {n}\"></a>\n\
                     <figcaption><b>Figure {n}.</b> {cap} <br>Vector: <a href=\"{stem}.svg\">{stem}.svg</a>; data: {data}.</figcaption>\n</figure>",
                    stem = html_escape(&f.stem),
                    cap = f.caption,
                    data = data.join(", ")
                );
            }
            h.push_str("</section>\n");
        }
        h.push_str("<p><a href=\"summary.json\">summary.json</a> holds the key numbers of this report.</p>\n</body>\n</html>\n");
        write_atomic(&self.dir.join("index.html"), h.as_bytes())?;
        self.commit()?;
        Ok(self.target.join("index.html"))
    }
}

/// An HTML table from a header and rows of cells (first column left-aligned).
pub fn html_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut h = String::from("<table>\n<tr>");
    for (i, c) in header.iter().enumerate() {
        let _ = write!(
            h,
            "<th{}>{}</th>",
            if i == 0 { " class=\"l\"" } else { "" },
            html_escape(c)
        );
    }
    h.push_str("</tr>\n");
    for r in rows {
        h.push_str("<tr>");
        for (i, c) in r.iter().enumerate() {
            let _ = write!(
                h,
                "<td{}>{}</td>",
                if i == 0 { " class=\"l\"" } else { "" },
                c
            );
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</table>\n");
    h
}

fn logspace(a: f64, b: f64, n: usize) -> impl Iterator<Item = f64> {
    (0..n).map(move |i| (a.ln() + (b.ln() - a.ln()) * i as f64 / (n - 1) as f64).exp())
}

fn estimate_text(e: &Estimate) -> String {
    format!("{:.5} ± {:.2e}", e.value, e.std_error)
}

/// Runs the default study and writes its report into `out`.
pub fn run(out: &Path) -> Result<(), CliError> {
    // Said before any work, as every long run does (measured 90 to 140 s).
    eprintln!(
        "note: the default study takes about 2 min on 2 cores; Ctrl-C stops it and keeps any earlier report as it was"
    );
    let start = Instant::now();
    let mut report = Report::new(
        out,
        "vibroimpact default study: impact vibrations after T. Fujita (1977)",
    )?;
    let stop = crate::interrupt::on_ctrl_c();
    // After Ctrl-C a section's own error (an interrupted integration) is
    // reported as the interruption it is.
    let checked = |result: Result<(), CliError>| {
        if stop.requested() {
            Err(CliError::new(
                "interrupted (Ctrl-C): no report was written (an earlier report in its folder is kept as it was)",
            ))
        } else {
            result
        }
    };
    checked(impacts::compute().and_then(|d| impacts::render(&mut report, &d)))?;
    checked(identification::compute().and_then(|d| identification::render(&mut report, &d)))?;
    checked(time_history::compute(&stop).and_then(|d| time_history::render(&mut report, &d)))?;
    checked(
        frequency_response::compute(&stop)
            .and_then(|d| frequency_response::render(&mut report, &d)),
    )?;
    checked(maps::compute(&stop).and_then(|d| maps::render(&mut report, &d)))?;
    peer_speed::render(&mut report)?;
    let index = report.finish()?;
    println!(
        "report written: {} ({:.2} s)",
        index.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
