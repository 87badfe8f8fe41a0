//! Issue 38, "the core faces never mislead": each answer that was
//! silently wrong, each unclear message, tried as a hostile user would,
//! becomes right or a clear refusal naming the option or key.

mod common;
use common::*;

/// The row example with its mass replaced.
fn row_with_mass(dir: &std::path::Path, mass: &str) -> String {
    let text = std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
        .unwrap()
        .replace("mass = 0.227 ", &format!("mass = {mass} "));
    write_model(dir, "row.toml", &text)
}

/// `row.mass = 1e-100` (down to 1e-300) "completed" with every body
/// exactly at rest in 10 steps: refused at the row's line, naming the
/// mass and the least that keeps its forces. `mass = 1e307` blamed
/// `damping = inf`, a key never set: it names the mass and the
/// frequency.
#[test]
fn masses_beyond_double_precision_are_refused_by_name() {
    let dir = temp_dir("core-mass");
    for tiny in ["1e-100", "1e-300"] {
        let model = row_with_mass(&dir, tiny);
        assert_clean_error(
            &["simulate", &model, "--periods", "1"],
            "row.toml:8: [row] body p1: mass = ",
        );
        assert_clean_error(
            &["simulate", &model, "--periods", "1"],
            "give a mass of at least 1.27e-65 kg",
        );
    }
    let model = row_with_mass(&dir, "1e307");
    assert_clean_error(
        &["simulate", &model, "--periods", "1"],
        "[row] mass = 1e307 with natural_frequency = 7.41: the stiffness m ω² overflows",
    );
}

/// Tolerances outside (1e-15, 0.1) are refused, naming the option: an
/// impact integrated at rtol 1 gave a restitution of 1.0967 and exit 0; a
/// periodic orbit at tol 1 was "converged" with a residual of 0.196;
/// rtol 1e-20 ran 57 s into the step cap with no word. Each is refused
/// before any work (here within a second).
#[test]
fn tolerances_outside_their_range_are_refused() {
    let row2 = repo_file("examples/fujita-row-n2.toml");
    let row = repo_file("examples/fujita-row.toml");
    let range = "give a tolerance in (1e-15, 0.1)";
    let t0 = std::time::Instant::now();
    assert_clean_error(
        &[
            "impact",
            "--velocity",
            "0.1",
            "--method",
            "integrate",
            "--rtol",
            "1",
        ],
        "rtol = 1 is invalid: must lie in (1e-15, 0.1)",
    );
    assert_clean_error(
        &["periodic", &row2, "--tol", "1"],
        &format!("--tol 1: {range}"),
    );
    assert_clean_error(
        &["periodic", &row2, "--rtol", "0.5"],
        &format!("--rtol 0.5: {range}"),
    );
    assert_clean_error(
        &["simulate", &row, "--periods", "1", "--rtol", "1e-20"],
        &format!("rtol = 1e-20: {range}"),
    );
    assert_clean_error(
        &[
            "sweep",
            &row2,
            "--parameter",
            "frequency",
            "--from",
            "5",
            "--to",
            "6",
            "--points",
            "2",
            "--rtol",
            "0.5",
        ],
        &format!("--rtol 0.5: {range}"),
    );
    assert!(t0.elapsed().as_secs_f64() < 5.0, "{:?}", t0.elapsed());
    // The range's inside runs.
    let out = run(&[
        "impact",
        "--velocity",
        "0.1",
        "--method",
        "integrate",
        "--rtol",
        "1e-6",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `sweep … --record 1` reported "distinct 1, spread 0" at every value,
/// which reads as period 1: one Poincaré sample is one point whatever the
/// orbit. Refused, naming the option.
#[test]
fn one_recorded_period_is_refused() {
    let row2 = repo_file("examples/fujita-row-n2.toml");
    assert_clean_error(
        &[
            "sweep",
            &row2,
            "--parameter",
            "frequency",
            "--from",
            "5",
            "--to",
            "6",
            "--points",
            "2",
            "--record",
            "1",
        ],
        "--record 1: record at least two periods",
    );
}

/// `--periods 0` was reported as a negative `duration`, and `--periods
/// 1e12` (or `--rtol 1`) as a stiff model, with rodas as the advice: the
/// option is named, and a long run of a model that is not stiff says so.
#[test]
fn a_run_length_is_named_and_a_long_run_is_not_called_stiff() {
    let row = repo_file("examples/fujita-row.toml");
    assert_clean_error(
        &["simulate", &row, "--periods", "0"],
        "--periods 0: give a positive, finite number of forcing periods",
    );
    assert_clean_error(
        &["simulate", &row, "--duration", "-1"],
        "--duration -1: give a positive, finite time (s)",
    );
    let out = run(&["simulate", &row, "--periods", "1e12"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("the model is not stiff") && !err.contains("rodas"),
        "{err}"
    );
}

/// `--guess homotpy` (a keyword's typo) was read as a missing file.
#[test]
fn a_guess_that_is_neither_keyword_nor_file_is_named() {
    let row2 = repo_file("examples/fujita-row-n2.toml");
    assert_clean_error(
        &["periodic", &row2, "--guess", "homotpy"],
        "--guess homotpy: neither `simulate`, `homotopy` nor an existing JSON file",
    );
}

/// `--out /dev/null` said "File exists (os error 17)": a path that is not
/// a folder is named as such, before any work.
#[test]
fn an_out_that_is_not_a_folder_is_named() {
    let row = repo_file("examples/fujita-row.toml");
    assert_clean_error(
        &["simulate", &row, "--periods", "1", "--out", "/dev/null"],
        "cannot write /dev/null: not a folder: --out names the folder",
    );
}

/// A refused `simulate … --out D --output-step 0` exited 1 but left
/// `D/history.csv.tmpPID`: nothing is left.
#[test]
fn a_refused_simulation_leaves_no_temporary_file() {
    let dir = temp_dir("core-output-step");
    let row = repo_file("examples/fujita-row.toml");
    let out = dir.join("out");
    assert_clean_error(
        &[
            "simulate",
            &row,
            "--periods",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--output-step",
            "0",
        ],
        "output step = 0",
    );
    assert_no_temporary_files(&out);
}

/// SIGTERM (what `timeout` and batch schedulers send) left
/// `history.csv.tmpPID` (4.4 GB for N = 10⁶): it is handled as Ctrl-C
/// is, the history kept complete up to the stop and nothing temporary
/// left.
#[cfg(unix)]
#[test]
fn sigterm_stops_as_ctrl_c_does() {
    let dir = temp_dir("core-sigterm");
    let mut cmd = bin();
    cmd.args(["simulate", &repo_file("examples/fujita-row.toml")])
        .args(["--periods", "1000000", "--format", "json", "--out"])
        .arg(&dir);
    let out = signal_after(cmd, 1500, libc::SIGTERM);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["completed"], false);
    assert!(dir.join("history.csv").exists());
    assert_no_temporary_files(&dir);
}

/// `chart` 200 × 200 (3–20 min) and `basins` 40 × 40 (about 200 s) said
/// nothing first where standard error was not a terminal (CI, nohup, a
/// notebook): each announces its estimate before any work; Ctrl-C then
/// stops it.
#[cfg(unix)]
#[test]
fn long_charts_and_basins_say_so_first() {
    let row2 = repo_file("examples/fujita-row-n2.toml");
    let mut chart = bin();
    chart
        .args([
            "chart",
            &row2,
            "--x",
            "frequency",
            "--x-from",
            "3.7",
            "--x-to",
            "11.1",
        ])
        .args([
            "--x-points",
            "200",
            "--y",
            "amplitude",
            "--y-from",
            "0.01",
            "--y-to",
            "0.1",
        ])
        .args(["--y-points", "200"]);
    let mut basins = bin();
    basins
        .args([
            "basins",
            &row2,
            "--x",
            "u1",
            "--x-from=-0.9e-3",
            "--x-to",
            "0.9e-3",
        ])
        .args([
            "--x-points",
            "40",
            "--y",
            "v1",
            "--y-from=-0.05",
            "--y-to",
            "0.05",
        ])
        .args(["--y-points", "40", "--transient", "400", "--record", "30"]);
    for cmd in [chart, basins] {
        let out = interrupt_after(cmd, 2500);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("note: a long run: about "), "{err}");
        assert!(err.contains("interrupted (Ctrl-C)"), "{err}");
    }
}

/// The docs' `--special-points` example, chained as written, fed the row
/// of three's branch to the row of two: "start state: needs 4 values, got
/// 6", naming neither the file nor the mismatch. Both are named now (and
/// the docs' example chains a branch of the same model).
#[test]
fn special_points_of_another_model_are_named() {
    let dir = temp_dir("core-special-points");
    let branch = dir.join("branch");
    let out = run(&[
        "continue",
        &repo_file("examples/fujita-row.toml"),
        "--parameter",
        "frequency",
        "--from",
        "11.1",
        "--to",
        "3.7",
        "--out",
        branch.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = branch.join("branch.json");
    assert_clean_error(
        &[
            "continue",
            &repo_file("examples/fujita-row-n2.toml"),
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
            json.to_str().unwrap(),
        ],
        "branch.json: special_points[0]: a state of 6 values, a branch of a model with 3 bodies; ",
    );
}

/// `continue --start homotopy` reported "from 11.1 to 11.1 (ReachedEnd)"
/// after folding back at 10.387: it says the branch turned back, with
/// the span it covered.
#[test]
fn a_branch_that_turns_back_says_so() {
    let out = run(&[
        "continue",
        &repo_file("examples/fujita-row.toml"),
        "--parameter",
        "frequency",
        "--from",
        "11.1",
        "--to",
        "3.7",
        "--start",
        "homotopy",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("from 11.1 to 11.1 (spanning 10.38")
            && text.contains("turned back and left the range on the side it started from"),
        "{text}"
    );
    let doc = json(&[
        "continue",
        &repo_file("examples/fujita-row.toml"),
        "--parameter",
        "frequency",
        "--from",
        "11.1",
        "--to",
        "3.7",
        "--start",
        "homotopy",
        "--format",
        "json",
    ]);
    assert_eq!(doc["stop"], "TurnedBack");
}

/// A row of 10⁶ printed 10⁶ + 1 per-contact lines in its summary: the
/// table lists the 20 busiest and counts the rest; JSON keeps every one.
#[test]
fn a_long_row_keeps_its_summary_readable() {
    let dir = temp_dir("core-long-row");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
        .unwrap()
        .replacen("count = 3", "count = 100", 1);
    let model = write_model(&dir, "row.toml", &text);
    let out = run(&["simulate", &model, "--periods", "3"]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(table.lines().count() < 30, "{table}");
    assert!(
        table.contains("... 81 more contacts not shown ("),
        "{table}"
    );
    let doc = json(&["simulate", &model, "--periods", "3", "--format", "json"]);
    assert_eq!(doc["impacts_per_contact"].as_array().unwrap().len(), 101);
}

/// The sweep's default 100 periods left the lightly damped N = 2 row at
/// 7.3 rad/s as "20 distinct", read as a cloud, while 1000 periods give
/// period 1. The table now says what the samples do: `period 1` after the
/// periods the convergence needed (its own transient column over 100), or
/// with `--settle 0` `settling (+n)`, the periods it still needs.
#[test]
fn a_sweep_calls_a_value_periodic_only_once_settled() {
    let table = |extra: &[&str]| {
        let mut args = vec![
            "sweep".to_string(),
            repo_file("examples/fujita-row-n2.toml"),
        ];
        for a in [
            "--parameter",
            "frequency",
            "--from",
            "7.3",
            "--to",
            "7.4",
            "--points",
            "2",
        ]
        .iter()
        .chain(extra)
        {
            args.push(a.to_string());
        }
        let out = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap()
    };
    let settled = table(&[]);
    let row = settled.lines().nth(1).unwrap();
    assert!(row.contains(" period 1 "), "{settled}");
    let transient: usize = row.split_whitespace().nth(7).unwrap().parse().unwrap();
    assert!(transient > 100, "{settled}");
    let unsettled = table(&["--settle", "0"]);
    assert!(
        unsettled.lines().nth(1).unwrap().contains("settling (+"),
        "{unsettled}"
    );
}

/// `summary.json` said nothing of how it was made. It now carries the
/// version, the method, rtol, atol, the integrator and the SHA-256 of the
/// model's canonical text: a comment changes nothing, a value changes it.
#[test]
fn a_simulation_summary_says_how_it_was_made() {
    let dir = temp_dir("core-provenance");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row-n2.toml")).unwrap();
    let provenance = |name: &str, text: &str| {
        let model = write_model(&dir, name, text);
        let doc = json(&[
            "simulate",
            &model,
            "--periods",
            "1",
            "--rtol",
            "1e-7",
            "--format",
            "json",
        ]);
        doc["provenance"].clone()
    };
    let p = provenance("a.toml", &text);
    assert_eq!(p["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(
        (p["method"].as_str(), p["integrator"].as_str()),
        (Some("dop853"), Some("auto"))
    );
    assert_eq!(
        (p["rtol"].as_f64(), p["atol"].as_f64()),
        (Some(1e-7), Some(1e-11))
    );
    let digest = p["model_sha256"].as_str().unwrap();
    assert_eq!(digest.len(), 64);
    let commented = provenance("b.toml", &format!("# another comment\n{text}"));
    assert_eq!(commented["model_sha256"], digest);
    let changed = provenance(
        "c.toml",
        &text.replace("amplitude = 0.05", "amplitude = 0.06"),
    );
    assert_ne!(changed["model_sha256"], digest);
}

/// `periodic` on a row of 10⁶ bodies printed nothing first; its GMRES
/// solve then ran 20 s past Ctrl-C. A row of 10⁵ announces its work
/// before any, and stops within seconds of Ctrl-C, in the middle of
/// Newton–Krylov shooting.
#[cfg(unix)]
#[test]
fn a_long_periodic_run_says_so_first_and_stops() {
    let dir = temp_dir("core-periodic-long");
    let text = std::fs::read_to_string(repo_file("examples/fujita-row.toml"))
        .unwrap()
        .replace("count = 3\n", "count = 100000\n");
    let model = write_model(&dir, "row.toml", &text);
    let mut cmd = bin();
    cmd.args(["periodic", &model]);
    let clock = std::time::Instant::now();
    let out = interrupt_after(cmd, 12_000);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("note: a long run: about "), "{err}");
    assert!(err.contains("interrupted (Ctrl-C)"), "{err}");
    let past = clock.elapsed().as_secs_f64() - 12.0;
    assert!(past < 5.0, "stopped {past:.1} s after Ctrl-C");
}
