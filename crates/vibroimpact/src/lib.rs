//! # vibroimpact
//!
//! Vibrating systems whose bodies collide, after T. Fujita, "An analytical
//! method for the vibrations of the multi-degree-of-freedom system with
//! mutual impact interactions" (Seisan Kenkyu 29, 1977).
//!
//! Modules follow the physics:
//! - [`contact`]: contact laws (Fujita's exponential law, seed eq. 1, and
//!   Hertz, Kelvin–Voigt, Hunt–Crossley, Lankarani–Nikravesh);
//! - [`impact`]: two-body impact relations, closed form (seed eqs. 8–18)
//!   and by direct integration;
//! - [`identify`]: identification of a/b and α from measured impacts
//!   (seed §3);
//! - [`model`]: N bodies, springs, contact pairs and excitation (§4);
//! - [`dynamics`]: the equations of motion with their banded Jacobian;
//! - [`simulate`]: time histories with an impact log;
//! - [`variational`]: sensitivities and monodromy matrices (§5);
//! - [`integrate`]: the integrators (DOP853, RODAS) shared by every time
//!   integration;
//! - [`numeric`]: scalar special functions and root finders.
//!
//! The library does no I/O: callers hand it numbers and get numbers back.

pub mod contact;
pub mod continuation;
pub mod dynamics;
pub mod identify;
pub mod impact;
pub mod integrate;
pub mod model;
pub mod numeric;
pub mod periodic;
pub mod simulate;
pub mod variational;
