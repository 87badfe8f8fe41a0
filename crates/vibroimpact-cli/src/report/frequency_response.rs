//! Section "Frequency response of the row" (seed parts I–II): branches of
//! periodic solutions of R2 (N = 2 and 3) by continuation with stability
//! and special points, the asymmetric branches of N = 2, brute-force sweeps
//! over them, and the comparison with AUTO-07p. [`compute`] runs the
//! studies; [`render`] writes the section.

use std::time::Instant;

use vibroimpact::continuation::{
    branch_switch_start, continue_branch, Branch, ContinuationOptions,
};
use vibroimpact::integrate::Interrupt;
use vibroimpact::maps::sweep::{sweep, Direction, SweepOptions, SweepSummary};
use vibroimpact::model::family::of;
use vibroimpact::model::reference;
use vibroimpact::model::{Model, ModelError};
use vibroimpact::periodic::{guess_by_simulation_with, ShootingOptions};

use super::{html_escape, html_table, DataFile, Report};
use crate::error::CliError;
use crate::plot::{Figure, Marker, Series};

/// AUTO-07p's special points of the N = 2 symmetric branch (bench/auto,
/// results/compare-2026-11-22.txt: collocation, NTST 300, NCOL 4, adaptive
/// mesh); TR is AUTO's torus (Neimark–Sacker) point. (kind, Ω/ω0).
const AUTO_N2: [(&str, f64); 7] = [
    ("branch-point", 0.9831002),
    ("branch-point", 0.9493928),
    ("branch-point", 0.7945276),
    ("branch-point", 0.5524972),
    ("branch-point", 0.5340433),
    ("branch-point", 0.5094748),
    ("neimark-sacker", 0.5024794),
];

/// Frequencies of the brute-force sweeps: Ω/ω0 = 0.5 + k/60.
const SWEEP_POINTS: usize = 61;

/// The studies of one row size.
pub(super) struct RowResponse {
    pub n: usize,
    /// The symmetric (in-phase) branch from 1.5 ω0 down to 0.5 ω0.
    pub branch: Branch,
    /// N = 2: the asymmetric branches from BP1 and BP2, with their names.
    pub asymmetric: Vec<(Branch, String)>,
    /// (Ω/ω0, max |u1| in mm) from rest at every frequency.
    pub sweep: Vec<(f64, f64)>,
    /// The same downward, each frequency from the state the previous reached.
    pub sweep_down: Vec<(f64, f64)>,
}

fn row(n: usize, w: f64) -> Result<Model, ModelError> {
    reference::r2(n, reference::CLEARANCE, w)
}

/// Runs every study of the section; `stop` interrupts them.
pub(super) fn compute(stop: &Interrupt) -> Result<Vec<RowResponse>, CliError> {
    let w0 = reference::NATURAL_FREQUENCY;
    let mut rows = Vec::new();
    for n in [2usize, 3] {
        let start = row(n, 1.5 * w0)?;
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
        let branch = continue_branch(
            of("frequency", |w| row(n, w)),
            1.5 * w0,
            &guess,
            0.5 * w0,
            &opts,
            |_| true,
        )?;
        eprintln!(
            "R2 N = {n}: branch of {} points in {:.1} s",
            branch.points.len(),
            t0.elapsed().as_secs_f64()
        );
        let (sweep, sweep_down) = sweeps(n, stop)?;
        let asymmetric = if n == 2 {
            asymmetric_branches(n, &branch, &opts)?
        } else {
            Vec::new()
        };
        rows.push(RowResponse {
            n,
            branch,
            asymmetric,
            sweep,
            sweep_down,
        });
    }
    Ok(rows)
}

/// The brute-force sweeps of R2 N = `n` over 0.5–1.5 ω0 by the library's
/// sweep: from rest at every frequency (150 transient periods), and
/// downward from 1.5 ω0, each frequency from the state the previous one
/// reached (100 periods): (Ω/ω0, max |u1| in mm over 10 recorded periods),
/// the values that completed.
type Sweeps = (Vec<(f64, f64)>, Vec<(f64, f64)>);
fn sweeps(n: usize, stop: &Interrupt) -> Result<Sweeps, CliError> {
    let w0 = reference::NATURAL_FREQUENCY;
    let values: Vec<f64> = (0..SWEEP_POINTS)
        .map(|k| (0.5 + k as f64 / 60.0) * w0)
        .collect();
    let options = |transient, only: Option<Direction>| SweepOptions {
        transient,
        record: 10,
        up_down: only.is_some(),
        only,
        rtol: Some(1e-9),
        atol: Some(1e-13),
        interrupt: Some(stop.clone()),
        ..SweepOptions::default()
    };
    let run = |transient, only| {
        let family = of("frequency", |w| row(n, w));
        sweep(family, &values, &options(transient, only), &|| {})
    };
    let amplitudes = |s: SweepSummary| -> Vec<(f64, f64)> {
        s.points
            .iter()
            .filter(|p| p.error.is_none())
            .map(|p| (p.parameter / w0, 1e3 * p.max_displacement[0]))
            .collect()
    };
    // The downward sweep goes one value after the other: beside the other.
    let (rest, down) = rayon::join(|| run(150, None), || run(100, Some(Direction::Down)));
    let (rest, mut down) = (amplitudes(rest?), amplitudes(down?));
    down.reverse();
    Ok((rest, down))
}

/// The asymmetric branches born at the first two pitchforks (N = 2).
fn asymmetric_branches(
    n: usize,
    branch: &Branch,
    opts: &ContinuationOptions,
) -> Result<Vec<(Branch, String)>, CliError> {
    let w0 = reference::NATURAL_FREQUENCY;
    let mut out = Vec::new();
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
        let switched = branch_switch_start(
            of("frequency", |w| row(n, w)),
            bp,
            (1.5 * w0, 0.5 * w0),
            &switch_opts,
            0.02,
        )
        .and_then(|(p, x)| {
            let target = if p >= bp.parameter {
                1.5 * w0
            } else {
                0.5 * w0
            };
            continue_branch(
                of("frequency", |w| row(n, w)),
                p,
                &x,
                target,
                &switch_opts,
                |_| true,
            )
        })
        .map_err(|e| CliError::new(format!("R2 N = 2, switching at {label}: {e}")))?;
        eprintln!(
            "R2 N = 2: asymmetric branch from {label}, {} points in {:.1} s ({})",
            switched.points.len(),
            t0.elapsed().as_secs_f64(),
            switched.stop
        );
        out.push((switched, format!("asymmetric, from {label}")));
    }
    Ok(out)
}

const INTRO: &str = "<p>Periodic solutions of the row (the seed's parts I–II) found by shooting (Newton on the period map, \
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
     BP2 returns to the symmetric branch at BP3 and stops there (the rest is its mirror image).</p>\n";

/// Writes the section: per row size the response figure with its data, the
/// comparison with AUTO-07p (N = 2), then the table of special points.
pub(super) fn render(report: &mut Report, rows: &[RowResponse]) -> Result<(), CliError> {
    let mut table = Vec::new();
    for (k, r) in rows.iter().enumerate() {
        if k == 0 {
            report.section(
                "Frequency response of the row: periodic solutions, stability and special points (seed parts I–II)",
                INTRO.to_string(),
            );
        }
        table.extend(render_row(report, r)?);
        if r.n == 2 {
            render_auto_comparison(report, &r.branch);
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

/// The response figure of one row size: branches, sweeps, and head room
/// above the data for the legend (10 % of the data's span per entry).
fn response_figure(r: &RowResponse) -> Figure {
    let w0 = reference::NATURAL_FREQUENCY;
    let mut all: Vec<(&Branch, &str)> = vec![(&r.branch, "symmetric (in-phase)")];
    all.extend(r.asymmetric.iter().map(|(b, name)| (b, name.as_str())));
    let mut fig = crate::figures::branch_figure(
        &all,
        &format!("Frequency response of the seed's row, N = {}", r.n),
        "forcing frequency Ω/ω0",
        1.0 / w0,
        0,
    );
    fig.push(
        Series::markers("brute force from rest", r.sweep.clone(), Marker::Circle).with_color(6),
    );
    fig.push(
        Series::markers(
            "brute force downward, continued state",
            r.sweep_down.clone(),
            Marker::Circle,
        )
        .with_color(1),
    );
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
    fig
}

/// CSV rows of a branch: Ω/ω0, max |u_i|, largest |multiplier|, stable,
/// impacts per period.
fn branch_rows(b: &Branch) -> Vec<Vec<f64>> {
    let w0 = reference::NATURAL_FREQUENCY;
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
}

/// Writes one row size's figure and data; returns its special-point rows.
fn render_row(report: &mut Report, r: &RowResponse) -> Result<Vec<Vec<String>>, CliError> {
    let (n, branch, w0) = (r.n, &r.branch, reference::NATURAL_FREQUENCY);
    let stem = format!("fig{}_frequency_response_n{n}", 7 + n);
    let mut columns = vec!["omega_over_omega0"];
    columns.extend(["max_u_p1", "max_u_p2", "max_u_p3"].iter().take(n));
    columns.extend(["largest_multiplier_modulus", "stable", "impacts_per_period"]);
    report.summary(
        &format!("r2_n{n}_branch"),
        serde_json::json!({"points": branch.points.len(), "stop": branch.stop.to_string(),
            "special_points": branch.special.iter().map(|s| serde_json::json!({"label": s.label, "kind": s.kind.name(), "omega_over_omega0": s.parameter / w0})).collect::<Vec<_>>()}),
    );
    let table = branch
        .special
        .iter()
        .map(|s| {
            let mu = s
                .multipliers
                .iter()
                .map(|m| format!("{:.3}{:+.3}i", m.re, m.im))
                .collect::<Vec<_>>()
                .join(", ");
            vec![
                format!("N = {n}"),
                s.label.clone(),
                s.kind.name().to_string(),
                format!("{:.8}", s.parameter / w0),
                html_escape(&mu),
            ]
        })
        .collect();
    let others: String = r
        .asymmetric
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
    let sweep_file = |suffix: &str, data: &[(f64, f64)]| {
        DataFile::new(
            &format!("{stem}_{suffix}.csv"),
            vec!["omega_over_omega0", "max_u_p1_mm"],
            data.iter().map(|&(a, b)| vec![a, b]).collect(),
        )
    };
    let files = std::iter::once(DataFile::new(
        &format!("{stem}_branch.csv"),
        columns.clone(),
        branch_rows(branch),
    ))
    .chain(r.asymmetric.iter().enumerate().map(|(k, (b, _))| {
        DataFile::new(
            &format!("{stem}_asymmetric_bp{}.csv", k + 1),
            columns.clone(),
            branch_rows(b),
        )
    }))
    .chain([
        sweep_file("sweep", &r.sweep),
        sweep_file("sweep_down", &r.sweep_down),
    ])
    .collect();
    report.figure(&response_figure(r), &stem, &caption, files)?;
    Ok(table)
}

/// The N = 2 special points against AUTO-07p's, each matched to ours of the
/// same kind.
fn render_auto_comparison(report: &mut Report, branch: &Branch) {
    let w0 = reference::NATURAL_FREQUENCY;
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
         The differences are within AUTO's discretisation error (~5e-6). Timing: the section on the \
         continuation cost below; a SciPy solve_ivp sweep of as many frequencies as the branch has points \
         costs about 1100× ours (bench/auto/compare_branch.py).</p>\n{}",
        html_table(&["kind", "AUTO-07p Ω/ω0", "ours", "Ω/ω0", "ours − AUTO"], &cmp)
    ));
}
