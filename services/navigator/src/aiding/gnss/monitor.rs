//! Whether the GNSS receiver can be believed, judged by the inertial solution.
//!
//! A receiver can report a good fix and be wrong: its position jumps (multipath, a faulty
//! correction, a spoofer's capture), or is pulled away slowly (a spoofer walking it off). An
//! aided inertial solution sees both. A jump makes every fix fall outside the innovation gate:
//! one such fix is an outlier, [`GnssAidingConfig::reject_after_fixes`] in a row are the receiver.
//! A slow drift stays inside the gate, because the filter follows it a little at every fix; but
//! the innovations it leaves are biased, not white, so a cumulative sum (CUSUM, Page 1954) of each
//! horizontal axis's normalised innovation — less an allowance `drift_slack` per fix — grows
//! under it and stays near zero under noise. Past `drift_threshold` the receiver is rejected.
//!
//! A rejected receiver is not used; the solution coasts on the inertial one, its covariance
//! growing. Its fixes go on being compared; once they have passed the gate for
//! `readmit_after_s`, it is re-admitted and the sums start again. The caller holds a receiver
//! rejected for a jump out while its fixes stay about as far away as they jumped (see
//! [`crate::aiding::gnss`]): the grown covariance alone would in time let a persistent jump back.

use crate::aiding::gnss::config::GnssAidingConfig;

/// Why the receiver was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RejectReason {
    /// Consecutive fixes outside the gate.
    Jump,
    /// The drift test fired.
    Drift,
}

/// What to do with one fix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Apply it.
    Use,
    /// Outside the gate, alone so far: skip it.
    Outlier,
    /// The receiver is rejected (now or before): skip it.
    Rejected,
    /// The receiver passed the gate long enough to come back: apply this fix.
    Readmitted,
}

/// One change of the receiver's standing, for logs and reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transition {
    /// Rejected at device time `t_us`.
    Rejected {
        /// Device time, µs.
        t_us: u64,
        /// Why.
        reason: RejectReason,
    },
    /// Re-admitted at device time `t_us`.
    Readmitted {
        /// Device time, µs.
        t_us: u64,
    },
}

/// The receiver's standing.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Standing {
    Accepted,
    Rejected {
        reason: RejectReason,
        /// Device time since which every fix passed the gate.
        consistent_since_us: Option<u64>,
    },
}

/// The consistency monitor of one receiver. Allocation-free.
#[derive(Debug, Clone)]
pub struct GnssMonitor {
    config: GnssAidingConfig,
    standing: Standing,
    outside_gate: u32,
    /// Upper and lower cumulative sums, north and east.
    cusum: [[f64; 2]; 2],
    last_transition: Option<Transition>,
    rejections: u64,
}

impl GnssMonitor {
    /// A monitor that trusts the receiver until its fixes say otherwise.
    pub fn new(config: GnssAidingConfig) -> Self {
        Self {
            config,
            standing: Standing::Accepted,
            outside_gate: 0,
            cusum: [[0.0; 2]; 2],
            last_transition: None,
            rejections: 0,
        }
    }

    /// Judges the fix at device time `t_us`: `d2` the squared Mahalanobis distance of its
    /// position innovation, `normalised` its north and east innovations over their σ.
    pub fn judge(&mut self, t_us: u64, d2: f64, normalised: [f64; 2]) -> Verdict {
        let gate2 = self.config.gate * self.config.gate;
        let inside = d2.is_finite() && d2 <= gate2;
        match self.standing {
            Standing::Accepted => {
                if !inside {
                    self.outside_gate += 1;
                    if self.outside_gate >= self.config.reject_after_fixes {
                        self.reject(t_us, RejectReason::Jump);
                        return Verdict::Rejected;
                    }
                    return Verdict::Outlier;
                }
                self.outside_gate = 0;
                let k = self.config.drift_slack;
                for (sums, z) in self.cusum.iter_mut().zip(normalised) {
                    let z = if z.is_finite() { z } else { 0.0 };
                    sums[0] = (sums[0] + z - k).max(0.0);
                    sums[1] = (sums[1] - z - k).max(0.0);
                }
                if self.drift_statistic() > self.config.drift_threshold {
                    self.reject(t_us, RejectReason::Drift);
                    return Verdict::Rejected;
                }
                Verdict::Use
            }
            Standing::Rejected {
                reason,
                consistent_since_us,
            } => {
                if !inside {
                    self.standing = Standing::Rejected {
                        reason,
                        consistent_since_us: None,
                    };
                    return Verdict::Rejected;
                }
                let since = consistent_since_us.unwrap_or(t_us);
                if t_us.saturating_sub(since) as f64 * 1e-6 >= self.config.readmit_after_s {
                    self.standing = Standing::Accepted;
                    self.outside_gate = 0;
                    self.cusum = [[0.0; 2]; 2];
                    self.last_transition = Some(Transition::Readmitted { t_us });
                    return Verdict::Readmitted;
                }
                self.standing = Standing::Rejected {
                    reason,
                    consistent_since_us: Some(since),
                };
                Verdict::Rejected
            }
        }
    }

    /// Rejects a receiver still believed for a drift another test saw (see
    /// [`crate::aiding::gnss::displacement`]); nothing when it is rejected already.
    pub fn reject_for_drift(&mut self, t_us: u64) {
        if self.standing == Standing::Accepted {
            self.reject(t_us, RejectReason::Drift);
        }
    }

    fn reject(&mut self, t_us: u64, reason: RejectReason) {
        self.standing = Standing::Rejected {
            reason,
            consistent_since_us: None,
        };
        self.outside_gate = 0;
        self.rejections += 1;
        self.last_transition = Some(Transition::Rejected { t_us, reason });
    }

    /// The largest of the four cumulative sums, σ.
    pub fn drift_statistic(&self) -> f64 {
        self.cusum.iter().flatten().copied().fold(0.0, f64::max)
    }

    /// Whether the receiver is rejected now, and why.
    pub fn rejected(&self) -> Option<RejectReason> {
        match self.standing {
            Standing::Accepted => None,
            Standing::Rejected { reason, .. } => Some(reason),
        }
    }

    /// The last change of standing.
    pub fn last_transition(&self) -> Option<Transition> {
        self.last_transition
    }

    /// Times the receiver was rejected.
    pub fn rejections(&self) -> u64 {
        self.rejections
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    const FIX_US: u64 = 200_000;

    fn monitor() -> GnssMonitor {
        GnssMonitor::new(GnssAidingConfig::default())
    }

    #[test]
    fn white_innovations_never_reject_over_an_hour_of_fixes() {
        let mut m = monitor();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for i in 0..18_000u64 {
            let z: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
            let d2 = z.iter().map(|x| x * x).sum::<f64>();
            let verdict = m.judge(i * FIX_US, d2, [z[0], z[1]]);
            assert_ne!(verdict, Verdict::Rejected, "fix {i}");
        }
        assert_eq!(m.rejections(), 0);
    }

    #[test]
    fn a_jump_is_rejected_at_the_third_fix_outside_the_gate_and_readmitted_after_it_ends() {
        let mut m = monitor();
        assert_eq!(m.judge(0, 1.0, [0.0; 2]), Verdict::Use);
        assert_eq!(m.judge(FIX_US, 1e4, [100.0, 0.0]), Verdict::Outlier);
        assert_eq!(m.judge(2 * FIX_US, 1e4, [100.0, 0.0]), Verdict::Outlier);
        assert_eq!(m.judge(3 * FIX_US, 1e4, [100.0, 0.0]), Verdict::Rejected);
        assert_eq!(m.rejected(), Some(RejectReason::Jump));
        // Consistent again from 4 fixes on: back after readmit_after_s (3 s = 15 fixes).
        let mut back = None;
        for i in 4..40 {
            if m.judge(i * FIX_US, 1.0, [0.0; 2]) == Verdict::Readmitted {
                back = Some(i);
                break;
            }
        }
        assert_eq!(back, Some(19));
        assert_eq!(m.rejected(), None);
    }

    #[test]
    fn a_single_outlier_is_skipped_not_held_against_the_receiver() {
        let mut m = monitor();
        for i in 0..100 {
            let d2 = if i % 10 == 0 { 1e4 } else { 1.0 };
            assert_ne!(m.judge(i * FIX_US, d2, [0.1, 0.1]), Verdict::Rejected);
        }
    }

    #[test]
    fn a_persistent_bias_of_four_sigma_is_a_drift_within_13_fixes() {
        let mut m = monitor();
        // Each fix adds 4 − 2 = 2 σ to the upper north sum: past 25 σ at the 13th fix.
        let mut fired = None;
        for i in 0..40 {
            if m.judge(i * FIX_US, 16.0, [4.0, 0.0]) == Verdict::Rejected {
                fired = Some(i);
                break;
            }
        }
        assert_eq!(fired, Some(12));
        assert_eq!(m.rejected(), Some(RejectReason::Drift));
        assert_eq!(
            m.last_transition(),
            Some(Transition::Rejected {
                t_us: 12 * FIX_US,
                reason: RejectReason::Drift
            })
        );
    }
}
