//! A building of a row (docs/earthquakes.md): a shear frame fixed at the
//! ground, or standing on an isolation layer (a base slab on bearings) with
//! a moat wall around its base.
//!
//! A fixed building's floors are bodies, its storeys springs (or
//! hysteretic storeys) and dampers exactly as before rows existed. An
//! isolated one adds its base slab below the first floor: the bearings are
//! a storey from the ground to the slab, the superstructure's Rayleigh
//! damping (on its fixed-base modes) acts relative to the slab (α m_i from
//! floor i to the slab, β k_i beside storey i), so it does not damp the
//! isolation mode. The moat wall is a contact on each side of the slab at
//! the moat gap, with a rigid wall or a flexible one (a wall body on a
//! spring and damper to the ground).

use serde::Deserialize;

use super::frame::Gravity;
use super::ShearFrame;
use crate::contact::ContactLaw;
use crate::model::hysteresis::{BoucWen, Degradation, LawError, StoreyLaw, StoreySpec};
use crate::model::{Body, Contact, ContactPair, Coupling, Impacts, Storey};

/// Standard gravity (m/s²): a friction pendulum's weight, P-Δ loads,
/// accelerations in g.
pub use crate::model::record::STANDARD_GRAVITY as GRAVITY;

/// One building of a row.
#[derive(Clone, Debug, PartialEq)]
pub struct Building {
    /// Its name in results and errors (`left`, `right` in a pair file).
    pub name: String,
    /// Its superstructure.
    pub frame: ShearFrame,
    /// Its isolation layer, if isolated.
    pub isolation: Option<Isolation>,
}

/// An isolation layer: a base slab on bearings, a moat wall around it.
#[derive(Clone, Debug, PartialEq)]
pub struct Isolation {
    /// The base slab's mass (kg).
    pub mass: f64,
    /// The bearings' law.
    pub bearing: Bearing,
    /// A viscous damper beside the bearings (N s/m; 0: the bearings'
    /// hysteresis alone).
    pub damping: f64,
    /// The bearings' displacement capacity (m): a run that goes beyond it
    /// says so in its results.
    pub capacity: Option<f64>,
    /// The moat wall, if any.
    pub moat: Option<Moat>,
}

/// The bearings of an isolation layer (the total of the layer).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Bearing {
    /// Lead-rubber bearings as a bilinear law.
    Bilinear {
        /// Elastic stiffness (N/m).
        stiffness: f64,
        /// Yield displacement (m).
        yield_drift: f64,
        /// Post-yield over elastic stiffness.
        post_yield_ratio: f64,
    },
    /// Lead-rubber bearings as Bouc–Wen.
    BoucWen {
        /// Elastic stiffness (N/m).
        stiffness: f64,
        /// Yield displacement (m).
        yield_drift: f64,
        /// Post-yield over elastic stiffness.
        post_yield_ratio: f64,
        /// n, default 2.
        exponent: Option<f64>,
        /// β, default 0.5.
        beta: Option<f64>,
        /// γ, default 0.5.
        gamma: Option<f64>,
    },
    /// Friction pendulum: restoring W/R and friction μ W through a sharp
    /// Bouc–Wen (stick–slip smoothed over `yield_drift`).
    FrictionPendulum {
        /// Radius of the sliding surface R (m).
        radius: f64,
        /// Friction coefficient μ ≥ 0.
        friction: f64,
        /// The sliding onset displacement (m), default 0.5 mm.
        yield_drift: Option<f64>,
        /// The Bouc–Wen exponent, default 2.
        exponent: Option<f64>,
    },
}

impl Bearing {
    /// The law of the layer carrying the weight `weight` (N). A friction
    /// pendulum is W/R d + μ W z/u_y, z of a Bouc–Wen with β = γ = ½: the
    /// Bouc–Wen law of stiffness W/R + μ W/u_y and post-yield ratio
    /// (W/R)/(W/R + μ W/u_y); without friction, the pendulum's spring.
    /// Errors name the key.
    pub fn law(&self, weight: f64) -> Result<StoreyLaw, LawError> {
        // Lead-rubber bearings are the storey laws with their stiffness.
        let law = match *self {
            Bearing::Bilinear {
                stiffness,
                yield_drift,
                post_yield_ratio,
            } => {
                return StoreySpec::Bilinear {
                    yield_drift,
                    post_yield_ratio,
                }
                .law(stiffness)
            }
            Bearing::BoucWen {
                stiffness,
                yield_drift,
                post_yield_ratio,
                exponent,
                beta,
                gamma,
            } => {
                return StoreySpec::BoucWen {
                    yield_drift,
                    post_yield_ratio,
                    exponent,
                    beta,
                    gamma,
                    degradation_a: None,
                    degradation_nu: None,
                    degradation_eta: None,
                }
                .law(stiffness)
            }
            Bearing::FrictionPendulum {
                radius,
                friction,
                yield_drift,
                exponent,
            } => {
                let bad = |key, value, message| LawError {
                    key,
                    value,
                    message,
                };
                if !(radius.is_finite() && radius > 0.0) {
                    return Err(bad("radius", radius, "must be finite and > 0"));
                }
                if !(friction.is_finite() && (0.0..1.0).contains(&friction)) {
                    return Err(bad(
                        "friction",
                        friction,
                        "must be in [0, 1) (a sliding bearing's coefficient is about 0.02 to 0.2)",
                    ));
                }
                let pendulum = weight / radius;
                if friction == 0.0 {
                    return Ok(StoreyLaw::Elastic {
                        stiffness: pendulum,
                    });
                }
                let uy = yield_drift.unwrap_or(5e-4);
                let slide = friction * weight / uy;
                StoreyLaw::BoucWen(BoucWen {
                    stiffness: pendulum + slide,
                    yield_drift: uy,
                    post_yield_ratio: pendulum / (pendulum + slide),
                    exponent: exponent.unwrap_or(2.0),
                    beta: 0.5,
                    gamma: 0.5,
                    degradation: Degradation::default(),
                })
            }
        };
        law.check()?;
        Ok(law)
    }

    /// The layer's stiffness for its period: post-yield (W/R for a
    /// friction pendulum), or elastic where there is no post-yield
    /// stiffness.
    fn period_stiffness(&self, weight: f64) -> f64 {
        match *self {
            Bearing::Bilinear {
                stiffness,
                post_yield_ratio,
                ..
            }
            | Bearing::BoucWen {
                stiffness,
                post_yield_ratio,
                ..
            } => {
                if post_yield_ratio > 0.0 {
                    post_yield_ratio * stiffness
                } else {
                    stiffness
                }
            }
            Bearing::FrictionPendulum { radius, .. } => weight / radius,
        }
    }
}

/// A moat wall around an isolated building's base slab.
#[derive(Clone, Debug, PartialEq)]
pub struct Moat {
    /// The clear distance from the slab to the wall on either side (m).
    pub gap: f64,
    /// The contact law of slab and wall.
    pub law: ContactLaw,
    /// A flexible wall (each side), or None for a rigid one.
    pub wall: Option<Wall>,
    /// How slab and wall impact: through the law (soft, the default) or
    /// as velocity jumps (rigid, docs/theory.md §12).
    pub impacts: Impacts,
}

/// A flexible moat wall: the mass that moves with it and its spring and
/// damper to the ground (each side).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// Mass (kg).
    pub mass: f64,
    /// Stiffness (N/m).
    pub stiffness: f64,
    /// Damping (N s/m), default 0.
    #[serde(default)]
    pub damping: f64,
}

/// Where a building's bodies sit in the row's model.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// The body of floor 1 (floor f is `first_floor + f − 1`).
    pub first_floor: usize,
    /// The base slab's body, if isolated.
    pub base: Option<usize>,
    /// Its hysteretic storeys: (the model's storey index, the building's
    /// storey from 0 or None for the bearings).
    pub storeys: Vec<(usize, Option<usize>)>,
    /// Its moat contacts (model contact indices).
    pub moat: Vec<usize>,
}

/// A row model under construction.
#[derive(Default)]
pub(super) struct Parts {
    pub bodies: Vec<Body>,
    pub couplings: Vec<Coupling>,
    pub storeys: Vec<Storey>,
    pub contacts: Vec<Contact>,
}

impl Parts {
    /// Adds a flexible moat wall's body (`{tag}W{side}`); its index.
    fn wall(&mut self, tag: &str, side: &str, w: Wall) -> usize {
        self.bodies.push(Body {
            name: format!("{tag}W{side}"),
            mass: w.mass,
            stiffness: w.stiffness,
            damping: w.damping,
        });
        self.bodies.len() - 1
    }
}

impl Building {
    /// How many floors.
    pub fn floors(&self) -> usize {
        self.frame.masses.len()
    }

    /// The weight on the bearings: the slab and every floor (N).
    pub fn weight(&self) -> f64 {
        GRAVITY
            * (self.frame.masses.iter().sum::<f64>()
                + self.isolation.as_ref().map_or(0.0, |i| i.mass))
    }

    /// The bearings' law, if isolated (errors name the key).
    pub fn bearing_law(&self) -> Result<Option<StoreyLaw>, String> {
        self.isolation
            .as_ref()
            .map(|i| {
                i.bearing
                    .law(self.weight())
                    .map_err(|e| format!("isolation: {e}"))
            })
            .transpose()
    }

    /// Checks the building: its frame, and its isolation layer (slab mass,
    /// damping, capacity, bearings, moat gap and wall). Messages begin
    /// with `what` (e.g. `left frame`).
    pub fn check(&self, what: &str) -> Result<(), String> {
        self.frame.check(what)?;
        let Some(iso) = &self.isolation else {
            return Ok(());
        };
        let positive = |key: &str, v: f64, zero_ok: bool| {
            if v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0)) {
                Ok(())
            } else {
                let need = if zero_ok { ">= 0" } else { "> 0" };
                Err(format!(
                    "{what}: isolation: {key} = {v}: must be finite and {need}"
                ))
            }
        };
        positive("mass", iso.mass, false)?;
        positive("damping", iso.damping, true)?;
        if let Some(c) = iso.capacity {
            positive("capacity", c, false)?;
        }
        self.bearing_law().map_err(|e| format!("{what}: {e}"))?;
        if let Some(m) = &iso.moat {
            positive("moat.gap", m.gap, true)?;
            if let Some(w) = m.wall {
                positive("moat.wall.mass", w.mass, false)?;
                positive("moat.wall.stiffness", w.stiffness, false)?;
                positive("moat.wall.damping", w.damping, true)?;
            }
        }
        Ok(())
    }

    /// Whether a run needs the free-vibration tail: a storey yields or the
    /// bearings are hysteretic.
    pub fn inelastic(&self) -> bool {
        self.frame.inelastic()
            || matches!(self.bearing_law(), Ok(Some(law)) if !matches!(law, StoreyLaw::Elastic { .. }))
    }

    /// The fundamental circular frequency (rad/s): the frame's, or for an
    /// isolated building the structure's with the bearings at their
    /// post-yield stiffness (elastic where there is none; W/R for a
    /// friction pendulum).
    pub fn frequency(&self) -> f64 {
        let Some(iso) = &self.isolation else {
            return self.frame.natural_frequencies()[0];
        };
        let mut masses = vec![iso.mass];
        masses.extend(&self.frame.masses);
        let mut stiffnesses = vec![iso.bearing.period_stiffness(self.weight())];
        // The storeys' P-Δ (none in the bearings) in their stiffnesses.
        let geometric = self.frame.geometric_stiffnesses();
        stiffnesses.extend(
            self.frame
                .stiffnesses
                .iter()
                .zip(geometric)
                .map(|(k, g)| k - g),
        );
        ShearFrame {
            masses,
            stiffnesses,
            damping_ratio: self.frame.damping_ratio,
            storeys: Vec::new(),
            heights: Vec::new(),
            gravity: Gravity::default(),
        }
        .natural_frequencies()[0]
    }

    /// The fundamental period 2π/ω₁ (s) of [`Building::frequency`].
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.frequency()
    }

    /// Adds the building's bodies, couplings, storeys and moat contacts to
    /// `parts` (bodies named `{tag}1`…, the slab `{tag}0`, walls `{tag}W-`
    /// and `{tag}W+`): a flexible left wall, the slab, the floors, a
    /// flexible right wall. `contacts` false leaves the moat out.
    pub(super) fn place(
        &self,
        tag: &str,
        parts: &mut Parts,
        contacts: bool,
    ) -> Result<Placement, String> {
        let iso = self.isolation.as_ref();
        let wall = iso.and_then(|i| i.moat.as_ref()).and_then(|m| m.wall);
        let left_wall = wall.map(|w| parts.wall(tag, "-", w));
        let mut placement = Placement {
            first_floor: 0,
            base: None,
            storeys: Vec::new(),
            moat: Vec::new(),
        };
        if let (Some(i), Some(law)) = (iso, self.bearing_law()?) {
            placement.base = Some(parts.bodies.len());
            let spring = Self::spring_or_storey(
                (law, 0.0),
                (None, parts.bodies.len()),
                None,
                parts,
                &mut placement,
            );
            parts.bodies.push(Body {
                name: format!("{tag}0"),
                mass: i.mass,
                stiffness: spring,
                damping: i.damping,
            });
        }
        self.place_floors(tag, parts, &mut placement)?;
        let right_wall = wall.map(|w| parts.wall(tag, "+", w));
        if let (Some(moat), Some(base), true) =
            (iso.and_then(|i| i.moat.as_ref()), placement.base, contacts)
        {
            let sides = [
                match left_wall {
                    Some(w) => ContactPair::Bodies {
                        left: w,
                        right: base,
                    },
                    None => ContactPair::LeftWall { body: base },
                },
                match right_wall {
                    Some(w) => ContactPair::Bodies {
                        left: base,
                        right: w,
                    },
                    None => ContactPair::RightWall { body: base },
                },
            ];
            for pair in sides {
                placement.moat.push(parts.contacts.len());
                parts.contacts.push(Contact {
                    pair,
                    clearance: moat.gap,
                    law: moat.law,
                });
            }
        }
        Ok(placement)
    }

    /// The spring of an elastic law; a hysteretic one becomes a storey
    /// between `(below, above)` (`storey`: the building's storey from 0,
    /// None for the bearings) and its spring is 0.
    /// `p_delta` is the storey's P-Δ stiffness P/h: an elastic storey's
    /// spring is k − P/h, a hysteretic one carries it.
    fn spring_or_storey(
        (law, p_delta): (StoreyLaw, f64),
        (below, above): (Option<usize>, usize),
        storey: Option<usize>,
        parts: &mut Parts,
        placement: &mut Placement,
    ) -> f64 {
        match law {
            StoreyLaw::Elastic { stiffness } => stiffness - p_delta,
            law => {
                placement.storeys.push((parts.storeys.len(), storey));
                parts.storeys.push(Storey {
                    below,
                    above,
                    law,
                    p_delta,
                });
                0.0
            }
        }
    }

    /// Adds the floors above the slab (or the ground): storey i + 1 joins
    /// the floor below to floor i + 1, its damper β k beside it (on the
    /// initial stiffness, linear when the storey yields), and the
    /// mass-proportional damper α m joins each floor to the slab (to the
    /// ground for a fixed building).
    fn place_floors(
        &self,
        tag: &str,
        parts: &mut Parts,
        placement: &mut Placement,
    ) -> Result<(), String> {
        let (alpha, beta) = self.frame.rayleigh();
        let laws = self.frame.laws()?;
        let geometric = self.frame.geometric_stiffnesses();
        let first = parts.bodies.len();
        placement.first_floor = first;
        let to_ground = placement.base.is_none();
        for (i, (&m, &k)) in self
            .frame
            .masses
            .iter()
            .zip(&self.frame.stiffnesses)
            .enumerate()
        {
            let below = if i == 0 {
                placement.base
            } else {
                Some(first + i - 1)
            };
            let spring = Self::spring_or_storey(
                (laws[i], geometric[i]),
                (below, first + i),
                Some(i),
                parts,
                placement,
            );
            parts.bodies.push(Body {
                name: format!("{tag}{}", i + 1),
                mass: m,
                stiffness: if below.is_none() { spring } else { 0.0 },
                damping: if to_ground { alpha * m } else { 0.0 }
                    + if below.is_none() { beta * k } else { 0.0 },
            });
            if let Some(b) = below {
                let slab_damper = if !to_ground && i == 0 { alpha * m } else { 0.0 };
                parts.couplings.push(Coupling {
                    a: b,
                    b: first + i,
                    stiffness: spring,
                    damping: beta * k + slab_damper,
                });
            }
            if let (Some(base), true) = (placement.base, i > 0) {
                parts.couplings.push(Coupling {
                    a: base,
                    b: first + i,
                    stiffness: 0.0,
                    damping: alpha * m,
                });
            }
        }
        Ok(())
    }
}
