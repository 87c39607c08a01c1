//! Which of the last [`WINDOW`] sequence numbers of one frame type were received: a fixed bitmap,
//! so that a number behind the newest can be told a duplicate (received) from a late frame (not
//! received yet) without allocating.

/// Numbers tracked behind (and including) the newest one.
pub const WINDOW: u64 = 1024;

const WORDS: usize = (WINDOW / 64) as usize;

/// Bit `i` is set when the number `newest − i` was received (bit 0 is the newest itself).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReceivedWindow {
    bits: [u64; WORDS],
}

impl ReceivedWindow {
    /// A window holding only the newest number: what came before it is not known.
    pub fn newest_only() -> Self {
        let mut w = Self::default();
        w.bits[0] = 1;
        w
    }

    /// The newest number moves `k` ≥ 1 forward and is received: every bit moves `k` places up,
    /// those beyond the window fall out.
    pub fn advance(&mut self, k: u64) {
        if k >= WINDOW {
            *self = Self::newest_only();
            return;
        }
        // Both fit: k < WINDOW.
        let words = (k / 64) as usize;
        let bits = (k % 64) as u32;
        for i in (0..WORDS).rev() {
            let low = i.checked_sub(words).map_or(0, |j| self.bits[j]);
            let carry = match i.checked_sub(words + 1) {
                Some(j) if bits > 0 => self.bits[j] >> (64 - bits),
                _ => 0,
            };
            self.bits[i] = (low << bits) | carry;
        }
        self.bits[0] |= 1;
    }

    /// Whether the number `behind` places behind the newest was received; `false` beyond the window.
    pub fn received(&self, behind: u64) -> bool {
        behind < WINDOW && {
            let (word, bit) = ((behind / 64) as usize, behind % 64);
            self.bits[word] & (1 << bit) != 0
        }
    }

    /// Marks the number `behind` places behind the newest as received (nothing beyond the window).
    pub fn mark(&mut self, behind: u64) {
        if behind < WINDOW {
            let (word, bit) = ((behind / 64) as usize, behind % 64);
            self.bits[word] |= 1 << bit;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_move_with_the_newest_across_words() {
        let mut w = ReceivedWindow::newest_only();
        w.mark(3);
        w.advance(62); // newest was 0 places behind, now 62; 3 behind is now 65
        assert!(w.received(0) && w.received(62) && w.received(65));
        assert!(!w.received(1) && !w.received(63) && !w.received(64));
        w.advance(WINDOW - 66); // 65 → 1023: the last bit of the window
        assert!(w.received(WINDOW - 1));
        w.advance(1);
        assert!(!w.received(WINDOW - 1) && !w.received(WINDOW));
        assert!(w.received(0) && w.received(1));
        w.advance(WINDOW);
        assert_eq!(w, ReceivedWindow::newest_only());
    }

    #[test]
    fn marks_beyond_the_window_are_ignored() {
        let mut w = ReceivedWindow::newest_only();
        w.mark(WINDOW);
        w.mark(u64::MAX);
        assert_eq!(w, ReceivedWindow::newest_only());
    }
}
