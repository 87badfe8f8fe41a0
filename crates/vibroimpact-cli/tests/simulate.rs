//! End-to-end tests of the default study's report and of `simulate`.

mod common;
use common::*;

/// The default study writes every figure as SVG and PNG with its data, an
/// index.html and summary.json; the same run gives the same bytes.
#[test]
fn default_study_report_is_complete_and_deterministic() {
    let a = temp_dir("report-a");
    let b = temp_dir("report-b");
    for dir in [&a, &b] {
        let out = bin().arg("--out").arg(dir).output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let index = std::fs::read_to_string(a.join("index.html")).unwrap();
    for stem in [
        "fig1_phase_trajectories",
        "fig2_restitution",
        "fig3_peak_force",
        "fig4_identify_restitution",
        "fig5_identify_alpha",
        "fig_map_chart_n1",
        "fig_map_chart_n2",
        "fig_map_diagram_n2",
        "fig_map_lyapunov_n2",
        "fig_map_basins_n2",
    ] {
        for ext in ["svg", "png"] {
            let f = a.join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&f)
                    .map(|m| m.len() > 1000)
                    .unwrap_or(false),
                "{f:?}"
            );
        }
        assert!(index.contains(&format!("{stem}.png")), "index lacks {stem}");
    }
    let mut names: Vec<_> = std::fs::read_dir(&a)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(names.iter().any(|n| n.to_string_lossy().ends_with(".csv")));
    assert!(
        !names.iter().any(|n| n.to_string_lossy().contains(".tmp")),
        "temporary files left: {names:?}"
    );
    for n in &names {
        assert_eq!(
            std::fs::read(a.join(n)).unwrap(),
            std::fs::read(b.join(n)).unwrap(),
            "{n:?} differs between runs"
        );
    }
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("summary.json")).unwrap()).unwrap();
    assert!(
        summary["max_abs_restitution_difference_integrated_vs_closed_form"]
            .as_f64()
            .unwrap()
            < 1e-9
    );
    // The maps: R2 N = 1's two folds give four fold curves (both ways from
    // each), its two branch points one closed curve; the basin fractions
    // add up to one.
    let kinds: Vec<&str> = summary["curves_n1"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["fold", "fold", "fold", "fold", "branch-point"]);
    let fractions: f64 = summary["basins_n2_fractions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_f64().unwrap())
        .sum();
    assert!((fractions - 1.0).abs() < 1e-12, "{fractions}");
    assert!(
        summary["chart_n2_cells_per_class"]["period 1"]
            .as_u64()
            .unwrap()
            > 100
    );
}

#[test]
fn simulate_example_row_json_and_outputs() {
    let model = repo_file("examples/fujita-row.toml");
    let doc = json(&["simulate", &model, "--periods", "5", "--format", "json"]);
    for key in [
        "final_time",
        "impact_count",
        "rhs_evaluations",
        "steps",
        "rejected_steps",
    ] {
        assert!(doc[key].is_number(), "missing {key}");
    }
    assert_eq!(doc["final_displacement"].as_array().unwrap().len(), 3);
    assert_eq!(doc["final_velocity"].as_array().unwrap().len(), 3);
    assert!(doc["impact_count"].as_u64().unwrap() > 10);
    let period = 2.0 * std::f64::consts::PI / 7.0395;
    assert!((doc["final_time"].as_f64().unwrap() - 5.0 * period).abs() < 1e-9);
    let dir = temp_dir("simulate-out");
    let out = run(&[
        "simulate",
        &model,
        "--duration",
        "2",
        "--out",
        &dir.display().to_string(),
        "--energy",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "history.csv",
        "impacts.csv",
        "summary.json",
        "displacements.png",
        "phase_portrait.svg",
        "impact_velocities.png",
    ] {
        assert!(dir.join(f).exists(), "{f} missing");
    }
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    assert!(history.starts_with("t,u_p1,u_p2,u_p3,v_p1,v_p2,v_p3\n"));
    let log = std::fs::read_to_string(dir.join("impacts.csv")).unwrap();
    assert!(log.starts_with("start_time,end_time,pair,impact_velocity,rebound_velocity,restitution,peak_force,duration,impacts,impulse,energy_lost\n"));
    assert!(log.lines().count() > 5);
}

#[test]
fn simulate_bad_models() {
    let dir = temp_dir("simulate-bad");
    let good = std::fs::read_to_string(repo_file("examples/fujita-row.toml")).unwrap();
    let cases: Vec<(&str, String, &str)> = vec![
        ("unknown.toml", good.replace("count = 3", "count = 3\ncolour = 1"), "unknown field `colour`"),
        ("missing.toml", good.replace("clearance = 0.001", ""), "missing field `clearance`"),
        ("mass.toml", good.replace("mass = 0.227", "mass = 0"), "mass = 0"),
        ("gap.toml", good.replace("clearance = 0.001 ", "clearance = -0.001 "), "clearance"),
        ("alpha.toml", good.replace("alpha = 1.3e5", "alpha = -1.0"), "alpha"),
        (
            "body.toml",
            "[[body]]\nname = \"a\"\nmass = 1.0\n[[contact]]\nbetween = [\"a\", \"b\"]\nclearance = 0.001\nlaw = { law = \"hertz\", stiffness = 1e9 }\n".into(),
            "unknown body `b`",
        ),
        (
            "overlap.toml",
            "[[body]]\nname = \"a\"\nmass = 1.0\ninitial_displacement = 0.002\n[[contact]]\nbetween = [\"a\", \"wall\"]\nclearance = 0.001\nlaw = { law = \"hertz\", stiffness = 1e9 }\n".into(),
            "overlap",
        ),
        (
            "nofile.toml",
            "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n[excitation]\ntype = \"accelerogram\"\nfile = \"missing.csv\"\n".into(),
            "missing.csv: cannot read the accelerogram",
        ),
    ];
    for (name, text, needle) in cases {
        let path = write_model(&dir, name, &text);
        let out_dir = dir.join(format!("{name}.out"));
        assert_clean_error(
            &[
                "simulate",
                &path,
                "--duration",
                "0.1",
                "--out",
                &out_dir.display().to_string(),
            ],
            needle,
        );
        assert!(
            !out_dir.exists(),
            "{name}: output written despite the error"
        );
    }
    std::fs::write(dir.join("back.csv"), "0,0\n1,1\n0.5,0\n").unwrap();
    let path = write_model(
        &dir,
        "back.toml",
        "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n[excitation]\ntype = \"accelerogram\"\nfile = \"back.csv\"\n",
    );
    assert_clean_error(&["simulate", &path, "--duration", "0.1"], "back.csv:3:");
    std::fs::write(dir.join("fwd.csv"), "0,0\n1,1\n2,0\n").unwrap();
    let path = write_model(
        &dir,
        "fwd.toml",
        &std::fs::read_to_string(&path)
            .unwrap()
            .replace("back.csv", "fwd.csv"),
    );
    assert_clean_error(
        &["simulate", &path, "--periods", "1"],
        "--periods needs a periodic excitation",
    );
    // A record is not extended with zeros.
    assert_clean_error(
        &["simulate", &path, "--duration", "3"],
        "the accelerogram ends at 2 s",
    );
    let ok = run(&["simulate", &path, "--duration", "2"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let model = repo_file("examples/fujita-row.toml");
    assert_clean_error(&["simulate", &model, "--duration", "-1"], "duration");
    assert_clean_error(
        &["simulate", &model, "--duration", "1", "--rtol", "0"],
        "rtol",
    );
    assert_clean_error(
        &[
            "simulate",
            &dir.join("nope.toml").display().to_string(),
            "--duration",
            "1",
        ],
        "cannot read",
    );
}

/// The explicit-form example (two buildings pounding under an accelerogram)
/// runs with every method and gives the same impacts.
#[test]
fn pounding_example_with_each_method() {
    let model = repo_file("examples/pounding-buildings.toml");
    let counts: Vec<u64> = ["dop853", "dopri5", "auto"]
        .iter()
        .map(|m| {
            let doc = json(&[
                "simulate",
                &model,
                "--duration",
                "20",
                "--method",
                m,
                "--format",
                "json",
            ]);
            assert_eq!(doc["completed"], true);
            doc["impact_count"].as_u64().unwrap()
        })
        .collect();
    assert!(
        counts[0] > 5 && counts.iter().all(|&c| c == counts[0]),
        "{counts:?}"
    );
}

/// A legal run that will take long says so up front on standard error
/// (estimated steps and time, and that the step limit or its pace ends
/// it); a forcing at 4.3e9 rad/s then stops at once for want of progress.
/// A run of ordinary length is silent.
#[test]
fn a_long_run_is_announced_up_front() {
    let dir = temp_dir("long-run");
    let row = repo_file("examples/fujita-row-n2.toml");
    let text = std::fs::read_to_string(&row)
        .unwrap()
        .replace("frequency = 7.0395", "frequency = 4.3e9");
    let fast = write_model(&dir, "fast.toml", &text);
    let out = run(&["simulate", &fast, "--duration", "10"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.starts_with("note: a long run: about ") && err.contains("far beyond the step limit"),
        "{err}"
    );
    let short = run(&["simulate", &row, "--periods", "20"]);
    assert!(short.status.success() && short.stderr.is_empty());
}

/// Rigid impacts from the command line (docs/theory.md §12): the shipped
/// impact oscillator settles on its closed-form orbit (U = 2.50361 m/s,
/// e = 0.8), logged as rigid with its impulse and loss; `--impacts soft`
/// integrates the wall's law instead; bad flags are refused by name.
#[test]
fn rigid_impacts_from_the_command_line() {
    let model = repo_file("examples/impact-oscillator.toml");
    let dir = temp_dir("rigid-impacts");
    let out = run(&[
        "simulate",
        &model,
        "--periods",
        "40",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let log = std::fs::read_to_string(dir.join("impacts.csv")).unwrap();
    let header: Vec<&str> = log.lines().next().unwrap().split(',').collect();
    let last: Vec<&str> = log.lines().last().unwrap().split(',').collect();
    let col = |name: &str| last[header.iter().position(|h| *h == name).unwrap()];
    assert_eq!(log.lines().count(), 41);
    assert_eq!(col("impacts"), "rigid");
    let u: f64 = col("impact_velocity").parse().unwrap();
    assert!((u / 2.503614666 - 1.0).abs() < 1e-6, "{u}");
    let impulse: f64 = col("impulse").parse().unwrap();
    assert!((impulse / (1.8 * u) - 1.0).abs() < 1e-12, "{impulse}");
    let lost: f64 = col("energy_lost").parse().unwrap();
    assert!((lost / (0.5 * u * u * 0.36) - 1.0).abs() < 1e-12, "{lost}");
    let soft = json(&[
        "simulate",
        &model,
        "--periods",
        "4",
        "--impacts",
        "soft",
        "--format",
        "json",
    ]);
    assert!(soft["contact_evaluations"].as_u64().unwrap() > 0, "{soft}");
    assert_clean_error(
        &[
            "simulate",
            &model,
            "--periods",
            "4",
            "--impacts",
            "soft",
            "--restitution",
            "0.5",
        ],
        "--restitution 0.5: a coefficient of restitution is for rigid impacts",
    );
    assert_clean_error(
        &["simulate", &model, "--periods", "4", "--restitution", "1.5"],
        "restitution = 1.5 is invalid: must lie in (0, 1]",
    );
    // The local integrator takes the jumps between exact motions: the same
    // orbit, no right-hand side.
    let summary = |integrator: &str| {
        json(&[
            "simulate",
            &model,
            "--periods",
            "40",
            "--integrator",
            integrator,
            "--format",
            "json",
        ])
    };
    let (global, local) = (summary("global"), summary("local"));
    assert_eq!(local["integrator"], "local", "{local}");
    assert_eq!(local["impact_count"], 40, "{local}");
    assert_eq!(local["rhs_evaluations"], 0, "{local}");
    let u = |s: &serde_json::Value| s["final_displacement"][0].as_f64().unwrap();
    assert!((u(&global) - u(&local)).abs() < 1e-8, "{global} {local}");
}
