//! The peaks of a row's run, taken as its samples stream by (nothing
//! stored): drifts, residual drifts, floor accelerations and displacements
//! per building, closings per joint floor, the isolators' displacements;
//! then the impact log and the storeys' hysteretic energy at the end.

use super::{IsolatorResponse, Response, Row, RowModel, StoreyLoop};
use crate::simulate::Simulation;

/// Running peaks of one run.
pub(super) struct Peaks {
    /// Per building: where its floors start, its slab, how many floors.
    layout: Vec<(usize, Option<usize>, usize)>,
    /// Per building, the time its residual window opens (its last
    /// fundamental period).
    windows: Vec<f64>,
    drift: Vec<Vec<f64>>,
    acceleration: Vec<Vec<f64>>,
    displacement: Vec<Vec<f64>>,
    /// Per building, the drift sums over its window and their count.
    residual: Vec<(Vec<f64>, usize)>,
    /// Per building with a slab: peak |u| and its sum over the window.
    slab: Vec<(f64, f64)>,
    /// Per joint, per floor: (left body, right body, largest closing).
    closing: Vec<Vec<(usize, usize, f64)>>,
    /// Per hysteretic storey of the model (its order).
    loops: Vec<Tracked>,
}

/// A hysteretic storey's body below (None: the ground) and above, and its
/// loop so far.
type Tracked = (Option<usize>, usize, StoreyLoop);

impl Peaks {
    /// Empty peaks of `row` run as `rm` up to `t_end`.
    pub(super) fn new(row: &Row, rm: &RowModel, t_end: f64) -> Self {
        let layout: Vec<_> = rm
            .placements
            .iter()
            .zip(&row.buildings)
            .map(|(p, b)| (p.first_floor, p.base, b.floors()))
            .collect();
        let zeros: Vec<Vec<f64>> = layout.iter().map(|l| vec![0.0; l.2]).collect();
        let closing = row
            .joints
            .iter()
            .enumerate()
            .map(|(j, joint)| {
                let (a, b) = (&rm.placements[j], &rm.placements[j + 1]);
                joint
                    .floors
                    .iter()
                    .map(|&f| {
                        (
                            a.first_floor + f - 1,
                            b.first_floor + f - 1,
                            f64::NEG_INFINITY,
                        )
                    })
                    .collect()
            })
            .collect();
        let mut loops: Vec<(usize, Tracked)> = Vec::new();
        for (k, p) in rm.placements.iter().enumerate() {
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
                loops.push((s, (below, above, empty)));
            }
        }
        loops.sort_by_key(|l| l.0);
        Self {
            loops: loops.into_iter().map(|l| l.1).collect(),
            windows: row.buildings.iter().map(|b| t_end - b.period()).collect(),
            drift: zeros.clone(),
            acceleration: zeros.clone(),
            displacement: zeros.clone(),
            residual: zeros.into_iter().map(|z| (z, 0)).collect(),
            slab: vec![(0.0, 0.0); layout.len()],
            layout,
            closing,
        }
    }

    /// Takes the sample `row` = [u.., v.., a.., storey forces..] at `t`
    /// with ground acceleration `ag`; returns the largest storey drift in
    /// it.
    pub(super) fn sample(&mut self, t: f64, row: &[f64], ag: f64) -> f64 {
        let mut worst = 0.0f64;
        let n = (row.len() - self.loops.len()) / 3;
        let (u, a, forces) = (&row[..n], &row[2 * n..3 * n], &row[3 * n..]);
        for ((below, above, l), &f) in self.loops.iter_mut().zip(forces) {
            l.drift.push(u[*above] - below.map_or(0.0, |b| u[b]));
            l.force.push(f);
        }
        for (k, &(first, base, floors)) in self.layout.iter().enumerate() {
            let late = t >= self.windows[k];
            let slab = base.map_or(0.0, |b| u[b]);
            for i in 0..floors {
                let below = if i == 0 { slab } else { u[first + i - 1] };
                let d = u[first + i] - below;
                worst = worst.max(d.abs());
                self.drift[k][i] = self.drift[k][i].max(d.abs());
                self.displacement[k][i] = self.displacement[k][i].max(u[first + i].abs());
                self.acceleration[k][i] = self.acceleration[k][i].max((a[first + i] + ag).abs());
                if late {
                    self.residual[k].0[i] += d;
                }
            }
            self.residual[k].1 += usize::from(late);
            self.slab[k].0 = self.slab[k].0.max(slab.abs());
            if late {
                self.slab[k].1 += slab;
            }
        }
        for joint in &mut self.closing {
            for (l, r, c) in joint.iter_mut() {
                *c = c.max(u[*l] - u[*r]);
            }
        }
        worst
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
        // A run stopped before a building's window opened (a collapse
        // study's drift limit) has no residual: NaN (null in documents).
        let mean = |sum: f64, count: usize| {
            if count == 0 {
                f64::NAN
            } else {
                sum / count as f64
            }
        };
        let residual: Vec<Vec<f64>> = self
            .residual
            .iter()
            .map(|(sum, count)| sum.iter().map(|s| mean(*s, *count)).collect())
            .collect();
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
                let (peak, sum) = self.slab[k];
                Some(IsolatorResponse {
                    peak_displacement: peak,
                    residual_displacement: mean(sum, self.residual[k].1),
                    hysteretic_energy: bearing_energy[k],
                    beyond_capacity: iso.capacity.is_some_and(|c| peak > c),
                    moat_impacts: moat.len(),
                    moat_peak_force: moat.iter().fold(0.0, |m, i| m.max(i.peak_force)),
                })
            })
            .collect();
        Response {
            drift: self.drift,
            residual_drift: residual,
            acceleration: self.acceleration,
            displacement: self.displacement,
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
                .closing
                .into_iter()
                .map(|j| j.into_iter().map(|(_, _, c)| c).collect())
                .collect(),
            loops: self.loops.into_iter().map(|(_, _, l)| l).collect(),
        }
    }
}
