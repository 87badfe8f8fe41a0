//! Section part "Identification from measured impacts" (seed §3, figures
//! 4–5): a/b and α fitted to the example data, sequentially as the seed and
//! jointly. [`compute`] fits and evaluates the curves; [`render`] writes.

use vibroimpact::contact::{ContactLaw, ForceForm};
use vibroimpact::identify::{Estimate, Identification};
use vibroimpact::impact::closed_form::ExponentialImpact;
use vibroimpact::model::reference;

use super::{estimate_text, html_table, logspace, DataFile, Report};
use crate::error::CliError;
use crate::measurements::Measurements;
use crate::plot::{Figure, LegendPosition, Marker, Series};

/// The example impact data shipped in `examples/seed-impacts/` (embedded so
/// the default study runs from any directory).
const EXAMPLE_RESTITUTION: &str = include_str!("../../../../examples/seed-impacts/restitution.csv");
const EXAMPLE_ACCELERATION: &str =
    include_str!("../../../../examples/seed-impacts/acceleration.csv");

/// The data of the section part.
pub(super) struct IdentificationStudy {
    pub data: Measurements,
    pub sequential: Identification,
    pub joint: Identification,
    /// Sequential estimates (a/b, α) and joint ones.
    pub estimates: [(Estimate, Estimate); 2],
    /// (U, e fitted, A fitted, e true, A true) on a grid of U.
    pub curves: Vec<[f64; 5]>,
}

/// Fits the example data both ways and evaluates the fitted and the true
/// relations.
pub(super) fn compute() -> Result<IdentificationStudy, CliError> {
    let bodies = reference::seed_bodies();
    let data = Measurements::parse(
        Some((EXAMPLE_RESTITUTION, "examples/seed-impacts/restitution.csv")),
        Some((
            EXAMPLE_ACCELERATION,
            "examples/seed-impacts/acceleration.csv",
        )),
    )?;
    let sequential = data.identify(bodies, None, false)?;
    let joint = data.identify(bodies, None, true)?;
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
    let fitted_law =
        ContactLaw::exponential_from_ratio(q.value, alpha.value, 1.0, ForceForm::Published)?;
    let fitted = ExponentialImpact::new(&fitted_law, bodies)?;
    let truth = ExponentialImpact::new(&reference::seed_law(), bodies)?;
    let mut curves = Vec::new();
    for u in logspace(0.02, 0.8, 200) {
        let (f, s) = (fitted.impact(u)?, truth.impact(u)?);
        curves.push([
            u,
            f.restitution,
            f.peak_acceleration[0],
            s.restitution,
            s.peak_acceleration[0],
        ]);
    }
    Ok(IdentificationStudy {
        data,
        sequential,
        joint,
        estimates: [(q, alpha), (qj, alphaj)],
        curves,
    })
}

/// CSV rows (U, measured, fitted, residual) of fit residuals.
fn residual_rows<'a>(
    residuals: impl Iterator<Item = &'a vibroimpact::identify::Residual>,
) -> Vec<Vec<f64>> {
    residuals
        .map(|r| vec![r.impact_velocity, r.measured, r.fitted, r.residual])
        .collect()
}

/// Appends the table and figures 4–5 to the current section.
pub(super) fn render(report: &mut Report, study: &IdentificationStudy) -> Result<(), CliError> {
    let (sequential, joint, data) = (&study.sequential, &study.joint, &study.data);
    let [(q, alpha), (qj, alphaj)] = study.estimates;
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
    render_fig4(report, study, &q)?;
    render_fig5(report, study, &alpha)
}

fn render_fig4(
    report: &mut Report,
    study: &IdentificationStudy,
    q: &Estimate,
) -> Result<(), CliError> {
    let (rest, _) = study.data.samples();
    let fit_e: Vec<(f64, f64)> = study.curves.iter().map(|c| (c[0], c[1])).collect();
    let seed_e: Vec<(f64, f64)> = study.curves.iter().map(|c| (c[0], c[3])).collect();
    let curve_rows: Vec<Vec<f64>> = study.curves.iter().map(|c| c.to_vec()).collect();
    let sequential = &study.sequential;
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
    Ok(())
}

fn render_fig5(
    report: &mut Report,
    study: &IdentificationStudy,
    alpha: &Estimate,
) -> Result<(), CliError> {
    let (_, acc) = study.data.samples();
    let fit_a: Vec<(f64, f64)> = study.curves.iter().map(|c| (c[0], c[2])).collect();
    let seed_a: Vec<(f64, f64)> = study.curves.iter().map(|c| (c[0], c[4])).collect();
    let sequential = &study.sequential;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The example data give back the values they were made from, within
    /// three standard errors, both ways.
    #[test]
    fn example_data_identify_the_seed_values() {
        let study = compute().unwrap();
        for (q, alpha) in study.estimates {
            assert!(
                (q.value - reference::A_OVER_B).abs() < 3.0 * q.std_error,
                "{q:?}"
            );
            assert!(
                (alpha.value - reference::ALPHA).abs() < 3.0 * alpha.std_error,
                "{alpha:?}"
            );
        }
        assert_eq!(study.curves.len(), 200);
    }
}
