//! A growable set of small indices, one bit each: the live sets of the
//! liveness dataflow, whose members are interned places (dense indices), so
//! that joining, copying and comparing sets in the fixpoint loop is word
//! arithmetic instead of hashing.

/// Indices `0..` as bits; grows on insert. Sets are equal when they hold
/// the same indices, whatever their capacity.
#[derive(Debug, Default)]
pub(crate) struct BitSet(Vec<u64>);

impl Clone for BitSet {
    fn clone(&self) -> BitSet {
        BitSet(self.0.clone())
    }

    /// Reuses this set's words (the fixpoint copies sets in a loop).
    fn clone_from(&mut self, source: &BitSet) {
        self.0.clone_from(&source.0);
    }
}

impl BitSet {
    /// Adds `i`; whether it was absent.
    #[inline]
    pub fn insert(&mut self, i: u32) -> bool {
        let (w, b) = (i as usize / 64, i % 64);
        if w >= self.0.len() {
            self.0.resize(w + 1, 0);
        }
        let had = self.0[w] >> b & 1 == 1;
        self.0[w] |= 1 << b;
        !had
    }

    /// Removes `i`; whether it was present.
    #[inline]
    pub fn remove(&mut self, i: u32) -> bool {
        let (w, b) = (i as usize / 64, i % 64);
        match self.0.get_mut(w) {
            Some(word) if *word >> b & 1 == 1 => {
                *word &= !(1 << b);
                true
            }
            _ => false,
        }
    }

    #[inline]
    pub fn contains(&self, i: u32) -> bool {
        self.0
            .get(i as usize / 64)
            .is_some_and(|w| w >> (i % 64) & 1 == 1)
    }

    /// Makes room for the indices below `n` at once (the words a set
    /// would otherwise grow one insert or union at a time).
    #[inline]
    pub fn reserve_indices(&mut self, n: u32) {
        let words = (n as usize).div_ceil(64);
        if words > self.0.len() {
            self.0.resize(words, 0);
        }
    }

    /// Removes every index, keeping the words for reuse.
    #[inline]
    pub fn clear(&mut self) {
        self.0.fill(0);
    }

    /// The words, lowest indices first (flat tables of sets copy them).
    #[inline]
    pub fn words(&self) -> &[u64] {
        &self.0
    }

    /// Adds every index of a set given as its words.
    #[inline]
    pub fn union_words(&mut self, words: &[u64]) {
        if words.len() > self.0.len() {
            self.0.resize(words.len(), 0);
        }
        for (a, b) in self.0.iter_mut().zip(words) {
            *a |= b;
        }
    }

    /// Whether this set holds exactly the indices of a set given as its
    /// words (as `==`).
    #[inline]
    pub fn same_words(&self, words: &[u64]) -> bool {
        let (short, long) = if self.0.len() <= words.len() {
            (&self.0[..], words)
        } else {
            (words, &self.0[..])
        };
        short.iter().zip(long.iter()).all(|(a, b)| a == b)
            && long[short.len()..].iter().all(|&w| w == 0)
    }

    /// The indices, smallest first.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.0.iter().enumerate().flat_map(|(w, &word)| {
            let mut rest = word;
            std::iter::from_fn(move || {
                if rest == 0 {
                    return None;
                }
                let b = rest.trailing_zeros();
                rest &= rest - 1;
                Some(w as u32 * 64 + b)
            })
        })
    }
}

impl PartialEq for BitSet {
    fn eq(&self, other: &BitSet) -> bool {
        let (short, long) = if self.0.len() <= other.0.len() {
            (&self.0, &other.0)
        } else {
            (&other.0, &self.0)
        };
        // Word by word: the sets are a few words long, and the fixpoint
        // compares them at every visit (a `memcmp` call each was slower).
        short.iter().zip(long.iter()).all(|(a, b)| a == b)
            && long[short.len()..].iter().all(|&w| w == 0)
    }
}

impl Eq for BitSet {}

#[cfg(test)]
mod tests {
    use super::BitSet;

    #[test]
    fn insert_remove_contains() {
        let mut s = BitSet::default();
        assert!(!s.contains(5));
        assert!(s.insert(5));
        assert!(!s.insert(5), "second insert finds it there");
        assert!(s.insert(200));
        assert!(s.contains(5) && s.contains(200) && !s.contains(6) && !s.contains(1000));
        assert!(s.remove(5));
        assert!(!s.remove(5));
        assert!(!s.remove(10_000), "far beyond the capacity: absent");
        assert_eq!(s.iter().collect::<Vec<_>>(), [200]);
    }

    #[test]
    fn iterates_in_order_across_words() {
        let mut s = BitSet::default();
        for i in [130, 0, 63, 64, 1, 127] {
            s.insert(i);
        }
        assert_eq!(s.iter().collect::<Vec<_>>(), [0, 1, 63, 64, 127, 130]);
    }

    #[test]
    fn equality_ignores_capacity() {
        let mut a = BitSet::default();
        let mut b = BitSet::default();
        a.insert(3);
        b.insert(3);
        b.insert(500);
        assert_ne!(a, b);
        b.remove(500);
        assert_eq!(a, b, "b has more words, all zero");
        assert_eq!(b, a);
        assert_eq!(BitSet::default(), b.clone().tap_clear());
    }

    #[test]
    fn reserve_keeps_members() {
        let mut a = BitSet::default();
        a.insert(5);
        a.reserve_indices(1000);
        assert_eq!(a.iter().collect::<Vec<_>>(), [5]);
        assert_eq!(a, {
            let mut b = BitSet::default();
            b.insert(5);
            b
        });
        assert!(a.insert(999) && a.contains(999));
    }

    #[test]
    fn clear() {
        let mut a = BitSet::default();
        a.insert(3);
        a.insert(700);
        a.clear();
        assert_eq!(a.iter().count(), 0);
        assert_eq!(a, BitSet::default());
        assert!(a.insert(700), "absent after clearing");
    }

    #[test]
    fn union() {
        let mut a = BitSet::default();
        a.insert(1);
        let mut b = BitSet::default();
        b.insert(2);
        b.insert(300);
        a.union_words(b.words());
        assert_eq!(a.iter().collect::<Vec<_>>(), [1, 2, 300]);
        let mut c = b.clone();
        c.union_words(BitSet::default().words());
        assert_eq!(c, b);
        // Sets given as words compare as sets do, whatever their length.
        assert!(b.same_words(c.words()) && !a.same_words(b.words()));
        assert!(c.same_words(&[4, 0, 0, 0, 1 << 44, 0]) && !c.same_words(&[4]));
        let mut d = BitSet::default();
        d.insert(900);
        d.clone_from(&a);
        assert_eq!(d, a, "clone_from replaces, not merges");
    }

    impl BitSet {
        fn tap_clear(mut self) -> BitSet {
            let all: Vec<u32> = self.iter().collect();
            for i in all {
                self.remove(i);
            }
            self
        }
    }
}
