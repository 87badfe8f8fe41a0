//! A rigid contact's soft episodes (docs/theory.md §12): where the rigid
//! idealisation breaks (impacts that overlap, a resting contact) the run
//! integrates the contact's own law until the bodies separate, then takes
//! its impacts as jumps again.

use super::{ChainDynamics, Screen};

impl Screen {
    /// The screen's (α, b/a, limit) in the screening arrays: skip where
    /// `α s + (b/a)|ṡ| < limit`.
    pub(super) fn parts(self) -> (f64, f64, f64) {
        match self {
            Screen::Exponential {
                alpha,
                b_over_a,
                limit,
            } => (alpha, b_over_a, limit),
            Screen::CompactSupport => (1.0, 0.0, 0.0),
            Screen::Never => (0.0, 0.0, f64::INFINITY),
        }
    }
}

impl ChainDynamics {
    /// Starts (`on`) or ends contact k's soft episode: its law evaluated
    /// in the right-hand side, or skipped again. A contact without rigid
    /// impacts is left as it is.
    pub fn set_soft_episode(&mut self, k: usize, on: bool) {
        let c = &mut self.contacts[k];
        if c.rigid.is_none() {
            return;
        }
        (c.screen, c.absurd) = if on {
            c.soft
        } else {
            (Screen::Never, f64::INFINITY)
        };
        let (alpha, boa, limit) = c.screen.parts();
        let test = &mut self.screen.test[k];
        (test[1], test[2], test[3]) = (alpha, boa, limit);
    }

    /// Whether rigid contact k is in a soft episode.
    pub fn in_soft_episode(&self, k: usize) -> bool {
        let c = &self.contacts[k];
        c.rigid.is_some() && !matches!(c.screen, Screen::Never)
    }
}
