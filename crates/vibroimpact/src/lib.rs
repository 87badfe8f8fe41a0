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
//!   (seed §3); [`measured`]: tables of measured data (CSV text);
//! - [`model`]: N bodies, springs, contact pairs and excitation (§4);
//! - [`dynamics`]: the equations of motion with their banded Jacobian;
//! - [`simulate`]: time histories with an impact log, by the global or
//!   the local integrator;
//! - [`free_motion`]: the exact motion of bodies between contacts;
//! - [`variational`]: sensitivities and monodromy matrices (§5);
//! - [`newton`]: the damped Newton method of every periodic solve;
//! - [`periodic`]: periodic solutions by shooting, Floquet multipliers;
//! - [`lyapunov`]: Lyapunov exponents by QR re-orthonormalisation;
//! - [`continuation`]: branches of periodic solutions and their special
//!   points;
//! - [`sweep`]: brute-force bifurcation diagrams (Poincaré samples);
//! - [`attractor`]: the attractor a simulation reaches, and whether two
//!   runs reached the same one;
//! - [`chart`]: brute-force stability charts over two parameters;
//! - [`basins`]: basins of attraction in a plane of initial states;
//! - [`model_file`]: the model-file schema (TOML text → [`model::Model`]);
//! - [`parameter`]: a numeric key of a model file made a parameter;
//! - [`field_error`]: an option refused by name, spelled by each face;
//! - [`family`]: a family of models in one or two parameters, the problem
//!   every parameter study takes;
//! - [`reference`](mod@reference): the reference problems R1–R3 (`docs/theory.md` §6);
//! - [`results`]: the documents of results (the CLI's JSON, Python's
//!   result objects);
//! - [`record`], [`spectrum`], [`pounding`]: earthquake records, their
//!   response spectra, and rows of buildings (fixed or isolated) pounding
//!   under them;
//! - [`collapse`]: incremental dynamic analysis to collapse, per record,
//!   and the median collapse scale (FEMA P695);
//! - [`hysteresis`]: the force–drift laws of inelastic storeys (bilinear,
//!   Bouc–Wen);
//! - [`integrate`]: the integrators (DOP853, DOPRI5, RODAS) shared by
//!   every time integration;
//! - [`linalg`]: the band LU, GMRES and Arnoldi, eigenvalues of general
//!   real matrices, the null vector;
//! - [`numeric`]: scalar special functions and root finders.
//!
//! The library does no I/O: callers hand it numbers and text and get
//! numbers back.

#![warn(missing_docs)]
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

pub mod attractor;
pub mod basins;
pub mod chart;
pub mod collapse;
pub mod contact;
pub mod continuation;
pub mod dynamics;
pub mod family;
pub mod field_error;
pub mod free_motion;
pub mod hysteresis;
pub mod identify;
pub mod impact;
pub mod integrate;
pub mod linalg;
pub mod lyapunov;
pub mod measured;
pub mod model;
pub mod model_file;
pub mod newton;
pub mod numeric;
pub mod parameter;
pub mod periodic;
pub mod pounding;
pub mod record;
pub mod reference;
pub mod results;
pub mod simulate;
pub mod spectrum;
pub mod sweep;
pub mod variational;
