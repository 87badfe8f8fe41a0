//! End-to-end tests of robustness: closed pipes, Ctrl-C, temporary files,
//! determinism across thread counts.

mod common;
use common::*;
use std::path::Path;

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
    let mut cmd = bin();
    cmd.args(["sweep", &repo_file("examples/fujita-row.toml")])
        .args(["--parameter", "frequency", "--from", "5.9", "--to", "8.9"])
        .args(["--points", "2000", "--out"])
        .arg(&dir);
    let out = interrupt_after(cmd, 1500);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted (Ctrl-C)"), "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let points = summary["points"].as_array().unwrap();
    let done = points.iter().filter(|p| p["completed"] == true).count();
    assert_eq!(points.len(), 2000, "every value is reported, run or not");
    assert!(done < 2000, "{done} values completed");
    assert_no_temporary_files(&dir);
}

/// A long `pounding` says so before any work, and Ctrl-C stops every run
/// at its next step: the command exits non-zero at once saying so, and
/// writes nothing (a study is written whole). Before, the runs never
/// looked at the request, and only `simulate` announced a long run.
#[cfg(unix)]
#[test]
fn interrupted_pounding_writes_nothing() {
    let dir = temp_dir("pounding-interrupted");
    let quake = dir.join("long.csv");
    let mut text = String::from("time,acceleration\n");
    for k in 0..=60_000 {
        let t = k as f64 * 0.01;
        text += &format!("{t},{}\n", 3.0 * (std::f64::consts::TAU * 1.5 * t).sin());
    }
    std::fs::write(&quake, text).unwrap();
    let mut cmd = bin();
    cmd.args(["pounding", &repo_file("examples/pounding-frames.toml")])
        .arg(&quake)
        .args(["--units", "m/s2", "--sample", "1e-6", "--out"])
        .arg(dir.join("out"));
    let start = std::time::Instant::now();
    let out = interrupt_after(cmd, 1000);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(start.elapsed().as_secs_f64() < 6.0, "{stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("interrupted (Ctrl-C): nothing written"),
        "{stderr}"
    );
    // Announced before any work (6e8 samples: about a minute).
    assert!(
        stderr.starts_with("note: a long run:") && stderr.contains("nothing is written"),
        "{stderr}"
    );
    assert!(!dir.join("out").join("pounding.json").exists());
}

/// Ctrl-C in `simulate --out` keeps a complete, valid history up to the
/// time reached (every row whole), the impact log and the summary, and no
/// temporary file; the exit status says it was interrupted.
#[test]
fn interrupted_simulation_keeps_complete_outputs() {
    let dir = temp_dir("simulate-interrupted");
    let mut cmd = bin();
    cmd.args(["simulate", &repo_file("examples/fujita-row.toml")])
        .args(["--periods", "1000000", "--format", "json", "--out"])
        .arg(&dir);
    let out = interrupt_after(cmd, 1500);
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
    assert_no_temporary_files(&dir);
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
    // (A long transient: the whole default run takes 0.4 s, and the stop
    // must land inside it.)
    cmd.args(["periodic", &repo_file("examples/fujita-row.toml")])
        .args(["--guess-periods", "500", "--out"])
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
    assert_no_temporary_files(&dir);
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
