//! The captures' results added up per protocol and in total, and the text table of them.

use std::fmt::Write as _;

use serde::Serialize;

use super::replay::{CHUNK_BYTES, NS_PER_BYTE, ProtocolGroup};
use super::{CaptureResult, Failure};

/// Sums over a set of captures.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Totals {
    /// Captures evaluated.
    pub captures: usize,
    /// Captures with at least one reference epoch.
    pub with_reference: usize,
    /// Of those, captures with at least one published fix matched to a reference epoch.
    pub with_reference_yielding_fix: usize,
    /// Reference epochs.
    pub reference_epochs: usize,
    /// gpsd's fixes that the receivers' own UBX output calls time-only: not reference epochs (a
    /// time-only solution measures no position; see [`super::reference`]).
    pub reference_time_only_epochs: usize,
    /// Published fixes with a position.
    pub published_with_position: usize,
    /// Published fixes matched to a reference epoch.
    pub matched: usize,
    /// `matched` as a percentage of `reference_epochs`.
    pub matched_pct: f64,
    /// Matched fixes within 1 cm of the reference horizontally.
    pub within_1cm: usize,
    /// `within_1cm` as a percentage of `reference_epochs`.
    pub within_1cm_pct: f64,
    /// Published fixes with a position that match no reference epoch.
    pub unmatched: usize,
    /// Captures whose bytes came in but of which nothing was used.
    pub silent: usize,
    /// Published fixes with a position for which their capture has a position message (GGA,
    /// GNS, RMC, GLL, NAV-PVT, NAV-POSLLH, NAV-SOL) of the same receiver time.
    pub fixes_with_own_position: usize,
    /// Of those, fixes within 1 cm of at least one such message.
    pub fixes_within_1cm_of_own: usize,
    /// Published fixes with a position without such a message, or not a number.
    pub fixes_without_own_position: usize,
    /// Largest distance of a fix from its nearest own position message, m.
    pub worst_own_horizontal_m: Option<f64>,
}

/// The totals of the captures of one protocol group.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupTotals {
    /// The group.
    pub protocols: ProtocolGroup,
    /// Its sums.
    #[serde(flatten)]
    pub totals: Totals,
}

/// The evaluation's report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CapturesReport {
    /// Bytes per decoder read.
    pub chunk_bytes: usize,
    /// Line time per byte, ns (9600 baud).
    pub ns_per_byte: u64,
    /// Every capture evaluated, in name order.
    pub captures: Vec<CaptureResult>,
    /// Captures that could not be read.
    pub failures: Vec<Failure>,
    /// Names of the captures whose bytes came in but of which nothing was used.
    pub silent_captures: Vec<String>,
    /// Sums per protocol group (groups without captures left out).
    pub by_protocol: Vec<GroupTotals>,
    /// Sums over every capture.
    pub totals: Totals,
}

/// Adds up `captures`.
pub fn totals<'a>(captures: impl IntoIterator<Item = &'a CaptureResult>) -> Totals {
    let mut t = Totals::default();
    for c in captures {
        let s = &c.score;
        t.captures += 1;
        if s.reference_epochs > 0 {
            t.with_reference += 1;
            if s.matched > 0 {
                t.with_reference_yielding_fix += 1;
            }
        }
        t.reference_epochs += s.reference_epochs;
        t.reference_time_only_epochs += c.reference_time_only_epochs;
        t.published_with_position += s.published_with_position;
        t.matched += s.matched;
        t.within_1cm += s.within_1cm;
        t.unmatched += s.unmatched;
        t.silent += usize::from(c.decoder.silent());
        t.fixes_with_own_position += c.own.fixes_with_own_position;
        t.fixes_within_1cm_of_own += c.own.fixes_within_1cm_of_own;
        t.fixes_without_own_position += c.own.fixes_without_own_position;
        if let Some(w) = c.own.worst_own {
            t.worst_own_horizontal_m = Some(
                t.worst_own_horizontal_m
                    .map_or(w.horizontal_m, |m| m.max(w.horizontal_m)),
            );
        }
    }
    t.matched_pct = pct(t.matched, t.reference_epochs);
    t.within_1cm_pct = pct(t.within_1cm, t.reference_epochs);
    t
}

/// `n` as a percentage of `of` (0 when `of` is 0).
fn pct(n: usize, of: usize) -> f64 {
    if of == 0 {
        0.0
    } else {
        100.0 * n as f64 / of as f64
    }
}

/// The report of `captures` and `failures`.
pub fn build(captures: Vec<CaptureResult>, failures: Vec<Failure>) -> CapturesReport {
    let groups = [
        ProtocolGroup::NmeaOnly,
        ProtocolGroup::UbxOnly,
        ProtocolGroup::Mixed,
        ProtocolGroup::Neither,
    ];
    let by_protocol = groups
        .into_iter()
        .map(|g| GroupTotals {
            protocols: g,
            totals: totals(captures.iter().filter(|c| c.protocols == g)),
        })
        .filter(|g| g.totals.captures > 0)
        .collect();
    CapturesReport {
        chunk_bytes: CHUNK_BYTES,
        ns_per_byte: NS_PER_BYTE,
        silent_captures: captures
            .iter()
            .filter(|c| c.decoder.silent())
            .map(|c| c.name.clone())
            .collect(),
        by_protocol,
        totals: totals(&captures),
        captures,
        failures,
    }
}

fn group_name(g: ProtocolGroup) -> &'static str {
    match g {
        ProtocolGroup::NmeaOnly => "nmea-only",
        ProtocolGroup::UbxOnly => "ubx-only",
        ProtocolGroup::Mixed => "mixed",
        ProtocolGroup::Neither => "neither",
    }
}

fn metres(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_string(), |m| format!("{m:.3}"))
}

/// The report as text: one line per capture, then the sums.
pub fn to_table(r: &CapturesReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<34} {:<9} {:>5} {:>5} {:>5} {:>5} {:>5} {:>9} {:>9} | {:>5} {:>8} {:>6} {:>11} | decoder: bytes sent ubx cksum unpars unsup malf epochs",
        "capture",
        "protocol",
        "ref",
        "tonly",
        "pub",
        "match",
        "<=1cm",
        "worst h m",
        "worst v m",
        "own",
        "own<=1cm",
        "no own",
        "worst own m"
    );
    for c in &r.captures {
        let (sc, d) = (&c.score, &c.decoder);
        let _ = writeln!(
            s,
            "{:<34} {:<9} {:>5} {:>5} {:>5} {:>5} {:>5} {:>9} {:>9} | {:>5} {:>8} {:>6} {:>11} | {} {} {} {} {} {} {} {}{}",
            c.name,
            group_name(c.protocols),
            sc.reference_epochs,
            c.reference_time_only_epochs,
            sc.published_with_position,
            sc.matched,
            sc.within_1cm,
            metres(sc.worst_horizontal_m),
            metres(sc.worst_vertical_m),
            c.own.fixes_with_own_position,
            c.own.fixes_within_1cm_of_own,
            c.own.fixes_without_own_position,
            metres(c.own.worst_own.map(|w| w.horizontal_m)),
            d.bytes,
            d.sentences,
            d.ubx_frames,
            d.checksum_errors,
            d.unparsable,
            d.unsupported,
            d.malformed,
            d.epochs,
            if d.silent() { "  SILENT" } else { "" },
        );
    }
    let _ = writeln!(
        s,
        "\n{:<10} {:>8} {:>8} {:>9} {:>9} {:>6} {:>9} {:>8} {:>9} {:>8} {:>9} {:>6} | {:>6} {:>8} {:>6} {:>11}",
        "protocol",
        "captures",
        "with ref",
        "yielding",
        "ref",
        "tonly",
        "matched",
        "%",
        "<=1cm",
        "%",
        "unmatched",
        "silent",
        "own",
        "own<=1cm",
        "no own",
        "worst own m"
    );
    let rows = r
        .by_protocol
        .iter()
        .map(|g| (group_name(g.protocols), &g.totals))
        .chain(std::iter::once(("total", &r.totals)));
    for (name, t) in rows {
        let _ = writeln!(
            s,
            "{:<10} {:>8} {:>8} {:>9} {:>9} {:>6} {:>9} {:>8.1} {:>9} {:>8.1} {:>9} {:>6} | {:>6} {:>8} {:>6} {:>11}",
            name,
            t.captures,
            t.with_reference,
            t.with_reference_yielding_fix,
            t.reference_epochs,
            t.reference_time_only_epochs,
            t.matched,
            t.matched_pct,
            t.within_1cm,
            t.within_1cm_pct,
            t.unmatched,
            t.silent,
            t.fixes_with_own_position,
            t.fixes_within_1cm_of_own,
            t.fixes_without_own_position,
            metres(t.worst_own_horizontal_m)
        );
    }
    // gpsd's latitude and longitude repeat the first epoch for some u-blox receivers while its
    // ECEF follows them: say which positions a fix is measured from.
    let _ = writeln!(
        s,
        "\n<=1cm: horizontal distance from gpsd's latitude and longitude, or from its ECEF \
         position (WGS84) where its report carries one and that is nearer"
    );
    let _ = writeln!(
        s,
        "tonly: gpsd's fixes whose epoch the receiver's own NAV-PVT/NAV-SOL calls time-only \
         (fix type 5): no position measured, not in ref"
    );
    let _ = writeln!(
        s,
        "own: published fixes for which the capture itself has a position message (GGA, GNS, RMC, \
         GLL, NAV-PVT, NAV-POSLLH, NAV-SOL) of the same receiver time (UTC within 10 ms, iTOW \
         equal, a repeated time matched epoch by epoch); own<=1cm: within 1 cm of the epoch's \
         GGA, GNS, NAV-PVT or NAV-POSLLH, or without one of its RMC, GLL or NAV-SOL; no own: \
         fixes without one"
    );
    if !r.silent_captures.is_empty() {
        let _ = writeln!(
            s,
            "silent (bytes in, nothing used): {}",
            r.silent_captures.join(", ")
        );
    }
    for f in &r.failures {
        let _ = writeln!(s, "not evaluated: {}: {}", f.name, f.reason);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss_captures::replay::ProtocolsSeen;
    use crate::gnss_captures::score::{OwnScore, Score};
    use rins_gnss_protocol::decode::GnssDecoderStats;

    fn capture(
        name: &str,
        group: ProtocolGroup,
        reference: usize,
        matched: usize,
    ) -> CaptureResult {
        CaptureResult {
            name: name.to_string(),
            protocols: group,
            seen: ProtocolsSeen::default(),
            reference_fixes_without_time: 0,
            reference_unreadable_lines: 0,
            reference_time_only_epochs: reference / 5,
            own: OwnScore {
                fixes_with_own_position: matched,
                fixes_within_1cm_of_own: matched / 2,
                fixes_without_own_position: 1,
                ..OwnScore::default()
            },
            score: Score {
                reference_epochs: reference,
                published: matched + 1,
                published_with_position: matched + 1,
                matched,
                unmatched: 1,
                within_1cm: matched / 2,
                worst_horizontal_m: Some(0.5),
                worst_vertical_m: None,
            },
            decoder: GnssDecoderStats {
                bytes: 100,
                sentences: matched as u64,
                ..GnssDecoderStats::default()
            },
        }
    }

    #[test]
    fn totals_add_up_per_group_and_overall() {
        let report = build(
            vec![
                capture("a.log", ProtocolGroup::NmeaOnly, 10, 4),
                capture("b.log", ProtocolGroup::NmeaOnly, 0, 0),
                capture("c.log", ProtocolGroup::UbxOnly, 6, 0),
                capture("d.log", ProtocolGroup::Mixed, 4, 4),
            ],
            vec![Failure {
                name: "e.log".to_string(),
                reason: "cannot read".to_string(),
            }],
        );
        let t = &report.totals;
        assert_eq!(t.captures, 4);
        assert_eq!(t.with_reference, 3);
        assert_eq!(t.with_reference_yielding_fix, 2);
        assert_eq!(t.reference_epochs, 20);
        // A fifth of each capture's reference: 2 + 0 + 1 + 0.
        assert_eq!(t.reference_time_only_epochs, 3);
        assert_eq!(t.matched, 8);
        assert!((t.matched_pct - 40.0).abs() < 1e-12);
        assert_eq!(t.within_1cm, 4);
        assert!((t.within_1cm_pct - 20.0).abs() < 1e-12);
        assert_eq!(t.unmatched, 4);
        assert_eq!(t.silent, 2);
        assert_eq!(t.fixes_with_own_position, 8);
        assert_eq!(t.fixes_within_1cm_of_own, 4);
        assert_eq!(t.fixes_without_own_position, 4);
        assert_eq!(report.silent_captures, ["b.log", "c.log"]);
        let groups: Vec<_> = report.by_protocol.iter().map(|g| g.protocols).collect();
        assert_eq!(
            groups,
            [
                ProtocolGroup::NmeaOnly,
                ProtocolGroup::UbxOnly,
                ProtocolGroup::Mixed
            ]
        );
        assert_eq!(report.by_protocol[0].totals.reference_epochs, 10);
        let table = to_table(&report);
        assert!(
            table.contains("not evaluated: e.log: cannot read"),
            "{table}"
        );
        assert!(table.contains("silent (bytes in, nothing used): b.log, c.log"));
    }

    #[test]
    fn no_reference_is_zero_percent() {
        assert_eq!(pct(3, 0), 0.0);
    }
}
