//! # vibroimpact
//!
//! Vibrating systems whose bodies collide, after T. Fujita, "An analytical
//! method for the vibrations of the multi-degree-of-freedom system with
//! mutual impact interactions" (Seisan Kenkyu 29, 1977).
//!
//! The modules follow the physics, from the ground up (each folder's
//! `mod.rs` opens with a map of its files; `docs/architecture.md` is the
//! one-page guide):
//! - [`numeric`], [`linalg`], [`newton`]: scalar special functions and root
//!   finders; the band LU, GMRES and Arnoldi, eigenvalues, the null vector;
//!   the damped Newton method of every periodic solve;
//! - [`contact`]: contact laws (Fujita's exponential law, seed eq. 1, and
//!   Hertz, Kelvin–Voigt, Hunt–Crossley, Lankarani–Nikravesh);
//! - [`field_error`]: an option refused by name, spelled by each face;
//! - [`integrate`]: the integrators (DOP853, DOPRI5, RODAS) on one step
//!   driver, events, the tangent tape;
//! - [`impact`]: two-body impact relations, closed form (seed eqs. 8–18)
//!   and by direct integration;
//! - [`identify`]: identification of a/b and α from measured impacts
//!   (seed §3), and the measured-data tables;
//! - [`model`]: N bodies, springs, contact pairs, storeys and their laws,
//!   excitation and ground-motion records (§4); the model file, its
//!   parameters and families; the reference problems R1–R3;
//! - [`dynamics`]: the equations of motion with their banded Jacobian, and
//!   the variational equations (§5);
//! - [`simulate`]: time histories with an impact log, by the global or the
//!   local integrator (exact motion between contacts);
//! - [`periodic`]: periodic solutions by shooting, Floquet multipliers;
//! - [`continuation`]: branches of periodic solutions, their special points
//!   and curves of special points in two parameters;
//! - [`maps`]: brute-force maps: sweeps, stability charts, basins,
//!   attractors, Lyapunov exponents;
//! - [`seismic`]: response spectra, rows of pounding buildings, collapse
//!   studies (FEMA P695);
//! - [`results`]: the documents of results (the CLI's JSON, Python's result
//!   objects) and their readers.
//!
//! The library does no I/O: callers hand it numbers and text and get
//! numbers back.

#![warn(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod contact;
pub mod continuation;
pub mod dynamics;
pub mod field_error;
pub mod identify;
pub mod impact;
pub mod integrate;
pub mod linalg;
pub mod maps;
pub mod model;
pub mod newton;
pub mod numeric;
pub mod periodic;
pub mod results;
pub mod seismic;
pub mod simulate;
