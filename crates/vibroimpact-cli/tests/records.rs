//! End-to-end tests of `spectrum` on recorded ground motions.

mod common;
use common::*;

/// A short AT2 record in g (a decaying 2 Hz sine), and the same samples as
/// two columns in gal.
fn records(dir: &std::path::Path) -> (String, String) {
    let n = 400;
    let values: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * 0.01;
            0.2 * (2.0 * std::f64::consts::PI * 2.0 * t).sin() * (-t / 2.0).exp()
        })
        .collect();
    let mut at2 = String::from(
        "PEER NGA STRONG MOTION DATABASE RECORD\nTEST 1/1/00, STATION, 000\nACCELERATION TIME SERIES IN UNITS OF G\n",
    );
    at2.push_str(&format!("NPTS=  {n}, DT=   .0100 SEC\n"));
    for chunk in values.chunks(5) {
        let line: Vec<String> = chunk.iter().map(|v| format!("{v:15.7E}")).collect();
        at2.push_str(&line.join(""));
        at2.push('\n');
    }
    let mut cols = String::from("time (s)   acceleration (cm/s2)\n");
    for (k, v) in values.iter().enumerate() {
        let g: f64 = format!("{v:.7E}").parse().unwrap();
        cols.push_str(&format!("{} {:e}\n", k as f64 * 0.01, g * 980.665));
    }
    let a = dir.join("r.AT2");
    let c = dir.join("r.txt");
    std::fs::write(&a, at2).unwrap();
    std::fs::write(&c, cols).unwrap();
    (a.display().to_string(), c.display().to_string())
}

/// JSON rows with the documented fields, the record's metadata, and the
/// same spectrum from the record in g (AT2) and in gal (two columns).
#[test]
fn spectrum_of_a_record_in_two_units() {
    let dir = temp_dir("records");
    let (at2, cols) = records(&dir);
    let args = |f: &str| {
        json(&[
            "spectrum",
            f,
            "--periods",
            "0.1:2:8log",
            "--damping",
            "0.05",
            "--format",
            "json",
        ])
    };
    let (a, c) = (args(&at2), args(&cols));
    assert_eq!(a["record"]["units"], "g");
    assert_eq!(c["record"]["units"], "gal");
    assert_eq!(a["record"]["samples"], 400);
    assert_eq!(a["record"]["dt"], 0.01);
    let rows = a["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 8);
    for (x, y) in rows.iter().zip(c["rows"].as_array().unwrap()) {
        let (p, q) = (
            x["pseudo_acceleration"].as_f64().unwrap(),
            y["pseudo_acceleration"].as_f64().unwrap(),
        );
        assert!((p - q).abs() < 1e-12 * p, "{p} vs {q}");
        let w = 2.0 * std::f64::consts::PI / x["period"].as_f64().unwrap();
        let sd = x["displacement"].as_f64().unwrap();
        assert!((x["pseudo_velocity"].as_f64().unwrap() - w * sd).abs() < 1e-12 * w * sd);
    }
    let out = dir.join("spec");
    let ok = run(&["spectrum", &at2, "--out", out.to_str().unwrap()]);
    assert!(ok.status.success());
    for f in [
        "spectrum.json",
        "spectrum.csv",
        "spectrum.svg",
        "spectrum.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn bad_records_and_options_are_refused() {
    let dir = temp_dir("records-bad");
    let (at2, _) = records(&dir);
    let gap = dir.join("gap.txt");
    std::fs::write(&gap, "t a (g)\n0 1\n0.01 2\n0.02 1\n0.9 0\n0.91 1\n").unwrap();
    let nounits = dir.join("nounits.txt");
    std::fs::write(&nounits, "t a\n0 1\n0.01 2\n").unwrap();
    let gap_s = gap.display().to_string();
    let nounits_s = nounits.display().to_string();
    let frame = repo_file("examples/moment-frame-4.toml");
    let quake = repo_file("examples/synthetic-quake.csv");
    for (args, needle) in [
        (
            vec!["spectrum", &at2, "--units", "furlong"],
            "--units furlong: give g, m/s2 or gal",
        ),
        (
            vec!["spectrum", &at2, "--periods", "2:1:10"],
            "--periods 2:1:10",
        ),
        (vec!["spectrum", &at2, "--damping", "1.5"], "--damping 1.5"),
        (vec!["spectrum", &gap_s], "gap.txt:5: a gap"),
        (vec!["spectrum", &nounits_s], "states no units"),
        (vec!["spectrum", "/nonexistent/x.AT2"], "x.AT2"),
        // Found by the option fuzzer: rtol 0.5 controls no error (a run
        // under a scale of 5e8 did not end); refused before any run.
        (
            vec![
                "pounding", &frame, &quake, "--units", "m/s2", "--scale", "5e8", "--rtol", "0.5",
            ],
            "--rtol 0.5: give a relative tolerance in [1e-13, 1e-2]",
        ),
    ] {
        let out = run(&args);
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}

/// `pounding` on the example pair and the synthetic record: the JSON
/// fields, pounding below the required gap, amplification, the code rules'
/// order; the spectrum's cells and CSV; bad input refused.
#[test]
fn pounding_of_two_frames() {
    let pair = repo_file("examples/pounding-frames.toml");
    let quake = repo_file("examples/synthetic-quake.csv");
    let doc = json(&[
        "pounding", &pair, &quake, "--units", "m/s2", "--format", "json",
    ]);
    let run = &doc["runs"][0];
    assert_eq!(run["record"]["units"], "m/s2");
    // Rayleigh damping is stated: 5 % in modes 1 and 2, on the initial
    // stiffness.
    let rayleigh = &doc["row"]["buildings"][0]["rayleigh"];
    assert_eq!(rayleigh["ratio"], 0.05);
    assert!(rayleigh["alpha"].as_f64().unwrap() > 0.0 && rayleigh["beta"].as_f64().unwrap() > 0.0);
    assert!(rayleigh["basis"]
        .as_str()
        .unwrap()
        .contains("initial stiffness"));
    let need = run["joints"][0]["required_gap"].as_f64().unwrap();
    assert!(need > 0.02, "{need}");
    assert!(run["pounding"]["impacts"].as_u64().unwrap() > 0);
    assert!(run["pounding"]["peak_impact_force"].as_f64().unwrap() > 0.0);
    assert_eq!(run["free"]["impacts"], 0);
    let g = &run["joints"][0]["code_gaps"];
    let (abs, srss, ddc) = (
        g["absolute_sum"].as_f64().unwrap(),
        g["srss"].as_f64().unwrap(),
        g["double_difference"].as_f64().unwrap(),
    );
    assert!(ddc <= srss && srss <= abs && need <= abs);
    assert_eq!(
        run["amplification"]["drift"]["left"]
            .as_array()
            .unwrap()
            .len(),
        3
    );
    let dir = temp_dir("pounding");
    let spec = json(&[
        "pounding",
        &pair,
        &quake,
        "--units",
        "m/s2",
        "--gaps",
        "0.01:0.06:3",
        "--ratios",
        "0.5:2:2",
        "--format",
        "json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let cells = spec["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 6);
    for c in cells {
        let need = c["required_gap"]["median"].as_f64().unwrap();
        if c["gap"].as_f64().unwrap() > need {
            assert_eq!(c["impacts"]["median"].as_f64().unwrap(), 0.0);
        }
    }
    for f in [
        "pounding.json",
        "spectrum.csv",
        "spectrum.svg",
        "spectrum.png",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    let bad_pair = dir.join("bad.toml");
    std::fs::write(
        &bad_pair,
        std::fs::read_to_string(&pair)
            .unwrap()
            .replace("floors = [1, 2]", "floors = [3]"),
    )
    .unwrap();
    let bad = bad_pair.display().to_string();
    for (args, needle) in [
        (
            vec!["pounding", &bad, &quake, "--units", "m/s2"],
            "floor 3 is not a floor of both",
        ),
        (vec!["pounding", &pair, &quake], "states no units"),
        (
            vec![
                "pounding",
                &pair,
                &quake,
                "--units",
                "m/s2",
                "--gaps",
                "0.01:0.02:2",
            ],
            "--ratios",
        ),
    ] {
        let out = common::run(&args);
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // `--format csv` of the runs was offered, then refused: it is the
    // runs' peaks, a row per record, building and storey, the JSON's
    // numbers to the last bit.
    let out = common::run(&[
        "pounding", &pair, &quake, "--units", "m/s2", "--format", "csv",
    ]);
    assert!(out.status.success());
    let csv = String::from_utf8(out.stdout).unwrap();
    let doc = json(&[
        "pounding", &pair, &quake, "--units", "m/s2", "--format", "json",
    ]);
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0][3], "peak_drift_m");
    assert_eq!(rows.len(), 1 + 3 + 2, "{csv}");
    let right_2 = &rows[5];
    assert_eq!((right_2[1], right_2[2]), ("right", "2"));
    let drift: f64 = right_2[3].parse().unwrap();
    assert_eq!(
        drift,
        doc["runs"][0]["pounding"]["peak_drift"]["right"][1]
            .as_f64()
            .unwrap()
    );
}

/// `hysteresis`: a bilinear storey's loop over a cyclic protocol (the
/// dissipated energy of two cycles at 4 u_y is the parallelogram's area,
/// plus the first excursion's), its files, and bad settings by option.
#[test]
fn hysteresis_loop_and_bad_input() {
    let dir = temp_dir("hysteresis");
    let out = dir.join("loop");
    let doc = json(&[
        "hysteresis",
        "--stiffness",
        "1e8",
        "--yield-drift",
        "0.01",
        "--post-yield-ratio",
        "0.1",
        "--amplitudes",
        "0.04",
        "--cycles",
        "2",
        "--points",
        "8",
        "--format",
        "json",
        "--out",
        out.to_str().unwrap(),
    ]);
    // Plastic drift: 0 -> 4 uy: 3 uy; three swings of 8 uy: 6 uy each;
    // the last quarter -4 uy -> 0: 2 uy. Each dissipates (1 - b) k uy per
    // unit of plastic drift.
    let kh_uy = 0.9 * 1e8 * 0.01;
    let total = doc["total_dissipated"].as_f64().unwrap();
    let expected = kh_uy * 0.01 * (3.0 + 6.0 * 3.0 + 2.0);
    assert!(
        (total - expected).abs() < 1e-9 * expected,
        "{total} vs {expected}"
    );
    for f in [
        "hysteresis.csv",
        "hysteresis.json",
        "hysteresis.svg",
        "hysteresis.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let base = ["hysteresis", "--stiffness", "1e8", "--amplitudes", "0.02"];
    for (extra, needle) in [
        (
            &["--yield-drift", "0.01", "--post-yield-ratio", "1"][..],
            "--post-yield-ratio 1: must be in [0, 1)",
        ),
        (&[][..], "--yield-drift: give the yield drift"),
        (
            &[
                "--law",
                "bouc-wen",
                "--yield-drift",
                "0.01",
                "--exponent",
                "0",
            ][..],
            "--exponent 0:",
        ),
        (
            &["--yield-drift", "0.01", "--points", "10"][..],
            "--points 10: give a positive multiple of 4",
        ),
        (
            &["--law", "elastic", "--yield-drift", "0.01"][..],
            "--yield-drift: an elastic storey has no yield drift",
        ),
        // H3: a document of 2e7 row objects (30 GB) is refused up
        // front; the table of as many samples needs no document.
        (
            &[
                "--yield-drift",
                "0.01",
                "--points",
                "10000000",
                "--format",
                "json",
            ][..],
            "20000000 drift samples: the JSON document (--format json, --out) would hold about 30 GB",
        ),
    ] {
        assert_clean_error(&[&base[..], extra].concat(), needle);
    }
}

/// `pounding --moat-gaps` on the isolated example: the cells (no contacts
/// first, then each gap), the moat struck at the smallest gap and not at
/// a gap beyond the free slab's reach, the CSV and both figures; a pair
/// without isolation refused by the option's name.
#[test]
fn moat_gap_study_of_an_isolated_building() {
    let building = repo_file("examples/isolated-building.toml");
    let quake = repo_file("examples/synthetic-quake.csv");
    let dir = temp_dir("moat");
    let study = [
        "pounding",
        &building,
        &quake,
        "--units",
        "m/s2",
        "--scale",
        "2",
        "--moat-gaps",
        "0.05:1.5:2",
    ];
    let out_dir = dir.to_str().unwrap();
    let doc = json(&[&study[..], &["--format", "json", "--out", out_dir]].concat());
    let cells = doc["moat_cells"].as_array().unwrap();
    assert_eq!(cells.len(), 3);
    assert!(cells[0]["gap"].is_null());
    let reach = cells[0]["isolator_displacement"]["median"]
        .as_f64()
        .unwrap();
    assert!(reach > 0.05 && reach < 1.5, "{reach}");
    assert!(cells[1]["moat_impacts"]["median"].as_f64().unwrap() > 0.0);
    assert_eq!(cells[2]["moat_impacts"]["median"].as_f64().unwrap(), 0.0);
    for f in [
        "pounding.json",
        "moat.csv",
        "moat-drift.svg",
        "moat-acceleration.png",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    // The table prints the cells (it printed no results before): a row
    // for the run without contacts and one per gap, the JSON's medians.
    let out = run(&study);
    let table = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = table
        .lines()
        .filter(|l| l.contains("e-") || l.contains("e0"))
        .collect();
    assert_eq!(lines.len(), 3, "{table}");
    assert!(lines[0].trim_start().starts_with("free"), "{table}");
    assert!(lines[0].contains(&format!("{reach:.4e}")), "{table}");
    // The runs themselves draw each yielding building's loops.
    let runs = temp_dir("moat-runs");
    json(&[
        "pounding",
        &building,
        &quake,
        "--units",
        "m/s2",
        "--scale",
        "2",
        "--format",
        "json",
        "--out",
        runs.to_str().unwrap(),
    ]);
    assert!(runs.join("loops-1-isolated.svg").is_file());
    let pair = repo_file("examples/pounding-frames.toml");
    let out = run(&[
        "pounding",
        &pair,
        &quake,
        "--units",
        "m/s2",
        "--moat-gaps",
        "0.1:0.2:2",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--moat-gaps") && err.contains("isolated building with a moat"),
        "{err}"
    );
}

/// `collapse` on an undamped elastic–perfectly-plastic storey under a
/// step of ground acceleration: the collapse bracket holds the closed
/// form 1.9 (docs/earthquakes.md), CMR and ACMR follow from the given
/// S_MT and SSF; a largest scale below it leaves the record censored and
/// the median undetermined, said in the document; bad settings refused by
/// option.
#[test]
fn collapse_of_an_elastic_perfectly_plastic_storey() {
    let dir = temp_dir("collapse");
    let row = dir.join("epp.toml");
    std::fs::write(
        &row,
        "[[building]]\nname = \"epp\"\nmasses = [1e5]\nstiffnesses = [4e6]\ndamping_ratio = 0.0\n\
         storeys = [{ law = \"bilinear\", yield_drift = 0.05, post_yield_ratio = 0.0 }]\n",
    )
    .unwrap();
    let step = dir.join("step.txt");
    std::fs::write(&step, "0 1\n40 1\n").unwrap();
    let (row, step) = (row.display().to_string(), step.display().to_string());
    let args = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "collapse",
            &row,
            &step,
            "--units",
            "m/s2",
            "--drift-limit",
            "0.5",
            "--first",
            "0.5",
            "--sample",
            "0.002",
            "--rtol",
            "1e-10",
            "--format",
            "json",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let given = args(&["--period", "1", "--smt", "2", "--ssf", "1.2"]);
    let doc = json(&given.iter().map(String::as_str).collect::<Vec<_>>());
    let r = &doc["records"][0];
    let (low, high) = (
        r["survived"].as_f64().unwrap(),
        r["collapse"].as_f64().unwrap(),
    );
    assert!(
        low <= 1.9 && 1.9 <= high && high / low <= 1.02,
        "[{low}, {high}]"
    );
    // How it collapsed (the EPP storey passes the drift limit).
    assert_eq!(r["collapse_mode"], "drift limit");
    let s = &doc["summary"];
    assert_eq!(s["median_collapse_scale"].as_f64().unwrap(), high);
    let (s_t, cmr) = (s["s_t"].as_f64().unwrap(), s["cmr"].as_f64().unwrap());
    // S_T, Ŝ_CT and S_MT in g (`--smt 2` is 2 g): Ŝ_CT / S_MT.
    assert_eq!(doc["units"]["spectral_acceleration"], "g");
    assert!((s["s_ct"].as_f64().unwrap() - high * s_t).abs() < 1e-12);
    assert!((cmr - high * s_t / 2.0).abs() < 1e-12);
    assert!((s["acmr"].as_f64().unwrap() - 1.2 * cmr).abs() < 1e-12);
    // One record: the IDA figure, no fragility figure, and the reason.
    assert!(s["fragility"].is_null());
    let figures = dir.join("figures");
    let mut with_out = given.clone();
    with_out.extend(["--out".to_string(), figures.display().to_string()]);
    let out = run(&with_out.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success());
    assert!(figures.join("ida.svg").is_file() && figures.join("collapse.json").is_file());
    assert!(!figures.join("fragility.svg").exists());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no fragility figure (no fragility: 1 of 1 records collapsed; a fragility needs at least two collapses)"),
        "{err}"
    );
    // Two records at two levels: both collapse, so the fit is the closed
    // form (θ the geometric mean of the collapse intensities, β the
    // spread of their logarithms) and the figure is drawn.
    let step2 = dir.join("step2.txt");
    std::fs::write(&step2, "0 1.25\n40 1.25\n").unwrap();
    let mut two = given.clone();
    two.insert(2, step2.display().to_string());
    two.extend(["--out".to_string(), figures.display().to_string()]);
    let out = run(&two.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success());
    assert!(figures.join("fragility.svg").is_file() && figures.join("fragility.png").is_file());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let s_t = doc["summary"]["s_t"].as_f64().unwrap();
    let sa: Vec<f64> = doc["records"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["collapse"].as_f64().unwrap() * s_t)
        .collect();
    let fit = &doc["summary"]["fragility"];
    let (l0, l1) = (sa[0].ln(), sa[1].ln());
    assert!((fit["median"].as_f64().unwrap() - (0.5 * (l0 + l1)).exp()).abs() < 1e-12);
    assert!((fit["dispersion"].as_f64().unwrap() - 0.5 * (l0 - l1).abs()).abs() < 1e-12);
    assert_eq!(fit["intensity"], "s_t");
    let short = args(&["--max-scale", "1.5"]);
    let doc = json(&short.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(doc["records"][0]["note"], "no collapse up to scale 1.5");
    assert!(doc["records"][0]["collapse_mode"].is_null());
    assert!(doc["summary"]["median_collapse_scale"].is_null());
    assert!(doc["summary"]["note"]
        .as_str()
        .unwrap()
        .contains("not determined"));
    for (extra, needle) in [
        (vec!["--growth", "1"], "--growth 1"),
        (vec!["--tolerance", "1.5"], "--tolerance 1.5"),
        (vec!["--smt", "2"], "--period"),
        // W2: a negative S_MT printed a negative CMR; refused before the runs.
        (
            vec!["--period", "1", "--smt", "-2"],
            "--smt -2: give the positive MCE spectral acceleration S_MT in g",
        ),
        (
            vec!["--period", "1", "--smt", "2", "--ssf", "0"],
            "--ssf 0:",
        ),
        // --period 0 was answered about the spectrum's `--periods`.
        (
            vec!["--period", "0"],
            "--period 0: give the positive period (s) of the spectral acceleration",
        ),
        (
            vec!["--damping", "1"],
            "--damping 1: give a damping ratio in [0, 1)",
        ),
    ] {
        let a = args(&extra);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let out = run(&a);
        assert!(!out.status.success(), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{extra:?}: {err}");
    }
}
