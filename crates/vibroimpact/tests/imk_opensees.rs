//! The IMK storey against OpenSees' `IMKBilin` (Nov22), its peer: the
//! force along a cyclic protocol of growing amplitudes, with and without
//! cyclic deterioration, within 0.1 % of the yield force at every point
//! (the issue asks 1 %; measured 1.6e-13 and 9.8e-10).
//! The peer's forces are in `tests/data/imk-opensees.csv`, written by
//! `bench/opensees/imk_reference.py` (openseespy 3.7.1.2, 2 µm steps).

use vibroimpact::model::hysteresis::imk::Imk;

fn law(lambda: f64) -> Imk {
    Imk {
        stiffness: 1.2e8,
        yield_drift: 0.01,
        cap_ratio: 1.1,
        plastic_drift: 0.03,
        post_capping_drift: 0.1,
        residual_ratio: 0.3,
        ultimate_drift: 0.2,
        lambda: [lambda; 3],
        exponent: [1.0; 3],
    }
}

#[test]
fn imk_follows_opensees_imkbilin() {
    let text = include_str!("data/imk-opensees.csv");
    let rows: Vec<(String, f64, f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("case"))
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            let num = |i: usize| c[i].parse::<f64>().unwrap();
            (c[0].to_string(), num(1), num(2), num(3))
        })
        .collect();
    let fy = 1.2e8 * 0.01;
    for case in ["no-deterioration", "deteriorating"] {
        let points: Vec<_> = rows.iter().filter(|r| r.0 == case).collect();
        assert!(points.len() > 1000, "{case}: {} points", points.len());
        let imk = law(points[0].1);
        let mut s = imk.rest();
        let (mut worst, mut at) = (0.0f64, 0.0);
        let mut peak = 0.0f64;
        for p in &points {
            imk.advance(&mut s, p.2);
            let e = (s.force - p.3).abs() / fy;
            if e > worst {
                (worst, at) = (e, p.2);
            }
            peak = peak.max(p.3.abs());
        }
        assert!(worst < 1e-3, "{case}: {worst:.3e} of F_y at drift {at}");
        assert!(peak > fy, "{case}: the protocol yields ({peak})");
        eprintln!("{case}: largest difference {worst:.2e} F_y");
    }
}
