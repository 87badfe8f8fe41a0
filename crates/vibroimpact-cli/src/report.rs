//! The built-in default study and its report folder: every figure as SVG and
//! PNG, the data behind each figure as CSV, `summary.json` with the key
//! numbers, and `index.html` showing it all with captions.
//!
//! Every file is written atomically; `index.html` is written last. The
//! report's content is deterministic (timings go to the terminal only).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use vibroimpact::contact::{ContactLaw, ForceForm};
use vibroimpact::identify::Estimate;
use vibroimpact::impact::closed_form::{peak_force_dimensionless, restitution, ExponentialImpact};
use vibroimpact::impact::direct::{integrate_impact, DirectOptions};
use vibroimpact::impact::TwoBodies;
use vibroimpact::integrate::Interrupt;
use vibroimpact::reference;
use vibroimpact::simulate::{simulate, SimulationOptions};

use crate::error::CliError;
use crate::format::csv_text;
use crate::measurements::Measurements;
use crate::output::{ensure_dir, write_atomic, OutputError, Pending};
use crate::plot::{render, Figure, LegendPosition, Marker, Series};
use vibroimpact::identify::Identification;

/// The example impact data shipped in `examples/seed-impacts/` (embedded so
/// the default study runs from any directory).
const EXAMPLE_RESTITUTION: &str = include_str!("../../../examples/seed-impacts/restitution.csv");
const EXAMPLE_ACCELERATION: &str = include_str!("../../../examples/seed-impacts/acceleration.csv");

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

/// The seed's part III: impact relations of the exponential law and the
/// identification of its parameters.
fn seed_part3(report: &mut Report) -> Result<(), CliError> {
    let q = reference::A_OVER_B;
    let law = reference::seed_law();
    let bodies = reference::seed_bodies();
    let model = ExponentialImpact::new(&law, bodies)?;
    let opts = DirectOptions::default();

    // Reference table R1 (docs/theory.md §2) against the closed form and direct integration.
    let mut rows = Vec::new();
    let mut table_json = Vec::new();
    for reference::R1Row {
        v,
        e: e_ref,
        f_max: f_ref,
    } in reference::R1_TABLE
    {
        let e = restitution(v)?;
        let f = peak_force_dimensionless(v)?;
        let d = integrate_impact(&law, bodies, v * q, &opts)?;
        let f_int = d.peak_force / model.force_scale();
        rows.push(vec![
            format!("{v}"),
            format!("{e:.12}"),
            format!("{e_ref:.12}"),
            format!("{:.1e}", (e - e_ref).abs()),
            format!("{:.1e}", (d.restitution - e).abs()),
            format!("{f:.9e}"),
            format!("{f_ref:.8e}"),
            format!("{:.1e}", (f_int / f - 1.0).abs()),
        ]);
        table_json.push(
            serde_json::json!({"v": v, "restitution": e, "restitution_integrated": d.restitution,
            "peak_force_dimensionless": f, "peak_force_dimensionless_integrated": f_int}),
        );
    }
    report.summary("reference_table", serde_json::Value::Array(table_json));

    report.section(
        "Two-body impact with the exponential restitution force (seed part III)",
        format!(
            "<p>Two bodies collide through Fujita's exponential law <code>F = (a + b ds/dt) exp(alpha s)</code> \
             (seed eq. 1). Their relative motion has the exact phase trajectory of seed eq. (8); the coefficient of \
             restitution depends only on <code>V = U/(a/b)</code> (eqs. 9–10) and the dimensionless peak force \
             <code>f = F/(mu alpha (a/b)^2)</code> only on V (eqs. 14–17). Parameters: the seed's steel balls \
             (m1 = m2 = 0.227 kg, mu = m/2), a/b = 1.2 m/s, alpha = 1.3e5 1/m, a = 1 N. \
             Closed form: Newton on cancellation-free forms of eqs. (10) and (17); direct integration: DOP853 at \
             rtol 1e-12 in scaled variables, restitution read at the start position.</p>\n\
             <p>Reference values (docs/theory.md §2; its V = 0.01 entry is rounded at the 10th decimal) against the \
             closed form and the direct integration:</p>\n{}",
            html_table(
                &["V", "e closed form", "e reference", "|Δe|", "|e integrated − e closed|", "f_max closed form", "f_max reference", "rel. Δf integrated"],
                &rows
            )
        ),
    );

    // Figure 1: phase trajectories.
    let start = 40e-6;
    let mut fig1 = Figure::new(
        "Phase trajectories of two colliding balls (seed eq. 8)",
        "approach coordinate s = x1 − x2 + d  [µm]",
        "relative velocity ds/dt  [m/s]",
    )
    .x_range(-start * 1e6, 70.0)
    .legend_at(LegendPosition::Best);
    let mut fig1_rows = Vec::new();
    for (i, u) in [0.05, 0.1, 0.2, 0.4, 0.8].into_iter().enumerate() {
        let pts = model.trajectory(u, start, 801)?;
        fig1_rows.extend(pts.iter().map(|&(x, y)| vec![u, x, y]));
        fig1.push(
            Series::line(
                format!("U = {u} m/s (V = {:.3})", u / q),
                pts.iter().map(|&(x, y)| (x * 1e6, y)),
            )
            .with_color(i),
        );
    }
    report.figure(
        &fig1,
        "fig1_phase_trajectories",
        "Phase trajectories of the relative motion (seed figure 1) for impacts starting 40 µm apart: the \
         approach at y = U, the maximum penetration at y = 0 and the rebound at y = −eU at the same distance. \
         The effective contact point lies near s = ln(a)/alpha = 0 here (a = 1 N).",
        vec![DataFile::new("fig1_phase_trajectories.csv", vec!["impact_velocity", "s", "ds_dt"], fig1_rows)],
    )?;

    // Figures 2 and 3: e(V) and f_max(V), closed form with integration points.
    let mut line_e = Vec::new();
    let mut line_f = Vec::new();
    let mut line_rows = Vec::new();
    for v in logspace(1e-3, 1e2, 301) {
        let (e, f) = (restitution(v)?, peak_force_dimensionless(v)?);
        line_e.push((v, e));
        line_f.push((v, f));
        line_rows.push(vec![v, e, f]);
    }
    let mut pts_e = Vec::new();
    let mut pts_f = Vec::new();
    let mut pts_rows = Vec::new();
    let mut max_de: f64 = 0.0;
    let mut max_df: f64 = 0.0;
    for v in logspace(1e-3, 1e2, 21) {
        let d = integrate_impact(&law, bodies, v * q, &opts)?;
        let (e, f) = (restitution(v)?, peak_force_dimensionless(v)?);
        let f_int = d.peak_force / model.force_scale();
        max_de = max_de.max((d.restitution - e).abs());
        max_df = max_df.max((f_int / f - 1.0).abs());
        pts_e.push((v, d.restitution));
        pts_f.push((v, f_int));
        pts_rows.push(vec![
            v,
            d.restitution,
            e,
            f_int,
            f,
            d.contact_duration,
            d.max_penetration,
        ]);
    }
    report.summary(
        "max_abs_restitution_difference_integrated_vs_closed_form",
        serde_json::json!(max_de),
    );
    report.summary(
        "max_rel_peak_force_difference_integrated_vs_closed_form",
        serde_json::json!(max_df),
    );
    let fig2 = Figure::new(
        "Coefficient of restitution of the exponential law (seed eq. 10)",
        "dimensionless impact velocity V = U/(a/b)",
        "coefficient of restitution e",
    )
    .log_x()
    .y_range(0.0, 1.05)
    .legend_at(LegendPosition::LowerLeft)
    .with_series(Series::line("closed form, eq. (10)", line_e))
    .with_series(Series::markers("direct integration", pts_e, Marker::Circle))
    .with_series(Series::dashed(
        "small-V asymptote 1 − 2V/3",
        logspace(1e-3, 0.5, 50).map(|v| (v, 1.0 - 2.0 * v / 3.0)),
    ));
    report.figure(
        &fig2,
        "fig2_restitution",
        &format!(
            "Coefficient of restitution against the dimensionless impact velocity (seed figure 2). Circles: direct \
             integration of the equation of motion; largest difference from the closed form {max_de:.1e} over V in \
             [1e-3, 100]."
        ),
        vec![
            DataFile::new("fig2_fig3_closed_form.csv", vec!["v", "restitution", "peak_force_dimensionless"], line_rows),
            DataFile::new(
                "fig2_fig3_integrated.csv",
                vec!["v", "restitution_integrated", "restitution_closed_form", "peak_force_dimensionless_integrated",
                     "peak_force_dimensionless_closed_form", "contact_duration", "max_penetration"],
                pts_rows,
            ),
        ],
    )?;
    let fig3 = Figure::new(
        "Peak restitution force of the exponential law (seed eqs. 16–17)",
        "dimensionless impact velocity V = U/(a/b)",
        "dimensionless peak force f_max = F_max / (µ α (a/b)²)",
    )
    .log_x()
    .log_y()
    .legend_at(LegendPosition::UpperLeft)
    .with_series(Series::line("closed form, eqs. (16)–(17)", line_f))
    .with_series(Series::markers("direct integration", pts_f, Marker::Square))
    .with_series(Series::dashed(
        "small-V asymptote V²/2",
        logspace(1e-3, 1e2, 50).map(|v| (v, v * v / 2.0)),
    ));
    report.figure(
        &fig3,
        "fig3_peak_force",
        &format!(
            "Dimensionless peak force against the dimensionless impact velocity (seed figure 3); it grows like V²/2 \
             for small V and bends toward V ln V for large V. Largest relative difference of the direct integration \
             from the closed form: {max_df:.1e}."
        ),
        Vec::new(),
    )?;

    // Figures 4 and 5: identification from the example data.
    let data = Measurements::parse(
        Some((EXAMPLE_RESTITUTION, "examples/seed-impacts/restitution.csv")),
        Some((
            EXAMPLE_ACCELERATION,
            "examples/seed-impacts/acceleration.csv",
        )),
    )?;
    let sequential = data.identify(bodies, None, false)?;
    let joint = data.identify(bodies, None, true)?;
    identification_figures(report, &data, &sequential, &joint, bodies)?;
    Ok(())
}

/// CSV rows (U, measured, fitted, residual) of fit residuals.
fn residual_rows<'a>(
    residuals: impl Iterator<Item = &'a vibroimpact::identify::Residual>,
) -> Vec<Vec<f64>> {
    residuals
        .map(|r| vec![r.impact_velocity, r.measured, r.fitted, r.residual])
        .collect()
}

fn identification_figures(
    report: &mut Report,
    data: &Measurements,
    sequential: &Identification,
    joint: &Identification,
    bodies: TwoBodies,
) -> Result<(), CliError> {
    let (Some(q), Some(alpha)) = (sequential.a_over_b, sequential.alpha) else {
        return Err(CliError::new(
            "identification of the example data gave no estimate",
        ));
    };
    let (Some(qj), Some(alphaj)) = (joint.a_over_b, joint.alpha) else {
        return Err(CliError::new(
            "joint identification of the example data gave no estimate",
        ));
    };
    report.summary(
        "identification_sequential",
        serde_json::to_value(sequential)?,
    );
    report.summary("identification_joint", serde_json::to_value(joint)?);
    let (rest, acc) = data.samples();
    let z = |e: &Estimate, truth: f64| (e.value - truth) / e.std_error;
    report.append_html(&format!(
        "<h3>Identification from measured impacts (seed §3)</h3>\n<p>The example data set \
         <code>examples/seed-impacts/</code> imitates the seed's figures 4–5: {} restitution and {} acceleration \
         measurements made from a/b = 1.2 m/s and alpha = 1.3e5 1/m with measurement noise (the files say how). \
         Least squares recovers the values they were made from:</p>\n{}",
        rest.len(),
        acc.len(),
        html_table(
            &["fit", "a/b [m/s]", "(a/b − 1.2)/σ", "alpha [1/m]", "(alpha − 1.3e5)/σ", "corr."],
            &[
                vec![
                    "sequential (seed): a/b from e, then alpha".into(),
                    estimate_text(&q),
                    format!("{:+.2}", z(&q, reference::A_OVER_B)),
                    format!("{:.4e} ± {:.1e}", alpha.value, alpha.std_error),
                    format!("{:+.2}", z(&alpha, reference::ALPHA)),
                    "—".into(),
                ],
                vec![
                    "joint (weighted)".into(),
                    estimate_text(&qj),
                    format!("{:+.2}", z(&qj, reference::A_OVER_B)),
                    format!("{:.4e} ± {:.1e}", alphaj.value, alphaj.std_error),
                    format!("{:+.2}", z(&alphaj, reference::ALPHA)),
                    format!("{:.2}", joint.acceleration_fit.as_ref().map_or(0.0, |f| f.correlation)),
                ],
            ]
        )
    ));
    let u_range = || logspace(0.02, 0.8, 200);
    let fitted_law =
        ContactLaw::exponential_from_ratio(q.value, alpha.value, 1.0, ForceForm::Published)?;
    let fitted = ExponentialImpact::new(&fitted_law, bodies)?;
    let seed = ExponentialImpact::new(&reference::seed_law(), bodies)?;
    let mut curve_rows = Vec::new();
    let (mut fit_e, mut fit_a, mut seed_e, mut seed_a) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for u in u_range() {
        let (f, s) = (fitted.impact(u)?, seed.impact(u)?);
        fit_e.push((u, f.restitution));
        fit_a.push((u, f.peak_acceleration[0]));
        seed_e.push((u, s.restitution));
        seed_a.push((u, s.peak_acceleration[0]));
        curve_rows.push(vec![
            u,
            f.restitution,
            f.peak_acceleration[0],
            s.restitution,
            s.peak_acceleration[0],
        ]);
    }
    let fig4 = Figure::new(
        "Identification of a/b from restitution measurements (seed figure 4)",
        "impact velocity U  [m/s]",
        "coefficient of restitution e",
    )
    .y_range(0.5, 1.05)
    .legend_at(LegendPosition::Best)
    .with_series(Series::markers(
        "measured (example data)",
        rest.iter().map(|s| (s.impact_velocity, s.restitution)),
        Marker::Circle,
    ))
    .with_series(Series::line(
        format!("fit: a/b = {:.4} ± {:.4} m/s", q.value, q.std_error),
        fit_e,
    ))
    .with_series(Series::dashed(
        "values the data were made from (a/b = 1.2 m/s)",
        seed_e,
    ));
    report.figure(
        &fig4,
        "fig4_identify_restitution",
        "Measured coefficient of restitution against impact velocity with the least-squares curve e(U/(a/b)) of seed \
         eqs. (9)–(10) (seed figure 4; the seed found a/b = 120 cm/s by eye).",
        vec![
            DataFile::new(
                "fig4_fig5_fitted_curves.csv",
                vec!["impact_velocity", "restitution_fit", "peak_acceleration_fit", "restitution_true", "peak_acceleration_true"],
                curve_rows,
            ),
            DataFile::new(
                "fig4_residuals.csv",
                vec!["impact_velocity", "measured", "fitted", "residual"],
                residual_rows(sequential.restitution_fit.iter().flat_map(|f| &f.residuals)),
            ),
        ],
    )?;
    let fig5 = Figure::new(
        "Identification of alpha from peak accelerations (seed figure 5)",
        "impact velocity U  [m/s]",
        "peak acceleration of body 1, F_max/m1  [m/s²]",
    )
    .log_x()
    .log_y()
    .legend_at(LegendPosition::UpperLeft)
    .with_series(Series::markers(
        "measured (example data)",
        acc.iter().map(|s| (s.impact_velocity, s.peak_acceleration)),
        Marker::Triangle,
    ))
    .with_series(Series::line(
        format!("fit: α = {:.4e} ± {:.1e} 1/m", alpha.value, alpha.std_error),
        fit_a,
    ))
    .with_series(Series::dashed(
        "values the data were made from (α = 1.3e5 1/m)",
        seed_a,
    ));
    report.figure(
        &fig5,
        "fig5_identify_alpha",
        "Measured peak acceleration against impact velocity with the least-squares curve of seed eqs. (14), (16)–(17) \
         given the fitted a/b (seed figure 5; the seed found alpha = 1300 1/cm). Least squares on ln A (relative errors).",
        vec![DataFile::new(
            "fig5_residuals.csv",
            vec!["impact_velocity", "measured", "fitted", "residual_ln"],
            residual_rows(sequential.acceleration_fit.iter().flat_map(|f| &f.acceleration_residuals)),
        )],
    )?;
    Ok(())
}

/// The seed's row (R2, N = 3) near resonance: time history and impact log,
/// with the logged impacts over the two-body relations of part III.
fn seed_row_time_history(report: &mut Report, stop: &Interrupt) -> Result<(), CliError> {
    let (m, law) = (reference::MASS, reference::seed_law());
    let omega = 0.95 * reference::NATURAL_FREQUENCY;
    let model = reference::r2(3, reference::CLEARANCE, omega)?;
    let period = 2.0 * std::f64::consts::PI / omega;
    let periods = 20.0;
    let opts = SimulationOptions {
        t_end: periods * period,
        rtol: 1e-10,
        atol: 1e-14,
        output_step: Some(period / 200.0),
        energy: true,
        interrupt: Some(stop.clone()),
        ..SimulationOptions::default()
    };
    let sim = simulate(&model, &opts)?;
    if let Some(e) = &sim.error {
        return Err(CliError::new(format!("default study, R2 simulation: {e}")));
    }
    let summary = vibroimpact::results::simulation_summary(&model, &sim);
    report.summary("r2_n3_simulation", serde_json::to_value(&summary)?);
    let energy = summary.energy.as_ref().map_or(0.0, |e| e.residual);
    let mut counts = Vec::new();
    for (k, c) in summary.impacts_per_contact.iter().enumerate() {
        let imps: Vec<_> = sim
            .impacts
            .iter()
            .filter(|i| i.contact == k && i.complete())
            .collect();
        let mean = |f: &dyn Fn(&vibroimpact::simulate::ImpactRecord) -> f64| {
            imps.iter().map(|i| f(i)).sum::<f64>() / imps.len().max(1) as f64
        };
        counts.push(vec![
            html_escape(&c.contact),
            format!("{}", c.impacts),
            format!("{:.4}", mean(&|i| i.impact_velocity)),
            format!("{:.4}", mean(&|i| i.restitution())),
            format!(
                "{:.1}",
                imps.iter().map(|i| i.peak_force / m).fold(0.0, f64::max)
            ),
        ]);
    }
    report.section(
        "The seed's row of pendulums near resonance (R2, N = 3)",
        format!(
            "<p>Three pendulums (m = 0.227 kg, ω0 = 7.41 rad/s, ζ = 0.013) between two walls, every gap 1 mm, the \
             exponential law with the seed's a/b and α, base acceleration 0.05 sin(0.95 ω0 t) m/s², from rest, \
             {periods} forcing periods. DOP853 at rtol 1e-10: {} steps ({} rejected), {} impacts; energy balance \
             residual {:.1e} J of {:.2e} J input work.</p>\n{}",
            summary.steps,
            summary.rejected_steps,
            summary.impact_count,
            energy,
            summary.energy.as_ref().map_or(0.0, |e| e.input_work),
            html_table(&["contact", "impacts", "mean impact velocity [m/s]", "mean restitution", "max peak acceleration [m/s²]"], &counts)
        ),
    );
    let n = 3;
    let mut fig = Figure::new(
        "Seed's row near resonance: displacements",
        "time t  [s]",
        "displacement u  [mm]",
    )
    .legend_at(LegendPosition::Best);
    let mut rows = Vec::new();
    for (j, &t) in sim.times.iter().enumerate() {
        let st = &sim.states[j * 2 * n..(j + 1) * 2 * n];
        rows.push(
            std::iter::once(t)
                .chain(st.iter().copied())
                .collect::<Vec<f64>>(),
        );
    }
    for i in 0..n {
        fig.push(Series::line(
            format!("pendulum {}", i + 1),
            sim.times
                .iter()
                .enumerate()
                .map(|(j, &t)| (t, 1e3 * sim.states[j * 2 * n + i])),
        ));
    }
    report.figure(
        &fig,
        "fig6_row_displacements",
        "Displacements of the three pendulums relative to the table; the ±1 mm gaps to the walls and to each other \
         clip the motion into a sequence of impacts.",
        vec![DataFile::new("fig6_row_history.csv", vec!["t", "u_p1", "u_p2", "u_p3", "v_p1", "v_p2", "v_p3"], rows)],
    )?;
    // Impacts over the two-body relations: e(U) does not depend on the
    // masses; peak acceleration F/m differs for ball–ball (μ = m/2) and
    // ball–wall (μ = m).
    let ball = ExponentialImpact::new(&law, TwoBodies::new(m, m)?)?;
    let wall = ExponentialImpact::new(&law, TwoBodies::against_wall(m)?)?;
    let complete: Vec<_> = sim.impacts.iter().filter(|i| i.complete()).collect();
    let is_wall = |k: usize| model.contact_name(k).contains("wall");
    let u_max = complete
        .iter()
        .map(|i| i.impact_velocity)
        .fold(0.0, f64::max)
        * 1.1;
    let u_min = complete
        .iter()
        .map(|i| i.impact_velocity)
        .fold(f64::INFINITY, f64::min)
        .max(1e-4)
        * 0.9;
    let (mut e_line, mut a_ball, mut a_wall) = (Vec::new(), Vec::new(), Vec::new());
    for u in logspace(u_min, u_max, 100) {
        e_line.push((u, ball.impact(u)?.restitution));
        a_ball.push((u, ball.impact(u)?.peak_acceleration[0]));
        a_wall.push((u, wall.impact(u)?.peak_acceleration[0]));
    }
    let pts = |wall_side: bool,
               f: &dyn Fn(&vibroimpact::simulate::ImpactRecord) -> f64|
     -> Vec<(f64, f64)> {
        complete
            .iter()
            .filter(|i| is_wall(i.contact) == wall_side)
            .map(|i| (i.impact_velocity, f(i)))
            .collect()
    };
    let (e_lo, e_hi) = (0.95, 1.01);
    let outside = complete
        .iter()
        .filter(|i| !(e_lo..=e_hi).contains(&i.restitution()))
        .count();
    let fig7 = Figure::new(
        "Impacts in the row against the two-body relation",
        "impact velocity U  [m/s]",
        "coefficient of restitution e",
    )
    .log_x()
    .y_range(e_lo, e_hi)
    .legend_at(LegendPosition::LowerLeft)
    .with_series(Series::line("two-body closed form e(U/(a/b)), eq. (10)", e_line).with_color(0))
    .with_series(
        Series::markers(
            "ball–ball impacts in the row",
            pts(false, &|i| i.restitution()),
            Marker::Circle,
        )
        .with_color(2),
    )
    .with_series(
        Series::markers(
            "ball–wall impacts in the row",
            pts(true, &|i| i.restitution()),
            Marker::Square,
        )
        .with_color(4),
    );
    report.figure(
        &fig7,
        "fig7_row_restitution",
        &format!(
            "Coefficient of restitution of every impact logged in the row (rebound over impact velocity at the impact \
             threshold) against the two-body closed form. Fast impacts follow the seed's relation; slow ones depart \
             from it because springs and base excitation act during the 10–20 ms contacts ({outside} of {} impacts \
             fall outside the plotted range e in [{e_lo}, {e_hi}]; all are in the data file).",
            complete.len()
        ),
        vec![DataFile::new(
            "fig7_fig8_row_impacts.csv",
            vec!["start_time", "contact", "impact_velocity", "rebound_velocity", "restitution", "peak_force", "peak_acceleration", "duration"],
            complete
                .iter()
                .map(|i| vec![i.start_time, i.contact as f64, i.impact_velocity, i.rebound_velocity, i.restitution(), i.peak_force, i.peak_force / m, i.duration()])
                .collect(),
        )],
    )?;
    let fig8 = Figure::new(
        "Peak accelerations in the row against the two-body relation",
        "impact velocity U  [m/s]",
        "peak acceleration F_max/m  [m/s²]",
    )
    .log_x()
    .log_y()
    .legend_at(LegendPosition::Best)
    .with_series(Series::line("closed form, ball–ball (µ = m/2)", a_ball).with_color(0))
    .with_series(Series::dashed("closed form, ball–wall (µ = m)", a_wall).with_color(1))
    .with_series(
        Series::markers(
            "ball–ball impacts in the row",
            pts(false, &|i| i.peak_force / m),
            Marker::Circle,
        )
        .with_color(2),
    )
    .with_series(
        Series::markers(
            "ball–wall impacts in the row",
            pts(true, &|i| i.peak_force / m),
            Marker::Square,
        )
        .with_color(4),
    );
    report.figure(
        &fig8,
        "fig8_row_peak_acceleration",
        "Peak acceleration (peak contact force over the pendulum mass) of every logged impact against the closed \
         form of seed eqs. (14), (16)–(17) for two balls and for a ball against the rigid end.",
        Vec::new(),
    )?;
    Ok(())
}

/// The seed's parts I–II: frequency-response curves of the row (R2, N = 2
/// and 3) by continuation, with Floquet stability, special points and a
/// brute-force sweep over them.
fn seed_row_frequency_response(report: &mut Report, stop: &Interrupt) -> Result<(), CliError> {
    use rayon::prelude::*;
    use vibroimpact::continuation::{
        branch_switch_start, continue_branch, Branch, ContinuationOptions,
    };
    use vibroimpact::periodic::{guess_by_simulation_with, orbit_summary, ShootingOptions};

    let w0 = reference::NATURAL_FREQUENCY;
    let row =
        |n: usize, w: f64| reference::r2(n, reference::CLEARANCE, w).map_err(|e| e.to_string());
    let mut intro = String::from(
        "<p>Periodic solutions of the row (the seed's parts I–II) found by shooting (Newton on the period map, \
         monodromy from the variational equations) and followed in the forcing frequency Ω by pseudo-arclength \
         continuation from 1.5 ω0 downward; stability from the Floquet multipliers. Special points are located to \
         1e-8 in Ω: folds (LP), branch points (BP, symmetry breaking of the in-phase motion), period doublings (PD), \
         Neimark–Sacker points (NS) and grazings (GR, the number of impacts per period changes). Each branch is \
         checked against brute-force sweeps at 61 frequencies, max |u1| over 10 periods after a transient: from \
         rest (150 periods), and downward from 1.5 ω0 with each frequency starting from the state the previous one \
         reached (100 periods), which follows an attractor as long as it exists.</p>\n\
         <p>The rows are mirror-symmetric (u_i → −u_{N+1−i} with a half-period shift), and so is the in-phase \
         branch: it is followed on the symmetric half map S∘P_{T/2}, whose Jacobian's eigenvalue −1 marks a \
         symmetry-breaking pitchfork (BP) as a sign change of det(DG + I), a test the full period map does not \
         have (there a pitchfork's multiplier touches +1 without crossing). For N = 2 the asymmetric branches \
         born at BP1 and BP2 are switched onto along the symmetry-breaking eigenvector and continued; the one from \
         BP2 returns to the symmetric branch at BP3 and stops there (the rest is its mirror image).</p>\n",
    );
    // AUTO-07p's special points of the N = 2 symmetric branch (bench/auto,
    // results/compare-2026-11-22.txt: collocation, NTST 300, NCOL 4,
    // adaptive mesh); TR is AUTO's torus (Neimark–Sacker) point.
    const AUTO_N2: [(&str, f64); 7] = [
        ("branch-point", 0.9831002),
        ("branch-point", 0.9493928),
        ("branch-point", 0.7945276),
        ("branch-point", 0.5524972),
        ("branch-point", 0.5340433),
        ("branch-point", 0.5094748),
        ("neimark-sacker", 0.5024794),
    ];
    let mut table = Vec::new();
    for n in [2usize, 3] {
        let start = row(n, 1.5 * w0).map_err(CliError::new)?;
        let guess = guess_by_simulation_with(&start, 200.0, 1e-9, Some(stop.clone()))?;
        let defaults = ContinuationOptions::default();
        let opts = ContinuationOptions {
            max_points: 900,
            shooting: ShootingOptions {
                interrupt: Some(stop.clone()),
                ..defaults.shooting.clone()
            },
            ..defaults
        };
        let t0 = Instant::now();
        let branch: Branch =
            continue_branch(|w| row(n, w), 1.5 * w0, &guess, 0.5 * w0, &opts, |_| true)?;
        let seconds = t0.elapsed().as_secs_f64();
        eprintln!(
            "R2 N = {n}: branch of {} points in {seconds:.1} s",
            branch.points.len()
        );
        // Brute force twice: from rest at every frequency (in parallel), and
        // downward from 1.5 ω0 with each frequency starting from the state
        // the previous one reached (follows an attractor while it exists).
        let onward = || {
            let mut state: Option<Vec<f64>> = None;
            let mut out = Vec::new();
            for k in (0..61).rev() {
                let w = (0.5 + k as f64 / 60.0) * w0;
                let Ok(model) = row(n, w) else { continue };
                let t = 2.0 * std::f64::consts::PI / w;
                let opts = SimulationOptions {
                    t_end: 100.0 * t,
                    rtol: 1e-9,
                    atol: 1e-13,
                    start: state.clone(),
                    interrupt: Some(stop.clone()),
                    ..SimulationOptions::default()
                };
                let Ok(sim) = simulate(&model, &opts) else {
                    continue;
                };
                if sim.error.is_some() {
                    continue;
                }
                let end = sim.final_state();
                if let Ok(orbit) = orbit_summary(&model, &end, 10.0 * t, 2560, 1e-9) {
                    out.push((w / w0, 1e3 * orbit.max_displacement[0]));
                }
                state = Some(end);
            }
            out
        };
        let from_rest = || -> Vec<(f64, f64)> {
            (0..61)
                .into_par_iter()
                .map(|k| {
                    let w = (0.5 + k as f64 / 60.0) * w0;
                    let model = row(n, w).ok()?;
                    let t = 2.0 * std::f64::consts::PI / w;
                    let sim = simulate(
                        &model,
                        &SimulationOptions {
                            t_end: 150.0 * t,
                            rtol: 1e-9,
                            atol: 1e-13,
                            interrupt: Some(stop.clone()),
                            ..SimulationOptions::default()
                        },
                    )
                    .ok()?;
                    let end: Vec<f64> = sim.final_state();
                    let orbit = orbit_summary(&model, &end, 10.0 * t, 2560, 1e-9).ok()?;
                    Some((w / w0, 1e3 * orbit.max_displacement[0]))
                })
                .collect::<Vec<_>>()
                .into_iter()
                .flatten()
                .collect()
        };
        let (sweep, sweep_down) = rayon::join(from_rest, onward);
        // N = 2: the asymmetric branches from the first two pitchforks.
        let mut asymmetric: Vec<(Branch, String)> = Vec::new();
        if n == 2 {
            for label in ["BP1", "BP2"] {
                let Some(bp) = branch.special.iter().find(|s| s.label == label) else {
                    continue;
                };
                let switch_opts = ContinuationOptions {
                    max_points: 2000,
                    bounds: Some((0.5 * w0, 1.5 * w0)),
                    ..opts.clone()
                };
                let t0 = Instant::now();
                let switched = branch_switch_start(|w| row(n, w), bp, 1.5 * w0, &switch_opts, 0.02)
                    .and_then(|(p, x)| {
                        let target = if p >= bp.parameter {
                            1.5 * w0
                        } else {
                            0.5 * w0
                        };
                        continue_branch(|w| row(n, w), p, &x, target, &switch_opts, |_| true)
                    })
                    .map_err(|e| CliError::new(format!("R2 N = 2, switching at {label}: {e}")))?;
                eprintln!(
                    "R2 N = 2: asymmetric branch from {label}, {} points in {:.1} s ({})",
                    switched.points.len(),
                    t0.elapsed().as_secs_f64(),
                    switched.stop
                );
                asymmetric.push((switched, format!("asymmetric, from {label}")));
            }
        }
        let mut all: Vec<(&Branch, &str)> = vec![(&branch, "symmetric (in-phase)")];
        all.extend(asymmetric.iter().map(|(b, name)| (b, name.as_str())));
        let mut fig = crate::figures::branch_figure(
            &all,
            &format!("Frequency response of the seed's row, N = {n}"),
            "forcing frequency Ω/ω0",
            1.0 / w0,
            0,
        );
        fig.push(
            Series::markers("brute force from rest", sweep.clone(), Marker::Circle).with_color(6),
        );
        fig.push(
            Series::markers(
                "brute force downward, continued state",
                sweep_down.clone(),
                Marker::Circle,
            )
            .with_color(1),
        );
        // Head room above the data for the legend: 10 % of the data's span
        // per entry.
        let (lo, hi) = fig
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1))
            .filter(|y| y.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
                (a.min(y), b.max(y))
            });
        let entries = fig
            .series
            .iter()
            .filter(|s| s.label.as_deref().is_some_and(|l| !l.is_empty()))
            .count();
        if lo < hi {
            let span = hi - lo;
            fig = fig.y_range(lo - 0.05 * span, hi + 0.1 * entries as f64 * span);
        }
        let stem = format!("fig{}_frequency_response_n{n}", 7 + n);
        let rows = |b: &Branch| -> Vec<Vec<f64>> {
            b.points
                .iter()
                .map(|p| {
                    let mut r = vec![p.parameter / w0];
                    r.extend(p.max_displacement.iter().copied());
                    r.push(p.spectral_radius());
                    r.push(if p.stable { 1.0 } else { 0.0 });
                    r.push(p.impacts_per_period as f64);
                    r
                })
                .collect()
        };
        let mut columns = vec!["omega_over_omega0"];
        columns.extend(["max_u_p1", "max_u_p2", "max_u_p3"].iter().take(n));
        columns.extend(["largest_multiplier_modulus", "stable", "impacts_per_period"]);
        report.summary(
            &format!("r2_n{n}_branch"),
            serde_json::json!({"points": branch.points.len(), "stop": branch.stop.to_string(),
                "special_points": branch.special.iter().map(|s| serde_json::json!({"label": s.label, "kind": s.kind.name(), "omega_over_omega0": s.parameter / w0})).collect::<Vec<_>>()}),
        );
        for s in &branch.special {
            let mu = s
                .multipliers
                .iter()
                .map(|m| format!("{:.3}{:+.3}i", m.re, m.im))
                .collect::<Vec<_>>()
                .join(", ");
            table.push(vec![
                format!("N = {n}"),
                s.label.clone(),
                s.kind.name().to_string(),
                format!("{:.8}", s.parameter / w0),
                html_escape(&mu),
            ]);
        }
        let others: String = asymmetric
            .iter()
            .map(|(b, name)| {
                format!(
                    "; {name}: {} points, {} special points, {}",
                    b.points.len(),
                    b.special.len(),
                    b.stop
                )
            })
            .collect();
        let caption = format!(
            "Largest displacement of pendulum 1 over a period against the forcing frequency, N = {n}: periodic \
             solutions by continuation (solid stable, dashed unstable; symmetric branch: {} points, {} special points, \
             {}{others}) and the brute-force sweeps (circles), which settle on stable branches or wander where no \
             stable periodic orbit exists.",
            branch.points.len(),
            branch.special.len(),
            branch.stop
        );
        if n == 2 {
            report.section("Frequency response of the row: periodic solutions, stability and special points (seed parts I–II)", intro.clone());
            intro.clear();
        }
        report.figure(
            &fig,
            &stem,
            &caption,
            std::iter::once(DataFile::new(
                &format!("{stem}_branch.csv"),
                columns.clone(),
                rows(&branch),
            ))
            .chain(asymmetric.iter().enumerate().map(|(k, (b, _))| {
                DataFile::new(
                    &format!("{stem}_asymmetric_bp{}.csv", k + 1),
                    columns.clone(),
                    rows(b),
                )
            }))
            .chain(std::iter::once(DataFile::new(
                &format!("{stem}_sweep.csv"),
                vec!["omega_over_omega0", "max_u_p1_mm"],
                sweep.iter().map(|&(a, b)| vec![a, b]).collect(),
            )))
            .chain(std::iter::once(DataFile::new(
                &format!("{stem}_sweep_down.csv"),
                vec!["omega_over_omega0", "max_u_p1_mm"],
                sweep_down.iter().map(|&(a, b)| vec![a, b]).collect(),
            )))
            .collect(),
        )?;
        if n == 2 {
            // Against AUTO-07p: each AUTO point matched to ours of the same kind.
            let mut cmp = Vec::new();
            for (kind, auto) in AUTO_N2 {
                let ours = branch
                    .special
                    .iter()
                    .filter(|s| s.kind.name() == kind)
                    .min_by(|a, b| {
                        (a.parameter / w0 - auto)
                            .abs()
                            .total_cmp(&(b.parameter / w0 - auto).abs())
                    });
                cmp.push(match ours {
                    Some(o) => vec![
                        kind.to_string(),
                        format!("{auto:.7}"),
                        o.label.clone(),
                        format!("{:.7}", o.parameter / w0),
                        format!("{:+.1e}", o.parameter / w0 - auto),
                    ],
                    None => vec![
                        kind.to_string(),
                        format!("{auto:.7}"),
                        "missed".into(),
                        String::new(),
                        String::new(),
                    ],
                });
            }
            report.append_html(&format!(
                "<p>Special points of the N = 2 symmetric branch against AUTO-07p (bench/auto: orthogonal \
                 collocation, NTST 300, NCOL 4, adaptive mesh, forcing made autonomous by an appended oscillator). \
                 The differences are within AUTO's discretisation error (~5e-6); the same run times both tools on \
                 this branch (bench/auto/compare_branch.py: ours 0.78 s against AUTO 5.9 s with its branch-point \
                 location, 7.6×, and against a SciPy solve_ivp sweep of the same 225 frequencies, 1100×).</p>\n{}",
                html_table(&["kind", "AUTO-07p Ω/ω0", "ours", "Ω/ω0", "ours − AUTO"], &cmp)
            ));
        }
    }
    report.append_html(&format!(
        "<h3>Special points</h3>\n{}",
        html_table(
            &["system", "label", "kind", "Ω/ω0", "Floquet multipliers"],
            &table
        )
    ));
    Ok(())
}

/// Runs the default study into `out`.
pub fn run(out: &Path) -> Result<(), CliError> {
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
    checked(seed_part3(&mut report))?;
    checked(seed_row_time_history(&mut report, &stop))?;
    checked(seed_row_frequency_response(&mut report, &stop))?;
    let index = report.finish()?;
    println!(
        "report written: {} ({:.2} s)",
        index.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
