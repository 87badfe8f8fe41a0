//! Tests of the model-file schema.
use super::*;

fn parse(text: &str) -> Result<LoadedModel, ModelFileError> {
    ModelDocument::from_toml(text, "m.toml")?.build()
}

const ROW: &str = r#"
[row]
count = 3
mass = 0.227
natural_frequency = 7.41
damping_ratio = 0.013
clearance = 0.001
contact = { law = "exponential", a_over_b = 1.2, alpha = 1.3e5, a = 1.0 }

[excitation]
type = "harmonic-base"
amplitude = 0.05
frequency = 7.0395
"#;

const EXPLICIT: &str = r#"
[[body]]
name = "a"
mass = 1.0
stiffness = 100.0
[[body]]
name = "b"
mass = 2.0
natural_frequency = 5.0
damping_ratio = 0.02
initial_velocity = 0.1
[[spring]]
between = ["a", "b"]
stiffness = 10.0
[[contact]]
between = ["wall", "a"]
clearance = 0.002
law = { law = "hertz", stiffness = 1e9 }
[[contact]]
between = ["a", "b"]
clearance = 0.001
law = { law = "kelvin-voigt", stiffness = 1e6, damping = 10.0, form = "non-negative" }
[[force]]
body = "b"
amplitude = 1.0
frequency = 3.0
"#;

#[test]
fn row_form() {
    let m = parse(ROW).unwrap().model;
    assert_eq!(m.bodies().len(), 3);
    assert_eq!(m.contacts().len(), 4);
    assert!((m.bodies()[0].stiffness - 0.227 * 7.41 * 7.41).abs() < 1e-12);
    assert!((m.bodies()[0].damping - 2.0 * 0.013 * 0.227 * 7.41).abs() < 1e-14);
    assert_eq!(m.forcing_frequency(), Some(7.0395));
}

#[test]
fn explicit_form() {
    let text = EXPLICIT;
    let m = parse(text).unwrap().model;
    assert_eq!(m.couplings().len(), 1);
    assert_eq!(m.contact_name(0), "wall|a");
    assert_eq!(m.contacts()[1].law.form(), ForceForm::NonNegative);
    assert_eq!(m.initial_velocity(), &[0.0, 0.1]);
    assert_eq!(m.forcing_frequency(), Some(3.0));
}

fn err(text: &str) -> String {
    parse(text).expect_err("should fail").to_string()
}

#[test]
fn errors_name_line_and_key() {
    let e = err(&ROW.replace("mass = 0.227", "mass = 0.227\nmasss = 1"));
    assert!(e.starts_with("m.toml:") && e.contains("masss"), "{e}");
    // A value of the wrong type names its table and key (a Python dict's
    // TOML text has no lines the user wrote).
    let e = err(&ROW.replace("mass = 0.227", "mass = \"0.2\""));
    assert!(
        e.starts_with("m.toml:4: key `row.mass`: invalid type: string \"0.2\""),
        "{e}"
    );
    let e = err(&ROW.replace("clearance = 0.001\n", ""));
    assert!(e.contains("clearance"), "{e}");
    let e = err(&ROW.replace("mass = 0.227", "mass = -1"));
    assert!(e.starts_with("m.toml:2:") && e.contains("mass = -1"), "{e}");
    let e = err(&ROW.replace("alpha = 1.3e5", "alpha = 0"));
    assert!(e.contains("alpha"), "{e}");
    let e = err(&ROW.replace("clearance = 0.001", "clearance = -0.001"));
    assert!(e.contains("clearance"), "{e}");
    let e = err("[[body]]\nname = \"a\"\nmass = 1.0\n[[contact]]\nbetween = [\"a\", \"wall\", \"b\"]\nclearance = 0.0\nlaw = { law = \"hertz\", stiffness = 1.0 }\n");
    assert!(
        e.contains("m.toml:5") && e.contains("exactly two names") && e.contains("got 3"),
        "{e}"
    );
    let e = err(&ROW.replace("count = 3", "count = 3 # \u{1} x"));
    assert!(e.contains("control character U+0001"), "{e}");
    let line = ROW
        .lines()
        .position(|l| l.starts_with("count = 3"))
        .unwrap()
        + 1;
    assert!(e.starts_with(&format!("m.toml:{line}: ")), "{e}");
    let e = err("[[body]]\nname = \"a\"\nmass = 1.0\n[[contact]]\nbetween = [\"a\", \"zz\"]\nclearance = 0.0\nlaw = { law = \"hertz\", stiffness = 1.0 }\n");
    assert!(
        e.starts_with("m.toml:4:") && e.contains("unknown body `zz`"),
        "{e}"
    );
    let e = err("[[body]]\nname = \"a\"\nmass = 1.0\ninitial_displacement = 0.01\n[[contact]]\nbetween = [\"a\", \"wall\"]\nclearance = 0.001\nlaw = { law = \"hertz\", stiffness = 1.0 }\n");
    assert!(e.contains("overlap"), "{e}");
    let e = err(&ROW.replace("type = \"harmonic-base\"", "type = \"quake\""));
    assert!(e.contains("quake"), "{e}");
    let e = err(&ROW.replace("law = \"exponential\"", "law = \"magic\""));
    assert!(e.contains("magic"), "{e}");
}

#[test]
fn accelerograms_from_text_and_inline() {
    let a = parse_accelerogram_csv("time,acceleration\n0,0\n0.5,1\n1.0,0\n", "ok.csv").unwrap();
    assert_eq!((a.times.len(), a.acceleration[1]), (3, 1.0));
    let e = parse_accelerogram_csv("0,0\n0.5,1\n0.4,0\n", "bad.csv")
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.csv:3:") && e.contains("increase"), "{e}");
    let text = "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n[excitation]\ntype = \"accelerogram\"\nfile = \"ok.csv\"\nscale = 0.5\n";
    let doc = ModelDocument::parse(text, "m.toml", &mut |f, _| {
        assert_eq!(f, "ok.csv");
        Ok(a.clone())
    })
    .unwrap();
    let m = doc.build().unwrap().model;
    let BaseExcitation::Record(r) = m.base() else {
        panic!("a record")
    };
    assert_eq!(r.at(0.25), 0.25);
    // Written back with the record inline, it reads without the file.
    let again = ModelDocument::from_toml(&doc.to_toml(), "again").unwrap();
    assert_eq!(again.build().unwrap().model, m);
    let e = ModelDocument::from_toml(text, "m.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("ok.csv") && e.contains("inline"), "{e}");
}

#[test]
fn inline_records_and_settings_are_checked() {
    let base = "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n";
    let e = err(&format!(
            "{base}[excitation]\ntype = \"accelerogram\"\ntime = [0.0, 1.0, 2.0]\nacceleration = [0.0, 1.0]\n"
        ));
    assert!(
        e.starts_with("m.toml:7:") && e.contains("`time` has 3 values, `acceleration` 2"),
        "{e}"
    );
    let e = err(&format!("{base}[simulation]\natol = -1e-9\n"));
    assert!(
        e.contains("[simulation] atol = -0.000000001: must be finite and > 0"),
        "{e}"
    );
    let e = err(&format!("{base}[simulation]\nrtol = nan\n"));
    assert!(e.contains("[simulation] rtol = NaN"), "{e}");
}

/// Every example form survives the round trip through `to_toml`.
#[test]
fn round_trip() {
    for text in [ROW, EXPLICIT] {
        let doc = ModelDocument::from_toml(text, "m.toml").unwrap();
        let again = ModelDocument::from_toml(&doc.to_toml(), "again").unwrap();
        assert_eq!(again.build().unwrap().model, doc.build().unwrap().model);
    }
}

/// `[initial]` by body name: the named bodies' values, the others at rest;
/// an unknown name is an error with its line; the form survives the round
/// trip; a dotted parameter into it does not exist.
#[test]
fn initial_state_by_body_name() {
    let text = include_str!("../../../../../examples/granular-chain.toml");
    let doc = ModelDocument::from_toml(text, "chain.toml").unwrap();
    let m = doc.build().unwrap().model;
    assert_eq!(m.initial_velocity()[0], 1.0);
    assert!(m.initial_velocity()[1..].iter().all(|&v| v == 0.0));
    assert!(m.initial_displacement().iter().all(|&u| u == 0.0));
    let again = ModelDocument::from_toml(&doc.to_toml(), "again").unwrap();
    assert_eq!(again.build().unwrap().model, m);
    let bad = text.replace("{ p1 = 1.0 }", "{ p1 = 1.0, q7 = 2.0 }");
    let e = err(&bad);
    assert!(e.contains("chain.toml:") || e.contains(":2"), "{e}");
    assert!(e.contains("no body named \"q7\""), "{e}");
    assert!(doc.parameter("initial.velocity.1").is_err());
}

/// Issue 38: a row's mass of 1e-100 kg (down to 1e-300) "completed" with
/// every body exactly at rest: its moving forces (5e-102 N) were lost in
/// rounding against the exponential law's tails at rest (7e-57 N). It is
/// refused at the row's line, naming the mass and the least that works
/// (KEPT_ABOVE × tails / acceleration); 1e-60 kg, above it, is accepted.
/// A mass whose stiffness m ω² overflows names the mass and the frequency
/// (it blamed `damping = inf`, a key never set), and a heavy one whose
/// damping 2ζ√(km) alone would overflow on the way is computed.
#[test]
fn masses_outside_double_precision_are_refused_by_name() {
    let with = |mass: &str| ROW.replace("mass = 0.227", &format!("mass = {mass}"));
    for tiny in ["1e-100", "1e-300"] {
        let e = err(&with(tiny));
        assert!(
            e.starts_with("m.toml:2: [row] body p1: mass = ")
                && e.contains("would be lost in rounding")
                && e.contains("give a mass of at least 1.27e-65 kg"),
            "{e}"
        );
    }
    assert!(parse(&with("1e-60")).is_ok());
    let e = err(&with("1e307"));
    assert!(
        e.contains("mass = 1e307 with natural_frequency = 7.41") && !e.contains("damping ="),
        "{e}"
    );
    let heavy = parse(&with("1e300")).unwrap().model;
    let c = heavy.bodies()[0].damping;
    assert!(
        (c / (2.0 * 0.013 * 1e300 * 7.41) - 1.0).abs() < 1e-12,
        "{c}"
    );
}

/// Issue 38: a key's path took in the header's trailing comment (every
/// shipped example comments its headers): ``key `row]   # N identical
/// bodies between two walls.mas` ``. Unknown keys, wrong types and
/// duplicates under commented headers, `[row]` and `[[body]]` alike, now
/// name `row.mas`, `body.mass`.
#[test]
fn a_key_path_ends_at_its_header() {
    let commented = ROW.replace("[row]", "[row]                       # N identical bodies");
    let e = err(&commented.replace("mass = 0.227", "mas = 0.227"));
    assert!(
        e.starts_with("m.toml:4: key `row.mas`: unknown field `mas`"),
        "{e}"
    );
    let e = err(&commented.replace("mass = 0.227", "mass = \"heavy\""));
    assert!(
        e.starts_with("m.toml:4: key `row.mass`: invalid type"),
        "{e}"
    );
    let e = err(&commented.replace("mass = 0.227", "mass = 0.227\nmass = 0.3"));
    assert!(e.contains("key `row.mass`") && !e.contains('#'), "{e}");
    let e = err("[[body]]  # the first\nname = \"a\"\nmass = \"x\"\n");
    assert!(
        e.starts_with("m.toml:3: key `body.mass`: invalid type"),
        "{e}"
    );
}

/// Issue 38: a contact between a body and itself said "give the left body
/// first"; it says what is wrong.
#[test]
fn a_contact_of_a_body_with_itself_is_named() {
    let e = err("[[body]]\nname = \"p1\"\nmass = 1.0\n[[contact]]\nbetween = [\"p1\", \"p1\"]\nclearance = 0.001\nlaw = { law = \"hertz\", stiffness = 1e9 }\n");
    assert!(
        e.starts_with(
            "m.toml:4: [[contact]] between = [\"p1\", \"p1\"]: a body cannot strike itself"
        ),
        "{e}"
    );
}

/// `impacts = "rigid"` makes every contact of a row rigid, and a
/// `[[contact]]`'s with its `restitution`; bad values name the table, the
/// key and the line (docs/theory.md §12).
#[test]
fn impacts_are_soft_or_rigid() {
    use crate::model::Impacts;
    let m = parse(&ROW.replace("clearance = ", "impacts = \"rigid\"\nclearance = "))
        .unwrap()
        .model;
    assert!((0..4).all(|k| m.impacts(k) == Impacts::Rigid { restitution: None }));
    let text = EXPLICIT.replace(
        "law = { law = \"hertz\", stiffness = 1e9 }",
        "law = { law = \"hertz\", stiffness = 1e9 }\nimpacts = \"rigid\"\nrestitution = 0.8",
    );
    let m = parse(&text).unwrap().model;
    assert_eq!(
        m.impacts(0),
        Impacts::Rigid {
            restitution: Some(0.8)
        }
    );
    assert_eq!(m.impacts(1), Impacts::Soft);
    let e = err(&text.replace("impacts = \"rigid\"", "impacts = \"hard\""));
    assert!(
        e.contains("[[contact]] wall|a impacts = \"hard\": must be soft or rigid"),
        "{e}"
    );
    assert!(e.starts_with("m.toml:"), "{e}");
    let e = err(&text.replace("impacts = \"rigid\"\n", ""));
    assert!(
        e.contains("restitution = 0.8: a coefficient of restitution is for rigid impacts"),
        "{e}"
    );
    let e = err(&text.replace("restitution = 0.8", "restitution = 1.5"));
    assert!(
        e.contains("wall|a") && e.contains("restitution = 1.5 is invalid"),
        "{e}"
    );
    // A Kelvin–Voigt contact damped past critical never separates.
    let e = err(&EXPLICIT.replace(
        "damping = 10.0, form = \"non-negative\" }",
        "damping = 1e5 }\nimpacts = \"rigid\"",
    ));
    assert!(
        e.contains("[[contact]] a|b") && e.contains("never separates"),
        "{e}"
    );
}

/// `gravity` (top level, m/s² toward −u) reaches the model and breaks
/// its mirror symmetry; a value that is not finite is refused with the
/// line and the key.
#[test]
fn gravity_is_a_top_level_key() {
    let m = parse(&format!("gravity = 9.81\n{EXPLICIT}")).unwrap().model;
    assert_eq!(m.gravity(), 9.81);
    assert!(!m.is_mirror_symmetric());
    assert_eq!(parse(EXPLICIT).unwrap().model.gravity(), 0.0);
    let e = err(&format!("gravity = nan\n{EXPLICIT}"));
    assert!(
        e.starts_with("m.toml:1") && e.contains("gravity = NaN: must be finite"),
        "{e}"
    );
    let e = err(&format!("gravity = \"down\"\n{EXPLICIT}"));
    assert!(e.contains("gravity"), "{e}");
}

/// `[simulation] displacement_scale` is kept for the studies that shoot,
/// and refused unless finite and positive, by key.
#[test]
fn displacement_scale_is_a_simulation_setting() {
    let text = format!("{EXPLICIT}\n[simulation]\ndisplacement_scale = 0.1\n");
    let loaded = parse(&text).unwrap();
    assert_eq!(loaded.simulation.displacement_scale, Some(0.1));
    let e = err(&text.replace("0.1", "-1.0"));
    assert!(
        e.contains("[simulation] displacement_scale = -1: must be finite and > 0"),
        "{e}"
    );
}

/// A face's `--impacts` and `--restitution` rewrite the document's keys,
/// so that every model it builds has them (a sweep's, a branch's);
/// refusals name the option.
#[test]
fn impact_options_rewrite_the_document() {
    use crate::model::Impacts;
    let doc = ModelDocument::from_toml(ROW, "m.toml").unwrap();
    let rigid = doc
        .clone()
        .with_impact_options(Some("rigid"), Some(0.7))
        .unwrap();
    let m = rigid.build().unwrap().model;
    let want = Impacts::Rigid {
        restitution: Some(0.7),
    };
    assert!((0..4).all(|k| m.impacts(k) == want));
    let p = rigid.parameter("frequency").unwrap();
    let shifted = rigid.with_parameter(&p, 7.5).unwrap().model;
    assert!((0..4).all(|k| shifted.impacts(k) == want));
    // A coefficient alone changes the file's rigid contacts.
    let e = rigid
        .clone()
        .with_impact_options(None, Some(0.4))
        .unwrap()
        .build()
        .unwrap()
        .model;
    assert_eq!(
        e.impacts(0),
        Impacts::Rigid {
            restitution: Some(0.4)
        }
    );
    let soft = rigid.with_impact_options(Some("soft"), None).unwrap();
    assert!(!soft.build().unwrap().model.has_rigid_impacts());
    let e = doc
        .clone()
        .with_impact_options(Some("hard"), None)
        .unwrap_err();
    assert!(e.to_string().contains("impacts"), "{e}");
    let e = doc.with_impact_options(None, Some(0.5)).unwrap_err();
    assert!(
        e.to_string()
            .contains("restitution = 0.5: a coefficient of restitution is for rigid impacts"),
        "{e}"
    );
}
