//! End-to-end tests of `impact` and `identify`: output contracts and bad
//! input.

mod common;
use common::*;

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
