//! What a pounding run gives back: a row's peak [`Response`] (with a
//! [`Collapse`] where a storey passed its height), the loops, why it ended
//! ([`Stop`]), a time history, and one record's study with the joints'
//! gaps.

use super::RowModel;

/// The peak response of a row to one record; per building (left to
/// right), per storey or floor from the ground up.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    /// Peak storey drifts max |u_i − u_{i−1}| (m; storey 1 from the slab
    /// of an isolated building).
    pub drift: Vec<Vec<f64>>,
    /// Residual storey drifts (m, signed): the mean drift over each
    /// building's last fundamental period (of the free-vibration tail that
    /// follows the record for yielding storeys); NaN for a run stopped
    /// before that period.
    pub residual_drift: Vec<Vec<f64>>,
    /// Peak absolute floor accelerations max |ü_i + a_g| over the samples
    /// (m/s²).
    pub acceleration: Vec<Vec<f64>>,
    /// Peak floor displacements relative to the ground (m).
    pub displacement: Vec<Vec<f64>>,
    /// The energy each storey dissipated by hysteresis (J; 0 for an
    /// elastic storey).
    pub hysteretic_energy: Vec<Vec<f64>>,
    /// Per building, its isolation layer's response (None: fixed).
    pub isolators: Vec<Option<IsolatorResponse>>,
    /// Largest impact force between buildings (N), 0 without impacts.
    pub peak_impact_force: f64,
    /// Impacts between buildings.
    pub impacts: usize,
    /// Per joint, its impacts and their largest force (N; 0 without).
    pub joint_impacts: Vec<(usize, f64)>,
    /// Per joint, per pounding floor, the largest closing
    /// max (u_left − u_right) (m).
    pub closing: Vec<Vec<f64>>,
    /// The hysteresis loop of every hysteretic storey and bearing layer,
    /// at the samples.
    pub loops: Vec<StoreyLoop>,
    /// Where a storey moved more than its height (the building has
    /// collapsed): the run stopped there, and its peaks are those up to
    /// then. None for a run to its end.
    pub collapse: Option<Collapse>,
}

/// A storey past its height: the run that found it stops ([`Response`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collapse {
    /// The building (index in the row).
    pub building: usize,
    /// The storey from 0.
    pub storey: usize,
    /// The check at which it was found (s): at least every record sample.
    pub time: f64,
}

/// A hysteretic storey's (or bearing layer's) loop: drift and force at
/// the samples.
#[derive(Clone, Debug, PartialEq)]
pub struct StoreyLoop {
    /// The building (index in the row).
    pub building: usize,
    /// The storey from 0, or None for the bearings.
    pub storey: Option<usize>,
    /// Drift (m).
    pub drift: Vec<f64>,
    /// Force (N).
    pub force: Vec<f64>,
}

/// Why a run ([`Row::respond_until`](super::Row::respond_until)) ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    /// At the end of the record (and its tail).
    End,
    /// A storey drift passed the limit at `time` (s).
    Limit {
        /// When.
        time: f64,
    },
    /// The run did not converge (a step size that underflowed, the step
    /// limit).
    Diverged {
        /// Why.
        message: String,
    },
}

/// A row's time history ([`Row::history`](super::Row::history)).
#[derive(Clone, Debug)]
pub struct History {
    /// The model it ran, with its layout.
    pub model: RowModel,
    /// Sample times (s).
    pub times: Vec<f64>,
    /// Per sample, every body's displacement (m), body order.
    pub displacement: Vec<f64>,
    /// The impacts (between buildings and on moat walls), by start time.
    pub impacts: Vec<crate::simulate::ImpactRecord>,
    /// The hysteretic storeys' loops.
    pub loops: Vec<StoreyLoop>,
}

/// An isolation layer's response.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IsolatorResponse {
    /// Peak displacement of the slab relative to the ground (m).
    pub peak_displacement: f64,
    /// Its mean over the building's last fundamental period (m, signed).
    pub residual_displacement: f64,
    /// The energy the bearings dissipated by hysteresis (J).
    pub hysteretic_energy: f64,
    /// Whether the peak displacement passed the stated capacity.
    pub beyond_capacity: bool,
    /// Impacts on the moat wall.
    pub moat_impacts: usize,
    /// Largest moat impact force (N), 0 without.
    pub moat_peak_force: f64,
}

/// One record's pounding study: the row with and without its contacts.
#[derive(Clone, Debug, PartialEq)]
pub struct PoundingResult {
    /// With the contacts.
    pub pounding: Response,
    /// The buildings apart (no contacts: no pounding, no moat wall).
    pub free: Response,
    /// Per joint, the gap that avoids contact and the code rules' gaps.
    pub joints: Vec<JointGaps>,
}

/// A joint's separation: what the free buildings need, and the code rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointGaps {
    /// The smallest gap that avoids contact: the largest closing of the
    /// free buildings over the joint's floors (m; 0 if they never close).
    pub required_gap: f64,
    /// The code rules from the free buildings' peak displacements u_L, u_R
    /// at the joint's floors (largest over them, m): absolute sum, SRSS,
    /// and the double difference `√(u_L² + u_R² − 2ρ u_L u_R)` with ρ the
    /// correlation of two oscillators of the buildings' fundamental
    /// periods and damping (Der Kiureghian's CQC coefficient).
    pub code_gaps: CodeGaps,
}

/// Separation gaps of the code rules (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CodeGaps {
    /// u_L + u_R.
    pub absolute_sum: f64,
    /// √(u_L² + u_R²).
    pub srss: f64,
    /// √(u_L² + u_R² − 2ρ u_L u_R).
    pub double_difference: f64,
    /// ρ.
    pub correlation: f64,
}
