//! The modified Ibarra–Medina–Krawinkler storey (docs/theory.md §11), in
//! the bilinear-hysteresis form of Lignos and Krawinkler as OpenSees'
//! `IMKBilin` (Nov22) has it, symmetric, under a drift history.
//!
//! The backbone: elastic k to the yield force F_y = k u_y; hardening to the
//! cap F_c = (F_c/F_y)·F_y at u_y + d_p; a post-capping slope −F_c/d_pc
//! (d_pc runs from the cap to zero force); the residual F_r; nothing past
//! the ultimate drift d_u. The loop: the force moves along the unloading
//! stiffness K_u and is bounded, in the direction the drift moves, by that
//! direction's backbone, whose hardening and post-capping lines extend
//! across the origin (bilinear, kinematic). Cyclic deterioration by the
//! hysteretic energy, E_ref = λ F_y for each mode (λ a drift): at each
//! zero-force crossing after yield, β = (E_i/(E_ref − E))^c of the last
//! excursion's energy E_i scales the loaded direction's yield strength and
//! hardening slope (β_S) and its post-capping line's intercept (β_C); at
//! each reversal from the backbone, β_K scales K_u. Here the drift moves
//! continuously: every crossing, hit and corner is located exactly on the
//! piecewise-linear path, and the energy is its exact integral (OpenSees
//! takes them at its steps, so it converges to this as its steps shrink).

use super::{need, LawError};

/// The law's parameters (symmetric: one set for both directions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Imk {
    /// Elastic stiffness k (N/m).
    pub stiffness: f64,
    /// Yield drift u_y (m): F_y = k u_y.
    pub yield_drift: f64,
    /// F_c/F_y ≥ 1.
    pub cap_ratio: f64,
    /// Plastic drift to the cap d_p (m, > 0): the cap at u_y + d_p.
    pub plastic_drift: f64,
    /// Post-capping drift d_pc (m, > 0): from the cap to zero force.
    pub post_capping_drift: f64,
    /// F_r/F_y in [0, 1].
    pub residual_ratio: f64,
    /// Ultimate drift d_u (m, total, > the cap's): no force past it.
    pub ultimate_drift: f64,
    /// λ_S, λ_C, λ_K (m): E_ref = λ F_y for strength, cap and unloading
    /// stiffness (∞: none of that deterioration).
    pub lambda: [f64; 3],
    /// c_S, c_C, c_K (> 0).
    pub exponent: [f64; 3],
}

/// One direction's current backbone (signed: the negative side's values
/// are negative, its slopes positive as drawn).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Side {
    fy: f64,
    kp: f64,
    kpc: f64,
    ucap: f64,
    fcap: f64,
    fres: f64,
    /// Derived by [`Side::settled`] whenever the others change, so that
    /// the switch function, asked several times a step, divides nothing:
    /// the drifts where the backbone has a corner (the cap, the residual
    /// on the hardening and on the post-capping line; not finite where a
    /// slope is zero), the last being also the residual drift.
    corners: [f64; 3],
}

impl Side {
    /// The side with its derived drifts computed.
    fn settled(mut self) -> Self {
        self.corners = [
            self.ucap,
            self.ucap + (self.fres - self.fcap) / self.kp,
            self.ucap + (self.fres - self.fcap) / self.kpc,
        ];
        self
    }

    /// Where the post-capping line reaches the residual (None for a flat
    /// one).
    fn residual_drift(&self) -> Option<f64> {
        (self.kpc != 0.0).then_some(self.corners[2])
    }
}

/// What the loop carries: drift, force, both backbones, the unloading
/// stiffness, the energies and the failure state (0 elastic, 1 yielded,
/// 2 residual reached, 3/4 positive/negative strength lost, 5 both).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImkState {
    /// Drift (m).
    pub u: f64,
    /// Force (N).
    pub force: f64,
    pos: Side,
    neg: Side,
    kunload: f64,
    /// ∫ F dd so far (J).
    pub work: f64,
    /// The work at the last excursion's start.
    work_excursion: f64,
    failure: u8,
    on_backbone: bool,
    /// The direction the drift last moved (±1).
    dir: f64,
    /// The slope of the piece it is on (N/m; [`Imk::piece_slope`]), kept
    /// by every change of the state: the equations of motion ask for the
    /// piece's force a dozen times a step.
    slope: f64,
}

/// Sub-ulp guard on the drift axis.
fn tiny(x: f64) -> f64 {
    4.0 * f64::EPSILON * x.abs().max(1e-300)
}

impl Imk {
    /// Refuses parameters out of order: stiffness and yield drift > 0, a
    /// cap ratio ≥ 1, plastic and post-capping drifts > 0, a residual ratio
    /// in [0, 1] (not above the yield strength), an ultimate drift past
    /// the cap, λ > 0 and c > 0.
    pub fn check(&self) -> Result<(), LawError> {
        need(
            "stiffness",
            self.stiffness,
            self.stiffness > 0.0,
            "must be finite and > 0",
        )?;
        need(
            "yield_drift",
            self.yield_drift,
            self.yield_drift >= super::MIN_YIELD_DRIFT,
            "must be at least 1e-9 m",
        )?;
        need(
            "cap_ratio",
            self.cap_ratio,
            self.cap_ratio >= 1.0,
            "must be >= 1 (the cap at or above yield)",
        )?;
        need(
            "plastic_drift",
            self.plastic_drift,
            self.plastic_drift > 0.0,
            "must be > 0 (the capping drift beyond the yield drift)",
        )?;
        need(
            "post_capping_drift",
            self.post_capping_drift,
            self.post_capping_drift > 0.0,
            "must be > 0 (a negative post-capping slope)",
        )?;
        need(
            "residual_ratio",
            self.residual_ratio,
            (0.0..=1.0).contains(&self.residual_ratio),
            "must be in [0, 1] (the residual strength at most the yield strength)",
        )?;
        need(
            "ultimate_drift",
            self.ultimate_drift,
            self.ultimate_drift > self.yield_drift + self.plastic_drift,
            "must exceed the capping drift u_y + d_p",
        )?;
        for (k, key) in ["lambda_s", "lambda_c", "lambda_k"].into_iter().enumerate() {
            // (∞: no deterioration of that kind.)
            let l = self.lambda[k];
            if l.is_nan() || l <= 0.0 {
                return Err(LawError {
                    key,
                    value: l,
                    message: "must be > 0 (a drift, m; omit it for no deterioration)",
                });
            }
        }
        for (k, key) in ["c_s", "c_c", "c_k"].into_iter().enumerate() {
            need(
                key,
                self.exponent[k],
                self.exponent[k] > 0.0,
                "must be finite and > 0",
            )?;
        }
        Ok(())
    }

    fn fy(&self) -> f64 {
        self.stiffness * self.yield_drift
    }

    /// The positive side at rest; the negative is its mirror.
    fn initial_side(&self) -> Side {
        let fy = self.fy();
        let fcap = self.cap_ratio * fy;
        Side {
            fy,
            kp: (fcap - fy) / self.plastic_drift,
            kpc: -fcap / self.post_capping_drift,
            ucap: self.yield_drift + self.plastic_drift,
            fcap,
            fres: self.residual_ratio * fy,
            corners: [0.0; 3],
        }
        .settled()
    }

    /// The loop at rest.
    pub fn rest(&self) -> ImkState {
        let p = self.initial_side();
        ImkState {
            u: 0.0,
            force: 0.0,
            pos: p,
            neg: Side {
                fy: -p.fy,
                kp: p.kp,
                kpc: p.kpc,
                ucap: -p.ucap,
                fcap: -p.fcap,
                fres: -p.fres,
                corners: [0.0; 3],
            }
            .settled(),
            kunload: self.stiffness,
            work: 0.0,
            work_excursion: 0.0,
            failure: 0,
            on_backbone: false,
            dir: 1.0,
            slope: self.stiffness,
        }
    }

    /// The energy dissipated in `s`: the work less what the unloading
    /// spring stores, F²/(2 K_u).
    pub fn dissipated(&self, s: &ImkState) -> f64 {
        s.work - 0.5 * s.force * s.force / s.kunload
    }

    /// The backbone bound of the direction `dir` at drift `x` (a maximum
    /// force moving positive, a minimum moving negative).
    fn bound(&self, s: &ImkState, dir: f64, x: f64) -> f64 {
        let (side, lost, other_lost) = if dir > 0.0 {
            (&s.pos, 3, 4)
        } else {
            (&s.neg, 4, 3)
        };
        if s.failure == lost {
            return 0.0;
        }
        let beyond = if dir > 0.0 {
            x >= side.ucap
        } else {
            x <= side.ucap
        };
        let line = side.fcap + (x - side.ucap) * if beyond { side.kpc } else { side.kp };
        if s.failure == other_lost {
            return side.fres;
        }
        if dir > 0.0 {
            line.max(side.fres)
        } else {
            line.min(side.fres)
        }
    }

    /// The drifts ahead of `u` in direction `dir` (up to `to`) where the
    /// bound of `dir` has a corner.
    fn corners(&self, s: &ImkState, dir: f64, u: f64, to: f64) -> Corners {
        let side = if dir > 0.0 { &s.pos } else { &s.neg };
        let cand = side.corners;
        // (A zero slope has no corner: its candidate is not finite.)
        let mut out = Corners {
            xs: [f64::NAN; 3],
            n: 0,
        };
        for x in cand {
            if x.is_finite() && (x - u) * dir > tiny(u) && (to - x) * dir > 0.0 {
                out.xs[out.n] = x;
                out.n += 1;
            }
        }
        out.xs[..out.n].sort_by(|a, b| ((a - u) * dir).total_cmp(&((b - u) * dir)));
        out
    }

    /// The state after the drift moves monotonically from `s.u` to `to`.
    pub fn advance(&self, s: &mut ImkState, to: f64) {
        self.follow(s, to);
        s.slope = self.slope_of(s);
    }

    /// [`Imk::advance`] but for the piece's slope.
    fn follow(&self, s: &mut ImkState, to: f64) {
        if to == s.u {
            return;
        }
        let dir = (to - s.u).signum();
        s.dir = dir;
        if s.failure == 5 {
            s.u = to;
            s.force = 0.0;
            return;
        }
        if s.on_backbone && (s.force * dir < 0.0 || (s.force == 0.0 && s.u * dir <= 0.0)) {
            self.reversal(s);
            if s.failure == 5 {
                s.u = to;
                s.force = 0.0;
                return;
            }
        }
        // Each pass moves to the next event ahead (at most a few dozen).
        for _ in 0..64 {
            if (to - s.u) * dir <= 0.0 {
                break;
            }
            let next = if s.on_backbone {
                self.along_backbone(s, dir, to)
            } else {
                self.along_unloading(s, dir, to)
            };
            self.move_to(s, dir, next.0);
            match next.1 {
                Event::None => {}
                Event::Crossing => self.excursion(s, dir),
                Event::Hit => {
                    s.on_backbone = true;
                    s.force = self.bound(s, dir, s.u);
                    if s.failure == 0 {
                        s.failure = 1;
                    }
                }
            }
            self.check_failure(s, dir);
            if s.failure == 5 {
                s.u = to;
                s.force = 0.0;
                return;
            }
        }
    }

    /// Moves the state along its current piece to `x` (the force on the
    /// piece's line, the work its exact integral).
    fn move_to(&self, s: &mut ImkState, dir: f64, x: f64) {
        let f1 = if s.on_backbone {
            self.bound(s, dir, x)
        } else {
            s.force + s.kunload * (x - s.u)
        };
        s.work += 0.5 * (s.force + f1) * (x - s.u);
        s.u = x;
        s.force = f1;
    }

    /// On the backbone: to the next corner, the ultimate drift or `to`.
    fn along_backbone(&self, s: &ImkState, dir: f64, to: f64) -> (f64, Event) {
        let mut x = to;
        if let Some(&c) = self.corners(s, dir, s.u, to).ahead().first() {
            x = c;
        }
        // A backbone line through zero force (no residual): there the
        // direction's strength is lost.
        let side = if dir > 0.0 { &s.pos } else { &s.neg };
        if side.fres == 0.0 && side.kpc != 0.0 {
            let zero = side.ucap - side.fcap / side.kpc;
            if (zero - s.u) * dir > tiny(s.u) && (x - zero) * dir > 0.0 {
                x = zero;
            }
        }
        (self.before_ultimate(s.u, dir, x), Event::None)
    }

    /// Off the backbone, on the unloading line: to the zero crossing (after
    /// yield), the bound's hit, the ultimate drift or `to`, whichever first.
    fn along_unloading(&self, s: &ImkState, dir: f64, to: f64) -> (f64, Event) {
        let mut end = (self.before_ultimate(s.u, dir, to), Event::None);
        if s.failure > 0 && s.force * dir < 0.0 {
            let x0 = s.u - s.force / s.kunload;
            if (x0 - s.u) * dir > 0.0 && (end.0 - x0) * dir >= 0.0 {
                end = (x0, Event::Crossing);
            }
        }
        // The hit: g(x) = dir (F(x) − bound(x)) reaches 0, the bound
        // piecewise linear between its corners.
        let g = |x: f64| dir * (s.force + s.kunload * (x - s.u) - self.bound(s, dir, x));
        let (mut a, mut ga) = (s.u, g(s.u));
        if ga >= 0.0 {
            return (s.u, Event::Hit);
        }
        let corners = self.corners(s, dir, s.u, end.0);
        for &b in corners.ahead().iter().chain([end.0].iter()) {
            let gb = g(b);
            if gb >= 0.0 {
                return (a + (b - a) * (-ga) / (gb - ga), Event::Hit);
            }
            (a, ga) = (b, gb);
        }
        end
    }

    /// `x`, or the ultimate drift if that comes first on the way.
    fn before_ultimate(&self, u: f64, dir: f64, x: f64) -> f64 {
        let edge = dir * self.ultimate_drift;
        if (edge - u) * dir > 0.0 && (x - edge) * dir > 0.0 {
            edge
        } else {
            x
        }
    }

    /// A reversal from the backbone: the unloading stiffness deteriorates
    /// by β_K of the energy since the last excursion less what the spring
    /// stores.
    fn reversal(&self, s: &mut ImkState) {
        s.on_backbone = false;
        let stored = 0.5 * s.force * s.force / s.kunload;
        let e_ref = self.lambda[2] * self.fy();
        let total = s.work - stored;
        let excursion = s.work - s.work_excursion - stored;
        let beta = (excursion / (e_ref - total)).powf(self.exponent[2]);
        if beta > 1.0 {
            s.failure = 5;
            s.force = 0.0;
            return;
        }
        s.kunload *= 1.0 - beta.max(0.0);
        if s.failure > 1 {
            s.kunload = 0.5 * self.stiffness;
        }
    }

    /// A zero-force crossing after yield: the backbone of the direction
    /// now loaded deteriorates by the last excursion's energy.
    fn excursion(&self, s: &mut ImkState, dir: f64) {
        let fy = self.fy();
        let e_i = (s.work - s.work_excursion).max(0.0);
        let beta = |k: usize| (e_i / (self.lambda[k] * fy - s.work)).powf(self.exponent[k]);
        let (bs, bc) = (beta(0), beta(1));
        if bs > 1.0 || bc > 1.0 {
            s.failure = 5;
            s.force = 0.0;
            return;
        }
        let (bs, bc) = (bs.max(0.0), bc.max(0.0));
        s.work_excursion = s.work;
        let initial = self.initial_side();
        let (k, u_cross, ku) = (self.stiffness, s.u, s.kunload);
        let side = if dir > 0.0 { &mut s.pos } else { &mut s.neg };
        let sign = dir;
        let fcap_proj = side.fcap - side.kpc * side.ucap;
        side.fy *= 1.0 - bs;
        side.kp *= 1.0 - bs;
        let fcap_proj = fcap_proj * (1.0 - bc);
        let uy = side.fy / k;
        // The post-capping slope scaled by (F_y' − F_r)/(F_y − F_r), or
        // flat once the yield strength fell below the residual.
        side.kpc = if (side.fy - side.fres) * sign < 0.0 {
            0.0
        } else {
            initial.kpc * (side.fy - side.fres) / (sign * initial.fy - side.fres)
        };
        let fy_proj = side.fy - side.kp * uy;
        side.ucap = if side.kp <= side.kpc {
            0.0
        } else {
            (fcap_proj - fy_proj) / (side.kp - side.kpc)
        };
        side.fcap = fy_proj + side.kp * side.ucap;
        // Where the unloading line (through the crossing) reaches the
        // residual: the hardening slope pivots about the cap if the
        // backbone would start beneath it.
        let candidate = (side.fcap - side.fres) / (side.ucap - (u_cross + side.fres / ku));
        if (side.fcap - side.fres) * sign < 0.0 {
            side.fy = side.fres;
            side.fcap = side.fres;
            side.kp = 0.0;
            side.kpc = 0.0;
            side.ucap = 0.0;
        } else if candidate > 0.0 && side.kp > candidate {
            side.kp = candidate;
        }
        *side = side.settled();
    }

    /// Strength lost at the ultimate drift, or where the backbone reaches
    /// zero force; the residual reached.
    fn check_failure(&self, s: &mut ImkState, dir: f64) {
        let at_ultimate = s.u * dir >= self.ultimate_drift * (1.0 - 1e-15);
        let through_zero = s.on_backbone && s.force * dir <= 0.0 && s.u * dir > 0.0;
        if at_ultimate || through_zero {
            let (lost, other) = if dir > 0.0 { (3, 4) } else { (4, 3) };
            s.force = 0.0;
            s.failure = if s.failure == other { 5 } else { lost };
            return;
        }
        if s.failure < 2 {
            // (sign: +1 for the positive side, −1 for the negative.)
            let residual = |side: &Side, sign: f64| {
                if side.kpc == 0.0 {
                    s.force == side.fres && s.on_backbone
                } else {
                    let ures = (side.fres - side.fcap + side.kpc * side.ucap) / side.kpc;
                    (s.u - ures) * sign >= 0.0
                }
            };
            if residual(&s.pos, 1.0) || residual(&s.neg, -1.0) {
                s.failure = 2;
            }
        }
    }
}

/// The IMK storey between events of a time history (docs/theory.md §11):
/// from the state at its last event the force is linear in the drift (the
/// unloading line, or the backbone's segment), so a step sees a smooth
/// force; what ends the piece is a switch, located on the dense output.
impl Imk {
    /// The slope of the piece `s` is on (N/m), as last settled.
    fn piece_slope(&self, s: &ImkState) -> f64 {
        s.slope
    }

    /// The slope of the piece `s` is on (N/m), from its state.
    fn slope_of(&self, s: &ImkState) -> f64 {
        if s.failure == 5 {
            return 0.0;
        }
        if !s.on_backbone {
            return s.kunload;
        }
        // The segment just ahead of the anchor (the bound is linear on it).
        let dir = s.dir;
        let x = s.u + dir * 1e-9 * self.yield_drift;
        let (side, lost, other_lost) = if dir > 0.0 {
            (&s.pos, 3, 4)
        } else {
            (&s.neg, 4, 3)
        };
        if s.failure == lost || s.failure == other_lost {
            return 0.0;
        }
        let beyond = if dir > 0.0 {
            x >= side.ucap
        } else {
            x <= side.ucap
        };
        let slope = if beyond { side.kpc } else { side.kp };
        let line = side.fcap + (x - side.ucap) * slope;
        let clamped = if dir > 0.0 {
            line < side.fres
        } else {
            line > side.fres
        };
        if clamped {
            0.0
        } else {
            slope
        }
    }

    /// The force at drift `d` on the piece `s` is on.
    pub fn piece_force(&self, s: &ImkState, d: f64) -> f64 {
        if s.failure == 5 {
            0.0
        } else {
            s.force + self.piece_slope(s) * (d - s.u)
        }
    }

    /// The piece as a line in the drift, F = k d + F₀: (k, F₀).
    pub fn piece_line(&self, s: &ImkState) -> (f64, f64) {
        if s.failure == 5 {
            (0.0, 0.0)
        } else {
            let k = self.piece_slope(s);
            (k, s.force - k * s.u)
        }
    }

    /// The work ∫ F dd up to drift `d` along the piece.
    pub fn piece_work(&self, s: &ImkState, d: f64) -> f64 {
        s.work + 0.5 * (s.force + self.piece_force(s, d)) * (d - s.u)
    }

    /// The energy stored at drift `d` on the piece: F²/(2 K_u).
    pub fn piece_stored(&self, s: &ImkState, d: f64) -> f64 {
        let f = self.piece_force(s, d);
        0.5 * f * f / s.kunload
    }

    /// Bounds on how fast the two [`Imk::switch_parts`] change while the
    /// drift moves no faster than `speed` and its rate changes no faster
    /// than `acceleration` (force units per second): each drift term is a
    /// line in the drift, the distances to the ultimate and residual
    /// drifts and to the backbone's next corner of slope k, the piece's
    /// force of the piece's slope p, and off the backbone the distance
    /// from the piece's force to a bound of slope b − p, b a backbone
    /// slope (k_p, k_pc, or 0 on a residual or a lost side); the
    /// reversal's is k × the rate. (Twice the steepest slope of all
    /// bounded every term before: up to twice as loose, and most of the
    /// exact run's switch search went into halving what it did not
    /// clear.)
    pub fn switch_rate_bounds(&self, s: &ImkState, speed: f64, acceleration: f64) -> (f64, f64) {
        let p = s.slope;
        let mut steepest = self.stiffness.max(p.abs());
        if !s.on_backbone {
            for side in [&s.pos, &s.neg] {
                steepest = steepest.max((side.kp - p).abs()).max((side.kpc - p).abs());
            }
        }
        (steepest * speed, self.stiffness * acceleration)
    }

    /// Whether, while the drift moves one way, [`Imk::switch_parts`]' drift
    /// terms are each least at an end of every interval of it (so that
    /// positive ends exclude a switch between them): on the backbone they
    /// are lines (a concave minimum of them); after failure constant; off
    /// the backbone the term to the bound of the direction of motion, whose
    /// corners where a line meets the residual are convex, falls
    /// monotonically while no slope of either bound exceeds the unloading
    /// stiffness (post-capping slopes are not positive), the others being
    /// lines.
    pub fn drift_terms_least_at_ends(&self, s: &ImkState) -> bool {
        s.on_backbone
            || s.failure == 5
            || [s.pos, s.neg]
                .iter()
                .all(|side| side.kp.abs() <= s.kunload && side.kpc <= 0.0)
    }

    /// The switch function of the piece at drift `d` moving at `rate`:
    /// positive while the piece holds, zero where it ends. On the backbone:
    /// a reversal (the rate turns), its next corner, zero force without a
    /// residual, the ultimate drift. On the unloading line: the zero-force
    /// crossing (after yield), the bound of the direction it moves (with a
    /// slack of 1e-10 F_y, so that a piece just begun on a bound does not
    /// end at once), the ultimate drift. Drifts in force units (× k).
    pub fn switch_value(&self, s: &ImkState, d: f64, rate: f64) -> f64 {
        let (drift, turn) = self.switch_parts(s, d, rate);
        drift.min(turn)
    }

    /// [`Imk::switch_value`] in two parts, whose least it is: the terms in
    /// the drift (each a line in it), and the reversal's k × the rate on
    /// the backbone (∞ off it).
    pub fn switch_parts(&self, s: &ImkState, d: f64, rate: f64) -> (f64, f64) {
        if s.failure == 5 {
            return (1.0, f64::INFINITY);
        }
        let f = self.piece_force(s, d);
        let mut g = self.ultimate_ahead(s, d).min(self.residual_ahead(s, d));
        if s.on_backbone {
            return (
                g.min(self.backbone_ahead(s, d)),
                rate * s.dir * self.stiffness,
            );
        }
        if s.failure > 0 && s.force != 0.0 {
            g = g.min(f * s.force.signum());
        }
        let dir = if rate != 0.0 { rate.signum() } else { s.dir };
        let slack = 1e-10 * self.fy();
        (
            g.min(dir * (self.bound(s, dir, d) - f) + slack),
            f64::INFINITY,
        )
    }

    /// On the backbone, what ends the segment ahead other than a reversal:
    /// its next corner, zero force without a residual (force units).
    fn backbone_ahead(&self, s: &ImkState, d: f64) -> f64 {
        let (k, dir) = (self.stiffness, s.dir);
        let mut g = f64::INFINITY;
        if let Some(&c) = self
            .corners(s, dir, s.u, dir * f64::INFINITY)
            .ahead()
            .first()
        {
            g = g.min(k * dir * (c - d));
        }
        let side = if dir > 0.0 { &s.pos } else { &s.neg };
        if side.fres == 0.0 && s.u * dir > 0.0 {
            g = g.min(self.piece_force(s, d) * dir);
        }
        g.min(self.ultimate_ahead(s, d))
    }

    /// Before the residual is first reached: the distance to either side's
    /// residual drift (force units; ∞ after, or where a side has none). The
    /// unloading stiffness at the next reversal depends on it.
    fn residual_ahead(&self, s: &ImkState, d: f64) -> f64 {
        if s.failure >= 2 {
            return f64::INFINITY;
        }
        let k = self.stiffness;
        let mut g = f64::INFINITY;
        if let Some(x) = s.pos.residual_drift() {
            g = g.min(k * (x - d));
        }
        if let Some(x) = s.neg.residual_drift() {
            g = g.min(k * (d - x));
        }
        g
    }

    /// The ultimate drift on the side of `d`, while that side stands
    /// (force units; ∞ once its strength is lost).
    fn ultimate_ahead(&self, s: &ImkState, d: f64) -> f64 {
        let lost = if d >= 0.0 {
            matches!(s.failure, 3 | 5)
        } else {
            matches!(s.failure, 4 | 5)
        };
        if lost {
            f64::INFINITY
        } else {
            self.stiffness * (self.ultimate_drift - d.abs())
        }
    }

    /// The state at the event where the piece ended, at drift `d` moving
    /// at `rate`: the piece followed to `d` (to its zero crossing exactly
    /// where that ended it), then the law's own rules a hair on in the
    /// direction of motion: reversal, crossing, hit, corner, failure.
    pub fn switch(&self, s: &mut ImkState, d: f64, rate: f64) {
        // On the backbone a reversal is the event where the rate's term
        // is the least (the rate itself may have either sign there, by a
        // rounding): the direction turns.
        let dir = if s.on_backbone {
            if rate * s.dir * self.stiffness <= self.backbone_ahead(s, d) {
                -s.dir
            } else {
                s.dir
            }
        } else if rate != 0.0 {
            rate.signum()
        } else {
            s.dir
        };
        let slope = self.piece_slope(s);
        let mut at = d;
        // (Crossed: where the force changed sign, or is within 1e-9 F_y of
        // zero; the drift located there may be the crossing's to the last
        // bit, and it is a crossing all the same.)
        let crossing = !s.on_backbone && s.failure > 0 && s.force != 0.0;
        let crossed =
            crossing && (self.piece_force(s, d) * s.force <= 1e-9 * self.fy() * s.force.abs());
        if crossed {
            at = s.u - s.force / slope;
        }
        let f = self.piece_force(s, at);
        s.work += 0.5 * (s.force + f) * (at - s.u);
        s.u = at;
        s.force = if crossed { 0.0 } else { f };
        if crossed && s.failure < 5 {
            s.dir = dir;
            self.excursion(s, dir);
        }
        let hair = 1e-12 * self.yield_drift.max(at.abs());
        self.follow(s, at + dir * hair);
        s.slope = self.slope_of(s);
    }
}

/// The corners of a bound ahead of a drift, nearest first (at most three:
/// the cap and where each line meets the residual; no allocation, as
/// the switch function asks at every step).
struct Corners {
    xs: [f64; 3],
    n: usize,
}

impl Corners {
    fn ahead(&self) -> &[f64] {
        &self.xs[..self.n]
    }
}

/// What ends a piece.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Event {
    /// `to`, a corner or the ultimate drift.
    None,
    /// A zero-force crossing off the backbone.
    Crossing,
    /// The unloading line meets the backbone.
    Hit,
}
