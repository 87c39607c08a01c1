//! Fault commands as an operator writes them (`gyro2`, `bias 0.5`), as they travel to the simulator
//! ([`SimControl`]) and as the simulator applies them ([`ChannelFault`]). Pure parsing and
//! conversion; the process shells do the I/O.

use std::fmt;

use ipc_types::{MAX_CHANNELS, PAYLOAD_VERSION, SensorType, SimControl, SimFault};
use rins_runtime::payload::Versioned;

use crate::config::SimConfig;
use crate::device_fault::{DURATION_RANGE, Disconnect};
use crate::fault_parse_error::FaultParseError;
use crate::sensor_model::fault::{ChannelFault, InertialSensor};
use rins_earth::STANDARD_GRAVITY;

/// Period of an intermittent fault when none is given, s (dead for the first half of it).
pub const DEFAULT_INTERMITTENT_PERIOD_S: f64 = 0.2;

/// Longest accepted intermittent period, s.
const MAX_INTERMITTENT_PERIOD_S: f64 = 3600.0;

/// Why a disconnect cannot be given a channel.
pub const DISCONNECT_HAS_NO_CHANNEL: &str = "disconnect unplugs the whole device: give no channel (rins inject disconnect --duration S, \
     --inject disconnect=S@TIME)";

/// One redundant inertial channel: sensor type and 0-based index, written `gyro2`, `accel0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChannelId {
    /// Gyro or accelerometer.
    pub sensor: SensorType,
    /// 0-based channel index within its type, below `MAX_CHANNELS`; whether the block has it is checked
    /// separately ([`ChannelId::check_fitted`]).
    pub index: u8,
}

impl ChannelId {
    /// Parses `gyroN` / `accelN` with N in 0..MAX_CHANNELS. Whether the device has channel N is
    /// only known to whoever knows the sensor block's configuration.
    pub fn parse(text: &str) -> Result<Self, FaultParseError> {
        let token = || format!("channel {text:?}");
        let (sensor, digits) = if let Some(d) = text.strip_prefix("gyro") {
            (SensorType::Gyro, d)
        } else if let Some(d) = text.strip_prefix("accel") {
            (SensorType::Accel, d)
        } else {
            return Err(FaultParseError::new(
                token(),
                "expected gyro or accel followed by a 0-based index, e.g. gyro2 or accel0",
            ));
        };
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(FaultParseError::new(
                token(),
                format!(
                    "expected a 0-based index after {:?}, e.g. {}0",
                    sensor.name(),
                    sensor.name()
                ),
            ));
        }
        match digits.parse::<usize>() {
            Ok(index) if index < MAX_CHANNELS => Ok(Self {
                sensor,
                // Below MAX_CHANNELS (16), so it fits.
                index: index as u8,
            }),
            _ => Err(FaultParseError::new(
                token(),
                format!("index {digits} is out of range 0..={}", MAX_CHANNELS - 1),
            )),
        }
    }

    /// Checks the index against the channels the sensor block has of this type.
    pub fn check_fitted(&self, n_gyro: usize, n_accel: usize) -> Result<(), FaultParseError> {
        let n = match self.sensor {
            SensorType::Gyro => n_gyro,
            SensorType::Accel => n_accel,
        };
        if usize::from(self.index) < n {
            Ok(())
        } else {
            Err(FaultParseError::new(
                format!("channel \"{self}\""),
                format!(
                    "the sensor block has {n} {} channels (0..={})",
                    self.sensor.name(),
                    n.saturating_sub(1)
                ),
            ))
        }
    }

    /// The simulator's name for the sensor type.
    pub fn inertial_sensor(&self) -> InertialSensor {
        match self.sensor {
            SensorType::Gyro => InertialSensor::Gyro,
            SensorType::Accel => InertialSensor::Accel,
        }
    }
}

impl fmt::Display for ChannelId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", self.sensor.name(), self.index)
    }
}

/// What a fault's argument is, for messages and validation.
struct ArgSpec {
    name: &'static str,
    unit: &'static str,
    required: bool,
}

fn arg_spec(fault: SimFault) -> Option<ArgSpec> {
    match fault {
        SimFault::BiasStep => Some(ArgSpec {
            name: "STEP",
            unit: "rad/s for gyros, m/s² for accelerometers",
            required: true,
        }),
        SimFault::Ramp => Some(ArgSpec {
            name: "RATE",
            unit: "rad/s per s for gyros, m/s² per s for accelerometers",
            required: true,
        }),
        SimFault::Noise => Some(ArgSpec {
            name: "FACTOR",
            unit: "multiplies the configured white noise, >= 1",
            required: true,
        }),
        SimFault::Intermittent => Some(ArgSpec {
            name: "PERIOD_S",
            unit: "seconds; dead for the first half of each period",
            required: false,
        }),
        SimFault::Disconnect => Some(ArgSpec {
            name: "DURATION_S",
            unit: "seconds the device stays unplugged, > 0 and <= 3600",
            required: true,
        }),
        SimFault::GnssOutage | SimFault::GnssFreeze => Some(ArgSpec {
            name: "DURATION_S",
            unit: "seconds, >= 0 (0: until cleared)",
            required: false,
        }),
        SimFault::GnssJump => Some(ArgSpec {
            name: "METRES",
            unit: "metres north",
            required: true,
        }),
        SimFault::GnssDrift => Some(ArgSpec {
            name: "M_PER_S",
            unit: "metres per second north",
            required: true,
        }),
        SimFault::Clear | SimFault::Dead | SimFault::Stuck | SimFault::Saturate => None,
    }
}

/// Checks a fault parameter; the reason says what it must be.
pub fn check_param(fault: SimFault, param: f64) -> Result<(), &'static str> {
    let ok = match fault {
        SimFault::BiasStep | SimFault::Ramp => param.is_finite(),
        SimFault::Noise => param.is_finite() && param >= 1.0,
        SimFault::Intermittent => {
            param.is_finite() && param > 0.0 && param <= MAX_INTERMITTENT_PERIOD_S
        }
        SimFault::Disconnect => Disconnect::new(param).is_ok(),
        SimFault::GnssOutage | SimFault::GnssFreeze => {
            param.is_finite() && (0.0..=MAX_INTERMITTENT_PERIOD_S).contains(&param)
        }
        SimFault::GnssJump | SimFault::GnssDrift => param.is_finite(),
        SimFault::Clear | SimFault::Dead | SimFault::Stuck | SimFault::Saturate => true,
    };
    if ok {
        return Ok(());
    }
    Err(match fault {
        SimFault::Noise => {
            "must be a finite number >= 1 (it multiplies the configured white noise)"
        }
        SimFault::Intermittent => "must be > 0 and <= 3600 seconds",
        SimFault::Disconnect => DURATION_RANGE,
        SimFault::GnssOutage | SimFault::GnssFreeze => "must be >= 0 and <= 3600 seconds",
        _ => "must be a finite number",
    })
}

/// Every fault kind's name, for messages (the channel faults, then the whole-device one).
fn kind_names() -> String {
    let names: Vec<&str> = [
        SimFault::Dead,
        SimFault::Stuck,
        SimFault::BiasStep,
        SimFault::Ramp,
        SimFault::Noise,
        SimFault::Saturate,
        SimFault::Intermittent,
        SimFault::Clear,
    ]
    .iter()
    .map(|f| f.name())
    .collect();
    format!(
        "{} (for a channel) or {} (the whole device)",
        names.join(", "),
        SimFault::Disconnect.name()
    )
}

/// Parses a fault kind name (`dead`, `bias`, ...).
pub fn parse_kind(text: &str) -> Result<SimFault, FaultParseError> {
    SimFault::from_name(text).ok_or_else(|| {
        FaultParseError::new(
            format!("fault {text:?}"),
            format!("expected one of {}", kind_names()),
        )
    })
}

/// A validated fault command for one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultCommand {
    /// The channel the fault is applied to.
    pub channel: ChannelId,
    /// The kind of fault; it decides whether `param` is used and its unit.
    pub fault: SimFault,
    /// SI parameter (see [`SimFault`]); 0 for faults without one.
    pub param: f64,
}

impl FaultCommand {
    /// Builds a command from a numeric parameter, checking that it is given exactly when the fault
    /// takes one and that it is in range.
    pub fn new(
        channel: ChannelId,
        fault: SimFault,
        param: Option<f64>,
    ) -> Result<Self, FaultParseError> {
        if fault == SimFault::Disconnect {
            return Err(FaultParseError::new(
                format!("channel \"{channel}\""),
                DISCONNECT_HAS_NO_CHANNEL,
            ));
        }
        let param = match (arg_spec(fault), param) {
            (None, None) => 0.0,
            (None, Some(p)) => {
                return Err(FaultParseError::new(
                    format!("{} {p}", fault.name()),
                    "this fault takes no argument",
                ));
            }
            (Some(spec), None) if spec.required => {
                return Err(FaultParseError::new(
                    fault.name(),
                    format!("needs {} ({})", spec.name, spec.unit),
                ));
            }
            (Some(_), None) => DEFAULT_INTERMITTENT_PERIOD_S,
            (Some(spec), Some(p)) => {
                check_param(fault, p).map_err(|reason| {
                    FaultParseError::new(format!("{} {} = {p}", fault.name(), spec.name), reason)
                })?;
                p
            }
        };
        Ok(Self {
            channel,
            fault,
            param,
        })
    }

    /// Parses `CHANNEL FAULT [ARG]` as typed on the command line.
    pub fn parse(channel: &str, kind: &str, arg: Option<&str>) -> Result<Self, FaultParseError> {
        let channel = ChannelId::parse(channel)?;
        let fault = parse_kind(kind)?;
        let param = match arg {
            None => None,
            Some(text) => Some(parse_number(fault, text)?),
        };
        Self::new(channel, fault, param)
    }

    /// The IPC command.
    pub fn to_control(&self) -> SimControl {
        SimControl {
            version: PAYLOAD_VERSION,
            sensor: self.channel.sensor as u8,
            channel: self.channel.index,
            fault: self.fault as u8,
            _pad: [0; 3],
            param: self.param,
        }
    }

    /// Decodes and validates an IPC command.
    pub fn from_control(control: &SimControl) -> Result<Self, ControlError> {
        if !control.is_current() {
            return Err(ControlError::Unknown);
        }
        let sensor = SensorType::from_u8(control.sensor).ok_or(ControlError::Unknown)?;
        let fault = SimFault::from_u8(control.fault)
            .filter(|&f| f != SimFault::Disconnect)
            .ok_or(ControlError::Unknown)?;
        if usize::from(control.channel) >= MAX_CHANNELS {
            return Err(ControlError::NoSuchChannel);
        }
        check_param(fault, control.param).map_err(|_| ControlError::InvalidParameter)?;
        Ok(Self {
            channel: ChannelId {
                sensor,
                index: control.channel,
            },
            fault,
            param: control.param,
        })
    }

    /// The fault to set on the channel, or `None` to clear it. `noise` is the configured white
    /// noise σ per sample, which a noise factor F scales: F·σ in total is σ plus independent extra
    /// noise of σ·√(F² − 1).
    pub fn channel_fault(&self, noise: &WhiteNoise) -> Option<ChannelFault> {
        let p = self.param;
        match self.fault {
            SimFault::Clear => None,
            SimFault::Dead => Some(ChannelFault::Dead),
            SimFault::Stuck => Some(ChannelFault::Stuck),
            SimFault::BiasStep => Some(ChannelFault::BiasStep { bias: p }),
            SimFault::Ramp => Some(ChannelFault::Ramp { rate_per_s: p }),
            SimFault::Noise => Some(ChannelFault::NoiseBurst {
                sigma: noise.sigma(self.channel.sensor) * (p * p - 1.0).max(0.0).sqrt(),
            }),
            SimFault::Saturate => Some(ChannelFault::Saturated),
            SimFault::Intermittent => Some(ChannelFault::Intermittent {
                period_s: p,
                dropout_s: 0.5 * p,
            }),
            // Never a channel's fault: `new` and `from_control` refuse them, so nothing to set.
            SimFault::Disconnect
            | SimFault::GnssOutage
            | SimFault::GnssJump
            | SimFault::GnssFreeze
            | SimFault::GnssDrift => None,
        }
    }
}

impl fmt::Display for FaultCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.channel, self.fault.name())?;
        if arg_spec(self.fault).is_some() {
            write!(f, " {}", self.param)?;
        }
        Ok(())
    }
}

/// Parses a fault's numeric argument; the error names the fault, the argument and the text.
pub fn parse_number(fault: SimFault, text: &str) -> Result<f64, FaultParseError> {
    let Some(spec) = arg_spec(fault) else {
        return Err(FaultParseError::new(
            format!("{} {text:?}", fault.name()),
            "this fault takes no argument",
        ));
    };
    text.trim().parse::<f64>().map_err(|_| {
        FaultParseError::new(
            format!("{} {} {text:?}", fault.name(), spec.name),
            format!("not a number ({})", spec.unit),
        )
    })
}

/// Why the simulator refused an IPC command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControlError {
    /// Wrong payload version, unknown sensor type or fault kind.
    Unknown,
    /// Channel index beyond the block's channels.
    NoSuchChannel,
    /// Parameter out of range for the fault.
    InvalidParameter,
}

/// Configured white-noise σ per sample of each inertial sensor type (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WhiteNoise {
    /// Gyro σ per sample, rad/s.
    pub gyro_rps: f64,
    /// Accelerometer σ per sample, m/s².
    pub accel_mps2: f64,
}

impl WhiteNoise {
    /// σ per sample = noise density × √(sample rate), as the sensor model draws it.
    pub fn from_config(config: &SimConfig) -> Self {
        let sqrt_rate = config.imu_rate_hz.sqrt();
        let s = &config.sensors;
        Self {
            gyro_rps: s.gyro_noise_density_dps_rthz.to_radians() * sqrt_rate,
            accel_mps2: s.accel_noise_density_ug_rthz * 1e-6 * STANDARD_GRAVITY * sqrt_rate,
        }
    }

    /// The σ per sample of `sensor`'s channels, in its SI unit (rad/s or m/s²).
    pub fn sigma(&self, sensor: SensorType) -> f64 {
        match sensor {
            SensorType::Gyro => self.gyro_rps,
            SensorType::Accel => self.accel_mps2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(r: Result<FaultCommand, FaultParseError>) -> FaultParseError {
        r.expect_err("should be rejected")
    }

    #[test]
    fn channels_parse_with_sensor_and_index() {
        let c = ChannelId::parse("gyro2").unwrap();
        assert_eq!((c.sensor, c.index), (SensorType::Gyro, 2));
        let c = ChannelId::parse("accel15").unwrap();
        assert_eq!((c.sensor, c.index), (SensorType::Accel, 15));
        assert_eq!(c.to_string(), "accel15");
        for bad in ["gyro", "gyro16", "gyro-1", "mag0", "gyro2x", "Gyro2", ""] {
            let e = ChannelId::parse(bad).expect_err(bad);
            assert!(e.token.contains(&format!("{bad:?}")), "{bad}: {e}");
        }
        assert!(
            ChannelId::parse("gyro16")
                .unwrap_err()
                .reason
                .contains("0..=15")
        );
    }

    #[test]
    fn fitted_channels_are_checked_against_the_block() {
        let c = ChannelId::parse("accel4").unwrap();
        let e = c.check_fitted(4, 4).unwrap_err();
        assert!(e.to_string().contains("accel4") && e.reason.contains("4 accel channels"));
        assert!(c.check_fitted(4, 5).is_ok());
        assert!(
            ChannelId::parse("gyro3")
                .unwrap()
                .check_fitted(4, 0)
                .is_ok()
        );
    }

    #[test]
    fn commands_parse_with_their_arguments() {
        let c = FaultCommand::parse("gyro2", "dead", None).unwrap();
        assert_eq!((c.fault, c.param), (SimFault::Dead, 0.0));
        let c = FaultCommand::parse("accel1", "bias", Some("-0.5")).unwrap();
        assert_eq!((c.fault, c.param), (SimFault::BiasStep, -0.5));
        let c = FaultCommand::parse("gyro1", "ramp", Some("0.01")).unwrap();
        assert_eq!((c.fault, c.param), (SimFault::Ramp, 0.01));
        let c = FaultCommand::parse("gyro0", "noise", Some("10")).unwrap();
        assert_eq!((c.fault, c.param), (SimFault::Noise, 10.0));
        let c = FaultCommand::parse("accel3", "intermittent", None).unwrap();
        assert_eq!(c.param, DEFAULT_INTERMITTENT_PERIOD_S);
        let c = FaultCommand::parse("accel3", "intermittent", Some("0.5")).unwrap();
        assert_eq!(c.param, 0.5);
        assert_eq!(c.to_string(), "accel3 intermittent 0.5");
        for kind in ["stuck", "saturate", "clear"] {
            assert!(FaultCommand::parse("gyro0", kind, None).is_ok(), "{kind}");
        }
    }

    #[test]
    fn bad_arguments_name_the_argument_and_value() {
        let e = err(FaultCommand::parse("gyro2", "explode", None));
        assert!(
            e.token.contains("\"explode\"") && e.reason.contains("dead"),
            "{e}"
        );
        let e = err(FaultCommand::parse("gyro2", "bias", None));
        assert!(
            e.to_string().contains("bias") && e.reason.contains("STEP"),
            "{e}"
        );
        let e = err(FaultCommand::parse("gyro2", "bias", Some("abc")));
        assert_eq!(e.token, "bias STEP \"abc\"");
        let e = err(FaultCommand::parse("gyro2", "noise", Some("0.5")));
        assert_eq!(e.token, "noise FACTOR = 0.5");
        assert!(e.reason.contains(">= 1"));
        let e = err(FaultCommand::parse("gyro2", "dead", Some("3")));
        assert!(
            e.token.contains("dead") && e.reason.contains("no argument"),
            "{e}"
        );
        let e = err(FaultCommand::parse("gyro2", "intermittent", Some("0")));
        assert!(e.token.contains("PERIOD_S = 0"), "{e}");
        let e = err(FaultCommand::parse("gyro2", "bias", Some("inf")));
        assert!(e.reason.contains("finite"), "{e}");
        let e = err(FaultCommand::parse("gyro99", "dead", None));
        assert!(e.token.contains("gyro99"), "{e}");
    }

    #[test]
    fn control_round_trips_and_rejects_garbage() {
        let c = FaultCommand::parse("accel3", "ramp", Some("0.25")).unwrap();
        let ctl = c.to_control();
        assert_eq!(ctl.sensor, SensorType::Accel as u8);
        assert_eq!(ctl.channel, 3);
        assert_eq!(FaultCommand::from_control(&ctl), Ok(c));

        let bad_sensor = SimControl { sensor: 7, ..ctl };
        assert_eq!(
            FaultCommand::from_control(&bad_sensor),
            Err(ControlError::Unknown)
        );
        let bad_fault = SimControl { fault: 99, ..ctl };
        assert_eq!(
            FaultCommand::from_control(&bad_fault),
            Err(ControlError::Unknown)
        );
        let bad_version = SimControl { version: 0, ..ctl };
        assert_eq!(
            FaultCommand::from_control(&bad_version),
            Err(ControlError::Unknown)
        );
        let bad_channel = SimControl { channel: 16, ..ctl };
        assert_eq!(
            FaultCommand::from_control(&bad_channel),
            Err(ControlError::NoSuchChannel)
        );
        let noise = FaultCommand::parse("gyro0", "noise", Some("2")).unwrap();
        let bad_param = SimControl {
            param: 0.5,
            ..noise.to_control()
        };
        assert_eq!(
            FaultCommand::from_control(&bad_param),
            Err(ControlError::InvalidParameter)
        );
        let nan = SimControl {
            param: f64::NAN,
            ..ctl
        };
        assert_eq!(
            FaultCommand::from_control(&nan),
            Err(ControlError::InvalidParameter)
        );
    }

    #[test]
    fn noise_factor_adds_independent_noise_to_reach_the_total() {
        let noise = WhiteNoise {
            gyro_rps: 0.003,
            accel_mps2: 0.05,
        };
        for factor in [1.0, 2.0, 10.0] {
            let c = FaultCommand::parse("accel1", "noise", Some(&factor.to_string())).unwrap();
            let Some(ChannelFault::NoiseBurst { sigma }) = c.channel_fault(&noise) else {
                panic!("noise must map to a noise burst");
            };
            // Independent Gaussian noises add in variance: σ² + extra² = (F·σ)².
            let total = (noise.accel_mps2.powi(2) + sigma.powi(2)).sqrt();
            assert!(
                (total - factor * noise.accel_mps2).abs() < 1e-12,
                "{factor}: {total}"
            );
        }
    }

    #[test]
    fn commands_map_to_simulator_faults() {
        let noise = WhiteNoise {
            gyro_rps: 1.0,
            accel_mps2: 1.0,
        };
        let map = |kind: &str, arg: Option<&str>| {
            FaultCommand::parse("gyro0", kind, arg)
                .unwrap()
                .channel_fault(&noise)
        };
        assert_eq!(map("clear", None), None);
        assert_eq!(map("dead", None), Some(ChannelFault::Dead));
        assert_eq!(map("stuck", None), Some(ChannelFault::Stuck));
        assert_eq!(map("saturate", None), Some(ChannelFault::Saturated));
        assert_eq!(
            map("bias", Some("0.5")),
            Some(ChannelFault::BiasStep { bias: 0.5 })
        );
        assert_eq!(
            map("ramp", Some("0.01")),
            Some(ChannelFault::Ramp { rate_per_s: 0.01 })
        );
        assert_eq!(
            map("intermittent", Some("0.4")),
            Some(ChannelFault::Intermittent {
                period_s: 0.4,
                dropout_s: 0.2
            })
        );
    }

    #[test]
    fn white_noise_follows_the_configured_density() {
        let config = SimConfig::default();
        let w = WhiteNoise::from_config(&config);
        // 0.01 °/s/√Hz at 1 kHz: 0.01·√1000 °/s.
        let gyro = (0.01f64 * 1000f64.sqrt()).to_radians();
        assert!((w.gyro_rps - gyro).abs() < 1e-15);
        // 150 µg/√Hz at 1 kHz.
        let accel = 150e-6 * STANDARD_GRAVITY * 1000f64.sqrt();
        assert!((w.accel_mps2 - accel).abs() < 1e-15);
    }
}
