//! The sections of the benchmark, in the order they run; each is a file
//! with one entry, [`Section`].
//!
//! ## Files
//! - `n3.rs` — R2, N = 3, 5 periods: work-precision sweeps, robust settings;
//! - `n1000.rs` — R2, N = 1000, 1 period at rtol 1e-8 against ARKODE;
//! - `scaling.rs` — time per period for N = 10 … 10000;
//! - `shooting.rs` — one period map with the full monodromy, Newton–Krylov;
//! - `local.rs` — the local integrator against SUNDIALS and the global one,
//!   and on many clusters;
//! - `storeys.rs` — the local integrator with yielding storeys;
//! - `rigid.rs` — rigid impacts against the soft law they are the limit of.

use serde_json::Value;

use crate::common::Peers;

pub mod local;
pub mod n1000;
pub mod n3;
pub mod rigid;
pub mod scaling;
pub mod shooting;
pub mod storeys;

/// The entries a section adds to the JSON results: (key, value).
pub type Entries = Vec<(&'static str, Value)>;

/// A section's entry: it runs with the peers (if any) and `--quick`,
/// prints as it goes and returns its entries.
pub type Section = fn(Option<&Peers>, bool) -> Entries;

/// Every section in the order it runs, with the name `--only` takes.
pub const ALL: [(&str, Section); 8] = [
    ("n3", n3::run),
    ("n1000", n1000::run),
    ("scaling", scaling::run),
    ("shooting", shooting::run),
    ("local", local::run),
    ("clusters", local::clusters_section),
    ("storeys", storeys::run),
    ("rigid", rigid::run),
];
