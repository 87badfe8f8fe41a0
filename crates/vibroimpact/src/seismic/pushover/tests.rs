//! The pushover against closed forms: an elastic frame's flexibility with
//! P-Δ, a bilinear storey's post-yield slope b k − P/h (the stability
//! coefficient), its collapse drift where b k < P/h, and FEMA P695's
//! δ_y,eff, δ_u and μ_T for one storey.

use super::*;
use crate::model::hysteresis::StoreySpec;
use crate::seismic::pounding::Gravity;

fn frame(masses: Vec<f64>, k: Vec<f64>, storeys: Vec<StoreySpec>, leaning: Vec<f64>) -> ShearFrame {
    let n = masses.len();
    ShearFrame {
        masses,
        stiffnesses: k,
        damping_ratio: 0.05,
        storeys,
        heights: vec![3.5; n],
        gravity: Gravity {
            p_delta: true,
            leaning_loads: leaning,
        },
    }
}

/// Elastic storeys with P-Δ: the roof moves λ Σ S_i/(k_i − P_i/h_i) under
/// the load factor λ, at every point to 1e-12.
#[test]
fn an_elastic_frame_follows_its_flexibility() {
    let f = frame(
        vec![2e5, 2e5, 1.5e5],
        vec![6e7, 5e7, 4e7],
        Vec::new(),
        vec![1e6, 1e6, 1e6],
    );
    let p = pushover(&f, &PushoverOptions::default()).unwrap();
    let g = f.geometric_stiffnesses();
    assert!(g.iter().all(|g| *g > 0.0));
    let shares: Vec<f64> = (0..3).map(|i| p.pattern[i..].iter().sum()).collect();
    let flexibility: f64 = (0..3).map(|i| shares[i] / (f.stiffnesses[i] - g[i])).sum();
    assert!((shares[0] - 1.0).abs() < 1e-15);
    for (u, v) in p.roof_displacement.iter().zip(&p.base_shear).skip(1) {
        assert!((u / (v * flexibility) - 1.0).abs() < 1e-12, "{u} {v}");
    }
    assert!(!p.collapsed && !p.strength_loss);
    // The push ends at the critical storey's drift limit, 10 % of 3.5 m.
    let last = p.drifts.last().unwrap();
    assert!((last[p.critical_storey] - 0.35).abs() < 1e-12);
}

/// One bilinear storey, 3.5 m, under W = m g and a leaning load: R(d) =
/// k d − g d to yield, then k u_y + b k (d − u_y) − g d. With b k > g the
/// slope after yield is b k − g (the stability coefficient θ = g/(b k)
/// of the post-yield stiffness); with b k < g it collapses at
/// d* = (1 − b) k u_y/(g − b k). FEMA P695: C0 = 1, δ_y,eff = u_y (the
/// period's stiffness is k − g), δ_u where R = 0.8 (k − g) u_y.
#[test]
fn a_bilinear_storey_matches_its_closed_forms() {
    let (m, k, uy, b) = (1e5, 4e7, 0.01, 0.05);
    let storey = vec![StoreySpec::Bilinear {
        yield_drift: uy,
        post_yield_ratio: b,
    }];
    // g = P/h with P = m g₀ + L: leaning loads giving b k/g = 2 and 0.5.
    for (ratio, collapses) in [(2.0, false), (0.5, true)] {
        let g = b * k / ratio;
        let leaning = g * 3.5 - m * STANDARD_GRAVITY;
        let f = frame(vec![m], vec![k], storey.clone(), vec![leaning]);
        assert!((f.geometric_stiffnesses()[0] - g).abs() < 1e-9 * g);
        let p = pushover(&f, &PushoverOptions::default()).unwrap();
        let r = |d: f64| {
            if d <= uy {
                (k - g) * d
            } else {
                k * uy + b * k * (d - uy) - g * d
            }
        };
        for (d, v) in p.drifts.iter().zip(&p.base_shear) {
            assert!(
                (v - r(d[0])).abs() < 1e-9 * k * uy,
                "{d:?}: {v} against {}",
                r(d[0])
            );
        }
        assert_eq!(p.collapsed, collapses);
        assert!(
            (p.max_base_shear - (k - g) * uy).abs() < 1e-9 * k * uy || !collapses,
            "{} {}",
            p.max_base_shear,
            (k - g) * uy
        );
        assert!((p.c0 - 1.0).abs() < 1e-15);
        if collapses {
            let star = (1.0 - b) * k * uy / (g - b * k);
            let end = p.drifts.last().unwrap()[0];
            assert!((end / star - 1.0).abs() < 1e-12, "{end} against {star}");
            assert!(
                (p.yield_displacement / uy - 1.0).abs() < 1e-9,
                "{}",
                p.yield_displacement
            );
            let du = uy + 0.2 * (k - g) * uy / (g - b * k);
            assert!(p.strength_loss);
            assert!((p.ultimate_displacement / du - 1.0).abs() < 1e-12);
            assert!((p.ductility - du / uy).abs() < 1e-8 * du / uy);
        } else {
            // Two points past yield: the slope b k − g.
            let (j, i) = (p.drifts.len() - 1, p.drifts.len() - 11);
            let slope = (p.base_shear[j] - p.base_shear[i]) / (p.drifts[j][0] - p.drifts[i][0]);
            assert!((slope / (b * k - g) - 1.0).abs() < 1e-9, "{slope}");
        }
    }
}

/// Bad options are refused by name; a frame without heights too.
#[test]
fn bad_pushovers_are_refused() {
    let f = frame(vec![1e5], vec![4e7], Vec::new(), Vec::new());
    for (opts, key) in [
        (
            PushoverOptions {
                drift_ratio_limit: 0.0,
                ..Default::default()
            },
            "drift_ratio_limit",
        ),
        (
            PushoverOptions {
                points: 1,
                ..Default::default()
            },
            "points",
        ),
        (
            PushoverOptions {
                points: 1 << 40,
                ..Default::default()
            },
            "points",
        ),
        (
            PushoverOptions {
                code_period: Some(-1.0),
                ..Default::default()
            },
            "code_period",
        ),
        // Found by the option fuzzer: 85.6 gave μ_T NaN.
        (
            PushoverOptions {
                drift_ratio_limit: 1.5,
                ..Default::default()
            },
            "drift_ratio_limit",
        ),
    ] {
        let e = pushover(&f, &opts).unwrap_err();
        assert!(e.starts_with(key), "{e}");
    }
    let mut bare = f.clone();
    bare.heights.clear();
    bare.gravity = Gravity::default();
    assert!(pushover(&bare, &PushoverOptions::default())
        .unwrap_err()
        .starts_with("heights"));
}

/// An IMK storey pushed on a grid far coarser than its backbone (two
/// points over a drift ratio of 1, where its cap lies at 3 %): the peak
/// is still the cap's, R_c = F_c − (P/h) d_c, as on the default grid, to
/// 1e-12 (found by the option fuzzer: the coarse push gave V_max 0 and
/// μ_T NaN).
#[test]
fn a_coarse_push_still_finds_the_cap() {
    let (k, uy, dp) = (4e7, 0.02, 0.085);
    let imk = StoreySpec::imk(
        Some(uy),
        [Some(1.1), Some(dp), Some(0.3), Some(0.4), Some(0.6)],
        [None, None, None],
        [1.0, 1.0, 1.0],
    )
    .unwrap();
    let f = frame(vec![1e5], vec![k], vec![imk], vec![1e5]);
    let g = f.geometric_stiffnesses()[0];
    let (dc, fc) = (uy + dp, 1.1 * k * uy);
    let expected = fc - g * dc;
    for points in [2, 400] {
        let opts = PushoverOptions {
            drift_ratio_limit: 1.0,
            points,
            ..Default::default()
        };
        let p = pushover(&f, &opts).unwrap();
        assert!(
            (p.max_base_shear / expected - 1.0).abs() < 1e-12,
            "{points}: {} against {expected}",
            p.max_base_shear
        );
        assert!(p.ductility.is_finite() && p.ductility > 1.0);
    }
}
