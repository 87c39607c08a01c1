//! TIMESYNC: the peer measures the offset between its clock and rins's (CLOCK_MONOTONIC, the time
//! base of every `time_usec` rins sends) by asking with `tc1 = 0` and its own time in `ts1`; rins
//! answers with its time in `tc1` and the peer's `ts1` unchanged.

use crate::dialect::TIMESYNC_DATA;

/// The answer to `request` at rins time `now_ns`; `None` for a message that is itself an answer
/// (`tc1 != 0`) or is addressed to another system.
pub fn answer(request: &TIMESYNC_DATA, now_ns: u64, own_system: u8) -> Option<TIMESYNC_DATA> {
    if request.tc1 != 0 || (request.target_system != 0 && request.target_system != own_system) {
        return None;
    }
    Some(TIMESYNC_DATA {
        tc1: i64::try_from(now_ns).unwrap_or(i64::MAX),
        ts1: request.ts1,
        ..TIMESYNC_DATA::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_requests_only() {
        let request = TIMESYNC_DATA {
            tc1: 0,
            ts1: 42,
            ..TIMESYNC_DATA::default()
        };
        let a = answer(&request, 5_000, 1).unwrap();
        assert_eq!((a.tc1, a.ts1), (5_000, 42));
        assert_eq!(answer(&a, 6_000, 1), None);
        let other = TIMESYNC_DATA {
            target_system: 9,
            ..request
        };
        assert_eq!(answer(&other, 6_000, 1), None);
    }
}
