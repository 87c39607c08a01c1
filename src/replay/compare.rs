//! Comparing two runs' navigation output sample for sample: the same lane and sequence number must
//! carry the same bytes, all but the stages' publish times (wall-clock stamps of the run).

use std::collections::HashMap;

use ipc_types::NavState;
use rins_recording::Recordable;
use serde::Serialize;

/// How a replay's navigation output compares with the recorded one.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct NavComparison {
    /// Recorded samples found in the replay (same lane and sequence number) and compared.
    pub nav_samples_compared: u64,
    /// Compared samples whose content differs.
    pub nav_samples_different: u64,
    /// Recorded samples the replay did not produce.
    pub nav_samples_missing: u64,
    /// Sequence number and lane of the first different sample.
    pub first_different: Option<(u8, u64)>,
    /// The fields that differ in the first different sample, with the recorded and replayed
    /// values.
    pub first_different_fields: Vec<(String, String, String)>,
}

/// The top-level fields of two samples that differ, with both values.
fn differing_fields(a: &NavState, b: &NavState) -> Vec<(String, String, String)> {
    let (Ok(serde_json::Value::Object(a)), Ok(serde_json::Value::Object(b))) = (
        serde_json::to_value(content(a)),
        serde_json::to_value(content(b)),
    ) else {
        return Vec::new();
    };
    a.iter()
        .filter(|(k, v)| b.get(*k) != Some(v))
        .map(|(k, v)| {
            let other = b.get(k).map_or_else(String::new, ToString::to_string);
            (k.clone(), v.to_string(), other)
        })
        .collect()
}

/// `nav` with the run-dependent publish times cleared.
fn content(nav: &NavState) -> NavState {
    let mut n = *nav;
    n.header.stage_pub_ns = [0; ipc_types::Stage::COUNT];
    n
}

/// Compares, per lane, every recorded sample with the replayed sample of the same sequence number.
pub fn compare(recorded: &[Vec<NavState>; 2], replayed: &[Vec<NavState>; 2]) -> NavComparison {
    let mut c = NavComparison::default();
    for (lane, (rec, rep)) in recorded.iter().zip(replayed).enumerate() {
        let by_seq: HashMap<u64, &NavState> =
            rep.iter().map(|n| (n.header.origin_seq, n)).collect();
        for r in rec {
            let Some(p) = by_seq.get(&r.header.origin_seq) else {
                c.nav_samples_missing += 1;
                continue;
            };
            c.nav_samples_compared += 1;
            if content(r).as_bytes() != content(p).as_bytes() {
                c.nav_samples_different += 1;
                if c.first_different.is_none() {
                    c.first_different = Some((lane as u8, r.header.origin_seq));
                    c.first_different_fields = differing_fields(r, p);
                }
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nav(seq: u64, x: f64) -> NavState {
        let mut n = NavState::default();
        n.header.origin_seq = seq;
        n.velocity_ned_mps[0] = x;
        n
    }

    #[test]
    fn publish_times_do_not_count_content_does() {
        let rec = [
            vec![nav(1, 0.0), nav(2, 1.0), nav(3, 2.0)],
            vec![nav(1, 0.0)],
        ];
        let mut replayed = rec.clone();
        replayed[0][0].header.stage_pub_ns = [5, 6, 7, 8];
        assert_eq!(
            compare(&rec, &replayed),
            NavComparison {
                nav_samples_compared: 4,
                ..NavComparison::default()
            }
        );
        // One bit of one velocity, and a sample gone.
        replayed[0][1].velocity_ned_mps[0] = f64::from_bits(1.0f64.to_bits() + 1);
        replayed[1].clear();
        let c = compare(&rec, &replayed);
        assert_eq!(
            (
                c.nav_samples_compared,
                c.nav_samples_different,
                c.nav_samples_missing
            ),
            (3, 1, 1)
        );
        assert_eq!(c.first_different, Some((0, 2)));
        assert_eq!(c.first_different_fields.len(), 1);
        assert_eq!(c.first_different_fields[0].0, "velocity_ned_mps");
    }
}
