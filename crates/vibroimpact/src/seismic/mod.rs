//! Earthquake engineering on the library's models (docs/earthquakes.md):
//! what a record does to a structure, to a row of pounding buildings and
//! to their collapse. The records themselves and the storey laws live with
//! the model ([`crate::model::record`], [`crate::model::hysteresis`]).
//!
//! - `spectrum/` — elastic response spectra of a record.
//! - `pounding/` — rows of buildings (fixed or isolated in their moats)
//!   pounding under records: the row file, the buildings, the study, its
//!   peaks and documents, pounding spectra and moat-gap studies.
//! - `collapse/` — incremental dynamic analysis to collapse per record and
//!   the FEMA P695 margins.
//! - `pushover/` — a shear frame's static pushover and what FEMA P695
//!   reads from it (V_max, δ_y,eff, δ_u, μ_T).

pub mod collapse;
pub mod pounding;
pub mod pushover;
pub mod spectrum;
