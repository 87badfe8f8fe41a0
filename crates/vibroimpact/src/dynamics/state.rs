//! The state layout (see the module documentation of `dynamics`): body
//! order and interleaved order, a model's state length and its initial
//! state, known without building its system.

use super::ChainDynamics;
use crate::model::hysteresis::StoreyLaw;
use crate::model::Model;

/// Index in the interleaved state `[u_1, v_1, …]` of component k of a
/// body-order state `[u_1..u_N, v_1..v_N]` of N bodies.
#[inline]
pub fn interleaved_index(k: usize, n: usize) -> usize {
    if k < n {
        2 * k
    } else {
        2 * (k - n) + 1
    }
}

/// Body-order `[u.., v..]` to interleaved `[u_1, v_1, …]`.
pub fn to_interleaved(x: &[f64]) -> Vec<f64> {
    let n = x.len() / 2;
    let mut y = vec![0.0; x.len()];
    for (k, &v) in x.iter().enumerate() {
        y[interleaved_index(k, n)] = v;
    }
    y
}

/// Interleaved `[u_1, v_1, …]` (first 2N entries of `y`) to body order.
pub fn from_interleaved(y: &[f64], n: usize) -> Vec<f64> {
    (0..2 * n).map(|k| y[interleaved_index(k, n)]).collect()
}

impl ChainDynamics {
    /// The length of a model's ODE state: u, v interleaved, the Bouc–Wen
    /// storeys' two states each, and with `energy` the audit's three
    /// quadratures (the `dim` of its system, without building it).
    pub fn state_len(model: &Model, energy: bool) -> usize {
        let bouc_wen = model
            .storeys()
            .iter()
            .filter(|s| matches!(s.law, StoreyLaw::BoucWen(_)))
            .count();
        2 * model.bodies().len() + 2 * bouc_wen + if energy { 3 } else { 0 }
    }

    /// The initial ODE state of a model (interleaved, energy quadratures 0;
    /// [`ChainDynamics::state_len`] long).
    pub fn initial_state(model: &Model, energy: bool) -> Vec<f64> {
        let mut y = vec![0.0; Self::state_len(model, energy)];
        for i in 0..model.bodies().len() {
            y[2 * i] = model.initial_displacement()[i];
            y[2 * i + 1] = model.initial_velocity()[i];
        }
        y
    }
}
