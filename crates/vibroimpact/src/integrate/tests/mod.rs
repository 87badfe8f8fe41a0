//! Checks of the integrators together: the conformance suite every method
//! passes (`conformance.rs`) and the test systems the checks share
//! (`systems.rs`).

mod conformance;
pub(crate) mod systems;
