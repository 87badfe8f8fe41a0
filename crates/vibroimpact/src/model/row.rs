//! A row of identical bodies between walls: the model file's `[row]` and
//! the seed's row (reference problem R2, docs/theory.md §6).

use super::*;

impl Model {
    /// The seed's row (reference problem R2): `count` identical bodies named
    /// `p1..pN` between two walls, every clearance `clearance`, one law.
    #[allow(clippy::too_many_arguments)]
    pub fn row(
        count: usize,
        mass: f64,
        stiffness: f64,
        damping: f64,
        clearance: f64,
        law: ContactLaw,
        walls: (bool, bool),
        base: BaseExcitation,
    ) -> Result<Self, ModelError> {
        if count == 0 {
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                "row.count",
                "row: count must be >= 1",
            ));
        }
        let bodies = (1..=count)
            .map(|i| Body {
                name: format!("p{i}"),
                mass,
                stiffness,
                damping,
            })
            .collect();
        let mut contacts = Vec::with_capacity(count + 1);
        if walls.0 {
            contacts.push(Contact {
                pair: ContactPair::LeftWall { body: 0 },
                clearance,
                law,
            });
        }
        for i in 0..count - 1 {
            contacts.push(Contact {
                pair: ContactPair::Bodies {
                    left: i,
                    right: i + 1,
                },
                clearance,
                law,
            });
        }
        if walls.1 {
            contacts.push(Contact {
                pair: ContactPair::RightWall { body: count - 1 },
                clearance,
                law,
            });
        }
        Self::new(
            bodies,
            Vec::new(),
            contacts,
            base,
            Vec::new(),
            Vec::new(),
            Vec::new(),
        )
    }
}
