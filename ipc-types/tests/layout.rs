//! The payload layouts are the contract between processes built at different times: their size
//! and alignment must not change without a new [`PAYLOAD_VERSION`]. The figures are the layouts of
//! version 10.

use std::mem::{align_of, offset_of, size_of};

use rins_ipc_types::{
    Altitude, FaultApplied, FusedImu, FusionControl, FusionReply, GnssFix, GnssLinkReport, Header,
    Health, HealthReport, LinkReport, NavReport, NavState, PAYLOAD_VERSION, RawAirspeed, RawAux,
    RawBaro, RawImu, RawMag, RedundancyReport, ServiceHealth, SimControl, Truth,
};

/// Size and alignment in bytes of `T`.
fn layout<T>() -> (usize, usize) {
    (size_of::<T>(), align_of::<T>())
}

#[test]
fn the_layouts_are_those_of_version_10() {
    assert_eq!(PAYLOAD_VERSION, 10);
}

#[test]
fn every_payload_keeps_its_size_and_alignment() {
    assert_eq!(layout::<Header>(), (56, 8));
    assert_eq!(layout::<RawImu>(), (152, 8));
    assert_eq!(layout::<RawBaro>(), (80, 8));
    assert_eq!(layout::<RawMag>(), (80, 8));
    assert_eq!(layout::<RawAux>(), (72, 8));
    assert_eq!(layout::<RawAirspeed>(), (72, 8));
    assert_eq!(layout::<FusedImu>(), (232, 8));
    assert_eq!(layout::<Altitude>(), (88, 8));
    assert_eq!(layout::<NavState>(), (384, 8));
    assert_eq!(layout::<GnssFix>(), (152, 8));
    assert_eq!(layout::<Truth>(), (144, 8));
    assert_eq!(layout::<SimControl>(), (16, 8));
    assert_eq!(layout::<FaultApplied>(), (24, 8));
    assert_eq!(layout::<FusionControl>(), (8, 4));
    assert_eq!(layout::<FusionReply>(), (16, 4));
    assert_eq!(layout::<Health>(), (144, 8));
    assert_eq!(layout::<ServiceHealth>(), (24, 4));
    assert_eq!(layout::<LinkReport>(), (56, 8));
    assert_eq!(layout::<RedundancyReport>(), (88, 4));
    assert_eq!(layout::<NavReport>(), (16, 4));
    assert_eq!(layout::<GnssLinkReport>(), (248, 8));
    assert_eq!(layout::<HealthReport>(), (672, 8));
}

/// A reader checks the version before anything else, so it must sit at the same place in every
/// payload; the header of the pipeline payloads stays where it is.
#[test]
fn the_version_leads_every_payload_and_the_header_stays_in_place() {
    let version = [
        offset_of!(RawImu, version),
        offset_of!(RawBaro, version),
        offset_of!(RawMag, version),
        offset_of!(RawAux, version),
        offset_of!(RawAirspeed, version),
        offset_of!(GnssFix, version),
        offset_of!(FusedImu, version),
        offset_of!(Altitude, version),
        offset_of!(NavState, version),
        offset_of!(Truth, version),
        offset_of!(SimControl, version),
        offset_of!(FaultApplied, version),
        offset_of!(FusionControl, version),
        offset_of!(FusionReply, version),
        offset_of!(Health, version),
        offset_of!(HealthReport, version),
        offset_of!(GnssLinkReport, version),
    ];
    assert_eq!(version, [0; 17]);
    let header = [
        offset_of!(RawBaro, header),
        offset_of!(RawMag, header),
        offset_of!(RawAux, header),
        offset_of!(RawAirspeed, header),
        offset_of!(GnssFix, header),
        offset_of!(FusedImu, header),
        offset_of!(Altitude, header),
        offset_of!(NavState, header),
        offset_of!(Truth, header),
    ];
    assert_eq!(header, [8; 9]);
    assert_eq!(offset_of!(RawImu, header), 16);
}

/// The navigation state counts the updates of every aiding source, one `u32` each, the filter
/// state that follows them staying 8-byte aligned without hidden padding.
#[test]
fn the_navigation_state_counts_every_aiding_source() {
    assert_eq!(rins_ipc_types::AIDING_SOURCES, 7);
    assert_eq!(offset_of!(NavState, aiding_accepted), 264);
    assert_eq!(offset_of!(NavState, aiding_rejected), 292);
    assert_eq!(offset_of!(NavState, solution_start_seq), 320);
    assert_eq!(offset_of!(NavState, integrity_reasons), 380);
}
