//! `continue` on a model file: a [`BranchStudy`] in one of its keys and,
//! with a second key, the curves of the branch's special points in both
//! keys. The command line, Python and the report run this one study and
//! differ only in how they spell its settings and write its results.

use super::study::{BranchOutcome, BranchStudy, CheckedBranch, StudyError, StudyField};
use super::{curves_of_branch, BranchOrigin, BranchPoint, CurveSelection, Curves, SpecialPoint};
use crate::model::family::ParameterizedModel2;
use crate::model::file::ModelDocument;
use crate::model::parameter::ParameterizedModel;
use crate::periodic::ShootingOptions;

/// What the curves need of a branch, as read back from its document: its
/// special points, whether the branch is on the half map, and its period
/// multiple.
#[derive(Clone, Debug)]
pub struct BranchSpecialPoints {
    /// The special points (their states and parameters).
    pub special: Vec<SpecialPoint>,
    /// On the half map.
    pub symmetric: bool,
    /// Its period multiple.
    pub subharmonic: u32,
}

/// The curves a [`ContinueStudy`] follows after its branch.
#[derive(Clone, Debug)]
pub struct CurvesRequest {
    /// The second parameter (an alias or a dotted key of the model file).
    pub parameter2: String,
    /// Which curves, their step and the second parameter's bounds.
    pub selection: CurveSelection,
}

/// A branch of a model file in `parameter`, with the curves of its
/// special points when `curves` is given.
#[derive(Clone, Debug)]
pub struct ContinueStudy {
    /// The parameter (an alias or a dotted key).
    pub parameter: String,
    /// The branch: range, start, switch, linear algebra, options.
    pub branch: BranchStudy,
    /// The curves in a second parameter.
    pub curves: Option<CurvesRequest>,
}

/// A [`ContinueStudy`] whose checks passed.
#[derive(Clone, Debug)]
pub struct CheckedContinue {
    /// The branch study on the file's family.
    pub branch: CheckedBranch<ParameterizedModel>,
    /// The curves' plane (the parameter and the second one) and selection.
    pub plane: Option<(ParameterizedModel2, CurveSelection)>,
}

/// What a [`ContinueStudy`] computed.
#[derive(Debug)]
pub struct ContinueOutcome {
    /// The parameter's name as given.
    pub parameter: String,
    /// The branch (and the switched branch).
    pub branch: BranchOutcome,
    /// The curves with the second parameter's name, when asked for.
    pub curves: Option<(Curves, String)>,
}

impl ContinueStudy {
    /// The study on `document` after the branch study's checks and the
    /// curves' (the second parameter another key, the selection valid).
    pub fn check(self, document: ModelDocument) -> Result<CheckedContinue, StudyError> {
        let family = ParameterizedModel::new(document, &self.parameter)?;
        let plane = match self.curves {
            None => None,
            Some(request) => {
                let q = family.document().parameter(&request.parameter2)?;
                if q.key == family.parameter().key {
                    return Err(StudyError::Invalid {
                        field: StudyField::Parameter2,
                        message: format!(
                            "the same key as the parameter {}; give another",
                            family.parameter().name
                        ),
                    });
                }
                request.selection.check().map_err(StudyError::Field)?;
                let plane = ParameterizedModel2 {
                    document: family.document().clone(),
                    p: family.parameter().clone(),
                    q,
                };
                Some((plane, request.selection))
            }
        };
        Ok(CheckedContinue {
            branch: self.branch.check(family)?,
            plane,
        })
    }
}

impl CheckedContinue {
    /// The study's range.
    fn range(&self) -> (f64, f64) {
        (self.branch.study.from, self.branch.study.to)
    }

    /// Runs the branch (`on_point` sees every point and returns false to
    /// stop), then the curves through its special points.
    pub fn run(
        self,
        on_point: impl FnMut(&BranchPoint) -> bool,
    ) -> Result<ContinueOutcome, StudyError> {
        let range = self.range();
        let parameter = self.branch.family.parameter().name.clone();
        let branch = self.branch.run(on_point)?;
        let curves = match self.plane {
            None => None,
            Some((plane, selection)) => {
                let origin = BranchOrigin {
                    special: &branch.branch.special,
                    symmetric: branch.branch.symmetric,
                    range,
                    q0: plane.q.initial,
                };
                let linear = (&branch.options.shooting, branch.options.krylov);
                let name = plane.q.name.clone();
                Some((curves_of_branch(plane, origin, &selection, linear)?, name))
            }
        };
        Ok(ContinueOutcome {
            parameter,
            branch,
            curves,
        })
    }

    /// The curves through the special points of an earlier branch
    /// document (`read`), without computing the branch again.
    pub fn curves_from(self, read: &BranchSpecialPoints) -> Result<Curves, StudyError> {
        let range = self.range();
        let Some((plane, selection)) = self.plane else {
            return Err(StudyError::Invalid {
                field: StudyField::SpecialPoints,
                message: "needs the curves' second parameter too".into(),
            });
        };
        let options = self.branch.options;
        let shooting = ShootingOptions {
            subharmonic: read.subharmonic,
            ..options.shooting
        };
        let origin = BranchOrigin {
            special: &read.special,
            symmetric: read.symmetric,
            range,
            q0: plane.q.initial,
        };
        Ok(curves_of_branch(
            plane,
            origin,
            &selection,
            (&shooting, options.krylov),
        )?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::{Start, StudyField};
    use crate::model::reference;

    const ROW: &str = include_str!("../../../../examples/fujita-row-n2.toml");

    fn study(parameter2: Option<&str>) -> ContinueStudy {
        ContinueStudy {
            parameter: "frequency".into(),
            branch: BranchStudy {
                from: 7.0,
                to: 7.5,
                start: Start::Auto,
                guess_periods: 200.0,
                switch_at: None,
                linear: Default::default(),
                arnoldi: 20,
                options: Default::default(),
            },
            curves: parameter2.map(|q| CurvesRequest {
                parameter2: q.into(),
                selection: CurveSelection::default(),
            }),
        }
    }

    fn field(e: StudyError) -> StudyField {
        match e {
            StudyError::Invalid { field, .. } => field,
            other => panic!("{other}"),
        }
    }

    /// The curves' checks: the second parameter another key, and special
    /// points only with a second parameter.
    #[test]
    fn the_curves_settings_are_checked() {
        let doc = || ModelDocument::from_toml(ROW, "row.toml").unwrap();
        let same = study(Some("excitation.frequency"))
            .check(doc())
            .unwrap_err();
        assert_eq!(field(same), StudyField::Parameter2);
        let unknown = study(Some("no.such.key")).check(doc()).unwrap_err();
        assert!(matches!(unknown, StudyError::File(_)), "{unknown}");
        let read = BranchSpecialPoints {
            special: Vec::new(),
            symmetric: false,
            subharmonic: 1,
        };
        let alone = study(None).check(doc()).unwrap().curves_from(&read);
        assert_eq!(field(alone.unwrap_err()), StudyField::SpecialPoints);
        let mut bad_step = study(Some("amplitude"));
        bad_step.curves.as_mut().unwrap().selection.step = 0.0;
        let e = bad_step.check(doc()).unwrap_err();
        assert!(
            matches!(&e, StudyError::Field(f) if f.field == "curve_step"),
            "{e}"
        );
    }

    /// A model built in code cannot vary its amplitude alone: the
    /// homotopy start is refused by name, before any work.
    #[test]
    fn a_family_built_in_code_has_no_homotopy_start() {
        let family =
            crate::model::family::of("frequency", |w| reference::r2(2, reference::CLEARANCE, w));
        let branch = BranchStudy {
            start: Start::Homotopy,
            ..study(None).branch
        };
        let e = branch.check(family).unwrap().run(|_| true).unwrap_err();
        assert_eq!(field(e), StudyField::Start);
    }
    /// R2 N = 2 at 0.55 ω0: the 200-period guess has not settled onto a
    /// period-1 orbit (at 0.5 ω0 and rtol 1e-9 Newton from such a guess
    /// stalled after 23 variational period maps), so `auto` starts from the
    /// homotopy at once, on the same branch as `homotopy`, point for point.
    /// At 1.5 ω0 the guess is still settling slowly onto a period-1 orbit
    /// (differences 6e-6 a period): Newton starts from it. (From 0.5 to
    /// 0.85 ω0 the motion is chaotic for long, and whether a 200-period
    /// transient ends near a period-1 orbit changes with the tolerance.)
    #[test]
    fn an_unsettled_guess_starts_from_the_homotopy_at_once() {
        let doc = || ModelDocument::from_toml(ROW, "row.toml").unwrap();
        let family = crate::model::parameter::ParameterizedModel::new(doc(), "frequency").unwrap();
        let worth = |w: f64| {
            let model = family.model_at(w).unwrap();
            crate::periodic::settled_guess(&model, 200.0, super::super::study::GUESS_RTOL, None, 1)
                .unwrap()
                .1
        };
        assert!(!worth(4.0755));
        assert!(worth(11.115));
        let branch = |start| {
            let mut s = study(None);
            s.branch.from = 4.0755;
            s.branch.to = 4.2;
            s.branch.start = start;
            s.check(doc()).unwrap().run(|_| true).unwrap().branch.branch
        };
        let (auto, homotopy) = (branch(Start::Auto), branch(Start::Homotopy));
        assert_eq!(auto.points.len(), homotopy.points.len());
        for (a, h) in auto.points.iter().zip(&homotopy.points) {
            assert_eq!((a.parameter, &a.state), (h.parameter, &h.state));
        }
    }
}
