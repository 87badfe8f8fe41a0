//! How a contact's impacts are modelled (docs/theory.md §12): through its
//! soft law, integrated, or in the rigid limit as instantaneous velocity
//! jumps with the law's e(U) or a Newton coefficient.

use std::sync::{Arc, OnceLock};

use super::{Model, ModelError, ModelErrorKind};
use crate::field_error::{shown, FieldError};
use crate::impact::rigid::RigidLaw;

/// The rigid limits of a model's contacts, like contacts sharing one
/// ([`Model::rigid_limits`]).
#[derive(Clone, Debug)]
pub struct RigidLimits {
    /// The distinct limits.
    laws: Vec<RigidLaw>,
    /// Each contact's limit in `laws` (None: soft impacts).
    of: Vec<Option<usize>>,
}

impl RigidLimits {
    /// Contact `k`'s rigid limit (None: soft impacts, or no such contact).
    pub fn get(&self, k: usize) -> Option<&RigidLaw> {
        self.of.get(k).copied().flatten().map(|i| &self.laws[i])
    }
}

/// The contacts' shared rigid limits ([`Model::rigid_laws`]), built once
/// for a model and its clones: a reforced model (another base, the same
/// limits) shares them, so a branch's period maps do not build them
/// again for each model. Set again wherever the contacts' laws or
/// impacts change; not part of what a model is (equal whatever it holds).
#[derive(Clone, Default)]
pub(super) struct SharedLaws(Arc<OnceLock<Vec<Option<Arc<RigidLaw>>>>>);

impl PartialEq for SharedLaws {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for SharedLaws {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SharedLaws")
    }
}

/// A contact's impacts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Impacts {
    /// The soft law, integrated through every contact (the default).
    #[default]
    Soft,
    /// Velocity jumps where the approach reaches zero, with the law's
    /// e(U), or with this Newton coefficient in (0, 1].
    Rigid {
        /// A constant coefficient of restitution in place of the law's.
        restitution: Option<f64>,
    },
}

impl Impacts {
    /// From its name, `soft` or `rigid`, and an optional Newton
    /// coefficient (rigid impacts only).
    pub fn parse(name: &str, restitution: Option<f64>) -> Result<Self, String> {
        match (name, restitution) {
            ("soft", None) => Ok(Impacts::Soft),
            ("soft", Some(e)) => Err(format!(
                "restitution = {e}: a coefficient of restitution is for rigid impacts (impacts = \"rigid\"); a soft contact's comes from its law"
            )),
            ("rigid", restitution) => Ok(Impacts::Rigid { restitution }),
            (other, _) => Err(format!("impacts = \"{other}\": must be soft or rigid")),
        }
    }

    /// `soft` or `rigid`.
    pub fn name(&self) -> &'static str {
        match self {
            Impacts::Soft => "soft",
            Impacts::Rigid { .. } => "rigid",
        }
    }

    /// Whether these are rigid impacts.
    pub fn is_rigid(&self) -> bool {
        matches!(self, Impacts::Rigid { .. })
    }
}

impl Model {
    /// Contact `k`'s impacts.
    pub fn impacts(&self, k: usize) -> Impacts {
        self.impacts[k]
    }

    /// Whether any contact's impacts are rigid.
    pub fn has_rigid_impacts(&self) -> bool {
        self.impacts.iter().any(Impacts::is_rigid)
    }

    /// Contact `k`'s rigid limit (None for soft impacts): its law's e(U)
    /// between the pair's reduced mass, or its Newton coefficient.
    pub fn rigid_law(&self, k: usize) -> Result<Option<RigidLaw>, ModelError> {
        let Impacts::Rigid { restitution } = self.impacts[k] else {
            return Ok(None);
        };
        self.built_rigid_law(k, self.reduced_mass(k), restitution)
    }

    /// Every contact's [`Model::rigid_law`], in contact order. A contact
    /// with the law, reduced mass and coefficient of the rigid one before
    /// shares its limit: a row of a thousand like pairs builds one.
    pub fn rigid_limits(&self) -> Result<RigidLimits, ModelError> {
        let mut limits = RigidLimits {
            laws: Vec::new(),
            of: Vec::with_capacity(self.contacts.len()),
        };
        let mut last: Option<(usize, f64, Option<f64>)> = None;
        for k in 0..self.contacts.len() {
            let Impacts::Rigid { restitution } = self.impacts[k] else {
                limits.of.push(None);
                continue;
            };
            let mu = self.reduced_mass(k);
            let same = last.filter(|&(j, m, e)| {
                self.contacts[j].law == self.contacts[k].law && m == mu && e == restitution
            });
            let index = match same {
                Some((j, ..)) => limits.of[j],
                None => self.built_rigid_law(k, mu, restitution)?.map(|law| {
                    limits.laws.push(law);
                    limits.laws.len() - 1
                }),
            };
            last = Some((k, mu, restitution));
            limits.of.push(index);
        }
        Ok(limits)
    }

    /// [`Model::rigid_limits`] as one shared limit per contact, built
    /// once for the model and its clones.
    pub fn rigid_laws(&self) -> Result<Vec<Option<Arc<RigidLaw>>>, ModelError> {
        if let Some(laws) = self.rigid.0.get() {
            return Ok(laws.clone());
        }
        let limits = self.rigid_limits()?;
        let laws: Vec<Arc<RigidLaw>> = limits.laws.into_iter().map(Arc::new).collect();
        let of: Vec<_> = limits
            .of
            .iter()
            .map(|i| i.map(|i| laws[i].clone()))
            .collect();
        Ok(self.rigid.0.get_or_init(|| of).clone())
    }

    /// Contact `k`'s reduced mass (a wall's side infinite).
    fn reduced_mass(&self, k: usize) -> f64 {
        let c = &self.contacts[k];
        let masses = [c.pair.left(), c.pair.right()].map(|b| b.map(|i| self.bodies[i].mass));
        match masses {
            [Some(a), Some(b)] => a / (1.0 + a / b),
            [Some(m), None] | [None, Some(m)] => m,
            [None, None] => f64::INFINITY,
        }
    }

    /// Contact `k`'s rigid limit between the reduced mass `mu`.
    fn built_rigid_law(
        &self,
        k: usize,
        mu: f64,
        restitution: Option<f64>,
    ) -> Result<Option<RigidLaw>, ModelError> {
        let c = &self.contacts[k];
        RigidLaw::new(&c.law, mu, restitution)
            .map(Some)
            .map_err(|e| {
                ModelError::new(
                    ModelErrorKind::InvalidValue,
                    format!("contact.{}.impacts", self.contact_name(k)),
                    format!("contact {}: rigid impacts: {e}", self.contact_name(k)),
                )
            })
    }

    /// Contact `k`'s impacts set to `impacts`; a rigid limit the law does
    /// not have (or a coefficient outside (0, 1]) is refused, naming the
    /// contact.
    pub fn with_impacts(mut self, k: usize, impacts: Impacts) -> Result<Self, ModelError> {
        self.impacts[k] = impacts;
        self.rigid = SharedLaws::default();
        self.rigid_law(k)?;
        Ok(self)
    }

    /// Every contact's impacts set to `impacts`.
    pub fn with_all_impacts(mut self, impacts: Impacts) -> Result<Self, ModelError> {
        for k in 0..self.contacts.len() {
            self = self.with_impacts(k, impacts)?;
        }
        Ok(self)
    }

    /// Every contact's impacts as a face's options set them, over the
    /// model file's: `impacts` `soft` or `rigid` (None: the file's), and
    /// `restitution` a Newton coefficient for rigid impacts (alone: on the
    /// file's rigid contacts). A refusal names the option.
    pub fn with_impact_options(
        mut self,
        impacts: Option<&str>,
        restitution: Option<f64>,
    ) -> Result<Self, FieldError> {
        let field = if restitution.is_some() {
            "restitution"
        } else {
            "impacts"
        };
        let refused = |e: ModelError| FieldError::about(field, e.message);
        let rigid = Impacts::Rigid { restitution };
        match impacts {
            Some("rigid") => return self.with_all_impacts(rigid).map_err(refused),
            Some("soft") | None => {}
            Some(other) => {
                return Err(FieldError::new("impacts", other, "must be soft or rigid"));
            }
        }
        match (impacts, restitution) {
            (Some(_), None) => self.with_all_impacts(Impacts::Soft).map_err(refused),
            (None, None) => Ok(self),
            (None, Some(_)) if self.has_rigid_impacts() => {
                for k in 0..self.contacts.len() {
                    if self.impacts[k].is_rigid() {
                        self = self.with_impacts(k, rigid).map_err(refused)?;
                    }
                }
                Ok(self)
            }
            (_, Some(e)) => Err(FieldError::new(
                "restitution",
                shown(e),
                "a coefficient of restitution is for rigid impacts: set impacts to rigid",
            )),
        }
    }
}

impl crate::model::file::ModelDocument {
    /// The document with every contact's impacts as a face's options set
    /// them ([`Model::with_impact_options`], whose refusals, naming the
    /// option, it gives): the `impacts` and `restitution` keys of `[row]`
    /// and of every `[[contact]]` rewritten, so that every model the
    /// document builds (a sweep's, a branch's) has them.
    pub fn with_impact_options(
        mut self,
        impacts: Option<&str>,
        restitution: Option<f64>,
    ) -> Result<Self, FieldError> {
        if impacts.is_none() && restitution.is_none() {
            return Ok(self);
        }
        let model = self
            .build()
            .map_err(|e| FieldError::about("impacts", e.to_string()))?
            .model
            .with_impact_options(impacts, restitution)?;
        let file = &mut self.file;
        let row = file.row.iter_mut().map(|r| {
            let spec = r.get_mut();
            (&mut spec.impacts, &mut spec.restitution)
        });
        let tables = file.contact.iter_mut().map(|c| {
            let spec = c.get_mut();
            (&mut spec.impacts, &mut spec.restitution)
        });
        let rigid = model.has_rigid_impacts();
        for (name, e) in row.chain(tables) {
            match impacts {
                Some(chosen) => {
                    *name = Some(chosen.to_string());
                    *e = restitution;
                }
                // A coefficient alone: on the file's rigid contacts.
                None if rigid && name.as_deref() == Some("rigid") => *e = restitution,
                None => {}
            }
        }
        Ok(self)
    }
}
