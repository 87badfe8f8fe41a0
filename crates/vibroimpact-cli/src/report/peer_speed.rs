//! Section "Continuation cost against AUTO-07p": the recorded peer
//! benchmarks of `bench/auto` (AUTO at the fastest configuration of its
//! settings scan for N = 2, and the cost growth with the row length N).
//! Times depend on the machine, and a ratio means something only when both
//! tools ran in the same benchmark run; so this section shows the recorded
//! run, with the commands that repeat it, and measures nothing itself.

use super::{html_table, DataFile, Report};
use crate::error::CliError;
use crate::plot::{Figure, LegendPosition, Marker, Series};

/// `python3 bench/auto/growth.py` of 2026-11-23 (results/growth-2026-11-23.*,
/// load 1.1–1.5): N, our wall time (s), our points, AUTO-07p's wall time at
/// its fastest passing NTST (s), AUTO's steps. The task: homotopy from rest
/// at 0.5 ω0, then the symmetric branch 0.5 → 0.537 ω0 with multipliers.
const GROWTH: [(usize, f64, usize, f64, usize); 4] = [
    (2, 0.073, 39, 0.36, 19),
    (4, 0.149, 43, 1.46, 32),
    (8, 0.309, 42, 13.59, 38),
    (16, 0.928, 48, 35.28, 36),
];

/// `python3 bench/auto/best_n2.py` of 2026-11-23 (R2 N = 2, 0.5 → 1.5 ω0):
/// ours, AUTO at its best on 1 and on 2 threads (s).
const BEST_N2: (f64, f64, f64) = (0.222, 1.609, 0.860);

/// Writes the section.
pub(super) fn render(report: &mut Report) -> Result<(), CliError> {
    let (ours, auto1, auto2) = BEST_N2;
    report.section(
        "Continuation cost against AUTO-07p (recorded benchmark)",
        format!(
            "<p>The R2 N = 2 branch 0.5 → 1.5 ω0 with Floquet multipliers at every point and its \
             seven special points: AUTO-07p at the fastest configuration of a 32-point scan of its \
             settings that still finds all seven to 1e-5 (NTST 400, NCOL 4, DS 0.005, DSMAX 0.05, \
             EPSL/EPSU 1e-6, EPSS 1e-5, branch points detected in the run) takes {auto1:.2} s on one \
             thread and {auto2:.2} s on two; <code>vibroimpact continue</code> with its defaults \
             {ours:.2} s, {:.1}× the faster AUTO run (2026-11-23, <code>python3 \
             bench/auto/best_n2.py</code>). Growth with the row length (<code>python3 \
             bench/auto/growth.py</code>): the same task for both tools at every N, the homotopy \
             from rest and the symmetric branch from 0.5 to 0.537 ω0 (for N ≥ 4 the branch folds \
             back at 0.538 ω0 in both tools); AUTO at the faster of NTST 200 and 400. AUTO's \
             collocation grows like NTST·(NCOL·NDIM)³ per step, our shooting like the monodromy's \
             N² columns times the integration.</p>\n{}",
            auto2.min(auto1) / ours,
            html_table(
                &["N", "ours (s)", "our points", "AUTO-07p (s)", "AUTO steps", "AUTO / ours"],
                &GROWTH
                    .iter()
                    .map(|&(n, o, op, a, ap)| {
                        vec![
                            n.to_string(),
                            format!("{o:.3}"),
                            op.to_string(),
                            format!("{a:.2}"),
                            ap.to_string(),
                            format!("{:.1}", a / o),
                        ]
                    })
                    .collect::<Vec<_>>(),
            )
        ),
    );
    let point = |k: usize| -> Vec<(f64, f64)> {
        GROWTH
            .iter()
            .map(|g| (g.0 as f64, if k == 0 { g.1 } else { g.3 }))
            .collect()
    };
    let mut fig = Figure::new(
        "Continuation cost against the row length N (R2, 0.5 → 0.537 ω0)",
        "bodies N",
        "wall time (s)",
    )
    .log_x()
    .log_y()
    .legend_at(LegendPosition::UpperLeft);
    for (k, (name, color)) in [("vibroimpact", 0), ("AUTO-07p", 3)]
        .into_iter()
        .enumerate()
    {
        fig.push(Series::line(name, point(k)).with_color(color));
        fig.push(Series::markers("", point(k), Marker::Circle).with_color(color));
    }
    let rows = GROWTH
        .iter()
        .map(|&(n, o, op, a, ap)| vec![n as f64, o, op as f64, a, ap as f64])
        .collect();
    report.figure(
        &fig,
        "continuation_cost_vs_n",
        "Wall time of the continuation against N, log–log (recorded run of bench/auto/growth.py, 2026-11-23).",
        vec![DataFile::new(
            "continuation_cost_vs_n.csv",
            vec!["n", "ours_s", "our_points", "auto_s", "auto_steps"],
            rows,
        )],
    )
}
