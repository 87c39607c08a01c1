//! Every message the builders make survives MAVLink 2 framing: written with the crate's encoder
//! and read back by its decoder, each arrives as the same message with the same fields, the
//! extension fields included (a receiver that truncates them would lose ODOMETRY's reset counter
//! and quality).

use ipc_types::{NavMode, NavState};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};
use rins_mavlink::dialect::{MavMessage, MavType};
use rins_mavlink::heartbeat::{Profile, heartbeat};
use rins_mavlink::local_frame::LocalOrigin;
use rins_mavlink::odometry::{ResetCounter, odometry};
use rins_mavlink::{attitude, position, status_text, sys_status};

fn flying() -> NavState {
    let mut nav = NavState {
        mode: NavMode::Navigating as u8,
        lane: 1,
        quaternion: [0.9, 0.1, -0.2, 0.3829708],
        velocity_ned_mps: [12.0, -3.5, 0.25],
        latitude_rad: 0.8203,
        longitude_rad: 0.1396,
        altitude_m: 512.5,
        solution_start_seq: 4,
        ..NavState::default()
    };
    nav.covariance_diag[6] = 0.25;
    nav.header.origin_rx_ns = 987_654_321_000;
    nav
}

/// Writes `msg` as a MAVLink 2 frame and reads it back.
fn round_trip(msg: MavMessage) -> MavMessage {
    let header = MavHeader {
        system_id: 1,
        component_id: 197,
        sequence: 7,
    };
    let mut frame = Vec::new();
    mavlink::write_v2_msg(&mut frame, header, &msg).expect("encodes");
    let mut reader = MavlinkReader::new(frame.as_slice());
    let (read_header, read) = reader
        .read_message::<MavMessage>(MavlinkVersion::V2)
        .expect("decodes");
    assert_eq!(read_header, header);
    read
}

#[test]
fn every_message_reads_back_as_written() {
    let nav = flying();
    let origin = LocalOrigin::new(0.82, 0.1395, 480.0);
    let mut resets = ResetCounter::default();
    resets.observe(&nav, 0);
    let reset_counter = resets.observe(&NavState { lane: 1, ..nav }, 1);
    assert_eq!(reset_counter, 1);
    let messages = [
        MavMessage::HEARTBEAT(heartbeat(Profile::Onboard, Some(&nav))),
        MavMessage::HEARTBEAT(heartbeat(
            Profile::Display {
                vehicle: MavType::MAV_TYPE_FIXED_WING,
            },
            None,
        )),
        MavMessage::ATTITUDE_QUATERNION(attitude::attitude_quaternion(&nav, [0.1, 0.2, -0.3])),
        MavMessage::GLOBAL_POSITION_INT(position::global_position_int(&nav, &origin)),
        MavMessage::LOCAL_POSITION_NED(position::local_position_ned(&nav, &origin)),
        MavMessage::ODOMETRY(odometry(
            &nav,
            &origin,
            [0.1, 0.2, -0.3],
            [1e-6; 3],
            reset_counter,
            10.0,
        )),
        MavMessage::SYS_STATUS(sys_status::sys_status(
            Some(&ipc_types::FusedImu::default()),
            Some(&nav),
            sys_status::present(nav.aiding),
            87,
        )),
        MavMessage::STATUSTEXT(status_text::channel_event(
            ipc_types::SensorType::Gyro,
            1,
            ipc_types::ChannelState::Excluded,
            ipc_types::FaultReason::Parity,
        )),
    ];
    for msg in messages {
        assert_eq!(round_trip(msg.clone()), msg);
    }
}

#[test]
fn odometry_keeps_its_extension_fields_on_the_wire() {
    let nav = flying();
    let msg = MavMessage::ODOMETRY(odometry(
        &nav,
        &LocalOrigin::new(0.82, 0.1395, 480.0),
        [0.0; 3],
        [0.0; 3],
        9,
        10.0,
    ));
    let MavMessage::ODOMETRY(read) = round_trip(msg) else {
        panic!("not an ODOMETRY");
    };
    // σ_h = 0.5 m against σ₀ = 10 m: 100·100/100.25 = 99.75, rounded down.
    assert_eq!((read.reset_counter, read.quality), (9, 99));
    assert_eq!(read.pose_covariance[0], 0.25);
    assert_eq!(read.time_usec, 987_654_321);
}
