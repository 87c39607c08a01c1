//! What the soak does next: the kinds of fault an operator asks for (`--faults`) and a random
//! draw of one concrete fault among them. Pure: the soak's loop carries the faults out.

use std::fmt;
use std::time::Duration;

use ipc_types::{SensorType, ServiceKind, SimFault};
use rand::Rng;
use rins_sim::fault_command::ChannelId;

/// Services the soak kills or hangs (the watchdog and the simulator are the test harness here).
pub const VICTIMS: [ServiceKind; 5] = [
    ServiceKind::Acquisition,
    ServiceKind::Fusion,
    ServiceKind::Altimeter,
    ServiceKind::Navigator,
    ServiceKind::NavigatorStandby,
];

/// Channel faults the sensor block's fault detection isolates in flight with four channels (a
/// bias or ramp is detected but, without a fifth channel, not isolated: it would corrupt the
/// solution rather than test the recovery).
pub const SENSOR_FAULTS: [SimFault; 4] = [
    SimFault::Dead,
    SimFault::Stuck,
    SimFault::Saturate,
    SimFault::Intermittent,
];

/// How long a channel fault stays before it is cleared, s.
pub const SENSOR_HOLD_S: (f64, f64) = (1.0, 3.0);
/// How long the serial device stays unplugged, s.
pub const DISCONNECT_S: (f64, f64) = (0.2, 1.0);

/// A kind of fault, as named in `--faults`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FaultKind {
    /// SIGKILL of a service: the watchdog restarts it.
    Kill,
    /// SIGSTOP of a service: its heartbeat stops and the watchdog kills and restarts it.
    Hang,
    /// A fault on one gyro or accelerometer channel of the sensor block: fusion isolates it; the
    /// soak clears it and readmits the channel.
    Sensor,
    /// The serial device unplugged for a moment: acquisition reconnects.
    Disconnect,
}

impl FaultKind {
    pub const ALL: [FaultKind; 4] = [
        FaultKind::Kill,
        FaultKind::Hang,
        FaultKind::Sensor,
        FaultKind::Disconnect,
    ];

    pub fn name(self) -> &'static str {
        match self {
            FaultKind::Kill => "kill",
            FaultKind::Hang => "hang",
            FaultKind::Sensor => "sensor",
            FaultKind::Disconnect => "disconnect",
        }
    }

    /// Parses a comma-separated list (`kill,sensor`); repeated names count once.
    pub fn parse_list(text: &str) -> Result<Vec<FaultKind>, String> {
        let mut kinds = Vec::new();
        for word in text.split(',').map(str::trim) {
            let kind = Self::ALL
                .into_iter()
                .find(|k| k.name() == word)
                .ok_or_else(|| {
                    let names: Vec<&str> = Self::ALL.iter().map(|k| k.name()).collect();
                    format!(
                        "--faults {text:?}: unknown fault kind {word:?}, expected a comma-separated list of {}",
                        names.join(", ")
                    )
                })?;
            if !kinds.contains(&kind) {
                kinds.push(kind);
            }
        }
        kinds.sort();
        Ok(kinds)
    }
}

impl fmt::Display for FaultKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One concrete fault.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fault {
    Kill(ServiceKind),
    Hang(ServiceKind),
    Sensor {
        channel: ChannelId,
        fault: SimFault,
        hold: Duration,
    },
    Disconnect {
        duration_s: f64,
    },
}

impl Fault {
    pub fn kind(&self) -> FaultKind {
        match self {
            Fault::Kill(_) => FaultKind::Kill,
            Fault::Hang(_) => FaultKind::Hang,
            Fault::Sensor { .. } => FaultKind::Sensor,
            Fault::Disconnect { .. } => FaultKind::Disconnect,
        }
    }

    /// What the fault hits, as the summary counts it: a service, `gyro2 stuck`, `device`.
    pub fn target(&self) -> String {
        match self {
            Fault::Kill(s) | Fault::Hang(s) => s.name().to_string(),
            Fault::Sensor { channel, fault, .. } => format!("{channel} {}", fault.name()),
            Fault::Disconnect { .. } => "device".to_string(),
        }
    }
}

/// Draws the next fault: a kind uniformly among `kinds` (not empty), then its target and
/// duration. `channels` is the number of gyro and of accelerometer channels in the block.
pub fn draw(kinds: &[FaultKind], channels: (u8, u8), rng: &mut impl Rng) -> Fault {
    let kind = kinds[rng.random_range(0..kinds.len())];
    match kind {
        FaultKind::Kill => Fault::Kill(VICTIMS[rng.random_range(0..VICTIMS.len())]),
        FaultKind::Hang => Fault::Hang(VICTIMS[rng.random_range(0..VICTIMS.len())]),
        FaultKind::Sensor => {
            let (sensor, n) = if rng.random_bool(0.5) {
                (SensorType::Gyro, channels.0)
            } else {
                (SensorType::Accel, channels.1)
            };
            Fault::Sensor {
                channel: ChannelId {
                    sensor,
                    index: rng.random_range(0..n.max(1)),
                },
                fault: SENSOR_FAULTS[rng.random_range(0..SENSOR_FAULTS.len())],
                hold: Duration::from_secs_f64(rng.random_range(SENSOR_HOLD_S.0..=SENSOR_HOLD_S.1)),
            }
        }
        FaultKind::Disconnect => Fault::Disconnect {
            duration_s: rng.random_range(DISCONNECT_S.0..=DISCONNECT_S.1),
        },
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;

    #[test]
    fn a_list_parses_in_any_order_once_each_and_a_bad_name_is_named() {
        assert_eq!(
            FaultKind::parse_list("sensor, kill,sensor").unwrap(),
            vec![FaultKind::Kill, FaultKind::Sensor]
        );
        let e = FaultKind::parse_list("kill,reboot").unwrap_err();
        assert!(
            e.contains("\"reboot\"") && e.contains("kill, hang, sensor, disconnect"),
            "{e}"
        );
        assert!(FaultKind::parse_list("").is_err());
        assert!(FaultKind::parse_list("kill,").is_err());
    }

    #[test]
    fn draws_stay_among_the_asked_kinds_and_inside_the_block() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let kinds = [FaultKind::Sensor, FaultKind::Disconnect];
        let mut seen = [0u32; 2];
        for _ in 0..2000 {
            match draw(&kinds, (4, 3), &mut rng) {
                Fault::Sensor {
                    channel,
                    fault,
                    hold,
                } => {
                    seen[0] += 1;
                    let n = if channel.sensor == SensorType::Gyro {
                        4
                    } else {
                        3
                    };
                    assert!(channel.index < n, "{channel}");
                    assert!(SENSOR_FAULTS.contains(&fault));
                    let s = hold.as_secs_f64();
                    assert!((SENSOR_HOLD_S.0..=SENSOR_HOLD_S.1).contains(&s), "{s}");
                }
                Fault::Disconnect { duration_s } => {
                    seen[1] += 1;
                    assert!((DISCONNECT_S.0..=DISCONNECT_S.1).contains(&duration_s));
                }
                other => panic!("not asked for: {other:?}"),
            }
        }
        // Uniform over the two kinds: 1000 ± 5σ (σ ≈ 22).
        assert!(seen.iter().all(|&n| (890..=1110).contains(&n)), "{seen:?}");
    }

    #[test]
    fn every_victim_is_drawn() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut hit = [false; VICTIMS.len()];
        for _ in 0..200 {
            let Fault::Hang(s) = draw(&[FaultKind::Hang], (4, 4), &mut rng) else {
                panic!("only hangs were asked for");
            };
            hit[VICTIMS.iter().position(|&v| v == s).unwrap()] = true;
        }
        assert!(hit.iter().all(|&h| h), "{hit:?}");
    }

    #[test]
    fn targets_name_what_is_hit() {
        let f = Fault::Sensor {
            channel: ChannelId {
                sensor: SensorType::Gyro,
                index: 2,
            },
            fault: SimFault::Stuck,
            hold: Duration::from_secs(1),
        };
        assert_eq!(
            (f.kind(), f.target().as_str()),
            (FaultKind::Sensor, "gyro2 stuck")
        );
        assert_eq!(Fault::Kill(ServiceKind::Fusion).target(), "fusion");
        assert_eq!(Fault::Disconnect { duration_s: 0.5 }.target(), "device");
    }
}
