//! Counting samples missing from a stream of increasing sequence numbers.

/// Counts the numbers missing from a sequence.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SeqGaps {
    last: Option<u64>,
    /// Sequence numbers skipped between consecutive observed samples.
    pub missing: u64,
    /// Samples that did not advance the sequence (repeats, or a source restarting from a lower number).
    pub out_of_order: u64,
}

impl SeqGaps {
    /// Takes sequence number `seq`, counting the numbers skipped since the last.
    pub fn observe(&mut self, seq: u64) {
        match self.last {
            Some(last) if seq > last => self.missing += seq - last - 1,
            Some(_) => self.out_of_order += 1,
            None => {}
        }
        if self.last.is_none_or(|last| seq > last) {
            self.last = Some(seq);
        }
    }

    /// The newest sequence number seen.
    pub fn last(&self) -> Option<u64> {
        self.last
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn counts_each_skipped_number() {
        let mut g = SeqGaps::default();
        for s in [5, 6, 9, 10, 10, 14] {
            g.observe(s);
        }
        assert_eq!(g.missing, 2 + 3);
        assert_eq!(g.out_of_order, 1);
        assert_eq!(g.last(), Some(14));
    }

    proptest! {
        #[test]
        fn missing_equals_span_minus_seen(mut seqs in proptest::collection::btree_set(0u64..10_000, 1..200)) {
            let v: Vec<u64> = std::mem::take(&mut seqs).into_iter().collect();
            let mut g = SeqGaps::default();
            for &s in &v { g.observe(s); }
            let span = v[v.len() - 1] - v[0] + 1;
            prop_assert_eq!(g.missing, span - v.len() as u64);
            prop_assert_eq!(g.out_of_order, 0);
        }
    }
}
