//! Starts on other branches: the crossing branch at a branch point (a
//! symmetry-breaking pitchfork or a simple crossing) and the period-2n
//! branch at a period doubling; [`switch_branch`] continues from them.

use crate::model::family::Family;
use nalgebra::DMatrix;

use super::branch::parameter_scale;
use super::problem::{period_image, Linear, Problem};
use super::{
    continue_branch, Branch, BranchPoint, ContinuationError, ContinuationOptions, SpecialKind,
    SpecialPoint,
};
use crate::model::Model;
use crate::periodic::{period_map, shoot, ShootingOptions};

/// Whether the periodic orbit through `x` is symmetric, `x(t + nT/2) =
/// S x(t)`: the model is mirror-symmetric and the half map fixes x to
/// 100 × the shooting tolerance.
pub fn is_symmetric_orbit(model: &Model, x: &[f64], opts: &ShootingOptions) -> bool {
    let half = ShootingOptions {
        symmetric: true,
        ..opts.clone()
    };
    let Some(image) = period_image(model, x, &half) else {
        return false;
    };
    let n = x.len() / 2;
    let w = model.forcing_frequency().unwrap_or(1.0);
    image.iter().zip(x).enumerate().all(|(k, (g, x))| {
        let scale = opts.displacement_scale * if k < n { 1.0 } else { w };
        (g - x).abs() <= 100.0 * opts.tol * scale
    })
}

/// A start on the period-2n branch that emanates from a period-doubling
/// point: shoots the 2nT map from `x* ± ε v` (v the eigenvector of the
/// multiplier nearest -1) at parameters just beyond and before the point,
/// and returns the first genuinely period-2n solution `(p, x)`.
pub fn period_doubled_start<F>(
    mut family: F,
    point: &SpecialPoint,
    opts: &ContinuationOptions,
) -> Result<(f64, Vec<f64>), ContinuationError>
where
    F: Family + Send,
{
    let model = family.model_at(point.parameter)?;
    let map = period_map(&model, &point.state, &opts.shooting)?;
    let d = point.state.len();
    // Null vector of Φ + I.
    let v = null_vector(&map.monodromy + DMatrix::<f64>::identity(d, d))?;
    let mut doubled = opts.shooting.clone();
    doubled.subharmonic = opts.shooting.subharmonic * 2;
    let scale = doubled.displacement_scale;
    for dp in [1e-3, -1e-3, 1e-2, -1e-2] {
        let p = point.parameter * (1.0 + dp);
        let model = family.model_at(p)?;
        for eps in [0.05, -0.05, 0.2, -0.2] {
            let guess: Vec<f64> = point
                .state
                .iter()
                .zip(&v)
                .map(|(x, v)| x + eps * scale * v * (d as f64).sqrt())
                .collect();
            let Ok(sol) = shoot(&model, &guess, &doubled) else {
                continue;
            };
            if !sol.converged {
                continue;
            }
            // Genuinely period-2n: the nT map does not fix it.
            let single = period_map(&model, &sol.initial_state, &opts.shooting)?;
            let gap = single
                .image
                .iter()
                .zip(&sol.initial_state)
                .map(|(a, b)| (a - b).abs() / scale)
                .fold(0.0, f64::max);
            if gap > 1e3 * opts.shooting.tol {
                return Ok((p, sol.initial_state));
            }
        }
    }
    Err(ContinuationError::Invalid(format!(
        "no period-{} solution found next to the period doubling at {}",
        2 * opts.shooting.subharmonic,
        point.parameter
    )))
}

/// Unit right null vector of a square matrix ([`crate::linalg::null_vector`]).
fn null_vector(m: DMatrix<f64>) -> Result<Vec<f64>, ContinuationError> {
    crate::linalg::null_vector(m).ok_or_else(|| ContinuationError::Invalid("SVD failed".into()))
}

/// A start on the other branch through a branch point. At a
/// symmetry-breaking point the direction is the eigenvector of the half
/// map's Jacobian for the eigenvalue -1 (the asymmetric mode) and a
/// corrected point that is still symmetric is refused; otherwise it is the
/// direction of the 2-D null space of `[Φ - I, G_p]` orthogonal to the
/// branch tangent. Steps `step` (then a quarter and 2.5 times it) both ways
/// and corrects in the full period map. `range`: the start and end values
/// of the branch `point` lies on, in that order (they set the parameter's
/// scale its tangent is in).
/// Returns `(p, x)`; the side of the point it lands on is not guaranteed:
/// continue both ways if needed.
pub fn branch_switch_start<F>(
    mut family: F,
    point: &SpecialPoint,
    range: (f64, f64),
    opts: &ContinuationOptions,
    step: f64,
) -> Result<(f64, Vec<f64>), ContinuationError>
where
    F: Family + Send,
{
    let model = family.model_at(point.parameter)?;
    // The predictor off the branch is poorer than along it: a larger
    // corrector budget, in the full period map (the crossing branch of a
    // symmetry-breaking point is asymmetric).
    let opts = &ContinuationOptions {
        max_corrector: 4 * opts.max_corrector,
        shooting: ShootingOptions {
            symmetric: false,
            ..opts.shooting.clone()
        },
        ..opts.clone()
    };
    // The parameter's scale of the branch `point` lies on, in which its
    // tangent is stored. (The velocities' scale is Ω at the point, not at
    // the branch's start: docs/decisions.md D23.)
    let p_scale = parameter_scale(opts, range.0, range.1);
    let mut problem = Problem::new(&mut family, opts.clone(), &model, p_scale);
    let z = problem.scale_state(&point.state, point.parameter);
    let (v, constraint) = switch_directions(&mut problem, &model, point, &z)?;
    for h in [step, 0.25 * step, 2.5 * step] {
        for sign in [1.0, -1.0] {
            let pred: Vec<f64> = z.iter().zip(&v).map(|(a, b)| a + sign * h * b).collect();
            let Some((solved, _)) = problem.correct(&pred, &constraint, None) else {
                continue;
            };
            // A corrector that wandered off to some other branch far away.
            let jump = solved
                .z
                .iter()
                .zip(&pred)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            if jump > 5.0 * h {
                continue;
            }
            let (x, p) = problem.unscale(&solved.z);
            if point.symmetry_breaking {
                let model = problem.model(p)?;
                if is_symmetric_orbit(&model, &x, &opts.shooting) {
                    continue; // back on the symmetric branch
                }
            }
            return Ok((p, x));
        }
    }
    Err(ContinuationError::Invalid(format!(
        "the corrector fails on the crossing branch at {}",
        point.parameter
    )))
}

/// The direction off the branch at a branch point and the constraint for
/// the corrector (see [`branch_switch_start`]), in scaled variables.
fn switch_directions<F: Family>(
    problem: &mut Problem<F>,
    model: &Model,
    point: &SpecialPoint,
    z: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), ContinuationError> {
    let (d, t) = (point.state.len(), &point.tangent);
    let mut directions: Vec<Vec<f64>> = Vec::new();
    if point.symmetry_breaking {
        let half = ShootingOptions {
            symmetric: true,
            ..problem.opts.shooting.clone()
        };
        let map = period_map(model, &point.state, &half)?;
        let v = null_vector(&map.monodromy + DMatrix::<f64>::identity(d, d))?;
        let unit = problem.state_unit;
        let mut dir: Vec<f64> = v
            .iter()
            .zip(&problem.scale)
            .map(|(a, s)| a / (s * unit))
            .collect();
        dir.push(0.0);
        directions.push(dir);
    } else {
        let Some(Linear::Dense { jac, .. }) = problem.residual(z, true).and_then(|r| r.linear)
        else {
            return Err(ContinuationError::Invalid(
                "cannot evaluate the branch point (branch switching needs the dense Jacobian: \
                 continue without krylov)"
                    .into(),
            ));
        };
        // The two eigenvectors of JᵀJ of the smallest eigenvalues span the
        // null space of the d × (d+1) Jacobian at a simple branch point.
        let eig = (jac.transpose() * &jac).symmetric_eigen();
        let mut idx: Vec<usize> = (0..=d).collect();
        idx.sort_by(|&a, &b| {
            eig.eigenvalues[a]
                .abs()
                .total_cmp(&eig.eigenvalues[b].abs())
        });
        directions.extend(
            idx.iter()
                .take(2)
                .map(|&i| eig.eigenvectors.column(i).iter().copied().collect()),
        );
    }
    // Predictor along the null vector v; constraint along its part
    // orthogonal to the tangent, which the old branch satisfies to first
    // order with zero: the corrector cannot fall back onto it nearby.
    let mut found = None;
    for v in &directions {
        let vn = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let v: Vec<f64> = v.iter().map(|a| a / vn).collect();
        let proj: f64 = v.iter().zip(t).map(|(a, b)| a * b).sum();
        let o: Vec<f64> = v.iter().zip(t).map(|(a, b)| a - proj * b).collect();
        let n = o.iter().map(|a| a * a).sum::<f64>().sqrt();
        if n > 1e-3 {
            found = Some((v, o.iter().map(|a| a / n).collect::<Vec<f64>>()));
            break;
        }
    }
    found
        .ok_or_else(|| ContinuationError::Invalid("no second direction at the branch point".into()))
}

/// Why a branch switch could not start: the special point's label and
/// why (each face spells the option before it: `--switch-at BP9: …`,
/// `switch_at = 'BP9': …`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("switch at {label}: {message}")]
pub struct SwitchError {
    /// The label asked for.
    pub label: String,
    /// Why the switch could not start.
    pub message: String,
}

/// The branch through special point `label` of `branch` (a branch point's
/// crossing branch or a period doubling's period-2n branch), continued
/// within `range` (the main branch's start and end values, in that order:
/// they set the parameter's scale of its stored tangents), away from the
/// special point.
pub fn switch_branch<F, C>(
    mut family: F,
    branch: &Branch,
    label: &str,
    range: (f64, f64),
    opts: &ContinuationOptions,
    progress: C,
) -> Result<Branch, SwitchError>
where
    F: Family + Send,
    C: FnMut(&BranchPoint) -> bool,
{
    let sp = branch
        .special
        .iter()
        .find(|s| s.label == label)
        .ok_or_else(|| SwitchError {
            label: label.to_string(),
            message: format!(
                "no such special point on the branch (found: {})",
                branch
                    .special
                    .iter()
                    .map(|s| s.label.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })?;
    let fail = |e: ContinuationError| SwitchError {
        label: label.to_string(),
        message: format!("{e} (the main branch is kept)"),
    };
    let sub = opts.shooting.subharmonic;
    let (p1, x1, sub) = match sp.kind {
        SpecialKind::PeriodDoubling => {
            let (p, x) = period_doubled_start(&mut family, sp, opts).map_err(fail)?;
            (p, x, sub * 2)
        }
        SpecialKind::BranchPoint => {
            let (p, x) = branch_switch_start(&mut family, sp, range, opts, 0.02).map_err(fail)?;
            (p, x, sub)
        }
        other => {
            return Err(SwitchError {
                label: label.to_string(),
                message: format!("cannot switch at a {} point (only BP and PD)", other.name()),
            })
        }
    };
    let switched_opts = ContinuationOptions {
        shooting: ShootingOptions {
            subharmonic: sub,
            ..opts.shooting.clone()
        },
        bounds: Some(range),
        ..opts.clone()
    };
    // Onward from the start, away from the special point (the branch stays
    // within the range).
    let (lo, hi) = (range.0.min(range.1), range.0.max(range.1));
    let target = if p1 >= sp.parameter { hi } else { lo };
    continue_branch(family, p1, &x1, target, &switched_opts, progress).map_err(fail)
}
