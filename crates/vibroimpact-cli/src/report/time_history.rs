//! Section "The seed's row near resonance" (R2, N = 3): a time history with
//! its impact log, and the logged impacts over the two-body relations of
//! part III. [`compute`] simulates; [`render`] writes the section.

use vibroimpact::impact::closed_form::ExponentialImpact;
use vibroimpact::impact::TwoBodies;
use vibroimpact::integrate::Interrupt;
use vibroimpact::model::reference;
use vibroimpact::model::Model;
use vibroimpact::simulate::{simulate, ImpactRecord, Simulation, SimulationOptions};

use super::{html_escape, html_table, logspace, DataFile, Report};
use crate::error::CliError;
use crate::plot::{Figure, LegendPosition, Marker, Series};

/// Forcing periods simulated.
const PERIODS: f64 = 20.0;

/// The data of the section: the model and its simulation.
pub(super) struct RowHistory {
    pub model: Model,
    pub sim: Simulation,
}

/// Simulates R2 with N = 3 at 0.95 ω0 from rest over 20 periods (energy
/// balance on, samples every 1/200 period); `stop` interrupts it.
pub(super) fn compute(stop: &Interrupt) -> Result<RowHistory, CliError> {
    let omega = 0.95 * reference::NATURAL_FREQUENCY;
    let model = reference::r2(3, reference::CLEARANCE, omega)?;
    let period = 2.0 * std::f64::consts::PI / omega;
    let opts = SimulationOptions {
        t_end: PERIODS * period,
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
    Ok(RowHistory { model, sim })
}

/// Writes the section: introduction with the impact table, figures 6–8.
pub(super) fn render(report: &mut Report, data: &RowHistory) -> Result<(), CliError> {
    render_intro(report, data)?;
    render_displacements(report, data)?;
    render_impacts(report, data)
}

fn render_intro(report: &mut Report, data: &RowHistory) -> Result<(), CliError> {
    let (model, sim, m) = (&data.model, &data.sim, reference::MASS);
    let periods = PERIODS;
    let summary = vibroimpact::results::simulation_summary(model, sim);
    report.summary("r2_n3_simulation", serde_json::to_value(&summary)?);
    let energy = summary.energy.as_ref().map_or(0.0, |e| e.residual);
    let mut counts = Vec::new();
    for (k, c) in summary.impacts_per_contact.iter().enumerate() {
        let imps: Vec<_> = sim
            .impacts
            .iter()
            .filter(|i| i.contact == k && i.complete())
            .collect();
        let mean = |f: &dyn Fn(&ImpactRecord) -> f64| {
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
    Ok(())
}

fn render_displacements(report: &mut Report, data: &RowHistory) -> Result<(), CliError> {
    let sim = &data.sim;
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
    Ok(())
}

/// Complete impacts and the closed-form curves over their velocity range.
fn render_impacts(report: &mut Report, data: &RowHistory) -> Result<(), CliError> {
    let (model, sim, m) = (&data.model, &data.sim, reference::MASS);
    let law = reference::seed_law();
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
    let pts = |wall_side: bool, f: &dyn Fn(&ImpactRecord) -> f64| -> Vec<(f64, f64)> {
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
    render_peak_accelerations(report, m, (a_ball, a_wall), &pts)
}

/// Points of a curve or a scatter.
type Points = Vec<(f64, f64)>;

/// The logged impacts of one side (wall or not) as (U, f(impact)) points.
type ImpactPoints<'a> = &'a dyn Fn(bool, &dyn Fn(&ImpactRecord) -> f64) -> Points;

/// Figure 8 from the closed-form curves and the row's impacts.
fn render_peak_accelerations(
    report: &mut Report,
    m: f64,
    (a_ball, a_wall): (Points, Points),
    pts: ImpactPoints<'_>,
) -> Result<(), CliError> {
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
