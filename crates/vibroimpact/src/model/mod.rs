//! The system model (docs/theory.md §4): N bodies on a line with springs and
//! dampers to the frame and between each other, contact pairs with their
//! clearances and laws, and the excitation.
//!
//! ## Files
//! - `mod.rs` — [`Model`]: bodies, couplings, contacts, walls;
//! - `row.rs` — a row of identical bodies between walls ([`Model::row`]);
//! - `excitation.rs` — what drives it: base motion, forces, accelerograms;
//! - `impacts.rs` — a contact's impacts, soft or rigid (docs/theory.md
//!   §12);
//! - `record/` — recorded ground motions (AT2, columns, units);
//! - `storey.rs`, `hysteresis/` — storeys and their force–drift laws
//!   (bilinear, Bouc–Wen; docs/theory.md §11);
//! - `file/` — the model file (`docs/model.md`) and its builder;
//! - `parameter.rs` — a numeric key of a model file made a parameter;
//! - `family.rs` — a family of models, the problem every parameter study
//!   takes;
//! - `reference.rs` — the reference problems R1–R3 (docs/theory.md §6);
//! - `scales.rs` — the model's force scales against double precision;
//! - `tests.rs` — the checks.
//!
//! Equations of motion in displacements `u` relative to a frame that moves
//! with base acceleration `z̈(t)`:
//!
//! ```text
//! m_i ü_i = -k_i u_i - c_i u̇_i - m_i z̈(t) + p_i(t)
//!           + Σ couplings (k_ij (u_j - u_i) + c_ij (u̇_j - u̇_i))
//!           + Σ contacts (∓F)
//! ```
//!
//! A contact between a left body l and a right body r has the approach
//! coordinate `s = u_l - u_r - g` (`g >= 0` the clearance at u = 0); a wall
//! on the right of body l gives `s = u_l - g`, a wall on the left of body r
//! `s = -u_r - g`. The contact force F pushes the pair apart: `-F` on the
//! left body, `+F` on the right one.

use crate::contact::ContactLaw;

/// A rigid body on the line with its spring and damper to the frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name used in files and reports.
    pub name: String,
    /// Mass m > 0 (kg).
    pub mass: f64,
    /// Spring to the frame k >= 0 (N/m).
    pub stiffness: f64,
    /// Damper to the frame c >= 0 (N s/m).
    pub damping: f64,
}

impl Body {
    /// A body from natural frequency ω0 (rad/s) and damping ratio ζ:
    /// `k = m ω0²`, `c = 2 ζ m ω0`.
    pub fn from_frequency(name: &str, mass: f64, omega0: f64, zeta: f64) -> Self {
        Self {
            name: name.to_string(),
            mass,
            stiffness: mass * omega0 * omega0,
            damping: 2.0 * zeta * mass * omega0,
        }
    }
}

/// A spring–damper between two bodies (indices into the body list).
#[derive(Clone, Debug, PartialEq)]
pub struct Coupling {
    /// First body.
    pub a: usize,
    /// Second body.
    pub b: usize,
    /// Stiffness (N/m), >= 0.
    pub stiffness: f64,
    /// Damping (N s/m), >= 0.
    pub damping: f64,
}

/// The two sides of a contact pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactPair {
    /// Bodies `left` < `right` along the line.
    Bodies {
        /// Left body index.
        left: usize,
        /// Right body index.
        right: usize,
    },
    /// A wall fixed to the frame on the left of `body`.
    LeftWall {
        /// The body.
        body: usize,
    },
    /// A wall fixed to the frame on the right of `body`.
    RightWall {
        /// The body.
        body: usize,
    },
}

impl ContactPair {
    /// Left body index (None for a left wall).
    pub fn left(&self) -> Option<usize> {
        match *self {
            ContactPair::Bodies { left, .. } => Some(left),
            ContactPair::RightWall { body } => Some(body),
            ContactPair::LeftWall { .. } => None,
        }
    }

    /// Right body index (None for a right wall).
    pub fn right(&self) -> Option<usize> {
        match *self {
            ContactPair::Bodies { right, .. } => Some(right),
            ContactPair::LeftWall { body } => Some(body),
            ContactPair::RightWall { .. } => None,
        }
    }
}

/// A contact pair with its clearance and law.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    /// Which bodies (or walls) touch.
    pub pair: ContactPair,
    /// Clearance g >= 0 at u = 0 (m).
    pub clearance: f64,
    /// Contact law.
    pub law: ContactLaw,
}

/// What is wrong with a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelErrorKind {
    /// A value outside its domain (negative mass, non-finite amplitude, …).
    InvalidValue,
    /// A reference to a body that does not exist.
    UnknownBody,
    /// Items out of order (contact bodies not left first, times not
    /// increasing).
    Order,
    /// Bodies overlapping at the start.
    Overlap,
    /// Something required is missing or of the wrong length.
    Missing,
}

/// An invalid model: its kind, the dotted key path of the offending item
/// (as in model files and parameters, 1-based: `body.2.mass`,
/// `contact.1.clearance`, `excitation.scale`) and a message naming it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct ModelError {
    /// What is wrong.
    pub kind: ModelErrorKind,
    /// Dotted key path of the offending item.
    pub key: String,
    /// The message for users.
    pub message: String,
}

impl ModelError {
    /// An error of `kind` at `key` with this message.
    pub fn new(kind: ModelErrorKind, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            kind,
            key: key.into(),
            message: message.into(),
        }
    }
}

/// The fastest free-flight rate of a model ([`Model::free_flight_rate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeFlightRate {
    /// The rate (1/s).
    pub rate: f64,
    /// The body that sets it.
    pub body: usize,
    /// Whether its damping (`Σc/m`) sets it, else its stiffness (`sqrt(Σk/m)`).
    pub damping: bool,
}

/// A complete, validated system.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    bodies: Vec<Body>,
    couplings: Vec<Coupling>,
    contacts: Vec<Contact>,
    base: BaseExcitation,
    forces: Vec<HarmonicForce>,
    initial_displacement: Vec<f64>,
    initial_velocity: Vec<f64>,
    storeys: Vec<Storey>,
    /// Per contact, its impacts (soft unless set).
    impacts: Vec<Impacts>,
    /// Gravity along the row (m/s², toward −u; 0 for a horizontal row).
    gravity: f64,
    /// The contacts' rigid limits, built on first use.
    rigid: impacts::SharedLaws,
}

/// `v` must be finite and >= 0; `key` is its path, `what` names it (both
/// made only for the error: a row of 10⁶ bodies formats nothing).
fn nonneg(
    key: impl FnOnce() -> String,
    what: impl FnOnce() -> String,
    v: f64,
) -> Result<(), ModelError> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(ModelError::new(
            ModelErrorKind::InvalidValue,
            key(),
            format!("{} = {v}: must be finite and >= 0", what()),
        ))
    }
}

impl Model {
    /// The force scale `F_ref` of contact `k`: over its sides, the smaller
    /// of `k_i g + m_i |z̈|max` (the spring force at the gap plus the peak
    /// base inertia: what the contact must balance); None where that is
    /// not positive and finite (free bodies, no gap, no base). The
    /// exponential law's negligible force is a part of it
    /// (docs/theory.md §10).
    pub fn contact_force_scale(&self, k: usize) -> Option<f64> {
        let c = &self.contacts[k];
        let peak = self.base.peak();
        let f = [c.pair.left(), c.pair.right()]
            .into_iter()
            .flatten()
            .map(|i| self.bodies[i].stiffness * c.clearance + self.bodies[i].mass * peak)
            .fold(f64::INFINITY, f64::min);
        (f > 0.0 && f.is_finite()).then_some(f)
    }

    /// A model of parts taken from a validated model and renumbered (the
    /// local integrator's set: its bodies, and the couplings, contacts,
    /// forces and storeys among them), at rest, soft, without gravity, as
    /// [`Model::new`] and [`Model::with_storeys`] would build it from these
    /// parts; not validated again: each part passed with the whole (and a
    /// state at rest says nothing of a set, which starts from the run's).
    pub(crate) fn part(
        bodies: Vec<Body>,
        couplings: Vec<Coupling>,
        contacts: Vec<Contact>,
        base: BaseExcitation,
        (forces, storeys): (Vec<HarmonicForce>, Vec<Storey>),
    ) -> Self {
        let n = bodies.len();
        Self {
            initial_displacement: vec![0.0; n],
            initial_velocity: vec![0.0; n],
            impacts: vec![Impacts::Soft; contacts.len()],
            bodies,
            couplings,
            contacts,
            base,
            forces,
            storeys,
            gravity: 0.0,
            rigid: Default::default(),
        }
    }

    /// Builds and validates a model. Initial displacements and velocities
    /// default to rest when empty.
    pub fn new(
        bodies: Vec<Body>,
        couplings: Vec<Coupling>,
        contacts: Vec<Contact>,
        base: BaseExcitation,
        forces: Vec<HarmonicForce>,
        initial_displacement: Vec<f64>,
        initial_velocity: Vec<f64>,
    ) -> Result<Self, ModelError> {
        let n = bodies.len();
        if n == 0 {
            return Err(ModelError::new(
                ModelErrorKind::Missing,
                "body",
                "the model has no bodies",
            ));
        }
        check_bodies(&bodies)?;
        check_couplings(&couplings, n)?;
        check_contacts(&contacts, &bodies)?;
        check_forces(&forces, &bodies)?;
        check_base(&base)?;
        let impacts = vec![Impacts::Soft; contacts.len()];
        let model = Self {
            initial_displacement: initial_values(initial_displacement, "displacement", n)?,
            initial_velocity: initial_values(initial_velocity, "velocity", n)?,
            bodies,
            couplings,
            contacts,
            base,
            impacts,
            forces,
            storeys: Vec::new(),
            gravity: 0.0,
            rigid: Default::default(),
        };
        check_overlaps(&model)?;
        scales::check_rounding(&model)?;
        Ok(model)
    }

    /// Replaces the initial state (validated like [`Model::new`]; the
    /// contacts' impacts kept).
    pub fn with_initial_state(
        self,
        displacement: Vec<f64>,
        velocity: Vec<f64>,
    ) -> Result<Self, ModelError> {
        let (impacts, gravity) = (self.impacts, self.gravity);
        Self::new(
            self.bodies,
            self.couplings,
            self.contacts,
            self.base,
            self.forces,
            displacement,
            velocity,
        )
        .map(|m| Self {
            impacts,
            gravity,
            ..m
        })
    }

    /// The model whose time 0 is this model's time `t0`: every harmonic
    /// term's phase advanced by `Ω t0`. None under a record (its time
    /// axis is its own).
    pub fn delayed(&self, t0: f64) -> Option<Self> {
        let mut m = self.clone();
        match &mut m.base {
            BaseExcitation::Record(_) => return None,
            BaseExcitation::Harmonic {
                frequency, phase, ..
            } => *phase += *frequency * t0,
            BaseExcitation::None => {}
        }
        for f in &mut m.forces {
            f.phase += f.frequency * t0;
        }
        Some(m)
    }

    /// The model with its base excitation replaced by `base`, validated as
    /// [`Model::new`] validates it (its values, and the rounding of the
    /// contacts' scales that the base's peak enters).
    pub fn reforced(&self, base: BaseExcitation) -> Result<Self, ModelError> {
        check_base(&base)?;
        let model = self.clone().with_base(base);
        scales::check_rounding(&model)?;
        Ok(model)
    }

    /// Replaces the base excitation.
    pub fn with_base(mut self, base: BaseExcitation) -> Self {
        self.base = base;
        self
    }

    /// Gives every contact the law `law` (clearances and pairs kept).
    pub fn with_contact_law(mut self, law: ContactLaw) -> Self {
        for c in &mut self.contacts {
            c.law = law;
        }
        self.rigid = Default::default();
        self
    }

    /// Bodies in order along the line.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }
    /// Spring–dampers between bodies.
    pub fn couplings(&self) -> &[Coupling] {
        &self.couplings
    }
    /// Contact pairs.
    pub fn contacts(&self) -> &[Contact] {
        &self.contacts
    }
    /// Base excitation.
    pub fn base(&self) -> &BaseExcitation {
        &self.base
    }
    /// Harmonic forces.
    pub fn forces(&self) -> &[HarmonicForce] {
        &self.forces
    }
    /// Initial displacements (m).
    pub fn initial_displacement(&self) -> &[f64] {
        &self.initial_displacement
    }
    /// Initial velocities (m/s).
    pub fn initial_velocity(&self) -> &[f64] {
        &self.initial_velocity
    }

    /// The fastest rate (1/s) of the free-flight dynamics (springs and
    /// dampers, contacts open) and the body and property that set it: the
    /// largest of `sqrt(Σk/m)` and `Σc/m` over the bodies, with Σ over a
    /// body's spring (damper) to the frame and twice its couplings
    /// (Gershgorin bounds of M⁻¹K and M⁻¹C; for a heavily damped body the
    /// fast eigenvalue is about −c/m). An explicit method's step is limited
    /// by stability to about 6/rate.
    pub fn free_flight_rate(&self) -> FreeFlightRate {
        let mut k: Vec<f64> = self.bodies.iter().map(|b| b.stiffness).collect();
        let mut c: Vec<f64> = self.bodies.iter().map(|b| b.damping).collect();
        for cp in &self.couplings {
            for i in [cp.a, cp.b] {
                k[i] += 2.0 * cp.stiffness;
                c[i] += 2.0 * cp.damping;
            }
        }
        let mut fastest = FreeFlightRate {
            rate: 0.0,
            body: 0,
            damping: false,
        };
        // (A square root only where a body is faster: √(k/m) > r where
        // k/m > r², both sides non-negative.)
        for (i, b) in self.bodies.iter().enumerate() {
            let w2 = k[i] / b.mass;
            if w2 > fastest.rate * fastest.rate {
                let w = w2.sqrt();
                if w > fastest.rate {
                    fastest = FreeFlightRate {
                        rate: w,
                        body: i,
                        damping: false,
                    };
                }
            }
            let rate = c[i] / b.mass;
            if rate > fastest.rate {
                fastest = FreeFlightRate {
                    rate,
                    body: i,
                    damping: true,
                };
            }
        }
        fastest
    }

    /// The forcing frequency Ω (rad/s) if the excitation is periodic with one
    /// frequency: the harmonic base's, else that shared by all harmonic
    /// forces. None for no forcing, an accelerogram, or mixed frequencies.
    pub fn forcing_frequency(&self) -> Option<f64> {
        let mut freq = match self.base {
            BaseExcitation::Harmonic { frequency, .. } => Some(frequency),
            BaseExcitation::Record(_) => return None,
            BaseExcitation::None => None,
        };
        for f in &self.forces {
            match freq {
                None => freq = Some(f.frequency),
                Some(w) if (w - f.frequency).abs() > 1e-12 * w => return None,
                _ => {}
            }
        }
        freq
    }

    /// Whether `other` is this model with another excitation only (the same
    /// bodies, couplings and contacts): then the equations of motion of the
    /// two differ by a function of time alone.
    pub fn differs_only_in_forcing(&self, other: &Model) -> bool {
        self.bodies == other.bodies
            && self.couplings == other.couplings
            && self.contacts == other.contacts
    }

    /// Whether the model is equivariant under the spatio-temporal mirror
    /// symmetry of a symmetric row: `u_i → -u_{N-1-i}` together with the
    /// time shift of half a forcing period (which flips the sign of every
    /// harmonic forcing term).
    ///
    /// True when mirrored bodies have equal mass, stiffness and damping,
    /// every coupling and contact has a mirror partner with the same
    /// constants and law (a left wall of body i mirrors a right wall of body
    /// N-1-i), the excitation is harmonic (or absent) with one frequency, and
    /// every harmonic force has a partner of the same amplitude and phase on
    /// the mirrored body. Then `x(t + T/2) = S x(t)` maps solutions to
    /// solutions, symmetric periodic orbits exist, and their symmetry can
    /// only break at a multiplier +1 (a pitchfork, never a period doubling).
    pub fn is_mirror_symmetric(&self) -> bool {
        let n = self.bodies.len();
        let m = |i: usize| n - 1 - i;
        if self.forcing_frequency().is_none() || self.gravity != 0.0 {
            return false;
        }
        let bodies = (0..n).all(|i| {
            let (a, b) = (&self.bodies[i], &self.bodies[m(i)]);
            a.mass == b.mass && a.stiffness == b.stiffness && a.damping == b.damping
        });
        let couplings = self.couplings.iter().all(|c| {
            self.couplings.iter().any(|o| {
                let same = o.stiffness == c.stiffness && o.damping == c.damping;
                let ends = (o.a, o.b) == (m(c.a), m(c.b)) || (o.a, o.b) == (m(c.b), m(c.a));
                same && ends
            })
        });
        let contacts = self.mirror_contacts().is_some();
        let forces = self.forces.iter().all(|f| {
            self.forces
                .iter()
                .any(|o| o.body == m(f.body) && o.amplitude == f.amplitude && o.phase == f.phase)
        });
        bodies && couplings && contacts && forces
    }

    /// The contact that is the mirror image of each contact (body i ↔
    /// N−1−i, left wall ↔ right wall; same clearance and law), if every
    /// contact has one.
    pub fn mirror_contacts(&self) -> Option<Vec<usize>> {
        let n = self.bodies.len();
        let m = |i: usize| n - 1 - i;
        let mirror_pair = |p: ContactPair| match p {
            ContactPair::Bodies { left, right } => ContactPair::Bodies {
                left: m(right),
                right: m(left),
            },
            ContactPair::LeftWall { body } => ContactPair::RightWall { body: m(body) },
            ContactPair::RightWall { body } => ContactPair::LeftWall { body: m(body) },
        };
        let nc = self.contacts.len();
        let image = |c: &Contact, o: &Contact| {
            o.pair == mirror_pair(c.pair) && o.clearance == c.clearance && o.law == c.law
        };
        // A row lists its contacts in order, so the mirror of contact k is
        // usually contact nc − 1 − k: tried first (a search of every
        // contact for every contact is O(nc²), 10⁶ comparisons at N = 1000).
        self.contacts
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let guess = nc - 1 - k;
                if image(c, &self.contacts[guess]) {
                    Some(guess)
                } else {
                    self.contacts.iter().position(|o| image(c, o))
                }
            })
            .collect()
    }

    /// Name of contact k, e.g. `wall|p1`, `p1|p2`, `p3|wall`.
    pub fn contact_name(&self, k: usize) -> String {
        let c = &self.contacts[k];
        let side = |b: Option<usize>| b.map_or("wall".to_string(), |i| self.bodies[i].name.clone());
        format!("{}|{}", side(c.pair.left()), side(c.pair.right()))
    }

    /// Approach coordinate s of contact k for displacements u.
    #[inline]
    pub fn approach(&self, k: usize, u: &[f64]) -> f64 {
        let c = &self.contacts[k];
        c.pair.left().map_or(0.0, |l| u[l]) - c.pair.right().map_or(0.0, |r| u[r]) - c.clearance
    }
}

mod excitation;
pub mod family;
pub mod file;
pub mod hysteresis;
mod impacts;
pub mod parameter;
pub mod record;
pub mod reference;
mod row;
mod scales;
mod storey;

pub use excitation::{Accelerogram, BaseExcitation, HarmonicForce};
pub use impacts::{Impacts, RigidLimits};
pub use storey::Storey;

/// Every body's mass finite and positive, its support's stiffness and
/// damping finite and nonnegative.
fn check_bodies(bodies: &[Body]) -> Result<(), ModelError> {
    for (i, b) in bodies.iter().enumerate() {
        let key = |what: &str| format!("body.{}.{what}", i + 1);
        if !(b.mass > 0.0 && b.mass.is_finite()) {
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                key("mass"),
                format!("body {}: mass = {}: must be finite and > 0", b.name, b.mass),
            ));
        }
        nonneg(
            || key("stiffness"),
            || format!("body {}: stiffness", b.name),
            b.stiffness,
        )?;
        nonneg(
            || key("damping"),
            || format!("body {}: damping", b.name),
            b.damping,
        )?;
    }
    Ok(())
}

/// Every spring joins two different existing bodies (of `n`), with finite,
/// nonnegative stiffness and damping.
fn check_couplings(couplings: &[Coupling], n: usize) -> Result<(), ModelError> {
    for (k, c) in couplings.iter().enumerate() {
        let key = |what: &str| format!("spring.{}.{what}", k + 1);
        if c.a >= n || c.b >= n || c.a == c.b {
            return Err(ModelError::new(
                ModelErrorKind::UnknownBody,
                key("between"),
                format!("spring {}: must join two different existing bodies", k + 1),
            ));
        }
        nonneg(
            || key("stiffness"),
            || format!("spring {}: stiffness", k + 1),
            c.stiffness,
        )?;
        nonneg(
            || key("damping"),
            || format!("spring {}: damping", k + 1),
            c.damping,
        )?;
    }
    Ok(())
}

/// Every contact between existing bodies, the left one first, or a body
/// and a wall, with a finite, nonnegative clearance.
fn check_contacts(contacts: &[Contact], bodies: &[Body]) -> Result<(), ModelError> {
    let n = bodies.len();
    let name = |i: usize| bodies[i].name.clone();
    for (k, c) in contacts.iter().enumerate() {
        let between = || format!("contact.{}.between", k + 1);
        let unknown = || {
            ModelError::new(
                ModelErrorKind::UnknownBody,
                between(),
                format!("contact {}: unknown body", k + 1),
            )
        };
        match c.pair {
            ContactPair::Bodies { left, right } => {
                if left >= n || right >= n {
                    return Err(unknown());
                }
                if left >= right {
                    return Err(ModelError::new(
                        ModelErrorKind::Order,
                        between(),
                        format!(
                            "contact {}: bodies must be given left first in their order along the line ({} is not left of {})",
                            k + 1,
                            name(left),
                            name(right)
                        ),
                    ));
                }
            }
            ContactPair::LeftWall { body } | ContactPair::RightWall { body } => {
                if body >= n {
                    return Err(unknown());
                }
            }
        }
        nonneg(
            || format!("contact.{}.clearance", k + 1),
            || format!("contact {}: clearance", k + 1),
            c.clearance,
        )?;
    }
    Ok(())
}

/// Every harmonic force on an existing body, finite, with a positive
/// frequency.
fn check_forces(forces: &[HarmonicForce], bodies: &[Body]) -> Result<(), ModelError> {
    let n = bodies.len();
    let name = |i: usize| bodies[i].name.clone();
    for (k, f) in forces.iter().enumerate() {
        let key = format!("force.{}", k + 1);
        if f.body >= n {
            return Err(ModelError::new(
                ModelErrorKind::UnknownBody,
                key,
                "harmonic force on an unknown body",
            ));
        }
        if !(f.frequency > 0.0
            && f.frequency.is_finite()
            && f.amplitude.is_finite()
            && f.phase.is_finite())
        {
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                key,
                format!(
                    "harmonic force on {}: needs finite amplitude and phase and frequency > 0",
                    name(f.body)
                ),
            ));
        }
    }
    Ok(())
}

/// A harmonic base excitation finite, with a positive frequency.
fn check_base(base: &BaseExcitation) -> Result<(), ModelError> {
    if let BaseExcitation::Harmonic {
        amplitude,
        frequency,
        phase,
    } = *base
    {
        if !(frequency > 0.0 && frequency.is_finite() && amplitude.is_finite() && phase.is_finite())
        {
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                "excitation",
                "harmonic base excitation: needs finite amplitude and phase and frequency > 0",
            ));
        }
    }
    Ok(())
}

/// Initial displacements or velocities (`what`) of `n` bodies: rest when
/// empty, else `n` finite values.
fn initial_values(v: Vec<f64>, what: &str, n: usize) -> Result<Vec<f64>, ModelError> {
    let key = format!("initial.{what}");
    if v.is_empty() {
        Ok(vec![0.0; n])
    } else if v.len() != n {
        Err(ModelError::new(
            ModelErrorKind::Missing,
            key,
            format!("initial {what}: {} values for {n} bodies", v.len()),
        ))
    } else if v.iter().any(|x| !x.is_finite()) {
        Err(ModelError::new(
            ModelErrorKind::InvalidValue,
            key,
            format!("initial {what}: values must be finite"),
        ))
    } else {
        Ok(v)
    }
}

/// No contact closed beyond contact at the initial displacements.
fn check_overlaps(model: &Model) -> Result<(), ModelError> {
    for k in 0..model.contacts.len() {
        let s = model.approach(k, &model.initial_displacement);
        if s > 0.0 {
            return Err(ModelError::new(
                ModelErrorKind::Overlap,
                format!("contact.{}", k + 1),
                format!(
                    "contact {} ({}): the bodies overlap at the start by {s:e} m",
                    k + 1,
                    model.contact_name(k)
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
