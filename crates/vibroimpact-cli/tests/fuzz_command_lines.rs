//! Issue 38: mutated command lines through the binary. The options come
//! from clap's own tree (each subcommand's `--help`: its usage line's
//! required options and positionals, every option with its possible
//! values), the values from typical ones and the fuzz corpus's extremes
//! (0, −1, 1e308, 5e-324, nan, inf, …). Every run must end without a
//! panic, never exit 0 with a non-finite number in its output, announce
//! itself (`note: a long run`) if it lasts over 10 s and then stop on
//! Ctrl-C within 10 s, and leave no temporary file. Seeded and bounded in
//! `cargo test` (40 lines); the run is
//! `VIBROIMPACT_FUZZ_CASES=500 cargo test --release -p vibroimpact-cli --test fuzz_command_lines`.

mod common;
use common::*;

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

use vibroimpact_fuzz::{cases, seed, Rng, NUMBERS};

/// One option of a subcommand: its name, whether it takes a value, its
/// possible values (empty: any).
#[derive(Debug)]
struct Opt {
    name: String,
    value: bool,
    choices: Vec<String>,
}

/// A subcommand: its required options and positionals (from the usage
/// line) and all its options.
#[derive(Debug)]
struct Sub {
    name: String,
    required: Vec<String>,
    positionals: Vec<String>,
    options: Vec<Opt>,
}

fn help(args: &[&str]) -> String {
    String::from_utf8(run(args).stdout).unwrap()
}

/// clap's tree, read from the binary's help.
fn tree() -> Vec<Sub> {
    let top = help(&["--help"]);
    let names: Vec<String> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|n| n != "help" && n != "report")
        .collect();
    names
        .into_iter()
        .map(|name| {
            let text = help(&[&name, "--help"]);
            let usage = text.lines().find(|l| l.starts_with("Usage:")).unwrap_or("");
            let words: Vec<&str> = usage.split_whitespace().skip(3).collect();
            let required = words
                .iter()
                .filter(|w| w.starts_with("--"))
                .map(|w| w.to_string())
                .collect();
            let positionals = words
                .iter()
                .enumerate()
                .filter(|(k, w)| w.starts_with('<') && (*k == 0 || !words[k - 1].starts_with("--")))
                .map(|(_, w)| {
                    w.trim_matches(|c| c == '<' || c == '>' || c == '.')
                        .to_string()
                })
                .collect();
            let mut options: Vec<Opt> = Vec::new();
            for line in text.lines() {
                let t = line.trim_start();
                if let Some(rest) = t.strip_prefix("--") {
                    let name = format!("--{}", rest.split_whitespace().next().unwrap_or(""));
                    if name == "--help" || name == "--version" {
                        continue;
                    }
                    options.push(Opt {
                        name,
                        value: rest.contains('<'),
                        choices: Vec::new(),
                    });
                } else if let (Some(opt), Some(v)) = (options.last_mut(), t.strip_prefix("- ")) {
                    // "- auto:   Local from 16 groups …": a possible value.
                    if let Some(choice) = v.split(':').next() {
                        opt.choices.push(choice.trim().to_string());
                    }
                } else if let (Some(opt), Some(i)) =
                    (options.last_mut(), t.find("[possible values: "))
                {
                    let list = &t[i + 18..t.len() - 1];
                    opt.choices = list.split(", ").map(String::from).collect();
                }
            }
            Sub {
                name,
                required,
                positionals,
                options,
            }
        })
        .collect()
}

/// A typical value of option `name` (so that a line gets past its
/// required options), or a number.
fn typical(name: &str, sub: &str) -> &'static str {
    match (sub, name) {
        ("basins", "--x") => "u1",
        ("basins", "--y") => "v1",
        (_, "--parameter" | "--x") => "frequency",
        (_, "--parameter2" | "--y") => "amplitude",
        (_, "--from" | "--x-from") => "6.5",
        (_, "--to" | "--x-to") => "7.5",
        (_, "--from2" | "--y-from") => "0.03",
        (_, "--to2" | "--y-to") => "0.06",
        (_, "--points" | "--x-points" | "--y-points") => "3",
        (_, "--velocity") => "0.1,0.3",
        (_, "--stiffness") => "1.2e8",
        (_, "--amplitudes") => "0.01,0.02",
        _ => "2",
    }
}

/// A positional's file: a model, a row or a record.
fn positional(name: &str, sub: &str) -> String {
    match (name, sub) {
        ("RECORD" | "RECORDS", _) => repo_file("examples/synthetic-quake.csv"),
        ("PAIR", "collapse") => repo_file("examples/isolated-building.toml"),
        ("PAIR", _) => repo_file("examples/pounding-frames.toml"),
        (_, "simulate") => repo_file("examples/fujita-row.toml"),
        _ => repo_file("examples/fujita-row-n2.toml"),
    }
}

/// A mutated command line of `sub`, run in `dir`.
fn line(rng: &mut Rng, sub: &Sub, dir: &Path) -> Vec<String> {
    let mut args = vec![sub.name.clone()];
    for p in &sub.positionals {
        args.push(positional(p, &sub.name));
    }
    let value = |rng: &mut Rng, opt: &Opt| -> String {
        if opt.name == "--out" {
            return dir.join("out").display().to_string();
        }
        if !opt.choices.is_empty() && rng.below(4) > 0 {
            return rng.pick(&opt.choices).clone();
        }
        match rng.below(3) {
            0 => typical(&opt.name, &sub.name).to_string(),
            _ => rng.pick(NUMBERS).to_string(),
        }
    };
    for name in &sub.required {
        let opt = sub.options.iter().find(|o| &o.name == name);
        args.push(name.clone());
        args.push(match (opt, rng.below(5)) {
            (Some(o), 0) => value(rng, o),
            _ => typical(name, &sub.name).to_string(),
        });
    }
    for _ in 0..rng.below(4) {
        let opt = rng.pick(&sub.options);
        args.push(opt.name.clone());
        if opt.value {
            args.push(value(rng, opt));
        }
    }
    args
}

/// Files whose name holds `.tmp` under `dir`.
fn temporary_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(temporary_files(&p));
        } else if p
            .file_name()
            .is_some_and(|n| n.to_string_lossy().contains(".tmp"))
        {
            out.push(p);
        }
    }
    out
}

/// A non-finite number printed as one (`NaN`, `inf`), not as JSON's null.
fn non_finite(text: &str) -> bool {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+'))
        .any(|w| {
            let w = w.trim_start_matches(['-', '+']);
            w.eq_ignore_ascii_case("nan") || w.eq_ignore_ascii_case("inf")
        })
}

#[cfg(unix)]
#[test]
fn mutated_command_lines_end_cleanly() {
    let subs = tree();
    assert!(
        subs.len() >= 12,
        "{:?}",
        subs.iter().map(|s| &s.name).collect::<Vec<_>>()
    );
    let mut rng = Rng(seed() ^ 38);
    let root = temp_dir("fuzz-command-lines");
    let mut failures = Vec::new();
    let mut exits = [0usize; 3];
    for case in 0..cases(40) {
        let dir = root.join(case.to_string());
        std::fs::create_dir_all(&dir).unwrap();
        let sub = &subs[rng.below(subs.len())];
        let args = line(&mut rng, sub, &dir);
        let (out_path, err_path) = (dir.join("stdout"), dir.join("stderr"));
        let mut child = bin()
            .args(&args)
            .current_dir(&dir)
            .stdout(Stdio::from(std::fs::File::create(&out_path).unwrap()))
            .stderr(Stdio::from(std::fs::File::create(&err_path).unwrap()))
            .spawn()
            .unwrap();
        let clock = Instant::now();
        let mut status = None;
        while clock.elapsed() < Duration::from_secs(10) {
            if let Some(s) = child.try_wait().unwrap() {
                status = Some(s);
                break;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let mut problem = None;
        let status = match status {
            Some(s) => s,
            None => {
                let err = std::fs::read_to_string(&err_path).unwrap_or_default();
                if !err.contains("note: a long run") {
                    problem = Some("ran over 10 s without a word".to_string());
                }
                // SAFETY: signalling our own child process.
                unsafe {
                    libc::kill(child.id() as libc::pid_t, libc::SIGINT);
                }
                let stop = Instant::now();
                loop {
                    if let Some(s) = child.try_wait().unwrap() {
                        break s;
                    }
                    if stop.elapsed() > Duration::from_secs(10) {
                        child.kill().unwrap();
                        problem = Some("did not stop within 10 s of Ctrl-C".to_string());
                        break child.wait().unwrap();
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
            }
        };
        let (stdout, stderr) = (
            std::fs::read_to_string(&out_path).unwrap_or_default(),
            std::fs::read_to_string(&err_path).unwrap_or_default(),
        );
        std::fs::remove_file(&out_path).unwrap();
        std::fs::remove_file(&err_path).unwrap();
        if stderr.contains("panicked") || status.code() == Some(101) {
            problem = Some(format!("panicked: {stderr}"));
        } else if status.success() && non_finite(&stdout) {
            problem = Some("exit 0 with a non-finite number in its output".into());
        }
        let leftovers = temporary_files(&dir);
        if !leftovers.is_empty() {
            problem = Some(format!("left {leftovers:?}"));
        }
        exits[match status.code() {
            Some(0) => 0,
            Some(_) => 1,
            None => 2,
        }] += 1;
        if let Some(p) = problem {
            failures.push(format!("{args:?}: {p}"));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    eprintln!(
        "{} command lines: {} exit 0, {} refused or failed, {} stopped by Ctrl-C",
        cases(40),
        exits[0],
        exits[1],
        exits[2]
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
