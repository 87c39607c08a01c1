use super::*;

/// A fix of `fix_type` at receiver time `receiver_s` (NMEA: time of day), received at `rx_s`.
fn fix(fix_type: GnssFixType, receiver_s: f64, rx_s: f64) -> GnssFix {
    let mut f = GnssFix {
        fix_type: fix_type as u8,
        receiver_time_us: (receiver_s * 1e6) as u64,
        latitude_rad: 0.8,
        longitude_rad: 0.2,
        ..GnssFix::default()
    };
    f.header.origin_rx_ns = (rx_s * 1e9) as u64;
    f
}

/// A listen of 2 s with these counters and epochs.
fn report(stats: GnssDecoderStats, fixes: &[GnssFix]) -> GnssLineReport {
    let mut tally = EpochTally::default();
    for f in fixes {
        tally.observe(f);
    }
    GnssLineReport {
        seconds: 2.0,
        stats,
        tally,
    }
}

fn silent(bytes: u64, unframed: u64) -> GnssDecoderStats {
    let mut s = GnssDecoderStats {
        bytes,
        ..GnssDecoderStats::default()
    };
    s.framing.unframed_bytes = unframed;
    s
}

#[test]
fn fix_classes_follow_the_fix_type() {
    assert_eq!(FixClass::of(GnssFixType::Fix3d as u8), FixClass::ThreeD);
    assert_eq!(FixClass::of(GnssFixType::RtkFixed as u8), FixClass::ThreeD);
    assert_eq!(
        FixClass::of(GnssFixType::Differential as u8),
        FixClass::ThreeD
    );
    assert_eq!(FixClass::of(GnssFixType::Fix2d as u8), FixClass::TwoD);
    assert_eq!(
        FixClass::of(GnssFixType::DeadReckoning as u8),
        FixClass::None
    );
    assert_eq!(FixClass::of(GnssFixType::NoFix as u8), FixClass::None);
    assert_eq!(FixClass::of(200), FixClass::None);
}

#[test]
fn no_bytes_asks_for_the_device_and_its_power() {
    let v = report(GnssDecoderStats::default(), &[]).verdict();
    assert!(v.starts_with("no bytes at all in 2.0 s"), "{v}");
    assert!(v.contains("powered and connected"), "{v}");
}

#[test]
fn noise_is_a_silent_line_of_unframed_bytes() {
    let mut s = silent(4000, 3990);
    s.framing.resyncs = 7;
    // A few accidental checksum failures do not outweigh 99.75 % unframed bytes.
    s.checksum_errors = 2;
    let v = report(s, &[]).verdict();
    assert!(v.starts_with("silent line: 4000 bytes"), "{v}");
    assert!(v.contains("wrong baud rate"), "{v}");
    assert!(
        v.contains("mostly unframed bytes (3990 of 4000, 7 resyncs)"),
        "{v}"
    );
}

#[test]
fn a_silent_line_names_its_dominant_message_problem() {
    let mut s = silent(4000, 100);
    s.checksum_errors = 40;
    let v = report(s, &[]).verdict();
    assert!(v.contains("mostly 40 checksum failures"), "{v}");

    // Sentences without checksum count as checksum errors too, and are told apart.
    let mut s = silent(4000, 100);
    s.checksum_errors = 30;
    s.nmea.without_checksum = 30;
    let v = report(s, &[]).verdict();
    assert!(v.contains("mostly 30 sentences without checksum"), "{v}");

    let mut s = silent(4000, 0);
    s.unsupported = 50;
    s.framing.lines_crlf = 50;
    let v = report(s, &[]).verdict();
    assert!(v.contains("only messages rins does not use"), "{v}");
}

#[test]
fn used_sentences_without_a_position_are_a_receiver_without_a_fix() {
    let s = GnssDecoderStats {
        bytes: 3000,
        sentences: 12,
        ..GnssDecoderStats::default()
    };
    let epochs = [
        fix(GnssFixType::NoFix, 10.0, 1.0),
        fix(GnssFixType::NoFix, 11.0, 2.0),
    ];
    let r = report(s, &epochs);
    assert_eq!(r.protocols(), ["NMEA"]);
    let v = r.verdict();
    assert!(
        v.starts_with("receiver without a fix: 12 NMEA sentences used, 2 epochs"),
        "{v}"
    );
    assert!(v.contains("view of the sky"), "{v}");
    assert_eq!(r.tally.last_fix, None);
}

#[test]
fn flowing_fixes_state_the_receivers_rate_and_protocol() {
    let s = GnssDecoderStats {
        bytes: 3000,
        sentences: 20,
        ..GnssDecoderStats::default()
    };
    // 1 Hz by the receiver's clock, delivered 10 times faster (a replay).
    let epochs: Vec<GnssFix> = (0..5)
        .map(|i| {
            let t = if i == 0 {
                GnssFixType::Fix2d
            } else {
                GnssFixType::Fix3d
            };
            fix(t, 100.0 + f64::from(i), 0.1 * f64::from(i))
        })
        .chain([fix(GnssFixType::NoFix, 105.0, 0.5)])
        .collect();
    let r = report(s, &epochs);
    assert_eq!((r.tally.fix_3d, r.tally.fix_2d, r.tally.no_fix), (4, 1, 1));
    assert!((r.tally.receiver_hz().unwrap() - 1.0).abs() < 1e-9);
    assert!((r.tally.arrival_hz().unwrap() - 10.0).abs() < 1e-6);
    let v = r.verdict();
    assert_eq!(
        v,
        "fixes flowing: 1.0 Hz over NMEA, 4 of 6 epochs 3-D, 1 2-D"
    );
    assert_eq!(r.tally.last_fix.unwrap().receiver_time_us, 104_000_000);
}

#[test]
fn a_span_across_midnight_falls_back_to_the_arrival_rate() {
    let epochs = [
        fix(GnssFixType::Fix3d, 86_399.0, 1.0),
        fix(GnssFixType::Fix3d, 0.0, 1.5),
    ];
    let r = report(GnssDecoderStats::default(), &epochs);
    assert_eq!(r.tally.receiver_hz(), None);
    assert!((r.tally.fix_hz().unwrap() - 2.0).abs() < 1e-6);
    // One fix has no rate at all.
    let r = report(GnssDecoderStats::default(), &epochs[..1]);
    assert_eq!(r.tally.fix_hz(), None);
}

#[test]
fn two_dimensional_fixes_only_are_flagged() {
    let s = GnssDecoderStats {
        bytes: 100,
        ubx_frames: 4,
        ..GnssDecoderStats::default()
    };
    let mut a = fix(GnssFixType::Fix2d, 1.0, 1.0);
    a.protocol = GnssProtocol::Ubx as u8;
    let v = report(s, &[a]).verdict();
    assert_eq!(
        v,
        "fixes flowing: one fix over UBX, 0 of 1 epochs 3-D, 1 2-D (2-D only: the receiver sees \
         too few satellites for a height)"
    );
}

#[test]
fn the_scan_picks_the_rate_with_the_most_used_messages() {
    assert_eq!(best_rate([(4800, 0), (9600, 30), (38_400, 2)]), Some(9600));
    // Equal counts (a pseudo-terminal ignores the rate): the first.
    assert_eq!(best_rate([(4800, 5), (9600, 5)]), Some(4800));
    assert_eq!(best_rate([(4800, 0), (9600, 0)]), None);
    assert_eq!(best_rate([]), None);

    let used = |bytes, sentences| {
        report(
            GnssDecoderStats {
                bytes,
                sentences,
                ..GnssDecoderStats::default()
            },
            &[],
        )
    };
    let v = scan_verdict(&[(4800, used(100, 0)), (9600, used(900, 14))]);
    assert_eq!(v, "receiver at 9600 baud: 14 sentences/frames used there");
    let v = scan_verdict(&[(4800, used(0, 0)), (9600, used(0, 0))]);
    assert!(v.starts_with("no bytes at any rate"), "{v}");
    let v = scan_verdict(&[(4800, used(10, 0)), (9600, used(0, 0))]);
    assert!(v.starts_with("bytes but no usable sentence"), "{v}");
}

#[test]
fn receiver_times_read_as_the_protocol_means_them() {
    let mut f = fix(GnssFixType::Fix3d, 0.0, 0.0);
    f.receiver_time_us = 45_296_789_000; // 12:34:56.789
    assert_eq!(receiver_time_text(&f), "12:34:56.789 UTC");
    f.protocol = GnssProtocol::Ubx as u8;
    f.receiver_time_us = 345_600_250_000;
    assert_eq!(receiver_time_text(&f), "GPS time of week 345600.250 s");
}

#[test]
fn every_counter_is_listed_by_name() {
    let mut s = GnssDecoderStats {
        checksum_errors: 3,
        ubx_late: 2,
        ..GnssDecoderStats::default()
    };
    s.framing.lines_lf = 9;
    s.nmea.gsv = 4;
    let all = counters(&s);
    let get = |name: &str| all.iter().find(|(n, _)| n == name).map(|(_, v)| *v);
    assert_eq!(get("checksum_errors"), Some(3));
    assert_eq!(get("ubx_late"), Some(2));
    assert_eq!(get("lines_lf"), Some(9));
    assert_eq!(get("unframed_bytes"), Some(0));
    assert_eq!(get("unused_gsv"), Some(4));
    assert_eq!(get("without_checksum"), Some(0));
    assert_eq!(get("nmea_epochs_superseded"), Some(0));
    // The service's own counts and the flags are not a probe's.
    for absent in ["published", "reconnects", "silent", "version", "now_ns"] {
        assert_eq!(get(absent), None, "{absent}");
    }
    assert!(all.iter().all(|(n, _)| !n.is_empty()));
}
