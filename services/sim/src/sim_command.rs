//! Every command the simulator takes: a fault of one channel ([`FaultCommand`]) or of the whole
//! device ([`Disconnect`]), as typed (`rins inject`, `--inject`, fault files) and as it travels on
//! [`ipc_types::names::SIM_CONTROL`]. Pure parsing and conversion.

use std::fmt;

use ipc_types::{PAYLOAD_VERSION, SimControl, SimFault};
use rins_runtime::payload::Versioned;

use crate::device_fault::Disconnect;
use crate::fault_command::{ChannelId, ControlError, FaultCommand};
use crate::fault_parse_error::FaultParseError;

/// A validated simulator command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimCommand {
    /// A fault (or its clearing) on one inertial channel.
    Channel(FaultCommand),
    /// The serial line unplugged for a while.
    Disconnect(Disconnect),
    /// A fault of the simulated GNSS receiver (or [`SimFault::Clear`] to end it).
    Gnss {
        /// One of the `Gnss*` faults, or `Clear`.
        fault: SimFault,
        /// Its parameter (0 for `clear`, and for an outage or freeze until cleared).
        param: f64,
    },
}

/// The target name of the GNSS receiver in `rins inject gnss …` and `gnss:KIND=PARAM@TIME`.
pub const GNSS_TARGET: &str = "gnss";

/// What a deployment has fitted, against which a fault is checked before it is scheduled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FittedSources {
    /// Gyro channels of the sensor block.
    pub n_gyro: usize,
    /// Accelerometer channels of the sensor block.
    pub n_accel: usize,
    /// A (simulated) GNSS receiver runs.
    pub gnss_receiver: bool,
}

impl SimCommand {
    /// A GNSS receiver fault from its short name (`outage`, `jump`, `freeze`, `drift`, `clear`)
    /// and parameter; errors name the piece that is wrong.
    pub fn gnss(kind: &str, param: Option<f64>) -> Result<Self, FaultParseError> {
        let fault = match kind {
            "clear" => SimFault::Clear,
            "outage" => SimFault::GnssOutage,
            "jump" => SimFault::GnssJump,
            "freeze" => SimFault::GnssFreeze,
            "drift" => SimFault::GnssDrift,
            other => {
                return Err(FaultParseError::new(
                    format!("gnss fault {other:?}"),
                    "expected outage [SECONDS], jump METRES, freeze [SECONDS], drift M_PER_S or clear",
                ));
            }
        };
        let param = match (fault, param) {
            (SimFault::Clear, None) => 0.0,
            (SimFault::Clear, Some(p)) => {
                return Err(FaultParseError::new(
                    format!("gnss clear {p}"),
                    "takes no parameter",
                ));
            }
            (SimFault::GnssOutage | SimFault::GnssFreeze, p) => p.unwrap_or(0.0),
            (_, Some(p)) => p,
            (_, None) => {
                return Err(FaultParseError::new(
                    format!("gnss {kind}"),
                    "needs its parameter: jump METRES or drift M_PER_S",
                ));
            }
        };
        crate::fault_command::check_param(fault, param)
            .map_err(|reason| FaultParseError::new(format!("gnss {kind} {param}"), reason))?;
        Ok(Self::Gnss { fault, param })
    }
}

impl SimCommand {
    /// Builds a command from its parts as a schedule gives them: a channel for channel faults,
    /// none for the whole device. Errors name the missing or superfluous piece.
    pub fn new(
        channel: Option<ChannelId>,
        fault: SimFault,
        param: Option<f64>,
    ) -> Result<Self, FaultParseError> {
        match (channel, fault) {
            (Some(channel), _) => FaultCommand::new(channel, fault, param).map(Self::Channel),
            (None, SimFault::Disconnect) => {
                let Some(duration_s) = param else {
                    return Err(FaultParseError::new(
                        fault.name(),
                        "needs DURATION_S (seconds the device stays unplugged)",
                    ));
                };
                Disconnect::new(duration_s)
                    .map(Self::Disconnect)
                    .map_err(|reason| {
                        FaultParseError::new(
                            format!("disconnect DURATION_S = {duration_s}"),
                            reason,
                        )
                    })
            }
            (None, _) => Err(FaultParseError::new(
                format!("fault {:?}", fault.name()),
                "needs a CHANNEL (gyro or accel followed by its 0-based index, e.g. gyro2)",
            )),
        }
    }

    /// Parses the arguments of `rins inject`: `CHANNEL FAULT [ARG]`, or `disconnect` with
    /// `--duration SECONDS`.
    pub fn parse_inject(
        target: &str,
        fault: Option<&str>,
        arg: Option<&str>,
        duration: Option<&str>,
    ) -> Result<Self, FaultParseError> {
        if target == SimFault::Disconnect.name() {
            if let Some(extra) = fault.or(arg) {
                return Err(FaultParseError::new(
                    format!("disconnect {extra:?}"),
                    "takes no channel or fault: rins inject disconnect --duration SECONDS",
                ));
            }
            let Some(text) = duration else {
                return Err(FaultParseError::new(
                    "disconnect",
                    "needs --duration SECONDS (how long the device stays unplugged)",
                ));
            };
            return Disconnect::parse("disconnect --duration", text).map(Self::Disconnect);
        }
        if target == GNSS_TARGET {
            let Some(kind) = fault else {
                return Err(FaultParseError::new(
                    "gnss",
                    "needs a FAULT: outage [SECONDS], jump METRES, freeze [SECONDS], drift M_PER_S or clear",
                ));
            };
            let param = arg
                .map(|a| {
                    a.parse::<f64>().map_err(|_| {
                        FaultParseError::new(format!("gnss {kind} {a:?}"), "expected a number")
                    })
                })
                .transpose()?;
            return Self::gnss(kind, param.or(duration.and_then(|d| d.parse().ok())));
        }
        let channel = ChannelId::parse(target)?;
        if let Some(text) = duration {
            return Err(FaultParseError::new(
                format!("--duration {text:?}"),
                "only the disconnect fault takes a duration (rins inject disconnect --duration S)",
            ));
        }
        let Some(kind) = fault else {
            return Err(FaultParseError::new(
                format!("channel \"{channel}\""),
                "needs a FAULT: dead, stuck, bias, ramp, noise, saturate, intermittent or clear",
            ));
        };
        // A disconnect given a channel is refused by `FaultCommand::new`, naming the channel.
        FaultCommand::parse(target, kind, arg).map(Self::Channel)
    }

    /// The fault kind.
    pub fn fault(&self) -> SimFault {
        match self {
            Self::Channel(c) => c.fault,
            Self::Disconnect(_) => SimFault::Disconnect,
            Self::Gnss { fault, .. } => *fault,
        }
    }

    /// The SI parameter (0 for faults without one).
    pub fn param(&self) -> f64 {
        match self {
            Self::Channel(c) => c.param,
            Self::Disconnect(d) => d.duration_s,
            Self::Gnss { param, .. } => *param,
        }
    }

    /// The channel addressed, `None` for the whole device.
    pub fn channel(&self) -> Option<ChannelId> {
        match self {
            Self::Channel(c) => Some(c.channel),
            Self::Disconnect(_) | Self::Gnss { .. } => None,
        }
    }

    /// What the command addresses, for messages: the channel's name, `gnss` or `device`.
    pub fn target(&self) -> String {
        if matches!(self, Self::Gnss { .. }) {
            return GNSS_TARGET.to_string();
        }
        self.channel()
            .map_or_else(|| "device".to_string(), |c| c.to_string())
    }

    /// Checks the command against what is fitted: a channel against the block's channels, a GNSS
    /// fault against the receiver; a disconnect fits any block.
    pub fn check_fitted(&self, fitted: &FittedSources) -> Result<(), FaultParseError> {
        match self {
            Self::Channel(c) => c.channel.check_fitted(fitted.n_gyro, fitted.n_accel),
            Self::Disconnect(_) => Ok(()),
            // Accepted without a receiver, the fault would change nothing and the run would look
            // like a receiver that survived it.
            Self::Gnss { fault, .. } if !fitted.gnss_receiver => Err(FaultParseError::new(
                fault.name(),
                "no GNSS receiver is fitted: run with --gnss (or [gnss] enabled = true)",
            )),
            Self::Gnss { .. } => Ok(()),
        }
    }

    /// The IPC command.
    pub fn to_control(&self) -> SimControl {
        match self {
            Self::Channel(c) => c.to_control(),
            Self::Disconnect(d) => SimControl {
                version: PAYLOAD_VERSION,
                sensor: SimControl::WHOLE_DEVICE,
                channel: 0,
                fault: SimFault::Disconnect as u8,
                _pad: [0; 3],
                param: d.duration_s,
            },
            Self::Gnss { fault, param } => SimControl {
                version: PAYLOAD_VERSION,
                sensor: SimControl::GNSS_RECEIVER,
                channel: 0,
                fault: *fault as u8,
                _pad: [0; 3],
                param: *param,
            },
        }
    }

    /// Decodes and validates an IPC command.
    pub fn from_control(control: &SimControl) -> Result<Self, ControlError> {
        if !control.is_current() {
            return Err(ControlError::Unknown);
        }
        if control.sensor == SimControl::GNSS_RECEIVER {
            let fault = SimFault::from_u8(control.fault).ok_or(ControlError::Unknown)?;
            let gnss_fault = matches!(
                fault,
                SimFault::Clear
                    | SimFault::GnssOutage
                    | SimFault::GnssJump
                    | SimFault::GnssFreeze
                    | SimFault::GnssDrift
            );
            if !gnss_fault || control.channel != 0 {
                return Err(ControlError::Unknown);
            }
            crate::fault_command::check_param(fault, control.param)
                .map_err(|_| ControlError::InvalidParameter)?;
            return Ok(Self::Gnss {
                fault,
                param: control.param,
            });
        }
        if control.fault != SimFault::Disconnect as u8 {
            return FaultCommand::from_control(control).map(Self::Channel);
        }
        if control.sensor != SimControl::WHOLE_DEVICE || control.channel != 0 {
            return Err(ControlError::Unknown);
        }
        Disconnect::new(control.param)
            .map(Self::Disconnect)
            .map_err(|_| ControlError::InvalidParameter)
    }
}

impl fmt::Display for SimCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Channel(c) => c.fmt(f),
            Self::Disconnect(d) => d.fmt(f),
            Self::Gnss { fault, param } => write!(f, "{GNSS_TARGET} {} {param}", fault.name()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inject(
        target: &str,
        fault: Option<&str>,
        arg: Option<&str>,
        duration: Option<&str>,
    ) -> Result<SimCommand, FaultParseError> {
        SimCommand::parse_inject(target, fault, arg, duration)
    }

    #[test]
    fn every_fault_kind_round_trips_through_its_number_and_name() {
        for (i, f) in SimFault::ALL.iter().enumerate() {
            assert_eq!(*f as usize, i, "{f:?}");
            assert_eq!(SimFault::from_u8(*f as u8), Some(*f));
            assert_eq!(SimFault::from_name(f.name()), Some(*f));
        }
        assert_eq!(
            SimFault::from_name("disconnect"),
            Some(SimFault::Disconnect)
        );
    }

    #[test]
    fn inject_parses_a_disconnect_and_channel_faults() {
        let d = inject("disconnect", None, None, Some("2")).unwrap();
        assert_eq!(d, SimCommand::Disconnect(Disconnect { duration_s: 2.0 }));
        assert_eq!(
            (d.fault(), d.param(), d.channel()),
            (SimFault::Disconnect, 2.0, None)
        );
        assert_eq!(d.target(), "device");
        assert_eq!(d.to_string(), "disconnect 2 s");
        let none = FittedSources {
            n_gyro: 0,
            n_accel: 0,
            gnss_receiver: false,
        };
        assert!(d.check_fitted(&none).is_ok());
        let c = inject("gyro2", Some("bias"), Some("0.5"), None).unwrap();
        assert_eq!((c.fault(), c.param()), (SimFault::BiasStep, 0.5));
        assert_eq!(c.target(), "gyro2");
        let two_gyros = FittedSources {
            n_gyro: 2,
            n_accel: 4,
            gnss_receiver: false,
        };
        assert!(c.check_fitted(&two_gyros).is_err());
    }

    #[test]
    fn a_gnss_fault_without_a_receiver_is_refused_naming_it() {
        let jump = inject("gnss", Some("jump"), Some("50"), None).unwrap();
        let mut fitted = FittedSources {
            n_gyro: 4,
            n_accel: 4,
            gnss_receiver: false,
        };
        let err = jump.check_fitted(&fitted).unwrap_err().to_string();
        assert!(
            err.contains("gnss-jump") && err.contains("no GNSS receiver"),
            "{err}"
        );
        fitted.gnss_receiver = true;
        assert!(jump.check_fitted(&fitted).is_ok());
    }

    #[test]
    fn inject_errors_name_the_offending_piece() {
        let e = |t, f, a, d| inject(t, f, a, d).expect_err("should be rejected");
        let err = e("disconnect", None, None, None);
        assert!(err.reason.contains("--duration"), "{err}");
        let err = e("disconnect", None, None, Some("abc"));
        assert_eq!(err.token, "disconnect --duration \"abc\"");
        let err = e("disconnect", None, None, Some("0"));
        assert_eq!(err.token, "disconnect --duration = 0");
        assert!(err.reason.contains("> 0"), "{err}");
        let err = e("disconnect", Some("gyro2"), None, Some("1"));
        assert!(
            err.token.contains("\"gyro2\"") && err.reason.contains("no channel"),
            "{err}"
        );
        let err = e("gyro2", Some("dead"), None, Some("1"));
        assert_eq!(err.token, "--duration \"1\"");
        let err = e("gyro2", Some("disconnect"), None, None);
        assert!(
            err.token.contains("gyro2") && err.reason.contains("whole device"),
            "{err}"
        );
        let err = e("gyro2", None, None, None);
        assert!(err.reason.contains("needs a FAULT"), "{err}");
        let err = e("gyro", Some("dead"), None, None);
        assert!(err.token.contains("channel \"gyro\""), "{err}");
    }

    #[test]
    fn schedule_parts_need_a_channel_exactly_for_channel_faults() {
        let gyro2 = ChannelId::parse("gyro2").ok();
        let d = SimCommand::new(None, SimFault::Disconnect, Some(1.5)).unwrap();
        assert_eq!(d.param(), 1.5);
        let err = SimCommand::new(None, SimFault::Disconnect, None).unwrap_err();
        assert!(err.reason.contains("DURATION_S"), "{err}");
        let err = SimCommand::new(None, SimFault::Disconnect, Some(-1.0)).unwrap_err();
        assert_eq!(err.token, "disconnect DURATION_S = -1");
        let err = SimCommand::new(gyro2, SimFault::Disconnect, Some(1.0)).unwrap_err();
        assert!(err.reason.contains("whole device"), "{err}");
        let err = SimCommand::new(None, SimFault::Dead, None).unwrap_err();
        assert!(
            err.token.contains("\"dead\"") && err.reason.contains("CHANNEL"),
            "{err}"
        );
        assert!(SimCommand::new(gyro2, SimFault::Dead, None).is_ok());
    }

    #[test]
    fn control_round_trips_and_rejects_malformed_disconnects() {
        let d = SimCommand::new(None, SimFault::Disconnect, Some(0.75)).unwrap();
        let ctl = d.to_control();
        assert_eq!(ctl.sensor, SimControl::WHOLE_DEVICE);
        assert_eq!(SimCommand::from_control(&ctl), Ok(d));
        let c = inject("accel1", Some("dead"), None, None).unwrap();
        assert_eq!(SimCommand::from_control(&c.to_control()), Ok(c));
        let bad = [
            (
                SimControl { param: 0.0, ..ctl },
                ControlError::InvalidParameter,
            ),
            (
                SimControl {
                    param: f64::NAN,
                    ..ctl
                },
                ControlError::InvalidParameter,
            ),
            (SimControl { sensor: 0, ..ctl }, ControlError::Unknown),
            (SimControl { channel: 3, ..ctl }, ControlError::Unknown),
            (SimControl { version: 0, ..ctl }, ControlError::Unknown),
        ];
        for (control, expected) in bad {
            assert_eq!(
                SimCommand::from_control(&control),
                Err(expected),
                "{control:?}"
            );
        }
        // A disconnect is never a channel's fault, whatever the sensor field says.
        let as_channel = SimControl { sensor: 0, ..ctl };
        assert_eq!(
            FaultCommand::from_control(&as_channel),
            Err(ControlError::Unknown)
        );
    }

    #[test]
    fn gnss_faults_parse_round_trip_and_name_bad_pieces() {
        let j = inject("gnss", Some("jump"), Some("50"), None).unwrap();
        assert_eq!(
            j,
            SimCommand::Gnss {
                fault: SimFault::GnssJump,
                param: 50.0
            }
        );
        assert_eq!(j.target(), "gnss");
        assert_eq!(SimCommand::from_control(&j.to_control()), Ok(j));
        let o = inject("gnss", Some("outage"), None, None).unwrap();
        assert_eq!((o.fault(), o.param()), (SimFault::GnssOutage, 0.0));
        let c = inject("gnss", Some("clear"), None, None).unwrap();
        assert_eq!(SimCommand::from_control(&c.to_control()), Ok(c));
        let err = inject("gnss", Some("wobble"), None, None).unwrap_err();
        assert!(err.token.contains("\"wobble\""), "{err}");
        let err = inject("gnss", Some("jump"), None, None).unwrap_err();
        assert!(err.reason.contains("METRES"), "{err}");
        let err = inject("gnss", Some("drift"), Some("fast"), None).unwrap_err();
        assert!(err.token.contains("\"fast\""), "{err}");
        let err = inject("gnss", Some("outage"), Some("-3"), None).unwrap_err();
        assert!(err.token.contains("-3"), "{err}");
        // A channel fault number sent to the receiver is refused.
        let bad = SimControl {
            fault: SimFault::Dead as u8,
            ..j.to_control()
        };
        assert_eq!(SimCommand::from_control(&bad), Err(ControlError::Unknown));
    }
}
