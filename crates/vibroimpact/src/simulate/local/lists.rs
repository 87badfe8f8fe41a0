//! Lists per group in one flat array (the items of group g are
//! `items[start[g]..start[g + 1]]`): a row of a thousand bodies sets up
//! its groups' contacts without an allocation per group.

use std::ops::Index;

/// Per group, a list of model indices (ascending within each group, as
/// given).
#[derive(Clone, Debug, Default)]
pub(super) struct Lists {
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Lists {
    /// The lists of `groups` groups from `(group, item)` pairs in item order
    /// (a pair equal to the one before it is dropped: an item whose two
    /// sides lie in one group is listed once).
    pub(super) fn new(groups: usize, pairs: impl Iterator<Item = (usize, usize)> + Clone) -> Self {
        // (No items, as a row without couplings has: every list empty.)
        if pairs.clone().next().is_none() {
            return Self::default();
        }
        let mut start = vec![0; groups + 1];
        let mut last = None;
        for p in pairs.clone() {
            if last != Some(p) {
                start[p.0 + 1] += 1;
            }
            last = Some(p);
        }
        for g in 0..groups {
            start[g + 1] += start[g];
        }
        let mut next = start.clone();
        let mut items = vec![0; start[groups]];
        let mut last = None;
        for p in pairs {
            if last != Some(p) {
                items[next[p.0]] = p.1;
                next[p.0] += 1;
            }
            last = Some(p);
        }
        Self { start, items }
    }
}

impl Index<usize> for Lists {
    type Output = [usize];

    fn index(&self, g: usize) -> &[usize] {
        if self.start.is_empty() {
            return &[];
        }
        &self.items[self.start[g]..self.start[g + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_group_lists_its_items_in_order_once() {
        let pairs = [(1, 0), (0, 0), (1, 1), (1, 1), (2, 3), (0, 4)];
        let l = Lists::new(4, pairs.iter().copied());
        assert_eq!(&l[0], &[0, 4]);
        assert_eq!(&l[1], &[0, 1]);
        assert_eq!(&l[2], &[3]);
        assert!(l[3].is_empty());
        let none = Lists::new(4, std::iter::empty());
        assert!((0..4).all(|g| none[g].is_empty()));
    }
}
