//! Where the end-to-end tail comes from: of the slowest 0.1 % of the samples (those beyond the
//! end-to-end p99.9), how long each hop of the data path took on average, and in how many of them each hop was the
//! longest. A tail carried by one hop points at the process that hop wakes (its wake-up and its
//! wait for a CPU); a tail spread over every hop points at the machine (a halted virtual CPU, a
//! burst of other work).

use ipc_types::{NavState, Stage};
use serde::Serialize;

/// The data path's hops whose sum is the end-to-end figure, as [`super::HOPS`] names them.
pub const TAIL_HOPS: [&str; 3] = [
    "serial rx -> acquisition published",
    "acquisition -> fusion published",
    "fusion -> navigator published",
];

/// The most samples a recorder keeps (a tool's buffer, reserved at once): 10 minutes at 1 kHz.
const MAX_SAMPLES: usize = 600_000;

/// One hop among the tail samples.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TailHop {
    /// Which hop.
    pub hop: &'static str,
    /// Its mean over the tail samples, µs.
    pub mean_us: f64,
    /// Tail samples in which it was the longest hop.
    pub dominant: u64,
}

/// The end-to-end tail (the slowest 0.1 % of the samples), hop by hop.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TailReport {
    /// The fastest end-to-end figure in the tail, µs.
    pub threshold_us: f64,
    /// Samples in the tail.
    pub samples: u64,
    /// Each hop of the path.
    pub hops: Vec<TailHop>,
}

/// Every sample's hops, kept for [`TailRecorder::report`].
#[derive(Debug)]
pub struct TailRecorder {
    samples: Vec<[u64; 3]>,
    limit: usize,
}

impl TailRecorder {
    /// Keeps up to `limit` samples (at most [`MAX_SAMPLES`]), room reserved at once; later ones
    /// are not kept.
    pub fn new(limit: usize) -> Self {
        let limit = limit.min(MAX_SAMPLES);
        Self {
            samples: Vec::with_capacity(limit),
            limit,
        }
    }

    /// One navigation sample; one without every stamp of the path, or with stamps out of order,
    /// is not kept.
    pub fn record(&mut self, s: &NavState) {
        let h = &s.header;
        let stamps = [
            h.origin_rx_ns,
            h.stage_ns(Stage::Acquisition),
            h.stage_ns(Stage::Fusion),
            h.stage_ns(Stage::Navigator),
        ];
        if self.samples.len() >= self.limit
            || stamps.contains(&0)
            || stamps.windows(2).any(|w| w[1] < w[0])
        {
            return;
        }
        self.samples.push([
            stamps[1] - stamps[0],
            stamps[2] - stamps[1],
            stamps[3] - stamps[2],
        ]);
    }

    /// The tail as it stands: the slowest 0.1 % of the samples (at least one); `None` before any
    /// sample.
    pub fn report(&self) -> Option<TailReport> {
        let mut order: Vec<(u64, usize)> = self
            .samples
            .iter()
            .enumerate()
            .map(|(i, h)| (h.iter().sum(), i))
            .collect();
        if order.is_empty() {
            return None;
        }
        order.sort_unstable_by(|a, b| b.cmp(a));
        let k = order.len().div_ceil(1000);
        let tail = &order[..k];
        let mut sums = [0u64; 3];
        let mut dominant = [0u64; 3];
        for &(_, i) in tail {
            let hops = &self.samples[i];
            for (sum, hop) in sums.iter_mut().zip(hops) {
                *sum += hop;
            }
            let longest = (0..3).max_by_key(|&j| hops[j]).unwrap_or(0);
            dominant[longest] += 1;
        }
        let threshold = tail.last().map_or(0, |&(total, _)| total);
        Some(TailReport {
            threshold_us: threshold as f64 / 1e3,
            samples: k as u64,
            hops: (0..3)
                .map(|j| TailHop {
                    hop: TAIL_HOPS[j],
                    mean_us: sums[j] as f64 / k as f64 / 1e3,
                    dominant: dominant[j],
                })
                .collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(rx: u64, hops_ns: [u64; 3]) -> NavState {
        let mut s = NavState::default();
        s.header.origin_rx_ns = rx;
        s.header.stamp(Stage::Acquisition, rx + hops_ns[0]);
        s.header.stamp(Stage::Fusion, rx + hops_ns[0] + hops_ns[1]);
        s.header
            .stamp(Stage::Navigator, rx + hops_ns[0] + hops_ns[1] + hops_ns[2]);
        s
    }

    #[test]
    fn the_tail_names_the_hop_that_carries_it() {
        let mut t = TailRecorder::new(10_000);
        for i in 0..9_990u64 {
            t.record(&sample(1_000_000 + i, [5_000, 30_000, 40_000]));
        }
        // Ten slow samples, eight of them slow in fusion's hop.
        for i in 0..8u64 {
            t.record(&sample(1 + i, [5_000, 2_000_000, 40_000]));
        }
        for i in 0..2u64 {
            t.record(&sample(1 + i, [5_000, 30_000, 3_000_000]));
        }
        let r = t.report().unwrap();
        assert_eq!(r.samples, 10);
        assert_eq!(r.threshold_us, 2_045.0);
        let dominant: Vec<u64> = r.hops.iter().map(|h| h.dominant).collect();
        assert_eq!(dominant, [0, 8, 2]);
        assert!((r.hops[1].mean_us - (8.0 * 2_000.0 + 2.0 * 30.0) / 10.0).abs() < 1e-9);
    }

    #[test]
    fn samples_without_the_whole_path_are_not_kept() {
        let mut t = TailRecorder::new(4);
        let mut none = TailRecorder::new(0);
        none.record(&sample(100, [1, 2, 3]));
        assert_eq!(none.report(), None, "a recorder of no room keeps nothing");
        let mut s = sample(100, [1, 2, 3]);
        s.header.stamp(Stage::Fusion, 0);
        t.record(&s);
        let mut backwards = sample(100, [1, 2, 3]);
        backwards.header.origin_rx_ns = 1_000;
        t.record(&backwards);
        assert_eq!(t.report(), None);
    }
}
