//! Who may command rins over the link, and how fast rins answers: the decisions, free of sockets
//! and clocks, that the link's reader and the service loop apply.
//!
//! A command (COMMAND_LONG) is admitted only when
//! 1. its signature is valid, when a signing key is set (unsigned, badly signed or replayed
//!    commands are refused); without a key, when the operator allowed unsigned commands or does not
//!    accept commands at all (then it is only answered "denied");
//! 2. its sender's system and component are in `command_sources` (when the list is not empty);
//! 3. the address it came from is in `command_addresses` (when the list is not empty).
//!
//! A refused command is not carried out and not answered at all: an answer would tell a stranger
//! what the gate checks, and would let anyone make rins send. Each refusal is counted under its
//! first reason, in that order.
//!
//! Acknowledgements then pass an [`AckLimiter`]: a token bucket, so that a flood of admitted
//! commands cannot make rins flood its link with COMMAND_ACKs.

use std::net::SocketAddr;

use crate::config::{CommandAddress, CommandSource, MavlinkConfig};
use crate::signing::SignatureCheck;

/// Why a command was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// Unsigned where a signature is required.
    Unsigned,
    /// Signed, but not with the key.
    BadSignature,
    /// Signed with the key but not newer than its stream's last frame.
    Replayed,
    /// From a system or component not in `command_sources`.
    Sender,
    /// From an address not in `command_addresses`.
    Address,
}

/// The rules commands are admitted by, from the configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct CommandGate {
    /// A signing key is set: commands must carry a valid signature.
    signed: bool,
    /// Without a key, unsigned commands may pass (the operator accepted the risk, or commands
    /// are off and only answered "denied").
    unsigned_pass: bool,
    sources: Vec<CommandSource>,
    addresses: Vec<CommandAddress>,
}

impl CommandGate {
    /// The gate of `config`; `signed` says whether a signing key was loaded.
    pub fn new(config: &MavlinkConfig, signed: bool) -> Self {
        Self {
            signed,
            unsigned_pass: config.allow_unsigned_commands || !config.accept_commands,
            sources: config.command_sources.clone(),
            addresses: config.command_addresses(),
        }
    }

    /// Whether a command whose frame's signature showed `signature`, sent by `(system,
    /// component)` from `from`, may pass; the first reason to refuse it otherwise.
    pub fn admit(
        &self,
        signature: SignatureCheck,
        sender: (u32, u8),
        from: SocketAddr,
    ) -> Result<(), Refusal> {
        self.admit_wired(signature, sender)?;
        if !self.addresses.is_empty() && !self.addresses.iter().any(|a| a.matches(from)) {
            return Err(Refusal::Address);
        }
        Ok(())
    }

    /// [`Self::admit`] for a command that came over a serial port: the port is a wire to one
    /// device and has no address, so only the signature and the sender are checked.
    pub fn admit_wired(&self, signature: SignatureCheck, sender: (u32, u8)) -> Result<(), Refusal> {
        let signature_ok = match signature {
            SignatureCheck::Valid => self.signed,
            SignatureCheck::NotChecked => !self.signed && self.unsigned_pass,
            SignatureCheck::Unsigned => return Err(Refusal::Unsigned),
            SignatureCheck::BadSignature => return Err(Refusal::BadSignature),
            SignatureCheck::Replayed => return Err(Refusal::Replayed),
        };
        if !signature_ok {
            return Err(Refusal::Unsigned);
        }
        if !self.sources.is_empty() && !self.sources.iter().any(|s| s.matches(sender.0, sender.1)) {
            return Err(Refusal::Sender);
        }
        Ok(())
    }
}

/// A token bucket for COMMAND_ACKs: `burst` at once, `rate_hz` a second on average.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AckLimiter {
    rate_hz: f64,
    burst: f64,
    tokens: f64,
    /// When the tokens were last counted, ns on the caller's clock.
    last_ns: Option<u64>,
}

impl AckLimiter {
    /// A full bucket of `burst` (at least 1) refilled at `rate_hz` (a non-positive or non-finite
    /// rate lets only the burst through).
    pub fn new(rate_hz: f64, burst: u32) -> Self {
        let burst = f64::from(burst.max(1));
        Self {
            rate_hz: if rate_hz.is_finite() && rate_hz > 0.0 {
                rate_hz
            } else {
                0.0
            },
            burst,
            tokens: burst,
            last_ns: None,
        }
    }

    /// Whether an acknowledgement may go at `now_ns` (a monotonic clock); takes its token if so.
    pub fn allow(&mut self, now_ns: u64) -> bool {
        if let Some(last) = self.last_ns {
            // A clock that went back adds nothing.
            let elapsed_s = now_ns.saturating_sub(last) as f64 * 1e-9;
            self.tokens = (self.tokens + elapsed_s * self.rate_hz).min(self.burst);
        }
        self.last_ns = Some(self.last_ns.map_or(now_ns, |l| l.max(now_ns)));
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(s: &str) -> SocketAddr {
        s.parse().unwrap()
    }

    fn signed_config() -> MavlinkConfig {
        MavlinkConfig {
            accept_commands: true,
            signing_key_file: Some("/k".into()),
            command_sources: vec![CommandSource {
                system: 255,
                component: Some(190),
            }],
            command_addresses: vec!["192.168.7.2".into()],
            ..MavlinkConfig::default()
        }
    }

    const GCS: (u32, u8) = (255, 190);

    #[test]
    fn a_key_admits_only_valid_signatures() {
        let gate = CommandGate::new(&signed_config(), true);
        let from = at("192.168.7.2:14550");
        assert_eq!(gate.admit(SignatureCheck::Valid, GCS, from), Ok(()));
        assert_eq!(
            gate.admit(SignatureCheck::Unsigned, GCS, from),
            Err(Refusal::Unsigned)
        );
        // The signed flag with a garbage signature.
        assert_eq!(
            gate.admit(SignatureCheck::BadSignature, GCS, from),
            Err(Refusal::BadSignature)
        );
        assert_eq!(
            gate.admit(SignatureCheck::Replayed, GCS, from),
            Err(Refusal::Replayed)
        );
        // Never "not checked" where a key is set.
        assert_eq!(
            gate.admit(SignatureCheck::NotChecked, GCS, from),
            Err(Refusal::Unsigned)
        );
    }

    #[test]
    fn signed_commands_from_others_are_refused() {
        let gate = CommandGate::new(&signed_config(), true);
        let from = at("192.168.7.2:14550");
        assert_eq!(
            gate.admit(SignatureCheck::Valid, (254, 190), from),
            Err(Refusal::Sender)
        );
        assert_eq!(
            gate.admit(SignatureCheck::Valid, (255, 191), from),
            Err(Refusal::Sender)
        );
        // A 32-bit system id whose low byte is allowed.
        assert_eq!(
            gate.admit(SignatureCheck::Valid, (255 + 256, 190), from),
            Err(Refusal::Sender)
        );
        assert_eq!(
            gate.admit(SignatureCheck::Valid, GCS, at("192.168.7.3:14550")),
            Err(Refusal::Address)
        );
        // Empty lists admit any signed sender.
        let open = MavlinkConfig {
            command_sources: Vec::new(),
            command_addresses: Vec::new(),
            ..signed_config()
        };
        let gate = CommandGate::new(&open, true);
        assert_eq!(
            gate.admit(SignatureCheck::Valid, (42, 1), at("10.1.1.1:9")),
            Ok(())
        );
    }

    #[test]
    fn without_a_key_unsigned_commands_pass_only_when_allowed() {
        let from = at("127.0.0.1:14550");
        let allowed = MavlinkConfig {
            accept_commands: true,
            allow_unsigned_commands: true,
            ..MavlinkConfig::default()
        };
        let gate = CommandGate::new(&allowed, false);
        assert_eq!(gate.admit(SignatureCheck::NotChecked, (1, 1), from), Ok(()));
        // Commands off: they pass the gate only to be answered "denied".
        let off = CommandGate::new(&MavlinkConfig::default(), false);
        assert_eq!(off.admit(SignatureCheck::NotChecked, (1, 1), from), Ok(()));
        // Accepting, not allowed unsigned, no key (a configuration validation refuses): refused.
        let unsafe_config = MavlinkConfig {
            accept_commands: true,
            ..MavlinkConfig::default()
        };
        let gate = CommandGate::new(&unsafe_config, false);
        assert_eq!(
            gate.admit(SignatureCheck::NotChecked, (1, 1), from),
            Err(Refusal::Unsigned)
        );
        // The allow-lists hold without a key too.
        let listed = MavlinkConfig {
            command_addresses: vec!["127.0.0.2".into()],
            ..allowed
        };
        let gate = CommandGate::new(&listed, false);
        assert_eq!(
            gate.admit(SignatureCheck::NotChecked, (1, 1), from),
            Err(Refusal::Address)
        );
    }

    #[test]
    fn acknowledgements_keep_to_the_rate_and_burst() {
        let mut limiter = AckLimiter::new(10.0, 5);
        // A flood of 10 000 in one second at t = 1 s..2 s: the burst, then 10 a second.
        let sent = (0..10_000u64)
            .filter(|i| limiter.allow(1_000_000_000 + i * 100_000))
            .count();
        assert!((14..=15).contains(&sent), "{sent}");
        // Quiet for a while: the bucket fills to the burst, no further.
        let t = 100_000_000_000;
        let sent = (0..100u64).filter(|i| limiter.allow(t + i)).count();
        assert_eq!(sent, 5);
        // A clock going back gives nothing.
        assert!(!limiter.allow(t - 50_000_000_000));
    }
}
