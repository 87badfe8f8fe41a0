//! Issue 38: every `vibroimpact` example of README.md and docs/*.md runs as
//! written. The examples are read from the documents (```sh blocks,
//! continuation lines joined), so a new one is covered without being
//! listed here; four of the docs' examples had failed.
//!
//! Each runs in a scratch folder that sees the repository's `examples/`,
//! without its optional `[…]` parts. Stand-ins are used where the docs
//! leave a choice: `RECORDS...` is the shipped synthetic record, and
//! grids above 6 × 6 values, sweeps above 8 values and branches above 60
//! points are cut to those sizes, so that the whole set stays within CI's
//! time. Its key output is asserted: exit 0, a JSON document where
//! `--format json` asks for one, a CSV with a header where `--format csv`
//! does, and a non-empty output folder where `--out` names one.

mod common;
use common::*;

use std::path::Path;

/// The `vibroimpact` command lines of the ```sh blocks of `text`.
fn commands(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut current = String::new();
    for line in text.lines() {
        let trimmed = line.trim();
        if trimmed.starts_with("```") {
            in_sh = trimmed == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        // A comment after the command (two spaces, then #).
        let code = line.split("  #").next().unwrap_or("").trim_end();
        let (code, more) = match code.strip_suffix('\\') {
            Some(c) => (c, true),
            None => (code, false),
        };
        current.push_str(code.trim());
        current.push(' ');
        if !more {
            let command = current.split_whitespace().collect::<Vec<_>>().join(" ");
            if command.starts_with("vibroimpact ") {
                out.push(command);
            }
            current.clear();
        }
    }
    out
}

/// `command` as run here: optional parts dropped, stand-ins put in, sizes
/// cut (see the module's comment).
fn as_run(command: &str) -> Vec<String> {
    let mut text = String::new();
    let mut depth = 0usize;
    for c in command.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            _ if depth == 0 => text.push(c),
            _ => {}
        }
    }
    let text = text.replace("RECORDS...", "examples/synthetic-quake.csv --units m/s2");
    let mut words: Vec<String> = text.split_whitespace().skip(1).map(String::from).collect();
    let cut = [
        ("--x-points", 6),
        ("--y-points", 6),
        ("--points", 8),
        ("--max-points", 60),
    ];
    for k in 0..words.len().saturating_sub(1) {
        if let Some(&(_, most)) = cut.iter().find(|(flag, _)| *flag == words[k]) {
            if let Ok(v) = words[k + 1].parse::<usize>() {
                words[k + 1] = v.min(most).to_string();
            }
        }
    }
    if words.first().is_some_and(|w| w == "continue") && !words.iter().any(|w| w == "--max-points")
    {
        words.extend(["--max-points".to_string(), "60".to_string()]);
    }
    words
}

/// The documents with examples.
fn documents() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = vec![root.join("README.md")];
    let mut docs: Vec<_> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    files
        .into_iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect()
}

#[test]
fn every_documented_example_runs() {
    let scratch = temp_dir("docs-examples");
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    std::os::unix::fs::symlink(examples.canonicalize().unwrap(), scratch.join("examples")).unwrap();
    let mut ran = 0;
    for (doc, text) in documents() {
        for command in commands(&text) {
            let args = as_run(&command);
            let out = bin().args(&args).current_dir(&scratch).output().unwrap();
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert!(
                out.status.success(),
                "{doc}: `{command}` (run as {args:?}) failed: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let flag = |name: &str| {
                args.iter()
                    .position(|a| a == name)
                    .and_then(|k| args.get(k + 1))
            };
            match flag("--format").map(String::as_str) {
                Some("json") => {
                    serde_json::from_str::<serde_json::Value>(&stdout)
                        .unwrap_or_else(|e| panic!("{doc}: `{command}`: not a JSON document: {e}"));
                }
                Some("csv") => {
                    let header = stdout.lines().next().unwrap_or("");
                    assert!(header.contains(','), "{doc}: `{command}`: no CSV header");
                }
                _ => assert!(
                    !stdout.trim().is_empty(),
                    "{doc}: `{command}`: printed nothing"
                ),
            }
            if let Some(dir) = flag("--out") {
                let files = std::fs::read_dir(scratch.join(dir)).map_or(0, |d| d.count());
                assert!(files > 0, "{doc}: `{command}`: {dir} is empty");
            }
            ran += 1;
        }
    }
    // The docs hold 23 examples (2026-11-29): all found, none skipped.
    assert!(ran >= 20, "only {ran} examples found");
}
