//! Issue 38: figures that a vibration researcher reads rightly. The
//! response figure marks and labels every special point (grazing
//! included) on its curve, with the parameter's units.

mod common;
use common::*;

/// `continue --out` on R2 N = 2: every special point carries its own
/// orbit's amplitude, within 0.2 µm of the chord between the branch
/// points around it (measured at most 0.065 µm, at GR2), where the
/// figure took the point before it (4.3 µm off at BP1, 2.7 µm at GR1).
/// The figure passes through them and labels each, GR1 and GR2 with
/// their grazing markers; the axis names the forcing frequency in rad/s.
#[test]
fn special_points_sit_on_their_curve_and_are_labelled() {
    let dir = temp_dir("figures-response");
    let out = run(&[
        "continue",
        &repo_file("examples/fujita-row-n2.toml"),
        "--parameter",
        "frequency",
        "--from",
        "3.705",
        "--to",
        "11.115",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("branch.json")).unwrap()).unwrap();
    let points = doc["points"].as_array().unwrap();
    let amplitude = |p: &serde_json::Value| p["max_displacement"][0].as_f64().unwrap();
    let special = doc["special_points"].as_array().unwrap();
    assert_eq!(special.len(), 9);
    for s in special {
        let i = s["after_point"].as_u64().unwrap() as usize;
        let (a, b) = (&points[i], &points[i + 1]);
        let (pa, pb) = (
            a["parameter"].as_f64().unwrap(),
            b["parameter"].as_f64().unwrap(),
        );
        let t = (s["parameter"].as_f64().unwrap() - pa) / (pb - pa);
        let chord = amplitude(a) + t * (amplitude(b) - amplitude(a));
        let own = amplitude(s);
        assert!(
            (own - chord).abs() < 2e-7,
            "{}: {own} m against the chord's {chord} m",
            s["label"]
        );
    }
    let svg = std::fs::read_to_string(dir.join("branch_response.svg")).unwrap();
    for s in special {
        let label = s["label"].as_str().unwrap();
        assert!(svg.contains(label), "{label} is not written on the figure");
    }
    for text in [
        "grazing",
        "branch-point",
        "neimark-sacker",
        "forcing frequency Ω  [rad/s]",
    ] {
        assert!(svg.contains(text), "{text} missing from the figure");
    }
}
