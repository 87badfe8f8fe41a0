//! The subcommands, one file each; none imports another (what several
//! share lives in `args`, `format`, `measurements`, `plot`, …).

pub mod basins;
pub mod branch;
pub mod chart;
pub mod collapse;
pub mod hysteresis;
pub mod identify;
pub mod impact;
pub mod periodic;
pub mod pounding;
pub mod pushover;
pub mod simulate;
pub mod spectrum;
pub mod sweep;
