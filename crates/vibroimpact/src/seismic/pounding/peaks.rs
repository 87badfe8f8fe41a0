//! The peaks of a row's run, exact on the dense output (the run's gauges
//! and extrema, whatever the sampling): drifts, residual drifts, floor
//! accelerations and displacements per building, closings per joint floor,
//! the isolators' displacements; the impact log and the storeys'
//! hysteretic energy at the end; the hysteresis loops at the samples.

use super::{IsolatorResponse, Response, Row, RowModel, StoreyLoop};
use crate::simulate::{Gauge, GaugeReading, Simulation};

/// The peaks of one run: the gauges it asks the simulation for, where
/// each peak is read, and the hysteresis loops at the samples.
pub(super) struct Peaks {
    /// Per building: where its floors start, its slab, how many floors.
    layout: Vec<(usize, Option<usize>, usize)>,
    /// The gauges, in order: per building, per floor, its storey's drift
    /// (with its mean over the building's last fundamental period), its
    /// absolute acceleration and its displacement (but the first floor's of
    /// a fixed building, its drift), then its slab's displacement (with
    /// its mean) if isolated; then per joint, per floor, its closing.
    gauges: Vec<Gauge>,
    /// Per building, per floor, its drift, acceleration and displacement
    /// gauges (a first floor's drift is its displacement where the
    /// building is fixed: one gauge).
    floor_gauges: Vec<Vec<[usize; 3]>>,
    /// Per building, the index of its slab's gauge, if isolated.
    slab_gauges: Vec<Option<usize>>,
    /// Per joint, its first closing gauge and how many.
    joint_gauges: Vec<(usize, usize)>,
    /// Per hysteretic storey of the model (its order), where the loops
    /// are kept (the samples then carry the storeys' forces); else none.
    loops: Vec<Tracked>,
}

/// A storey's drift limit ([`Peaks::limits`]): the bodies above and below
/// it (None: the ground), its bound (m), and its building and storey.
pub(super) struct Limit {
    above: usize,
    below: Option<usize>,
    bound: f64,
    at: (usize, usize),
}

/// A hysteretic storey's body below (None: the ground) and above, and its
/// loop so far.
type Tracked = (Option<usize>, usize, StoreyLoop);

impl Peaks {
    /// The peaks of `row` run as `rm` up to `t_end`, with the hysteretic
    /// storeys' loops where `loops`.
    pub(super) fn new(row: &Row, rm: &RowModel, t_end: f64, loops: bool) -> Self {
        let layout: Vec<_> = rm
            .placements
            .iter()
            .zip(&row.buildings)
            .map(|(p, b)| (p.first_floor, p.base, b.floors()))
            .collect();
        let (mut gauges, mut floor_gauges, mut slab_gauges) = (Vec::new(), Vec::new(), Vec::new());
        for (&(first, base, floors), b) in layout.iter().zip(&row.buildings) {
            // The residual window: the building's last fundamental period.
            let mean_from = Some(t_end - b.period());
            let mut push = |g: Gauge| {
                gauges.push(g);
                gauges.len() - 1
            };
            let mine = (0..floors)
                .map(|i| {
                    let right = if i == 0 { base } else { Some(first + i - 1) };
                    let left = Some(first + i);
                    let drift = push(Gauge::Separation {
                        left,
                        right,
                        mean_from,
                    });
                    let acceleration = push(Gauge::AbsoluteAcceleration { body: first + i });
                    let displacement = match right {
                        None => drift,
                        Some(_) => push(Gauge::Separation {
                            left,
                            right: None,
                            mean_from: None,
                        }),
                    };
                    [drift, acceleration, displacement]
                })
                .collect();
            floor_gauges.push(mine);
            slab_gauges.push(base.map(|slab| {
                gauges.push(Gauge::Separation {
                    left: Some(slab),
                    right: None,
                    mean_from,
                });
                gauges.len() - 1
            }));
        }
        let mut joint_gauges = Vec::new();
        for (j, joint) in row.joints.iter().enumerate() {
            let (a, b) = (&rm.placements[j], &rm.placements[j + 1]);
            joint_gauges.push((gauges.len(), joint.floors.len()));
            for &f in &joint.floors {
                gauges.push(Gauge::Separation {
                    left: Some(a.first_floor + f - 1),
                    right: Some(b.first_floor + f - 1),
                    mean_from: None,
                });
            }
        }
        let mut tracked: Vec<(usize, Tracked)> = Vec::new();
        for (k, p) in rm.placements.iter().enumerate().filter(|_| loops) {
            for &(s, storey) in &p.storeys {
                let (below, above) = match storey {
                    None => (None, p.base.unwrap_or(p.first_floor)),
                    Some(0) => (p.base, p.first_floor),
                    Some(i) => (Some(p.first_floor + i - 1), p.first_floor + i),
                };
                let empty = StoreyLoop {
                    building: k,
                    storey,
                    drift: Vec::new(),
                    force: Vec::new(),
                };
                tracked.push((s, (below, above, empty)));
            }
        }
        tracked.sort_by_key(|l| l.0);
        Self {
            loops: tracked.into_iter().map(|l| l.1).collect(),
            gauges,
            floor_gauges,
            slab_gauges,
            joint_gauges,
            layout,
        }
    }

    /// The gauges the run reads for these peaks.
    pub(super) fn gauges(&self) -> Vec<Gauge> {
        self.gauges.clone()
    }

    /// A sample of the loops: each hysteretic storey's drift and force.
    pub(super) fn sample(&mut self, row: &[f64]) {
        let n = (row.len() - self.loops.len()) / 2;
        let (u, forces) = (&row[..n], &row[2 * n..]);
        for ((below, above, l), &f) in self.loops.iter_mut().zip(forces) {
            l.drift.push(u[*above] - below.map_or(0.0, |b| u[b]));
            l.force.push(f);
        }
    }

    /// Each storey's drift against its bound in `bounds` (m, per building
    /// and storey), for [`Peaks::check`].
    pub(super) fn limits(&self, bounds: &[Vec<f64>]) -> Vec<Limit> {
        let mut limits = Vec::new();
        for (k, (&(first, base, floors), bound)) in self.layout.iter().zip(bounds).enumerate() {
            for (i, &bound) in bound.iter().enumerate().take(floors) {
                let below = match (i, base) {
                    (0, b) => b,
                    _ => Some(first + i - 1),
                };
                limits.push(Limit {
                    above: first + i,
                    below,
                    bound,
                    at: (k, i),
                });
            }
        }
        limits
    }

    /// The storey drifts of a sample against their `limits`: the building
    /// and storey of the largest drift over its bound, where one exceeds
    /// it. (A drift is divided by its bound only where it exceeds it, not
    /// every storey at every sample.)
    pub(super) fn check(&self, row: &[f64], limits: &[Limit]) -> Option<(usize, usize)> {
        let u = &row[..(row.len() - self.loops.len()) / 2];
        let mut worst: Option<(f64, (usize, usize))> = None;
        for l in limits {
            let drift = (u[l.above] - l.below.map_or(0.0, |b| u[b])).abs();
            if drift > l.bound && worst.is_none_or(|w| drift / l.bound > w.0) {
                worst = Some((drift / l.bound, l.at));
            }
        }
        worst.map(|w| w.1)
    }

    /// The response: these peaks with the run's impacts (between buildings
    /// and on the moat walls) and the storeys' hysteretic energy.
    pub(super) fn finish(self, row: &Row, rm: &RowModel, sim: &Simulation) -> Response {
        let mut hysteretic_energy: Vec<Vec<f64>> =
            self.layout.iter().map(|l| vec![0.0; l.2]).collect();
        let mut bearing_energy = vec![0.0; self.layout.len()];
        for (k, p) in rm.placements.iter().enumerate() {
            for &(s, storey) in &p.storeys {
                let e = sim.hysteretic_energy.get(s).copied().unwrap_or(0.0);
                match storey {
                    Some(i) => hysteretic_energy[k][i] = e,
                    None => bearing_energy[k] = e,
                }
            }
        }
        let in_joints = |c: usize| rm.joints.iter().any(|j| j.contains(&c));
        let between = sim.impacts.iter().filter(|i| in_joints(i.contact));
        // The run's readings; a run with no step has read nothing.
        let empty = GaugeReading {
            min: 0.0,
            max: 0.0,
            mean: None,
        };
        let readings = sim.extrema.as_ref().map(|e| e.gauges.as_slice());
        let read = |w: usize| readings.and_then(|r| r.get(w)).unwrap_or(&empty);
        // A run stopped before a building's window opened (a collapse
        // study's drift limit) has no residual: NaN (null in documents).
        let mean = |w: usize| read(w).mean.unwrap_or(f64::NAN);
        let per_floor = |f: &dyn Fn(usize, usize) -> f64| -> Vec<Vec<f64>> {
            self.layout
                .iter()
                .enumerate()
                .map(|(k, l)| (0..l.2).map(|i| f(k, i)).collect())
                .collect()
        };
        let gauge = |k: usize, i: usize, q: usize| self.floor_gauges[k][i][q];
        let drift = per_floor(&|k, i| read(gauge(k, i, 0)).peak());
        let residual = per_floor(&|k, i| mean(gauge(k, i, 0)));
        let acceleration = per_floor(&|k, i| read(gauge(k, i, 1)).peak());
        let displacement = per_floor(&|k, i| read(gauge(k, i, 2)).peak());
        let isolators = rm
            .placements
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let iso = row.buildings[k].isolation.as_ref()?;
                p.base?;
                let moat: Vec<_> = sim
                    .impacts
                    .iter()
                    .filter(|i| p.moat.contains(&i.contact))
                    .collect();
                let w = self.slab_gauges[k]?;
                let peak = read(w).peak();
                Some(IsolatorResponse {
                    peak_displacement: peak,
                    residual_displacement: mean(w),
                    hysteretic_energy: bearing_energy[k],
                    beyond_capacity: iso.capacity.is_some_and(|c| peak > c),
                    moat_impacts: moat.len(),
                    moat_peak_force: moat.iter().fold(0.0, |m, i| m.max(i.peak_force)),
                })
            })
            .collect();
        Response {
            drift,
            residual_drift: residual,
            acceleration,
            displacement,
            hysteretic_energy,
            isolators,
            peak_impact_force: between.clone().fold(0.0, |m, i| m.max(i.peak_force)),
            impacts: between.count(),
            joint_impacts: rm
                .joints
                .iter()
                .map(|contacts| {
                    let at = sim.impacts.iter().filter(|i| contacts.contains(&i.contact));
                    (
                        at.clone().count(),
                        at.fold(0.0f64, |m, i| m.max(i.peak_force)),
                    )
                })
                .collect(),
            closing: self
                .joint_gauges
                .iter()
                .map(|&(first, n)| (first..first + n).map(|w| read(w).max).collect())
                .collect(),
            loops: self.loops.into_iter().map(|(_, _, l)| l).collect(),
            collapse: None,
        }
    }
}
