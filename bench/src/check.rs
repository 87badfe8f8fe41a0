//! `--check`: the headline comparisons rerun in one go, each ratio (the
//! peer's time over ours at equal accuracy, so larger is better) printed
//! beside the one recorded in `bench/results/<name>.json`; the run fails
//! where a ratio fell by more than [`ALLOWED_FALL`]. `--record` writes the
//! new ratios as the current files and moves the old ones to
//! `bench/results/archive/<their date>/`.
//!
//! The comparisons: SUNDIALS on R2 at N = 3 and N = 1000, the local
//! integrator (R2 N = 1000 against SUNDIALS, the struck chain against the
//! global integrator), and where their tools are installed AUTO-07p on the
//! R2 N = 2 branch (`bench/auto/build.sh`), OpenSees on the pounding pair
//! and the IMK frame, and Dask on a sweep (openseespy and Dask in the
//! checkout's `.venv`, which `scripts/test.sh` makes). A comparison whose
//! tool is missing is reported as skipped, not as passed.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::{json, Value};

use crate::common::Peers;
use crate::sections::{local, n1000, n3};

/// The largest fall of a ratio against the recorded one that passes.
pub const ALLOWED_FALL: f64 = 0.2;

/// How one headline ratio is measured.
enum Measure {
    /// In this process, from a section's results (needs the SUNDIALS
    /// peers when `peers` is set).
    Section {
        peers: bool,
        run: fn(Option<&Peers>) -> Value,
        ratio: fn(&Value) -> Option<f64>,
    },
    /// A peer script writing a JSON document whose `pointer` holds the
    /// ratio; skipped unless `needs` exists (relative to the root).
    Script {
        python: Python,
        script: &'static str,
        args: &'static [&'static str],
        pointer: &'static str,
        needs: &'static str,
    },
}

/// Which Python runs a script.
#[derive(Clone, Copy)]
enum Python {
    /// The system's `python3` (standard library only).
    System,
    /// The checkout's `.venv` (vibroimpact, openseespy, Dask).
    Venv,
}

/// A headline comparison.
struct Headline {
    name: &'static str,
    what: &'static str,
    measure: Measure,
}

fn headlines() -> Vec<Headline> {
    vec![
        Headline {
            name: "sundials-n3",
            what: "R2 N = 3, 5 periods, error 1e-6: fastest SUNDIALS or SciPy / ours",
            measure: Measure::Section {
                peers: true,
                run: |p| section_value(n3::run(p, true), "r2_n3"),
                ratio: |v| {
                    v["robust"]
                        .as_array()?
                        .iter()
                        .filter(|r| {
                            !r["solver"]
                                .as_str()
                                .unwrap_or("")
                                .starts_with("vibroimpact")
                        })
                        .filter_map(|r| r["ratio_to_ours"].as_f64())
                        .reduce(f64::min)
                },
            },
        },
        Headline {
            name: "sundials-n1000",
            what: "R2 N = 1000, 1 period, equal accuracy: fastest ARKODE / ours",
            measure: Measure::Section {
                peers: true,
                run: |p| section_value(n1000::run(p, true), "r2_n1000"),
                ratio: |v| v["fastest_arkode_over_ours"].as_f64(),
            },
        },
        Headline {
            name: "local-n1000",
            what: "R2 N = 1000, 3 periods, error 1e-5: fastest SUNDIALS / local",
            measure: Measure::Section {
                peers: true,
                run: |p| local::r2_n1000(p, 2),
                ratio: |v| v["fastest_sundials_over_local"].as_f64(),
            },
        },
        Headline {
            name: "local-chain",
            what: "struck chain N = 1000, 0.02 s: global / local",
            measure: Measure::Section {
                peers: false,
                run: |_| local::struck_chain(true, 2),
                ratio: |v| {
                    let row = v["rows"].as_array()?.iter().find(|r| r["n"] == 1000)?;
                    Some(row["global_seconds"].as_f64()? / row["local_seconds"].as_f64()?)
                },
            },
        },
        Headline {
            name: "auto-n2",
            what: "R2 N = 2 whole branch: AUTO-07p at its best / ours",
            measure: Measure::Script {
                python: Python::System,
                script: "bench/auto/best_n2.py",
                args: &["--repeats", "3"],
                pointer: "/ratio",
                needs: "bench/auto/build/r2n2.exe",
            },
        },
        Headline {
            name: "opensees-pounding",
            what: "pounding pair, linear contact: OpenSees at its best / ours",
            measure: Measure::Script {
                python: Python::Venv,
                script: "bench/opensees/pounding_peer.py",
                args: &["--quick"],
                pointer: "/results/linear/ratio",
                needs: ".venv/lib",
            },
        },
        Headline {
            name: "opensees-frame",
            what: "4-storey IMK + P-Δ frame: OpenSees at its best / ours",
            measure: Measure::Script {
                python: Python::Venv,
                script: "bench/opensees/frame_peer.py",
                args: &["--quick", "--case", "imk"],
                pointer: "/results/imk/ratio",
                needs: ".venv/lib",
            },
        },
        Headline {
            name: "dask",
            what: "64-value sweep: 1 Dask worker / 2 workers",
            measure: Measure::Script {
                python: Python::Venv,
                script: "bench/python/bench.py",
                args: &["--quick", "--only", "dask"],
                pointer: "/dask/speedup",
                needs: ".venv/lib",
            },
        },
    ]
}

/// The value a section entered under `key`.
fn section_value(entries: crate::sections::Entries, key: &str) -> Value {
    entries
        .into_iter()
        .find_map(|(k, v)| (k == key).then_some(v))
        .unwrap_or(Value::Null)
}

/// Runs a peer script with `--out` into a temporary file and reads it.
fn run_script(root: &Path, python: Python, script: &str, args: &[&str]) -> Result<Value, String> {
    let out = std::env::temp_dir().join(format!(
        "vibroimpact-check-{}-{}.json",
        std::process::id(),
        script.replace('/', "_")
    ));
    let program = match python {
        Python::System => PathBuf::from("python3"),
        Python::Venv => root.join(".venv/bin/python"),
    };
    let status = Command::new(&program)
        .arg(root.join(script))
        .args(args)
        .arg("--out")
        .arg(&out)
        .current_dir(root)
        .status()
        .map_err(|e| format!("cannot run {}: {e}", program.display()))?;
    // A peer script exits 1 where its own target is not met, after
    // writing its results: the ratio is judged here against the record.
    let text = std::fs::read_to_string(&out)
        .map_err(|e| format!("{script} wrote no results ({status}): {e}"))?;
    let _ = std::fs::remove_file(&out);
    serde_json::from_str(&text).map_err(|e| format!("{script}'s output: {e}"))
}

/// One comparison's outcome.
enum Outcome {
    Measured { ratio: f64, detail: Value },
    Skipped(String),
    Failed(String),
}

fn measure(root: &Path, peers: Option<&Peers>, h: &Headline) -> Outcome {
    match &h.measure {
        Measure::Section {
            peers: needs,
            run,
            ratio,
        } => {
            if *needs && peers.is_none() {
                return Outcome::Skipped("--no-peers".into());
            }
            let detail = run(peers);
            match ratio(&detail) {
                Some(r) if r.is_finite() => Outcome::Measured { ratio: r, detail },
                _ => Outcome::Failed("the section gave no ratio".into()),
            }
        }
        Measure::Script {
            python,
            script,
            args,
            pointer,
            needs,
        } => {
            if !root.join(needs).exists() {
                return Outcome::Skipped(format!("{needs} is missing"));
            }
            match run_script(root, *python, script, args) {
                Ok(detail) => match detail.pointer(pointer).and_then(Value::as_f64) {
                    Some(r) if r.is_finite() => Outcome::Measured { ratio: r, detail },
                    _ => Outcome::Failed(format!("{script} wrote no ratio at {pointer}")),
                },
                Err(e) => Outcome::Failed(e),
            }
        }
    }
}

/// The recorded current file of a comparison, if any.
fn recorded(results: &Path, name: &str) -> Option<Value> {
    let text = std::fs::read_to_string(results.join(format!("{name}.json"))).ok()?;
    serde_json::from_str(&text).ok()
}

/// Writes `value` to `path` atomically (a temporary file renamed).
fn write_atomic(path: &Path, value: &Value) -> Result<(), String> {
    let tmp = path.with_extension("json.tmp");
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    std::fs::write(&tmp, text + "\n").map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Makes `value` the current file of `name`, the previous one moved to
/// `archive/<its date>/`.
fn record(results: &Path, name: &str, value: &Value) -> Result<(), String> {
    let current = results.join(format!("{name}.json"));
    if let Some(old) = recorded(results, name) {
        let date = old["date"].as_str().unwrap_or("undated").to_string();
        let dir = results.join("archive").join(date);
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        std::fs::rename(&current, dir.join(format!("{name}.json")))
            .map_err(|e| format!("{}: {e}", current.display()))?;
    }
    write_atomic(&current, value)
}

fn today() -> String {
    let out = Command::new("date").arg("-u").arg("+%Y-%m-%d").output();
    out.ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map_or_else(|| "undated".into(), |s| s.trim().to_string())
}

fn commit(root: &Path) -> String {
    let out = Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .current_dir(root)
        .output();
    out.ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map_or_else(String::new, |s| s.trim().to_string())
}

/// Runs the check; the process's exit code (1 where a ratio fell by more
/// than [`ALLOWED_FALL`], a comparison failed, or a record could not be
/// written).
pub fn run(root: &Path, peers: Option<&Peers>, write: bool, only: Option<&str>) -> i32 {
    let results = root.join("bench/results");
    let (date, commit) = (today(), commit(root));
    let mut rows = Vec::new();
    let mut code = 0;
    for h in headlines() {
        if only.is_some_and(|o| o != h.name) {
            continue;
        }
        println!("\n#### check {}: {}", h.name, h.what);
        let before = recorded(&results, h.name).and_then(|v| v["ratio"].as_f64());
        let line = match measure(root, peers, &h) {
            Outcome::Measured { ratio, detail } => {
                let verdict = match before {
                    Some(b) if ratio < (1.0 - ALLOWED_FALL) * b => {
                        code = 1;
                        "FELL"
                    }
                    Some(_) => "ok",
                    None => "new",
                };
                if write {
                    let value = json!({"comparison": h.name, "what": h.what, "ratio": ratio,
                                       "date": date, "commit": commit, "detail": detail});
                    if let Err(e) = record(&results, h.name, &value) {
                        eprintln!("error: {e}");
                        code = 1;
                    }
                }
                let recorded = before.map_or("—".into(), |b| format!("{b:.2}"));
                format!("{:<18} {:>9} {:>9.2}  {verdict}", h.name, recorded, ratio)
            }
            Outcome::Skipped(why) => format!("{:<18} skipped: {why}", h.name),
            Outcome::Failed(why) => {
                code = 1;
                format!("{:<18} FAILED: {why}", h.name)
            }
        };
        rows.push(line);
    }
    println!(
        "\n{:<18} {:>9} {:>9}  (ratio = peer / ours; fails below {:.0} % of the recorded)",
        "comparison",
        "recorded",
        "now",
        100.0 * (1.0 - ALLOWED_FALL)
    );
    for r in rows {
        println!("{r}");
    }
    code
}
