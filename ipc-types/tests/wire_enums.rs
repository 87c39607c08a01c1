//! Every wire enum: the numbers and names that travel or are typed are those of today, each
//! variant decodes back to itself, and a number or name no variant has decodes to `None`.

use rins_ipc_types::{
    ChannelState, FaultOutcome, FaultReason, Integrity, LinkError, NavMode, ReadmitOutcome,
    SensorType, ServiceKind, ServiceState, SimFault, Stage,
};

/// Checks `$enum` against its expected `(variant, wire value, name)` list, in order.
macro_rules! check_wire_enum {
    ($enum:ident, $decode:ident, [$(($variant:ident, $value:expr, $name:expr)),+ $(,)?]) => {{
        let expected = [$(($enum::$variant, $value, $name)),+];
        assert_eq!($enum::COUNT, expected.len(), stringify!($enum));
        assert_eq!($enum::ALL.map(|v| v as usize), expected.map(|(_, value, _)| value));
        for (variant, value, name) in expected {
            assert_eq!(variant as usize, value, "{variant:?}");
            assert_eq!(variant.name(), name, "{variant:?}");
            assert_eq!($enum::$decode(value as _), Some(variant), "{variant:?}");
            assert_eq!($enum::from_name(name), Some(variant), "{variant:?}");
        }
        assert_eq!($enum::$decode(expected.len() as _), None, stringify!($enum));
        assert_eq!($enum::$decode(u8::MAX as _), None, stringify!($enum));
        assert_eq!($enum::from_name(""), None, stringify!($enum));
        assert_eq!($enum::from_name(&expected[0].2.to_uppercase()), None, stringify!($enum));
    }};
}

#[test]
fn channel_state() {
    check_wire_enum!(
        ChannelState,
        from_u8,
        [
            (Ok, 0, "ok"),
            (Suspect, 1, "suspect"),
            (Excluded, 2, "excluded"),
            (Absent, 3, "absent"),
        ]
    );
    assert_eq!(ChannelState::default(), ChannelState::Ok);
}

#[test]
fn fault_reason() {
    check_wire_enum!(
        FaultReason,
        from_u8,
        [
            (None, 0, "none"),
            (Missing, 1, "missing"),
            (DeviceError, 2, "device-error"),
            (Saturated, 3, "saturated"),
            (Stuck, 4, "stuck"),
            (Noisy, 5, "noisy"),
            (Parity, 6, "parity"),
            (StationaryReference, 7, "stationary-reference"),
            (Temperature, 8, "temperature"),
        ]
    );
    assert_eq!(FaultReason::default(), FaultReason::None);
}

#[test]
fn nav_mode() {
    check_wire_enum!(
        NavMode,
        from_u8,
        [
            (Aligning, 0, "aligning"),
            (Navigating, 1, "navigating"),
            (Coasting, 2, "coasting"),
            (Invalid, 3, "invalid"),
        ]
    );
    assert_eq!(NavMode::default(), NavMode::Aligning);
    let usable = NavMode::ALL.map(NavMode::is_usable);
    assert_eq!(usable, [false, true, true, false]);
}

#[test]
fn integrity() {
    check_wire_enum!(
        Integrity,
        from_u8,
        [
            (Ok, 0, "ok"),
            (Degraded, 1, "degraded"),
            (Invalid, 2, "invalid")
        ]
    );
    assert_eq!(Integrity::default(), Integrity::Ok);
    // Ordered from best to worst: the worst of several is their maximum.
    assert!(Integrity::Ok < Integrity::Degraded && Integrity::Degraded < Integrity::Invalid);
}

#[test]
fn sensor_type() {
    check_wire_enum!(
        SensorType,
        from_u8,
        [(Gyro, 0, "gyro"), (Accel, 1, "accel")]
    );
}

#[test]
fn sim_fault() {
    check_wire_enum!(
        SimFault,
        from_u8,
        [
            (Clear, 0, "clear"),
            (Dead, 1, "dead"),
            (Stuck, 2, "stuck"),
            (BiasStep, 3, "bias"),
            (Ramp, 4, "ramp"),
            (Noise, 5, "noise"),
            (Saturate, 6, "saturate"),
            (Intermittent, 7, "intermittent"),
            (Disconnect, 8, "disconnect"),
            (GnssOutage, 9, "gnss-outage"),
            (GnssJump, 10, "gnss-jump"),
            (GnssFreeze, 11, "gnss-freeze"),
            (GnssDrift, 12, "gnss-drift"),
        ]
    );
}

#[test]
fn gnss_fix_type() {
    use rins_ipc_types::{GnssFixType, GnssProtocol};
    check_wire_enum!(
        GnssFixType,
        from_u8,
        [
            (NoFix, 0, "no-fix"),
            (DeadReckoning, 1, "dead-reckoning"),
            (Fix2d, 2, "2d"),
            (Fix3d, 3, "3d"),
            (Differential, 4, "dgps"),
            (RtkFloat, 5, "rtk-float"),
            (RtkFixed, 6, "rtk-fixed"),
        ]
    );
    check_wire_enum!(GnssProtocol, from_u8, [(Nmea, 0, "nmea"), (Ubx, 1, "ubx")]);
    assert!(GnssFixType::Fix3d.is_3d() && !GnssFixType::Fix2d.is_3d());
}

#[test]
fn fault_outcome() {
    check_wire_enum!(
        FaultOutcome,
        from_u8,
        [
            (Applied, 0, "applied"),
            (UnknownCommand, 1, "unknown-command"),
            (NoSuchChannel, 2, "no-such-channel"),
            (InvalidParameter, 3, "invalid-parameter"),
        ]
    );
}

#[test]
fn service_kind() {
    check_wire_enum!(
        ServiceKind,
        from_u8,
        [
            (Simulator, 0, "sim"),
            (Acquisition, 1, "acquisition"),
            (Fusion, 2, "fusion"),
            (Altimeter, 3, "altimeter"),
            (Navigator, 4, "navigator"),
            (Watchdog, 5, "watchdog"),
            (NavigatorStandby, 6, "navigator-standby"),
            (Mavlink, 7, "mavlink"),
            (Gnss, 8, "gnss"),
            (Bridge, 9, "bridge"),
        ]
    );
    assert_eq!(
        ServiceKind::NAVIGATOR_LANES,
        [ServiceKind::Navigator, ServiceKind::NavigatorStandby]
    );
}

#[test]
fn service_state() {
    check_wire_enum!(
        ServiceState,
        from_u8,
        [
            (Starting, 0, "starting"),
            (Running, 1, "running"),
            (Restarting, 2, "restarting"),
            (Silent, 3, "silent"),
            (GivenUp, 4, "given-up"),
        ]
    );
    assert_eq!(ServiceState::default(), ServiceState::Starting);
}

#[test]
fn stage() {
    check_wire_enum!(
        Stage,
        from_index,
        [
            (Acquisition, 0, "acquisition"),
            (Fusion, 1, "fusion"),
            (Altimeter, 2, "altimeter"),
            (Navigator, 3, "navigator"),
        ]
    );
}

#[test]
fn link_error() {
    check_wire_enum!(
        LinkError,
        from_u8,
        [
            (None, 0, "none"),
            (NoSync, 1, "no-sync"),
            (UnknownFrameType, 2, "unknown-frame-type"),
            (BadLength, 3, "bad-length"),
            (CrcMismatch, 4, "crc-mismatch"),
            (BadContent, 5, "bad-content"),
        ]
    );
    assert_eq!(LinkError::default(), LinkError::None);
}

#[test]
fn readmit_outcome() {
    check_wire_enum!(
        ReadmitOutcome,
        from_u8,
        [
            (Readmitted, 0, "readmitted"),
            (NotExcluded, 1, "not-excluded"),
            (NoSuchChannel, 2, "no-such-channel"),
            (BadRequest, 3, "bad-request"),
            (FaultStillPresent, 4, "fault-still-present"),
            (Busy, 5, "busy"),
        ]
    );
}

#[test]
fn every_flag_word_names_each_of_its_bits_once() {
    use rins_ipc_types::{aiding, bit_names, fused_flags, integrity_reason, status};
    for names in [
        &status::NAMES[..],
        &fused_flags::NAMES[..],
        &aiding::SOURCE_NAMES[..],
        &aiding::STALE_NAMES[..],
        &aiding::REJECTED_NAMES[..],
        &integrity_reason::NAMES[..],
    ] {
        let all = names.iter().fold(0u32, |acc, (bit, _)| {
            assert_eq!(bit.count_ones(), 1, "{names:?}");
            assert_eq!(acc & bit, 0, "a bit named twice in {names:?}");
            acc | bit
        });
        assert_eq!(bit_names(all, names).len(), names.len());
    }
    assert_eq!(
        bit_names(
            fused_flags::GYRO_INSUFFICIENT | 1 << 31,
            &fused_flags::NAMES
        ),
        ["gyro-insufficient"]
    );
    assert_eq!(
        bit_names(
            aiding::BARO | aiding::GRAVITY | aiding::MAG_STALE,
            &aiding::SOURCE_NAMES
        ),
        ["baro", "gravity"]
    );
}

#[test]
fn every_aiding_bit_has_a_name() {
    use rins_ipc_types::aiding::*;
    let defined = [
        BARO,
        MAG,
        ZUPT,
        HUPT,
        GRAVITY,
        GNSS,
        AIRSPEED,
        BARO_STALE,
        MAG_STALE,
        GNSS_STALE,
        GNSS_REJECTED,
    ];
    let named =
        NAME_GROUPS
            .iter()
            .flat_map(|(names, _)| names.iter())
            .fold(0u32, |acc, (bit, _)| {
                assert_eq!(acc & bit, 0, "bit {bit:#x} named twice");
                acc | bit
            });
    for bit in defined {
        assert_ne!(named & bit, 0, "aiding bit {bit:#x} has no name");
    }
    assert_eq!(named.count_ones() as usize, defined.len());
}

#[test]
fn device_status_bits_by_name() {
    use rins_ipc_types::{bit_names, status};
    assert_eq!(
        bit_names(status::DEVICE_ERROR | status::SATURATION, &status::NAMES),
        ["device-error", "saturation"]
    );
}
