//! End-to-end tests of the `vibroimpact` binary: output contracts, bad input
//! and the default study's report.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_vibroimpact"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("binary runs")
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// A fresh temporary directory for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vibroimpact-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn repo_file(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
        .display()
        .to_string()
}

/// Bad input: non-zero exit, one `error:` line naming the problem, no panic.
fn assert_clean_error(args: &[&str], needle: &str) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: expected `{needle}` in: {err}"
    );
    assert!(out.stdout.is_empty(), "{args:?} printed output on failure");
}

#[test]
fn impact_closed_form_json_reproduces_theory_table() {
    // V = U/1.2 = 0.01, 0.1, 1, 10.
    let doc = json(&[
        "impact",
        "--a-over-b",
        "1.2",
        "--alpha",
        "1.3e5",
        "--mass1",
        "0.227",
        "--mass2",
        "0.227",
        "--velocity",
        "0.012,0.12,1.2,12",
        "--format",
        "json",
    ]);
    let rows = doc["rows"].as_array().unwrap();
    let expect = [
        (0.01, 0.99337745439877, 4.96703803e-05),
        (0.1, 0.937475579950, 4.70080031e-03),
        (1.0, 0.593624260040, 3.50368739e-01),
        (10.0, 0.099981624753, 2.64635581e+01),
    ];
    for (row, (v, e, f)) in rows.iter().zip(expect) {
        assert!((row["v"].as_f64().unwrap() - v).abs() < 1e-14);
        assert!((row["restitution"].as_f64().unwrap() - e).abs() < 1e-12);
        let fd = row["peak_force_dimensionless"].as_f64().unwrap();
        assert!((fd / f - 1.0).abs() < 1e-9);
        // F = f μ α (a/b)² with μ = 0.1135.
        let force = row["peak_force"].as_f64().unwrap();
        assert!((force / (fd * 0.1135 * 1.3e5 * 1.44) - 1.0).abs() < 1e-12);
        assert!((row["peak_acceleration1"].as_f64().unwrap() - force / 0.227).abs() < 1e-9 * force);
        assert!(row.get("contact_duration").is_none());
    }
    assert_eq!(doc["contact_law"]["form"], "published");
}

#[test]
fn impact_integrate_agrees_with_closed_form() {
    let args = |method: &'static str| {
        vec![
            "impact",
            "--velocity",
            "0.001:10:7log",
            "--method",
            method,
            "--format",
            "json",
        ]
    };
    let cf = json(&args("closed-form"));
    let di = json(&args("integrate"));
    let (a, b) = (
        cf["rows"].as_array().unwrap(),
        di["rows"].as_array().unwrap(),
    );
    assert_eq!(a.len(), 7);
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x["restitution"].as_f64().unwrap() - y["restitution"].as_f64().unwrap()).abs() < 1e-9
        );
        assert!(y["contact_duration"].as_f64().unwrap() > 0.0);
        assert!(
            (x["peak_force"].as_f64().unwrap() / y["peak_force"].as_f64().unwrap() - 1.0).abs()
                < 1e-8
        );
    }
}

#[test]
fn impact_other_laws_wall_and_formats() {
    let doc = json(&[
        "impact",
        "--law",
        "hertz",
        "--stiffness",
        "5e9",
        "--mass2",
        "wall",
        "--velocity",
        "0.1,0.2",
        "--format",
        "json",
    ]);
    assert_eq!(doc["method"], "integrate");
    assert_eq!(doc["mass2"], "wall");
    for row in doc["rows"].as_array().unwrap() {
        assert!((row["restitution"].as_f64().unwrap() - 1.0).abs() < 1e-9);
        assert!(row["v"].is_null());
        assert_eq!(row["peak_acceleration2"].as_f64().unwrap(), 0.0);
    }
    let csv = run(&["impact", "--velocity", "0.1,0.2", "--format", "csv"]);
    let text = String::from_utf8(csv.stdout).unwrap();
    assert!(text.starts_with("impact_velocity,v,restitution,"));
    assert_eq!(text.lines().count(), 3);
    let table = run(&["impact", "--velocity", "0.1"]);
    assert!(table.status.success());
    assert!(String::from_utf8(table.stdout)
        .unwrap()
        .contains("restitution"));
}

#[test]
fn impact_bad_input() {
    assert_clean_error(&["impact", "--mass1", "-1", "--velocity", "0.1"], "mass1");
    assert_clean_error(&["impact", "--alpha", "0", "--velocity", "0.1"], "alpha");
    assert_clean_error(
        &["impact", "--a-over-b", "-2", "--velocity", "0.1"],
        "a_over_b",
    );
    assert_clean_error(&["impact", "--velocity", "0.1,-0.2"], "must be > 0");
    assert_clean_error(&["impact", "--velocity", "0.1,abc"], "not a number");
    assert_clean_error(&["impact", "--velocity", "1:2"], "range");
    assert_clean_error(
        &["impact", "--law", "hertz", "--velocity", "0.1"],
        "--stiffness",
    );
    assert_clean_error(
        &[
            "impact",
            "--law",
            "hertz",
            "--stiffness",
            "1e9",
            "--method",
            "closed-form",
            "--velocity",
            "0.1",
        ],
        "only for the exponential law",
    );
}

fn identify_example(extra: &[&str]) -> serde_json::Value {
    let r = repo_file("examples/seed-impacts/restitution.csv");
    let a = repo_file("examples/seed-impacts/acceleration.csv");
    let mut args = vec![
        "identify",
        "--restitution",
        &r,
        "--acceleration",
        &a,
        "--mass1",
        "0.227",
        "--mass2",
        "0.227",
        "--format",
        "json",
    ];
    args.extend_from_slice(extra);
    json(&args)
}

/// The shipped example data were made from a/b = 1.2 m/s, alpha = 1.3e5 1/m:
/// the fit recovers them within three standard errors.
#[test]
fn identify_recovers_the_values_the_example_was_made_from() {
    for extra in [&[][..], &["--joint"][..]] {
        let doc = identify_example(extra);
        let (q, sq) = (
            doc["a_over_b"]["value"].as_f64().unwrap(),
            doc["a_over_b"]["std_error"].as_f64().unwrap(),
        );
        let (al, sa) = (
            doc["alpha"]["value"].as_f64().unwrap(),
            doc["alpha"]["std_error"].as_f64().unwrap(),
        );
        assert!(
            sq > 0.0 && sq < 0.1 && (q - 1.2).abs() < 3.0 * sq,
            "{extra:?}: a/b = {q} ± {sq}"
        );
        assert!(
            sa > 0.0 && sa < 1e4 && (al - 1.3e5).abs() < 3.0 * sa,
            "{extra:?}: alpha = {al} ± {sa}"
        );
    }
    let fixed = identify_example(&["--a-over-b", "1.2"]);
    assert_eq!(fixed["a_over_b"]["std_error"].as_f64().unwrap(), 0.0);
    assert_eq!(fixed["method"], "alpha-given-a-over-b");
}

#[test]
fn identify_bad_input_names_file_and_line() {
    let dir = temp_dir("identify-bad");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let header = write("header.csv", "velocity,e\n0.1,0.9\n0.2,0.8\n");
    assert_clean_error(
        &["identify", "--restitution", &header],
        "header.csv:1: wrong header",
    );
    let cell = write(
        "cell.csv",
        "# comment\nimpact_velocity,restitution\n0.1,0.9\n0.2,zero\n",
    );
    assert_clean_error(
        &["identify", "--restitution", &cell],
        "cell.csv:4: column `restitution`: `zero` is not a number",
    );
    let one = write("one.csv", "impact_velocity,restitution\n0.1,0.9\n");
    assert_clean_error(
        &["identify", "--restitution", &one],
        "too few restitution points",
    );
    let neg = write(
        "neg.csv",
        "impact_velocity,restitution\n0.1,0.9\n-0.2,0.8\n",
    );
    assert_clean_error(
        &["identify", "--restitution", &neg],
        "neg.csv:3: impact_velocity = -0.2",
    );
    let elastic = write(
        "elastic.csv",
        "impact_velocity,restitution\n0.1,1.0\n0.2,1.0\n0.3,1.0\n",
    );
    assert_clean_error(
        &["identify", "--restitution", &elastic],
        "do not identify a/b",
    );
    let empty = write("empty.csv", "");
    assert_clean_error(&["identify", "--restitution", &empty], "empty.csv");
    assert_clean_error(
        &[
            "identify",
            "--restitution",
            &dir.join("missing.csv").display().to_string(),
        ],
        "cannot read",
    );
    assert_clean_error(&["identify"], "nothing to identify");
}

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
    assert!(log.starts_with("start_time,end_time,pair,impact_velocity,rebound_velocity,restitution,peak_force,duration\n"));
    assert!(log.lines().count() > 5);
}

fn write_model(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
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
    let ok = run(&["simulate", &path, "--duration", "3"]);
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
    let counts: Vec<u64> = ["dop853", "auto"]
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
    assert!(counts[0] > 5 && counts[0] == counts[1], "{counts:?}");
}

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
        "parameter,direction,period,u_p1,u_p2,u_p3,v_p1,v_p2,v_p3"
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

/// Bad input to `sweep`: one clean error line, non-zero exit; an integration
/// failure keeps the computed values and names the value that failed.
#[test]
fn sweep_bad_input_and_failures() {
    let model = repo_file("examples/fujita-row.toml");
    let base = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = ["sweep", &model, "--transient", "1", "--record", "1"]
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
    check(
        &[
            "--parameter",
            "frequency",
            "--from",
            "7",
            "--to",
            "8",
            "--points",
            "1",
        ],
        "at least 2",
    );
    check(
        &[
            "--parameter",
            "frequency",
            "--from",
            "7",
            "--to",
            "7",
            "--points",
            "3",
        ],
        "give a range",
    );
    check(
        &[
            "--parameter",
            "frequency",
            "--from",
            "nan",
            "--to",
            "7",
            "--points",
            "3",
        ],
        "finite",
    );
    check(
        &[
            "--parameter",
            "frequency",
            "--from",
            "7",
            "--to",
            "inf",
            "--points",
            "3",
        ],
        "finite",
    );
    check(
        &[
            "--parameter",
            "row.mass",
            "--from",
            "0.2",
            "--to",
            "-0.2",
            "--points",
            "3",
        ],
        "row.mass = 0:",
    );
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
    // An integration failure at one value (an impossible tolerance once the
    // bodies move): the other value is kept, the failed one is named.
    let out_dir = dir.join("fail");
    let out = run(&[
        "sweep",
        &model,
        "--parameter",
        "amplitude",
        "--from",
        "0",
        "--to",
        "0.05",
        "--points",
        "2",
        "--transient",
        "0",
        "--record",
        "2",
        "--rtol",
        "1e-18",
        "--atol",
        "1e-30",
        "--format",
        "json",
        "--out",
        &out_dir.display().to_string(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "should fail");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("amplitude = 0.05") && err.contains("1 of 2"),
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
        .contains("step size"));
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
    // N = 3 at 0.95 ω0 has no period-1 orbit near the simulated guess: the
    // failure says why Newton stopped and what to try, after the last
    // iterate marked as such.
    let out = run(&["periodic", &repo_file("examples/fujita-row.toml")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("Newton did not converge: the iteration budget ran out"),
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

/// Output into a closed pipe ends the command quietly (no panic message).
#[cfg(unix)]
#[test]
fn closed_pipe_ends_quietly() {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = bin()
        .args([
            "impact",
            "--velocity",
            "0.001:10:20000log",
            "--format",
            "json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 16];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    // The reading end is dropped here: the rest of the output meets a closed pipe.
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_ne!(out.status.code(), Some(101), "{stderr}");
}

/// Ctrl-C in a sweep keeps the values computed so far, in complete files,
/// and exits non-zero saying so.
#[cfg(unix)]
#[test]
fn interrupted_sweep_keeps_complete_outputs() {
    let dir = temp_dir("sweep-interrupted");
    let child = bin()
        .args([
            "sweep",
            &repo_file("examples/fujita-row.toml"),
            "--parameter",
            "frequency",
        ])
        .args(["--from", "5.9", "--to", "8.9", "--points", "2000", "--out"])
        .arg(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    // SAFETY: signalling our own child process.
    unsafe {
        libc::kill(child.id() as libc::pid_t, libc::SIGINT);
    }
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted (Ctrl-C)"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let points = summary["points"].as_array().unwrap();
    let done = points.iter().filter(|p| p["completed"] == true).count();
    assert_eq!(points.len(), 2000, "every value is reported, run or not");
    assert!(done < 2000, "{done} values completed");
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// Ctrl-C in `simulate --out` keeps a complete, valid history up to the
/// time reached (every row whole), the impact log and the summary, and no
/// temporary file; the exit status says it was interrupted.
#[test]
fn interrupted_simulation_keeps_complete_outputs() {
    let dir = temp_dir("simulate-interrupted");
    let child = bin()
        .args(["simulate", &repo_file("examples/fujita-row.toml")])
        .args(["--periods", "1000000", "--format", "json", "--out"])
        .arg(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    // SAFETY: signalling our own child process.
    unsafe {
        libc::kill(child.id() as libc::pid_t, libc::SIGINT);
    }
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted (Ctrl-C) at t ="), "{stderr}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["completed"], false);
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let rows: Vec<&str> = history.lines().collect();
    assert!(rows.len() > 100, "{} rows", rows.len());
    for row in &rows[1..] {
        let cells: Vec<f64> = row.split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(cells.len(), 7, "{row}");
    }
    let t_last: f64 = rows
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(t_last <= summary["final_time"].as_f64().unwrap());
    for f in [
        "impacts.csv",
        "summary.json",
        "displacements.svg",
        "phase_portrait.png",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    assert_clean_error(
        &[
            "simulate",
            &repo_file("examples/fujita-row.toml"),
            "--periods",
            "2",
            "--output-step",
            "1e-300",
            "--out",
            &dir.display().to_string(),
        ],
        "more than 1e9",
    );
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

/// Sends SIGINT to a child after `ms` milliseconds and returns its output.
fn interrupt_after(mut cmd: Command, ms: u64) -> Output {
    let child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(ms));
    // SAFETY: signalling our own child process.
    unsafe {
        libc::kill(child.id() as libc::pid_t, libc::SIGINT);
    }
    child.wait_with_output().unwrap()
}

/// Ctrl-C in `report` leaves the previous report untouched (the new one is
/// built in a staging folder that is removed) and in `periodic` writes
/// nothing; both exit 1 saying so. A folder that is not a report is not
/// replaced.
#[test]
fn interrupted_report_and_periodic_leave_no_partial_output() {
    let dir = temp_dir("report-interrupted");
    let target = dir.join("report");
    std::fs::create_dir_all(&target).unwrap();
    std::fs::write(target.join("index.html"), "OLD").unwrap();
    let mut cmd = bin();
    cmd.args(["report", "--out"]).arg(&target);
    let out = interrupt_after(cmd, 2500);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("interrupted (Ctrl-C): no report was written"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(target.join("index.html")).unwrap(),
        "OLD"
    );
    let siblings: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(siblings, vec!["report".to_string()], "{siblings:?}");

    let mut cmd = bin();
    cmd.args(["periodic", &repo_file("examples/fujita-row.toml"), "--out"])
        .arg(dir.join("orbit"));
    let out = interrupt_after(cmd, 300);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted (Ctrl-C)"), "{stderr}");
    assert!(!dir.join("orbit").exists());

    let other = dir.join("notes");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("mine.txt"), "keep").unwrap();
    assert_clean_error(
        &["report", "--out", &other.display().to_string()],
        "is not a report folder",
    );
    assert_eq!(
        std::fs::read_to_string(other.join("mine.txt")).unwrap(),
        "keep"
    );
}

/// A second Ctrl-C quits at once (status 130) and removes the temporary
/// files of the writes in progress: no `*.tmp<PID>` is left behind.
#[test]
fn second_ctrl_c_quits_without_temporary_files() {
    let dir = temp_dir("simulate-twice");
    let child = bin()
        .args(["simulate", &repo_file("examples/fujita-row.toml")])
        .args(["--periods", "1000000", "--out"])
        .arg(&dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1000));
    for _ in 0..2 {
        // SAFETY: signalling our own child process.
        unsafe {
            libc::kill(child.id() as libc::pid_t, libc::SIGINT);
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let out = child.wait_with_output().unwrap();
    let code = out.status.code();
    assert!(code == Some(130) || code == Some(1), "{code:?}");
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// The same input gives the same bytes at 1 and 2 threads (the parallel
/// commands: sweep, impact).
#[test]
fn outputs_are_the_same_bytes_at_one_and_two_threads() {
    use std::collections::hash_map::DefaultHasher;
    use std::hash::{Hash, Hasher};
    let hash = |bytes: &[u8]| {
        let mut h = DefaultHasher::new();
        bytes.hash(&mut h);
        h.finish()
    };
    let run_with = |threads: &str, out: &Path| {
        let sweep = bin()
            .env("RAYON_NUM_THREADS", threads)
            .args(["sweep", &repo_file("examples/fujita-row.toml")])
            .args(["--parameter", "frequency", "--from", "5.9", "--to", "8.9"])
            .args([
                "--points",
                "8",
                "--transient",
                "10",
                "--record",
                "3",
                "--up-down",
                "--out",
            ])
            .arg(out)
            .output()
            .unwrap();
        assert!(sweep.status.success());
        let impact = bin()
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "impact",
                "--velocity",
                "0.001:10:5000log",
                "--format",
                "csv",
            ])
            .output()
            .unwrap();
        assert!(impact.status.success());
        [
            hash(&std::fs::read(out.join("sweep.csv")).unwrap()),
            hash(&std::fs::read(out.join("summary.json")).unwrap()),
            hash(&sweep.stdout),
            hash(&impact.stdout),
        ]
    };
    let dir = temp_dir("threads");
    let one = run_with("1", &dir.join("one"));
    let two = run_with("2", &dir.join("two"));
    assert_eq!(one, two);
}
