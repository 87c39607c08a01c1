//! What the GNSS receiver's line carries and what the `gnss` service made of it: every byte and
//! every message counted under a name, so that a receiver whose output rins cannot use is never
//! mistaken for an absent one.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::PAYLOAD_VERSION;

/// The `gnss` service's line counters, published once a second on [`crate::names::GNSS_LINK`]
/// and carried in the watchdog's [`crate::HealthReport::gnss`]. Counters count since the service
/// started; a restarted service counts from zero.
///
/// Every byte read is in exactly one of: a used NMEA sentence, a used UBX frame, a message
/// counted as unused, bad or late, `unframed_bytes`, or the few bytes of a message still arriving.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::GnssLinkReport")]
pub struct GnssLinkReport {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// 1 once the service has reported (always 1 on the topic; in the watchdog's report 0 until
    /// the first one arrived, and the rest is meaningless while 0).
    pub heard: u8,
    /// 1 while the line carries bytes but no sentence or frame of them was usable in the last
    /// report period: a receiver set to another protocol or baud rate, or line noise.
    pub silent: u8,
    /// 1 while no byte arrived for the service's stale deadline.
    pub quiet: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 3],
    /// CLOCK_MONOTONIC ns when the service made the report.
    pub now_ns: u64,
    /// Bytes read from the receiver.
    pub bytes: u64,
    /// Times the receiver's device was reopened.
    pub reconnects: u64,
    /// NMEA sentences used (GGA, GNS, RMC, GLL, GST, VTG of any talker).
    pub sentences_used: u64,
    /// UBX frames used (NAV-PVT, HNR-PVT, NAV-SOL, NAV-POSLLH, NAV-VELNED, NAV-DOP, NAV-EOE).
    pub ubx_frames_used: u64,
    /// Valid NMEA sentences not used, by kind: GSV.
    pub unused_gsv: u64,
    /// GSA.
    pub unused_gsa: u64,
    /// ZDA.
    pub unused_zda: u64,
    /// TXT.
    pub unused_txt: u64,
    /// GBS.
    pub unused_gbs: u64,
    /// Other standard sentences.
    pub unused_other_nmea: u64,
    /// Proprietary sentences (`$P…`).
    pub unused_proprietary: u64,
    /// Valid UBX frames of other messages and `!` encapsulation sentences (AIS).
    pub unused_other_messages: u64,
    /// Sentences of a used kind with nothing to use in them (no time yet, a GST without σ).
    pub nothing_to_use: u64,
    /// NMEA sentences and UBX frames whose checksum did not match.
    pub checksum_errors: u64,
    /// NMEA sentences without a checksum (also in `checksum_errors`).
    pub without_checksum: u64,
    /// Messages with a good checksum that could not be read or hold values out of range.
    pub malformed: u64,
    /// UBX headers declaring a payload longer than any UBX message has (also in `malformed`).
    pub oversized: u64,
    /// UBX headers declaring another length than their message's (also in `malformed`).
    pub wrong_length: u64,
    /// Sentence starts dropped before their line end.
    pub resyncs: u64,
    /// Bytes in no sentence or usable frame.
    pub unframed_bytes: u64,
    /// Sentences ending in CR LF.
    pub lines_crlf: u64,
    /// Sentences ending in a bare LF.
    pub lines_lf: u64,
    /// Epochs assembled.
    pub epochs: u64,
    /// Epochs without a three-dimensional fix.
    pub epochs_without_fix: u64,
    /// Epochs published on [`crate::names::GNSS`].
    pub published: u64,
    /// Epochs that could not be published.
    pub publish_failures: u64,
    /// UBX frames that arrived after their epoch was published.
    pub ubx_late: u64,
    /// NMEA epochs not published because the receiver's UBX epochs are (one fix per epoch).
    pub nmea_epochs_superseded: u64,
    /// Periods in which the line carried bytes and nothing usable.
    pub silent_episodes: u64,
}

impl Default for GnssLinkReport {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            heard: 0,
            silent: 0,
            quiet: 0,
            _pad: [0; 3],
            now_ns: 0,
            bytes: 0,
            reconnects: 0,
            sentences_used: 0,
            ubx_frames_used: 0,
            unused_gsv: 0,
            unused_gsa: 0,
            unused_zda: 0,
            unused_txt: 0,
            unused_gbs: 0,
            unused_other_nmea: 0,
            unused_proprietary: 0,
            unused_other_messages: 0,
            nothing_to_use: 0,
            checksum_errors: 0,
            without_checksum: 0,
            malformed: 0,
            oversized: 0,
            wrong_length: 0,
            resyncs: 0,
            unframed_bytes: 0,
            lines_crlf: 0,
            lines_lf: 0,
            epochs: 0,
            epochs_without_fix: 0,
            published: 0,
            publish_failures: 0,
            ubx_late: 0,
            nmea_epochs_superseded: 0,
            silent_episodes: 0,
        }
    }
}
