//! Maps of long-run behaviour, by brute force: what a model settles to over
//! a parameter, a plane of parameters or a plane of initial states.
//!
//! - `sweep/` — the bifurcation diagram in one parameter (Poincaré samples,
//!   up and down, optional Lyapunov exponents); the runs every map shares.
//! - `attractor.rs` — the attractor one run reaches, and whether two runs
//!   reached the same one.
//! - `chart/` — the stability chart over two parameters.
//! - `basins/` — basins of attraction over a plane of initial states.
//! - `lyapunov/` — Lyapunov exponents by QR re-orthonormalisation
//!   (docs/theory.md §7).

pub mod attractor;
pub mod basins;
pub mod chart;
pub mod lyapunov;
pub mod sweep;
