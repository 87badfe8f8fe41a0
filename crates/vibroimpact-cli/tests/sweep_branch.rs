//! End-to-end tests of `sweep`, `periodic` and `continue`.

mod common;
use common::*;
use std::path::Path;

/// `sweep` on the example row: every value is reported, the outputs are
/// complete, and the result does not depend on thread scheduling.
#[test]
fn sweep_example_row_json_and_outputs() {
    let model = repo_file("examples/fujita-row.toml");
    let dir = temp_dir("sweep-row");
    let args = |out: &str| {
        vec![
            "sweep".to_string(),
            model.clone(),
            "--parameter".into(),
            "frequency".into(),
            "--from".into(),
            "7.0".into(),
            "--to".into(),
            "8.0".into(),
            "--points".into(),
            "3".into(),
            "--transient".into(),
            "10".into(),
            "--record".into(),
            "4".into(),
            "--up-down".into(),
            "--format".into(),
            "json".into(),
            "--out".into(),
            out.into(),
        ]
    };
    let a = dir.join("a").display().to_string();
    let b = dir.join("b").display().to_string();
    let run_args = |v: &Vec<String>| json(&v.iter().map(String::as_str).collect::<Vec<_>>());
    let doc = run_args(&args(&a));
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 6, "3 values, up and down");
    let params: Vec<f64> = points
        .iter()
        .map(|p| p["parameter"].as_f64().unwrap())
        .collect();
    assert_eq!(params, vec![7.0, 7.0, 7.5, 7.5, 8.0, 8.0]);
    for p in points {
        assert_eq!(p["completed"], true);
        assert_eq!(p["recorded_periods"], 4);
        let d = p["distinct_section_points"].as_u64().unwrap();
        assert!((1..=4).contains(&d), "{p}");
        let u = p["max_displacement"].as_array().unwrap();
        assert_eq!(u.len(), 3);
        assert!(u.iter().all(|x| x.as_f64().unwrap() > 0.0), "{p}");
        assert!(
            p["impacts_per_period"].as_f64().unwrap() > 0.0,
            "impacts at 1 mm gaps"
        );
    }
    assert_eq!(points[0]["direction"], "up");
    assert_eq!(points[1]["direction"], "down");
    for f in [
        "sweep.csv",
        "summary.json",
        "sweep.svg",
        "sweep.png",
        "sweep_amplitude.svg",
        "sweep_amplitude.png",
    ] {
        assert!(Path::new(&a).join(f).is_file(), "{f} missing");
    }
    let csv = std::fs::read_to_string(Path::new(&a).join("sweep.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "parameter,direction,section,u_p1,u_p2,u_p3,v_p1,v_p2,v_p3"
    );
    assert_eq!(lines.count(), 6 * 4, "one row per Poincaré sample");
    // The same run again gives the same bytes.
    run_args(&args(&b));
    for f in ["sweep.csv", "summary.json", "sweep.svg"] {
        assert_eq!(
            std::fs::read(Path::new(&a).join(f)).unwrap(),
            std::fs::read(Path::new(&b).join(f)).unwrap(),
            "{f} differs between runs"
        );
    }
    // Table output without --out.
    let out = run(&[
        "sweep",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "7",
        "--to",
        "7.2",
        "--points",
        "2",
        "--transient",
        "2",
        "--record",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.starts_with(" parameter") || text.contains("max|u_p1|"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 3);
}

/// R3, the linear limit: with gaps of 1 m nothing touches, and the recorded
/// max |u| is the exact steady-state amplitude
/// A / sqrt((w0² - W²)² + (2 ζ w0 W)²) (the transient has decayed by
/// exp(-ζ w0 t) ≈ e⁻⁵⁴ after 400 periods at W = 0.6 w0); one section point.
#[test]
fn sweep_linear_limit_matches_exact_amplitude() {
    let dir = temp_dir("sweep-r3");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
        .unwrap()
        .replace("clearance = 0.001 ", "clearance = 1.0 ");
    assert!(text.contains("clearance = 1.0"));
    let model = write_model(&dir, "r3.toml", &text);
    let (a, w0, zeta) = (0.05, 7.41, 0.013);
    let (w1, w2) = (0.6 * w0, 0.65 * w0);
    let doc = json(&[
        "sweep",
        &model,
        "--parameter",
        "frequency",
        "--from",
        &w1.to_string(),
        "--to",
        &w2.to_string(),
        "--points",
        "2",
        "--transient",
        "400",
        "--record",
        "5",
        "--format",
        "json",
    ]);
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    for (p, w) in points.iter().zip([w1, w2]) {
        // (serde_json parses floats to within an ulp)
        assert!((p["parameter"].as_f64().unwrap() - w).abs() < 1e-12);
        let exact = a / ((w0 * w0 - w * w).powi(2) + (2.0 * zeta * w0 * w).powi(2)).sqrt();
        for u in p["max_displacement"].as_array().unwrap() {
            let u = u.as_f64().unwrap();
            assert!(
                ((u - exact) / exact).abs() < 1e-4,
                "W = {w}: max|u| = {u}, exact {exact}"
            );
        }
        assert_eq!(p["distinct_section_points"], 1, "{p}");
        assert_eq!(p["impacts_per_period"].as_f64().unwrap(), 0.0);
        assert_eq!(p["completed"], true);
    }
}

/// `sweep --lyapunov`: in the linear limit (R3, N = 3) every exponent is
/// −ζω0 within its convergence estimate (all 2N by default up to 4
/// bodies); R2 N = 2 at 7.0 rad/s, where the Poincaré samples never
/// repeat, has a positive largest exponent and at 8.0 rad/s (a
/// quasi-periodic-looking cloud: 77 distinct samples of 200) none; the
/// figure is written. `--lyapunov 0` and `--record 1` are refused.
#[test]
fn sweep_lyapunov_exponents() {
    let dir = temp_dir("sweep-lyapunov");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
        .unwrap()
        .replace("clearance = 0.001 ", "clearance = 1.0 ");
    let r3 = write_model(&dir, "r3.toml", &text);
    let (w0, zeta) = (7.41, 0.013);
    let doc = json(&[
        "sweep",
        &r3,
        "--parameter",
        "frequency",
        "--from",
        "4.446",
        "--to",
        "4.8165",
        "--points",
        "2",
        "--transient",
        "400",
        "--record",
        "50",
        "--lyapunov",
        "--format",
        "json",
    ]);
    for p in doc["points"].as_array().unwrap() {
        let l = p["lyapunov"].as_array().unwrap();
        let u = p["lyapunov_uncertainty"].as_array().unwrap();
        assert_eq!(l.len(), 6, "{p}");
        for (l, u) in l.iter().zip(u) {
            let (l, u) = (l.as_f64().unwrap(), u.as_f64().unwrap());
            let err = (l + zeta * w0).abs();
            assert!(
                err <= u && err < 1e-3,
                "{l} vs {}: estimate {u}",
                -zeta * w0
            );
        }
    }
    let row = repo_file("examples/fujita-row-n2.toml");
    let out = dir.join("chaos");
    let doc = json(&[
        "sweep",
        &row,
        "--parameter",
        "frequency",
        "--from",
        "7.0",
        "--to",
        "8.0",
        "--points",
        "2",
        "--record",
        "200",
        "--lyapunov",
        "2",
        "--format",
        "json",
        "--out",
        out.to_str().unwrap(),
    ]);
    let largest = |k: usize| doc["points"][k]["lyapunov"][0].as_f64().unwrap();
    assert_eq!(doc["points"][0]["lyapunov"].as_array().unwrap().len(), 2);
    assert!(largest(0) > 0.3, "{}", largest(0));
    assert!(largest(1) < -0.05, "{}", largest(1));
    assert!(out.join("sweep_lyapunov.svg").is_file());
    let base = [
        "sweep",
        &row,
        "--parameter",
        "frequency",
        "--from",
        "7",
        "--to",
        "8",
        "--points",
        "2",
    ];
    for (extra, needle) in [
        (
            &["--lyapunov", "0"][..],
            "--lyapunov 0: between 1 and the state dimension 4",
        ),
        (&["--lyapunov", "5"][..], "--lyapunov 5"),
        (
            &["--lyapunov", "--record", "1"][..],
            "--record 1: record at least two periods",
        ),
    ] {
        assert_clean_error(&[&base[..], extra].concat(), needle);
    }
}

/// Bad input to `sweep`: one clean error line, non-zero exit; an integration
/// failure keeps the computed values and names the value that failed.
#[test]
fn sweep_bad_input_and_failures() {
    let model = repo_file("examples/fujita-row.toml");
    let base = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = ["sweep", &model, "--transient", "1", "--record", "2"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let check = |extra: &[&str], needle: &str| {
        let v = base(extra);
        assert_clean_error(&v.iter().map(String::as_str).collect::<Vec<_>>(), needle);
    };
    let range = ["--from", "7", "--to", "8", "--points", "3"];
    check(
        &[&["--parameter", "row.colour"][..], &range].concat(),
        "does not exist",
    );
    for (parameter, from, to, points, needle) in [
        ("frequency", "7", "8", "1", "at least 2"),
        ("frequency", "7", "7", "3", "give a range"),
        ("frequency", "nan", "7", "3", "finite"),
        ("frequency", "7", "inf", "3", "finite"),
        ("row.mass", "0.2", "-0.2", "3", "row.mass = 0:"),
    ] {
        check(
            &[
                "--parameter",
                parameter,
                "--from",
                from,
                "--to",
                to,
                "--points",
                points,
            ],
            needle,
        );
    }
    check(
        &[&["--parameter", "frequency", "--rtol", "0"][..], &range].concat(),
        "rtol",
    );
    check(
        &[&["--parameter", "row.contact.law"][..], &range].concat(),
        "not a number",
    );
    // No periodic forcing.
    let dir = temp_dir("sweep-bad");
    std::fs::write(dir.join("q.csv"), "0,0\n1,1\n2,0\n").unwrap();
    let quake = write_model(
        &dir,
        "quake.toml",
        "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n[excitation]\ntype = \"accelerogram\"\nfile = \"q.csv\"\n",
    );
    let out = run(&[
        "sweep",
        &quake,
        "--parameter",
        "row.mass",
        "--from",
        "1",
        "--to",
        "2",
        "--points",
        "2",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("periodic") && err.contains("row.mass = 1"),
        "{err}"
    );
}

/// An integration failure at one value of a sweep (a base acceleration
/// of 1e9 m/s² drives the bodies into the walls' stiff range, where the
/// explicit method gives up): the other value is kept, the failed one is
/// named.
#[test]
fn sweep_failure_keeps_the_other_values() {
    let model = repo_file("examples/fujita-row.toml");
    let out_dir = temp_dir("sweep-fail").join("fail");
    let out = run(&[
        "sweep",
        &model,
        "--parameter",
        "amplitude",
        "--from",
        "0",
        "--to",
        "1e9",
        "--points",
        "2",
        "--transient",
        "0",
        "--record",
        "2",
        "--format",
        "json",
        "--out",
        &out_dir.display().to_string(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "should fail");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("amplitude = 1000000000") && err.contains("1 of 2"),
        "{err}"
    );
    let doc: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("JSON is still printed");
    assert_eq!(doc["points"][0]["completed"], true);
    assert_eq!(doc["points"][0]["max_displacement"][0].as_f64(), Some(0.0));
    assert_eq!(doc["points"][1]["completed"], false);
    assert!(doc["points"][1]["error"]
        .as_str()
        .unwrap()
        .contains("stiff at t ="));
    assert!(out_dir.join("summary.json").is_file());
}

/// `periodic` and `continue` on the seed's row with N = 2: JSON contracts,
/// output files, and clean errors.
#[test]
fn periodic_and_continue_contracts() {
    let dir = temp_dir("branch");
    let model = write_model(
        &dir,
        "r2n2.toml",
        &std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
            .unwrap()
            .replace("count = 3", "count = 2"),
    );
    let doc = json(&["periodic", &model, "--format", "json"]);
    assert_eq!(doc["converged"], true);
    assert_eq!(doc["newton_stop"], "converged");
    // N = 3 at 0.95 ω0 has no period-1 orbit near the simulated guess (its
    // motion is irregular: where the guess lands, and so which way Newton
    // fails, depends on the last bits): the failure says why Newton
    // stopped and what to try, after the last iterate marked as such.
    let out = run(&["periodic", &repo_file("examples/fujita-row.toml")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        [
            "Newton did not converge: the iteration budget ran out",
            "Newton did not converge: no step along the Newton direction reduces"
        ]
        .iter()
        .any(|why| err.contains(why))
            && (err.contains("start from") || err.contains("try another guess")),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("NOT CONVERGED"));
    for key in [
        "period",
        "initial_state",
        "floquet_multipliers",
        "stable",
        "max_displacement",
        "impacts_per_period",
    ] {
        assert!(!doc[key].is_null(), "missing {key}");
    }
    assert_eq!(doc["floquet_multipliers"].as_array().unwrap().len(), 4);
    let out = dir.join("cont");
    let doc = json(&[
        "continue",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "8.0",
        "--to",
        "7.0",
        "--format",
        "json",
        "--out",
        &out.display().to_string(),
    ]);
    let points = doc["points"].as_array().unwrap();
    assert!(points.len() > 5);
    for p in points {
        assert!(
            p["parameter"].is_number()
                && p["max_displacement"].is_array()
                && p["stable"].is_boolean()
        );
        assert!(p["floquet_multipliers"].is_array());
    }
    let kinds: Vec<&str> = doc["special_points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"branch-point"), "{kinds:?}");
    for f in [
        "branch.csv",
        "branch_special_points.json",
        "branch_response.png",
        "branch_response.svg",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    assert_clean_error(
        &[
            "continue",
            &model,
            "--parameter",
            "colour",
            "--from",
            "7",
            "--to",
            "8",
        ],
        "does not exist",
    );
    assert_clean_error(
        &[
            "continue",
            &model,
            "--parameter",
            "frequency",
            "--from",
            "7",
            "--to",
            "7",
        ],
        "empty",
    );
    let unforced = write_model(&dir, "free.toml", "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n");
    assert_clean_error(&["periodic", &unforced], "no periodic forcing");
}

/// The brute-force sweep and shooting agree on R2 N = 2 at 1.5 ω0 (a stable
/// impacting orbit): max |u| to 1e-8, although the largest displacement is
/// a wall penetration far shorter than any output interval (both locate
/// the extrema on the dense output; sampled maxima were 2e-3 low).
#[test]
fn sweep_and_periodic_agree_on_the_stable_orbit() {
    let model = repo_file("examples/fujita-row-n2.toml");
    let sweep = json(&[
        "sweep",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "11.115",
        "--to",
        "11.1",
        "--points",
        "2",
        "--transient",
        "300",
        "--record",
        "5",
        "--rtol",
        "1e-10",
        "--atol",
        "1e-15",
        "--format",
        "json",
    ]);
    let dir = temp_dir("sweep-periodic");
    let file = dir.join("m.toml");
    let text = std::fs::read_to_string(&model)
        .unwrap()
        .replace("frequency = 7.0395", "frequency = 11.115");
    std::fs::write(&file, text).unwrap();
    let orbit = json(&["periodic", file.to_str().unwrap(), "--format", "json"]);
    assert_eq!(orbit["converged"], true);
    assert_eq!(orbit["stable"], true);
    for i in 0..2 {
        let at = sweep["points"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["parameter"] == 11.115)
            .unwrap();
        let a = at["max_displacement"][i].as_f64().unwrap();
        let b = orbit["max_displacement"][i].as_f64().unwrap();
        assert!(
            (a / b - 1.0).abs() < 1e-8,
            "body {i}: sweep {a} vs periodic {b}"
        );
    }
}

/// `--format csv` prints a table where the command has one (the same CSV as
/// the file in `--out`) and is refused where it prints a summary.
#[test]
fn csv_format_prints_tables_or_is_refused() {
    let model = repo_file("examples/fujita-row.toml");
    let out = run(&[
        "sweep",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "5.9",
        "--to",
        "8.9",
        "--points",
        "3",
        "--transient",
        "5",
        "--record",
        "2",
        "--format",
        "csv",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<&str> = text.lines().collect();
    assert!(rows[0].starts_with("parameter,"), "{}", rows[0]);
    assert!(
        rows.len() > 3
            && rows[1..]
                .iter()
                .all(|r| r.split(',').count() == rows[0].split(',').count())
    );
    for args in [
        vec!["simulate", &model, "--periods", "1"],
        vec!["periodic", &model],
        vec!["identify", "--restitution", &model],
    ] {
        let command = args[0];
        let out = run(&[args, vec!["--format", "csv"]].concat());
        assert_eq!(out.status.code(), Some(2), "{command}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("invalid value 'csv'") && err.contains("table, json"),
            "{err}"
        );
    }
}

/// R2 with N = 4 from 1.5 ω0: a simulated guess does not lead Newton to a
/// periodic orbit there; the default start falls back to the homotopy in
/// the forcing amplitude from rest and the branch starts.
#[test]
fn continue_starts_by_homotopy_where_simulation_does_not() {
    let dir = temp_dir("homotopy");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
        .unwrap()
        .replace("count = 3", "count = 4");
    let model = write_model(&dir, "r2n4.toml", &text);
    let args = |start: &'static str| -> Vec<&str> {
        vec![
            "continue",
            &model,
            "--parameter",
            "frequency",
            "--from",
            "11.115",
            "--to",
            "3.705",
            "--max-points",
            "4",
            "--format",
            "json",
            "--start",
            start,
        ]
    };
    for start in ["auto", "homotopy"] {
        let doc = json(&args(start));
        assert_eq!(doc["points"].as_array().unwrap().len(), 4, "{start}");
        assert_eq!(doc["points"][0]["parameter"], 11.115);
    }
}

/// Matrix-free continuation with an impossible Arnoldi dimension, and a
/// row too long for dense continuation, are refused with the remedy.
#[test]
fn continue_krylov_options_checked() {
    let model = repo_file("examples/fujita-row-n2.toml");
    let range = ["--parameter", "frequency", "--from", "7", "--to", "8"];
    // Too few Arnoldi vectors for a verdict are refused by the option's
    // name; more than the state's size 2N (the default 20 on a row of
    // three was refused as "between 6 and 6") is the whole state space, so
    // it is taken as 2N (issue 38).
    let args = [
        &["continue", &model, "--krylov", "--arnoldi", "1"][..],
        &range,
    ]
    .concat();
    assert_clean_error(&args, "--arnoldi: Arnoldi dimension 1: between 4");
    let row3 = repo_file("examples/fujita-row.toml");
    let out = run(&[
        "continue",
        &row3,
        "--krylov",
        "--parameter",
        "frequency",
        "--from",
        "11.1",
        "--to",
        "10.9",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = temp_dir("long-row");
    let text = std::fs::read_to_string(&model).unwrap();
    let long = write_model(
        &dir,
        "row.toml",
        &text.replacen("count = 2", "count = 2100", 1),
    );
    let args = [&["continue", &long, "--dense"][..], &range].concat();
    assert_clean_error(&args, "too large for dense continuation");
}

/// `chart`: a small (frequency, clearance) grid of the N = 2 row with two
/// starts a cell writes chart.json (cells row by row, runs per start),
/// chart.csv (a row per run) and the figure; start 0 of a cell is the
/// sweep's run at that value (same max |u| and impacts); bad input is
/// refused before any work.
#[test]
fn chart_grid_outputs_and_bad_input() {
    let dir = temp_dir("chart");
    let row = repo_file("examples/fujita-row-n2.toml");
    let out = dir.join("c");
    let doc = json(&[
        "chart",
        &row,
        "--x",
        "frequency",
        "--x-from",
        "6.5",
        "--x-to",
        "8.5",
        "--x-points",
        "3",
        "--y",
        "row.clearance",
        "--y-from",
        "1e-3",
        "--y-to",
        "2e-3",
        "--y-points",
        "2",
        "--transient",
        "20",
        "--record",
        "6",
        "--starts",
        "2",
        "--format",
        "json",
        "--out",
        out.to_str().unwrap(),
    ]);
    let cells = doc["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 6);
    assert_eq!(cells[1]["x"].as_f64().unwrap(), 7.5);
    assert_eq!(cells[3]["y"].as_f64().unwrap(), 2e-3);
    for c in cells {
        assert_eq!(c["runs"].as_array().unwrap().len(), 2, "{c}");
        assert!(c["attractors"].as_u64().unwrap() >= 1, "{c}");
    }
    let csv = std::fs::read_to_string(out.join("chart.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 12);
    assert!(csv.starts_with("frequency,row.clearance,start,attractors,period"));
    assert!(out.join("chart.svg").is_file() && out.join("chart.png").is_file());
    let sweep = json(&[
        "sweep",
        &row,
        "--parameter",
        "frequency",
        "--from",
        "6.5",
        "--to",
        "8.5",
        "--points",
        "3",
        "--transient",
        "20",
        "--record",
        "6",
        "--rtol",
        "1e-7",
        "--cluster-tolerance",
        "1e-3",
        "--format",
        "json",
    ]);
    for (c, p) in cells[..3].iter().zip(sweep["points"].as_array().unwrap()) {
        let max_u = p["max_displacement"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .fold(0.0, f64::max);
        assert_eq!(c["runs"][0]["max_displacement"].as_f64().unwrap(), max_u);
        assert_eq!(c["runs"][0]["impacts_per_period"], p["impacts_per_period"]);
    }
    let base = [
        "chart",
        &row,
        "--x",
        "frequency",
        "--x-from",
        "6.5",
        "--x-to",
        "8.5",
        "--y-from",
        "0.01",
        "--y-to",
        "0.1",
    ];
    let grid = ["--x-points", "3", "--y-points", "2"];
    for (extra, needle) in [
        (
            &[&grid[..], &["--y", "excitation.frequency"]].concat(),
            "the same key",
        ),
        (
            &[&grid[..], &["--y", "row.colour"]].concat(),
            "does not exist",
        ),
        (
            &[&grid[..], &["--y", "amplitude", "--starts", "0"]].concat(),
            "--starts 0",
        ),
        (
            &vec!["--y", "amplitude", "--x-points", "3", "--y-points", "1"],
            "--y-points 1",
        ),
        (
            &vec![
                "--y",
                "amplitude",
                "--x-points",
                "100000",
                "--y-points",
                "100000",
            ],
            "coarser grid",
        ),
        (
            &[&grid[..], &["--y", "row.count"]].concat(),
            "whole numbers",
        ),
    ] {
        let args = [&base[..], extra].concat();
        assert_clean_error(&args, needle);
    }
}

/// `basins`: a small (u1, v1) grid of the N = 2 row writes basins.json
/// (attractors with their fractions, one index per start), basins.csv and
/// the figure; a start overlapping the wall is not run; bad components and
/// a wrong --base are refused.
#[test]
fn basins_grid_outputs_and_bad_input() {
    let dir = temp_dir("basins");
    let row = repo_file("examples/fujita-row-n2.toml");
    let out = dir.join("b");
    let doc = json(&[
        "basins",
        &row,
        "--x",
        "u1",
        "--x-from",
        "-1.2e-3",
        "--x-to",
        "0.8e-3",
        "--x-points",
        "3",
        "--y",
        "v1",
        "--y-from",
        "-0.02",
        "--y-to",
        "0.02",
        "--y-points",
        "2",
        "--transient",
        "20",
        "--record",
        "6",
        "--format",
        "json",
        "--out",
        out.to_str().unwrap(),
    ]);
    let cells = doc["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 6);
    // u1 = −1.2 mm overlaps the left wall (gap 1 mm): not run.
    assert!(cells[0].is_null() && cells[3].is_null());
    assert_eq!(doc["inadmissible"], 2);
    let fractions: f64 = doc["attractors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["fraction"].as_f64().unwrap())
        .sum();
    assert!((fractions - 1.0).abs() < 1e-12, "{doc}");
    let csv = std::fs::read_to_string(out.join("basins.csv")).unwrap();
    assert_eq!(csv.lines().count(), 7);
    assert!(csv.starts_with("u1,v1,attractor"));
    assert!(out.join("basins.svg").is_file() && out.join("basins.png").is_file());
    let base = [
        "basins",
        &row,
        "--x-from",
        "-1e-4",
        "--x-to",
        "1e-4",
        "--x-points",
        "2",
        "--y-from",
        "-0.01",
        "--y-to",
        "0.01",
        "--y-points",
        "2",
    ];
    for (extra, needle) in [
        (&["--x", "u1", "--y", "u1"][..], "both u1"),
        (&["--x", "w1", "--y", "v1"][..], "--x: component `w1`"),
        (&["--x", "u1", "--y", "v3"][..], "--y: component `v3`"),
        (
            &["--x", "u1", "--y", "v1", "--base", "0,0,0"][..],
            "--base: needs 4 values",
        ),
    ] {
        assert_clean_error(&[&base[..], extra].concat(), needle);
    }
}

/// `continue --parameter2`: on R2 N = 1 the two folds and the symmetry-
/// breaking points are continued in (frequency, amplitude): the fold
/// curves start at the branch's folds at the model's amplitude, the two
/// branch points lie on one closed curve (followed once); the change of
/// the impact count at GR1 (an impact splitting in two, no contact
/// grazing) is listed as skipped; curves.json and the figure are written,
/// and drawn over a chart of the same plane.
#[test]
fn continue_two_parameter_curves() {
    let dir = temp_dir("curves");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row-n2.toml"))
        .unwrap()
        .replace("count = 2", "count = 1");
    let model = write_model(&dir, "n1.toml", &text);
    let out = dir.join("c");
    let doc = json(&[
        "continue",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "3.705",
        "--to",
        "11.115",
        "--parameter2",
        "amplitude",
        "--from2",
        "0.001",
        "--to2",
        "0.1",
        "--format",
        "json",
        "--out",
        out.to_str().unwrap(),
    ]);
    let special = doc["special_points"].as_array().unwrap();
    let curves = doc["curves"].as_array().unwrap();
    let kinds: Vec<&str> = curves.iter().map(|c| c["kind"].as_str().unwrap()).collect();
    assert_eq!(
        kinds,
        ["fold", "fold", "fold", "fold", "branch-point"],
        "{kinds:?}"
    );
    assert_eq!(curves[4]["stop"], "closed");
    let skipped = doc["curves_skipped"].as_array().unwrap();
    assert_eq!(skipped.len(), 1, "{skipped:?}");
    assert_eq!(skipped[0]["from"], "GR1");
    assert!(skipped[0]["reason"]
        .as_str()
        .unwrap()
        .contains("splits in two"));
    for c in &curves[..4] {
        let label = c["from"].as_str().unwrap();
        let s = special.iter().find(|s| s["label"] == label).unwrap();
        let first = &c["points"][0];
        let p = s["parameter"].as_f64().unwrap();
        assert!(
            (first["frequency"].as_f64().unwrap() - p).abs() < 1e-6 * p,
            "{first} vs {s}"
        );
        assert_eq!(first["amplitude"].as_f64().unwrap(), 0.05);
        assert_eq!(c["stop"], "left-bounds");
    }
    assert!(out.join("curves.json").is_file() && out.join("curves.svg").is_file());
    // The same curves from the branch.json of that run, without the branch.
    let again = dir.join("again");
    let branch_file = out.join("branch.json");
    let from_file = run(&[
        "continue",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "3.705",
        "--to",
        "11.115",
        "--parameter2",
        "amplitude",
        "--from2",
        "0.001",
        "--to2",
        "0.1",
        "--special-points",
        branch_file.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    assert!(
        from_file.status.success(),
        "{}",
        String::from_utf8_lossy(&from_file.stderr)
    );
    assert_eq!(
        std::fs::read(out.join("curves.json")).unwrap(),
        std::fs::read(again.join("curves.json")).unwrap()
    );
    // The curves over a chart of the same plane; a chart in another plane
    // refuses them.
    let curves_file = out.join("curves.json");
    let chart_dir = dir.join("chart");
    let grid = [
        "chart",
        &model,
        "--x-from",
        "4",
        "--x-to",
        "8",
        "--x-points",
        "3",
        "--y-from",
        "0.01",
        "--y-to",
        "0.05",
        "--y-points",
        "2",
        "--transient",
        "5",
        "--record",
        "4",
        "--overlay",
        curves_file.to_str().unwrap(),
    ];
    let ok = run(&[
        &grid[..],
        &[
            "--x",
            "frequency",
            "--y",
            "amplitude",
            "--out",
            chart_dir.to_str().unwrap(),
        ],
    ]
    .concat());
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let svg = std::fs::read_to_string(chart_dir.join("chart.svg")).unwrap();
    assert!(svg.contains("fold curve") && svg.contains("branch-point curve"));
    assert_clean_error(
        &[&grid[..], &["--x", "amplitude", "--y", "frequency"]].concat(),
        "curves in (frequency, amplitude), the chart is in (amplitude, frequency)",
    );
}

/// `continue --parameter2` refuses the same key twice, an unknown curve
/// kind, bounds that exclude the start, special points without a second
/// parameter and a file that is not a branch document.
#[test]
fn continue_two_parameter_bad_input() {
    let dir = temp_dir("curves-bad");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row-n2.toml"))
        .unwrap()
        .replace("count = 2", "count = 1");
    let model = write_model(&dir, "n1.toml", &text);
    let base = [
        "continue",
        &model,
        "--parameter",
        "frequency",
        "--from",
        "3.705",
        "--to",
        "11.115",
    ];
    for (extra, needle) in [
        (
            &["--parameter2", "excitation.frequency"][..],
            "the same key",
        ),
        (
            &["--parameter2", "amplitude", "--curves", "torus"][..],
            "--curves torus",
        ),
        (
            &["--parameter2", "amplitude", "--from2", "0.06"][..],
            "--from2 0.06",
        ),
        (
            &["--special-points", &model][..],
            "--parameter2 <PARAMETER2>",
        ),
        (
            &["--parameter2", "amplitude", "--special-points", &model][..],
            "not a branch.json",
        ),
    ] {
        assert_clean_error(&[&base[..], extra].concat(), needle);
    }
}

/// Rigid impacts and gravity from the command line (docs/theory.md §12):
/// the shipped bouncing ball's period-1 orbit has the closed form's
/// multipliers (−0.241599 ± 0.437756i at Γ = 1.3), and its branch in the
/// table's acceleration doubles its period at Γ_PD g = 14.97814050 m/s²
/// (the library's tests: to 1e-8).
#[test]
fn the_bouncing_ball_from_the_command_line() {
    let model = repo_file("examples/bouncing-ball.toml");
    let doc = json(&["periodic", &model, "--format", "json"]);
    assert_eq!(doc["converged"], true, "{doc}");
    assert_eq!(doc["impacts_per_period"], 1, "{doc}");
    for m in doc["floquet_multipliers"].as_array().unwrap() {
        let (re, im) = (m[0].as_f64().unwrap(), m[1].as_f64().unwrap());
        assert!(
            (re + 0.2415986).abs() < 1e-6 && (im.abs() - 0.4377558).abs() < 1e-6,
            "{m}"
        );
    }
    let doc = json(&[
        "continue",
        &model,
        "--parameter",
        "amplitude",
        "--from",
        "12.753",
        "--to",
        "16",
        "--format",
        "json",
    ]);
    let special = doc["special_points"].as_array().unwrap();
    assert_eq!(special.len(), 1, "{special:?}");
    assert_eq!(special[0]["kind"], "period-doubling");
    let p = special[0]["parameter"].as_f64().unwrap();
    assert!((p - 14.97814050).abs() < 1e-6, "{p}");
}

/// `--impacts` and `--restitution` reach every command that simulates
/// (issue 40): `periodic --restitution 0.6` shoots the impact oscillator
/// with e = 0.6, whose multipliers' product is e² e^{−2ζT} (the
/// saltation's determinant); `sweep`, `continue`, `chart` and `basins`
/// refuse a bad coefficient by the option's name.
#[test]
fn impact_options_on_every_command_that_simulates() {
    let model = repo_file("examples/impact-oscillator.toml");
    let doc = json(&[
        "periodic",
        &model,
        "--restitution",
        "0.6",
        "--format",
        "json",
    ]);
    assert_eq!(doc["converged"], true, "{doc}");
    let product = doc["floquet_multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m[0].as_f64().unwrap().hypot(m[1].as_f64().unwrap()))
        .product::<f64>();
    let period = 2.0 * std::f64::consts::PI / 1.5;
    let det = 0.36 * (-0.1 * period).exp();
    assert!((product / det - 1.0).abs() < 1e-6, "{product} vs {det}");
    let range = [
        "--parameter",
        "force.1.frequency",
        "--from",
        "1.4",
        "--to",
        "1.6",
    ];
    let grid = [
        "--x",
        "force.1.frequency",
        "--x-from",
        "1.4",
        "--x-to",
        "1.6",
        "--x-points",
        "2",
        "--y",
        "force.1.amplitude",
        "--y-from",
        "0.9",
        "--y-to",
        "1",
        "--y-points",
        "2",
    ];
    let bad = ["--impacts", "rigid", "--restitution", "1.5"];
    for command in [
        [
            &["sweep", &model, "--points", "2"][..],
            &range[..],
            &bad[..],
        ]
        .concat(),
        [&["continue", &model][..], &range[..], &bad[..]].concat(),
        [&["chart", &model][..], &grid[..], &bad[..]].concat(),
        [
            &[
                "basins",
                &model,
                "--x",
                "u1",
                "--x-from",
                "-1",
                "--x-to",
                "1",
                "--x-points",
                "2",
                "--y",
                "v1",
                "--y-from",
                "-1",
                "--y-to",
                "1",
                "--y-points",
                "2",
            ][..],
            &bad[..],
        ]
        .concat(),
    ] {
        assert_clean_error(
            &command,
            "--restitution: contact m|wall: rigid impacts: restitution = 1.5 is invalid",
        );
    }
}
