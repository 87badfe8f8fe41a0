//! Reading records: AT2, columns, units and bad input.

use super::*;

const AT2: &str = "PEER NGA STRONG MOTION DATABASE RECORD
IMPERIAL VALLEY 10/15/79 2316, EL CENTRO ARRAY #6, 230 (CDMG STATION 942)
ACCELERATION TIME SERIES IN UNITS OF G
NPTS=     7, DT=   .0100 SEC
  .1000E-01  -.2000E-01   .3000E-01  -.4000E-01   .5000E-01
  -.6000E-01   .7000E-01
";

#[test]
fn at2_is_read_with_its_header_units_and_step() {
    let r = parse_record(AT2, "RSN185.AT2", None).unwrap();
    assert_eq!(r.units, Units::G);
    assert_eq!(r.dt, Some(0.01));
    assert_eq!(r.times.len(), 7);
    assert!((r.times[6] - 0.06).abs() < 1e-15);
    assert!((r.acceleration[6] - 0.07 * STANDARD_GRAVITY).abs() < 1e-15);
    assert!((r.pga() - 0.07 * STANDARD_GRAVITY).abs() < 1e-15);
    assert_eq!(r.header.len(), 4);
    assert!(r.header[1].contains("EL CENTRO"));
    // The older header form `n dt NPTS, DT`.
    let old = AT2.replace("NPTS=     7, DT=   .0100 SEC", "    7   .0100    NPTS, DT");
    assert_eq!(
        parse_record(&old, "old.AT2", None).unwrap(),
        Record {
            source: "old.AT2".into(),
            header: old.lines().take(4).map(String::from).collect(),
            ..r.clone()
        }
    );
}

/// The same record in g, m/s² and gal (two columns with a header, CSV) is
/// the same ground motion.
#[test]
fn units_agree() {
    let g = parse_record(AT2, "a.AT2", None).unwrap();
    let columns = |factor: f64, sep: &str, head: &str| -> String {
        let mut t = format!("{head}\n");
        for (k, a) in g.acceleration.iter().enumerate() {
            t.push_str(&format!(
                "{:e}{sep}{:e}\n",
                g.times[k],
                a / STANDARD_GRAVITY * factor
            ));
        }
        t
    };
    let si = parse_record(
        &columns(STANDARD_GRAVITY, " ", "time [s]  acc [m/s2]"),
        "si",
        None,
    )
    .unwrap();
    let gal = parse_record(
        &columns(100.0 * STANDARD_GRAVITY, ",", "t,a (cm/s2)"),
        "gal.csv",
        None,
    )
    .unwrap();
    let stated = parse_record(
        &columns(1.0, "\t", "time acceleration"),
        "x",
        Some(Units::G),
    )
    .unwrap();
    assert_eq!(
        (si.units, gal.units, stated.units),
        (Units::MetersPerSecond2, Units::Gal, Units::G)
    );
    for r in [&si, &gal, &stated] {
        for (a, b) in r.acceleration.iter().zip(&g.acceleration) {
            assert!(
                (a - b).abs() < 1e-14 * b.abs().max(1e-3),
                "{}: {a} vs {b}",
                r.source
            );
        }
    }
}

#[test]
fn bad_records_name_the_line() {
    let cases = [
        (
            AT2.replace("NPTS=     7", "NPTS=     8"),
            "NPTS = 8, the file has 7",
        ),
        (
            AT2.replace("UNITS OF G", "UNITS OF FURLONGS"),
            ":3: no units",
        ),
        (
            AT2.replace("NPTS=     7, DT=   .0100 SEC", "seven points"),
            ":4: expected `NPTS=",
        ),
        (AT2.replace(".3000E-01", "nan"), ":5: `nan` is not finite"),
        (
            "t a (g)\n0 1\n0.01 2\n0.01 3\n".into(),
            "x:4: time 0.01 is not after",
        ),
        ("t a\n0 1\n0.01 2\n".into(), "states no units"),
        (
            "t a (g)\n0 1\n0.01 2\n0.02 3\n0.5 1\n0.51 1\n".into(),
            "x:5: a gap",
        ),
        ("t a (g)\n0 1\n".into(), "at least two"),
        // An empty file was answered about units; three columns and
        // garbage with "0 samples".
        ("".into(), "x: empty: no samples"),
        ("\n  \n".into(), "x: empty: no samples"),
        (
            "0 1 2\n0.01 2 3\n".into(),
            "x:1: expected two numbers (time, acceleration), found `0 1 2`",
        ),
        (
            "garbage here\nmore garbage\n".into(),
            "x: no samples: no line holds two numbers",
        ),
        // Found by the fuzzer: finite in g, infinite in m/s².
        (
            "t a (g)\n0 0\n0.01 -1e308\n".into(),
            "x: sample 2 (t = 0.01): -1e308 is not finite in m/s2",
        ),
    ];
    for (text, needle) in cases {
        let e = parse_record(&text, "x", None).unwrap_err();
        assert!(e.to_string().contains(needle), "{e}");
        assert_eq!(e.file, "x");
    }
    // The line is its own field where one line is to blame.
    let e = parse_record("t a (g)\n0 1\n0.01 2\n0.01 3\n", "x", None).unwrap_err();
    assert_eq!(
        (e.line, e.message.starts_with("time 0.01")),
        (Some(4), true)
    );
    let units = Units::parse("furlongs").unwrap_err();
    assert_eq!(
        (units.field, units.value.as_deref()),
        ("units", Some("furlongs"))
    );
    assert!(units.message.contains("g, m/s2 or gal"));
}
