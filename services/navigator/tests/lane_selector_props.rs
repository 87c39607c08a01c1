//! Properties of the lane selector under random kills, restarts and arrival orders.

use ipc_types::{NavMode, NavState};
use proptest::prelude::*;
use rins_navigator::lanes::{LaneSelector, SelectorConfig};

const N: u64 = 600;

fn nav(lane: u8, seq: u64, start: u64) -> NavState {
    let mut s = NavState {
        mode: NavMode::Navigating as u8,
        lane,
        solution_start_seq: start,
        ..NavState::default()
    };
    s.header.origin_seq = seq;
    s
}

/// Lane `lane` is down for `[from, from + len)`; it comes back with a new solution.
#[derive(Debug, Clone, Copy)]
struct Outage {
    lane: u8,
    from: u64,
    len: u64,
}

fn outages() -> impl Strategy<Value = Vec<Outage>> {
    // Outages alternate between lanes and never overlap: one lane is always up.
    prop::collection::vec((10u64..60, 1u64..80), 0..6).prop_map(|spans| {
        let mut at = 1;
        let mut lane = 0;
        let mut out = Vec::new();
        for (gap, len) in spans {
            at += gap;
            out.push(Outage {
                lane,
                from: at,
                len,
            });
            at += len;
            lane = 1 - lane;
        }
        out
    })
}

proptest! {
    #[test]
    fn the_output_is_contiguous_while_one_lane_is_up(
        outages in outages(),
        // Per sample, whether the standby's sample arrives before the primary's.
        order in prop::collection::vec(any::<bool>(), N as usize),
    ) {
        let config = SelectorConfig { switch_lag: 8, dead_after_ns: 8_000_000, dead_after_untrusted_ns: 100_000_000, settle: 50, min_dwell: 20 };
        let mut sel = LaneSelector::new(config);
        let mut out: Vec<u64> = Vec::new();
        let start = |lane: u8, seq: u64| {
            outages
                .iter()
                .filter(|o| o.lane == lane && o.from + o.len <= seq)
                .map(|o| o.from + o.len)
                .max()
                .unwrap_or(1)
        };
        let up = |lane: u8, seq: u64| {
            !outages
                .iter()
                .any(|o| o.lane == lane && (o.from..o.from + o.len).contains(&seq))
        };
        for seq in 1..=N {
            let lanes: [u8; 2] = if order[(seq - 1) as usize] { [1, 0] } else { [0, 1] };
            for lane in lanes {
                if up(lane, seq) {
                    sel.push(usize::from(lane), nav(lane, seq, start(lane, seq)));
                }
            }
            while let Some(s) = sel.pop() {
                out.push(s.header.origin_seq);
            }
        }
        // Every sequence number from 1, once and in order; at the end at most the switch lag is
        // still held back (a lane that died just before the end).
        prop_assert!(out.iter().enumerate().all(|(i, &s)| s == i as u64 + 1), "{out:?}");
        prop_assert!(out.len() as u64 >= N - config.switch_lag, "{}", out.len());
        // Per outage at most the switch away from the dead lane and one quality switch.
        prop_assert!(sel.switches() <= 2 * outages.len() as u64);
    }

    #[test]
    fn no_sample_is_delivered_twice_or_backwards_whatever_arrives(
        pushes in prop::collection::vec((0usize..2, 1u64..200), 0..400),
    ) {
        let mut sel = LaneSelector::new(SelectorConfig::default());
        let mut last = 0;
        for (lane, seq) in pushes {
            sel.push(lane, nav(lane as u8, seq, 1));
            while let Some(s) = sel.pop() {
                prop_assert!(s.header.origin_seq > last);
                last = s.header.origin_seq;
            }
        }
    }
}
