//! Faults planned ahead: `gyro2:dead@5s` or `disconnect=1.5@5s` on the command line or `[[fault]]`
//! entries of a scenario file, applied by the simulator at the first IMU tick at or after their
//! device time.

use ipc_types::SimFault;
use serde::Deserialize;

use crate::fault_command::{ChannelId, parse_kind, parse_number};
use crate::fault_parse_error::FaultParseError;
use crate::sim_command::SimCommand;

/// A command and the device time (s since the simulator started) it takes effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduledFault {
    /// Device time the command takes effect, s since the simulator started; finite and >= 0.
    pub at_s: f64,
    /// The channel fault or device disconnect to apply.
    pub command: SimCommand,
}

fn check_time(token: impl FnOnce() -> String, at_s: f64) -> Result<f64, FaultParseError> {
    if at_s.is_finite() && at_s >= 0.0 {
        Ok(at_s)
    } else {
        Err(FaultParseError::new(
            token(),
            "must be a finite number of seconds >= 0",
        ))
    }
}

/// Parses a time like `5s`, `3.2s`, `250ms` or a bare number of seconds.
pub fn parse_time_s(text: &str) -> Result<f64, FaultParseError> {
    let token = || format!("time {text:?}");
    let (number, scale) = if let Some(n) = text.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = text.strip_suffix('s') {
        (n, 1.0)
    } else {
        (text, 1.0)
    };
    let value: f64 = number.parse().map_err(|_| {
        FaultParseError::new(token(), "expected device seconds, e.g. 5s, 3.2s or 250ms")
    })?;
    check_time(token, value * scale)
}

impl ScheduledFault {
    /// Parses `CHANNEL:KIND[=PARAM]@TIME`, e.g. `gyro2:dead@5s`, `accel1:bias=0.5@3.2s`,
    /// `disconnect=DURATION_S@TIME` for the whole device, e.g. `disconnect=1.5@5s`, or
    /// `gnss:KIND[=PARAM]@TIME` for the GNSS receiver, e.g. `gnss:jump=50@30s`.
    pub fn parse(spec: &str) -> Result<Self, FaultParseError> {
        Self::parse_inner(spec).map_err(|e| e.within(&format!("{spec:?}")))
    }

    fn parse_inner(spec: &str) -> Result<Self, FaultParseError> {
        const FORM: &str = "expected CHANNEL:KIND[=PARAM]@TIME or disconnect=SECONDS@TIME, e.g. \
                            gyro2:dead@5s, accel1:bias=0.5@3.2s or disconnect=1.5@5s";
        let Some((what, time)) = spec.rsplit_once('@') else {
            return Err(FaultParseError::new("no \"@TIME\"", FORM));
        };
        if let Some(("gnss", fault)) = what.split_once(':') {
            let (kind, param) = match fault.split_once('=') {
                Some((k, p)) => (k, Some(p)),
                None => (fault, None),
            };
            let param = param
                .map(|p| {
                    p.parse::<f64>().map_err(|_| {
                        FaultParseError::new(format!("gnss {kind} {p:?}"), "expected a number")
                    })
                })
                .transpose()?;
            return Ok(Self {
                at_s: parse_time_s(time)?,
                command: SimCommand::gnss(kind, param)?,
            });
        }
        let (channel, fault) = match what.split_once(':') {
            Some((channel, fault)) => (Some(ChannelId::parse(channel)?), fault),
            None => (None, what),
        };
        let (kind, param) = match fault.split_once('=') {
            Some((k, p)) => (k, Some(p)),
            None => (fault, None),
        };
        // Only the whole-device fault goes without a channel; anything else without one is
        // most likely a forgotten colon.
        let is_device_fault = SimFault::from_name(kind) == Some(SimFault::Disconnect);
        if channel.is_none() && !is_device_fault {
            return Err(FaultParseError::new("no \"CHANNEL:\"", FORM));
        }
        let kind = parse_kind(kind)?;
        let param = param.map(|p| parse_number(kind, p)).transpose()?;
        Ok(Self {
            at_s: parse_time_s(time)?,
            command: SimCommand::new(channel, kind, param)?,
        })
    }
}

/// A scenario file: `[[fault]]` tables with `channel` (none for `disconnect`), `kind`, `at_s` and
/// optional `param`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultFile {
    /// The `[[fault]]` tables in file order; none when the file has no faults.
    #[serde(default)]
    pub fault: Vec<FaultFileEntry>,
}

/// One `[[fault]]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultFileEntry {
    /// `gyro2`, `accel0`, ...; absent for `disconnect`, which unplugs the whole device.
    #[serde(default)]
    pub channel: Option<String>,
    /// `dead`, `stuck`, `bias`, `ramp`, `noise`, `saturate`, `intermittent`, `clear`,
    /// `disconnect`.
    pub kind: String,
    /// Device time, s since the simulator started.
    pub at_s: f64,
    /// Bias step, ramp rate, noise factor, intermittent period or disconnect duration (SI
    /// units).
    pub param: Option<f64>,
}

impl FaultFile {
    /// Validates every entry; errors name the entry (`fault[i]`) and the offending field.
    pub fn schedule(&self) -> Result<Vec<ScheduledFault>, FaultParseError> {
        self.fault
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let entry = || -> Result<ScheduledFault, FaultParseError> {
                    let channel = e.channel.as_deref().map(ChannelId::parse).transpose()?;
                    let kind = parse_kind(&e.kind)?;
                    let at_s = check_time(|| format!("at_s = {}", e.at_s), e.at_s)?;
                    Ok(ScheduledFault {
                        at_s,
                        command: SimCommand::new(channel, kind, e.param)?,
                    })
                };
                entry().map_err(|err| err.within(&format!("fault[{i}]")))
            })
            .collect()
    }
}

/// Index of the first tick at or after `at_s` for ticks k/`imu_rate_hz` (a part per million of
/// a tick of slack absorbs round-off, so `2.5` s at 1 kHz is tick 2500).
pub fn tick_at(at_s: f64, imu_rate_hz: f64) -> u64 {
    // Non-negative and finite after validation; the float-to-int cast saturates otherwise.
    (at_s * imu_rate_hz - 1e-6).ceil().max(0.0) as u64
}

/// The planned faults in tick order, consumed as the simulator advances.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FaultSchedule {
    entries: Vec<(u64, SimCommand)>,
    next: usize,
}

impl FaultSchedule {
    /// Orders `faults` by tick; faults due on the same tick keep their given order, so a later
    /// entry for the same channel wins.
    pub fn new(faults: &[ScheduledFault], imu_rate_hz: f64) -> Self {
        let mut entries: Vec<(u64, SimCommand)> = faults
            .iter()
            .map(|f| (tick_at(f.at_s, imu_rate_hz), f.command))
            .collect();
        entries.sort_by_key(|(tick, _)| *tick);
        Self { entries, next: 0 }
    }

    /// The next command due at or before `tick`, if any; call until `None` each tick.
    /// Allocation-free.
    pub fn next_due(&mut self, tick: u64) -> Option<SimCommand> {
        let (due, command) = *self.entries.get(self.next)?;
        if due > tick {
            return None;
        }
        self.next += 1;
        Some(command)
    }

    /// Commands not yet handed out.
    pub fn remaining(&self) -> usize {
        self.entries.len() - self.next
    }
}

#[cfg(test)]
mod tests {
    use ipc_types::{SensorType, SimFault};
    use proptest::prelude::*;

    use super::*;

    #[test]
    fn specs_of_every_kind_parse() {
        let cases: [(&str, SensorType, u8, SimFault, f64, f64); 7] = [
            (
                "gyro2:dead@5s",
                SensorType::Gyro,
                2,
                SimFault::Dead,
                0.0,
                5.0,
            ),
            (
                "accel1:bias=0.5@3.2s",
                SensorType::Accel,
                1,
                SimFault::BiasStep,
                0.5,
                3.2,
            ),
            (
                "gyro0:noise=10@2s",
                SensorType::Gyro,
                0,
                SimFault::Noise,
                10.0,
                2.0,
            ),
            (
                "gyro1:ramp=0.01@4s",
                SensorType::Gyro,
                1,
                SimFault::Ramp,
                0.01,
                4.0,
            ),
            (
                "accel3:intermittent=0.2@6s",
                SensorType::Accel,
                3,
                SimFault::Intermittent,
                0.2,
                6.0,
            ),
            (
                "gyro3:stuck@5",
                SensorType::Gyro,
                3,
                SimFault::Stuck,
                0.0,
                5.0,
            ),
            (
                "accel0:saturate@250ms",
                SensorType::Accel,
                0,
                SimFault::Saturate,
                0.0,
                0.25,
            ),
        ];
        for (spec, sensor, index, fault, param, at_s) in cases {
            let s = ScheduledFault::parse(spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
            assert_eq!(
                s.command.channel(),
                Some(ChannelId { sensor, index }),
                "{spec}"
            );
            assert_eq!(s.command.fault(), fault, "{spec}");
            assert_eq!(s.command.param(), param, "{spec}");
            assert!((s.at_s - at_s).abs() < 1e-12, "{spec}");
        }
        let neg = ScheduledFault::parse("gyro1:bias=-0.02@1s").unwrap();
        assert_eq!(neg.command.param(), -0.02);
        let d = ScheduledFault::parse("disconnect=1.5@5s").unwrap();
        assert_eq!(
            (d.command.fault(), d.command.param()),
            (SimFault::Disconnect, 1.5)
        );
        assert_eq!((d.command.channel(), d.at_s), (None, 5.0));
    }

    #[test]
    fn bad_specs_name_the_offending_token() {
        let cases = [
            ("gyro2:dead", "no \"@TIME\""),
            ("gyro2dead@5s", "no \"CHANNEL:\""),
            ("gyro9x:dead@5s", "channel \"gyro9x\""),
            ("gyro2:explode@5s", "fault \"explode\""),
            ("gyro2:dead@xs", "time \"xs\""),
            ("gyro2:dead@-1s", "time \"-1s\""),
            ("gyro2:bias@5s", "bias"),
            ("gyro2:bias=abc@5s", "bias STEP \"abc\""),
            ("gyro2:noise=0.5@5s", "noise FACTOR = 0.5"),
            ("gyro2:dead=1@5s", "dead \"1\""),
            ("disconnect@5s", "disconnect"),
            ("disconnect=soon@5s", "disconnect DURATION_S \"soon\""),
            ("disconnect=0@5s", "disconnect DURATION_S = 0"),
            ("disconnect=1e9@5s", "disconnect DURATION_S = 1000000000"),
            ("disconnect=1@never", "time \"never\""),
            ("gyro2:disconnect=1@5s", "channel \"gyro2\""),
            ("dead@5s", "no \"CHANNEL:\""),
        ];
        for (spec, token) in cases {
            let e = ScheduledFault::parse(spec).expect_err(spec);
            assert!(e.token.starts_with(&format!("{spec:?}")), "{spec}: {e}");
            assert!(e.token.contains(token), "{spec}: {e} lacks {token}");
        }
    }

    #[test]
    fn scenario_file_parses_and_errors_name_the_entry() {
        let text = r#"
            [[fault]]
            channel = "gyro2"
            kind = "dead"
            at_s = 5.0

            [[fault]]
            channel = "accel1"
            kind = "bias"
            at_s = 3.2
            param = 0.5
        "#;
        let file: FaultFile = toml::from_str(text).unwrap();
        let s = file.schedule().unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].command.fault(), SimFault::Dead);
        assert_eq!(s[1].command.param(), 0.5);
        assert_eq!(s[1].at_s, 3.2);

        let bad = FaultFile {
            fault: vec![
                file.fault[0].clone(),
                FaultFileEntry {
                    kind: "explode".into(),
                    ..file.fault[0].clone()
                },
            ],
        };
        let e = bad.schedule().unwrap_err();
        assert!(e.token.starts_with("fault[1]: fault \"explode\""), "{e}");
        let bad = FaultFile {
            fault: vec![FaultFileEntry {
                at_s: f64::NAN,
                ..file.fault[0].clone()
            }],
        };
        assert!(bad.schedule().unwrap_err().token.contains("at_s = NaN"));
        let bad = FaultFile {
            fault: vec![FaultFileEntry {
                param: None,
                ..file.fault[1].clone()
            }],
        };
        assert!(bad.schedule().unwrap_err().reason.contains("STEP"));

        let device: FaultFile =
            toml::from_str("[[fault]]\nkind = \"disconnect\"\nat_s = 2\nparam = 0.5\n").unwrap();
        let s = device.schedule().unwrap();
        assert_eq!(
            (s[0].command.fault(), s[0].command.param()),
            (SimFault::Disconnect, 0.5)
        );
        let cases = [
            (
                "kind = \"disconnect\"\nat_s = 2\n",
                "fault[0]: disconnect",
                "DURATION_S",
            ),
            (
                "kind = \"disconnect\"\nat_s = 2\nparam = -1.0\n",
                "fault[0]: disconnect DURATION_S = -1",
                "> 0",
            ),
            (
                "channel = \"gyro1\"\nkind = \"disconnect\"\nat_s = 2\nparam = 1.0\n",
                "fault[0]: channel \"gyro1\"",
                "whole device",
            ),
            (
                "kind = \"dead\"\nat_s = 2\n",
                "fault[0]: fault \"dead\"",
                "CHANNEL",
            ),
        ];
        for (entry, token, reason) in cases {
            let file: FaultFile = toml::from_str(&format!("[[fault]]\n{entry}")).unwrap();
            let e = file.schedule().unwrap_err();
            assert!(
                e.token.starts_with(token) && e.reason.contains(reason),
                "{entry}: {e}"
            );
        }

        assert!(
            toml::from_str::<FaultFile>(
                "[[fault]]\nchannel = \"gyro0\"\nkind = \"dead\"\nat_s = 1\nwhen = 2\n"
            )
            .is_err()
        );
        assert!(
            toml::from_str::<FaultFile>("")
                .unwrap()
                .schedule()
                .unwrap()
                .is_empty()
        );
    }

    #[test]
    fn fault_times_land_on_the_first_tick_at_or_after_them() {
        assert_eq!(tick_at(2.5, 1000.0), 2500);
        assert_eq!(tick_at(3.2, 1000.0), 3200);
        assert_eq!(tick_at(0.0, 1000.0), 0);
        assert_eq!(tick_at(2.5004, 1000.0), 2501);
        assert_eq!(tick_at(0.1, 400.0), 40);
        assert_eq!(tick_at(1.0 / 3.0, 300.0), 100);
    }

    proptest! {
        #[test]
        fn tick_at_is_the_first_sample_not_before_the_time(k in 0u64..10_000_000, rate in prop::sample::select(vec![100.0, 400.0, 1000.0, 2000.0, 8000.0])) {
            // A time exactly on a sample maps to it; a time just after maps to the next one.
            let t = k as f64 / rate;
            prop_assert_eq!(tick_at(t, rate), k);
            prop_assert_eq!(tick_at(t + 0.01 / rate, rate), k + 1);
        }
    }

    #[test]
    fn schedule_hands_out_commands_in_tick_order() {
        let parse = |s: &str| ScheduledFault::parse(s).unwrap();
        let faults = [
            parse("gyro2:dead@5s"),
            parse("gyro1:bias=0.1@1s"),
            parse("gyro1:clear@1s"),
            parse("accel0:stuck@2.0005s"),
        ];
        let mut s = FaultSchedule::new(&faults, 1000.0);
        assert_eq!(s.remaining(), 4);
        assert_eq!(s.next_due(999), None);
        let a = s.next_due(1000).unwrap();
        let b = s.next_due(1000).unwrap();
        // Same tick: given order kept, so the clear comes last.
        assert_eq!(
            (a.fault(), b.fault()),
            (SimFault::BiasStep, SimFault::Clear)
        );
        assert_eq!(s.next_due(1000), None);
        assert_eq!(s.next_due(2000), None);
        assert_eq!(s.next_due(2001).unwrap().fault(), SimFault::Stuck);
        // A late call still delivers what is overdue.
        assert_eq!(s.next_due(9000).unwrap().fault(), SimFault::Dead);
        assert_eq!(s.next_due(9000), None);
        assert_eq!(s.remaining(), 0);
    }
}
