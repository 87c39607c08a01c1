//! The airspeed frame: its layout, and the refusal of values no pitot sensor produces even when
//! the CRC is right, counted as malformed by the streaming decoder.

mod common;

use common::encode_one;
use rins_protocol::error::ValueOutOfRange;
use rins_protocol::layout::{AIRSPEED_MAX_ABS_PA, AIRSPEED_PAYLOAD_LEN};
use rins_protocol::{
    AirspeedFrame, DecodeError, Decoder, EncodeError, Frame, FrameType, Payload, decode_frame,
    encode,
};

fn airspeed(diff_pressure_pa: f32, temperature_centi_c: i16) -> Frame {
    Frame {
        seq: 7,
        device_time_us: 1_000,
        payload: Payload::Airspeed(AirspeedFrame {
            diff_pressure_pa,
            temperature_centi_c,
        }),
    }
}

/// The frame's bytes with the differential pressure replaced by `bits` and the CRC made right
/// again: what a device with a broken converter would send.
fn with_pressure_bits(bits: u32) -> Vec<u8> {
    let mut bytes = encode_one(&airspeed(100.0, 2000));
    bytes[10..14].copy_from_slice(&bits.to_le_bytes());
    let end = bytes.len() - 4;
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI).checksum(&bytes[2..end]);
    bytes[end..].copy_from_slice(&crc.to_le_bytes());
    bytes
}

#[test]
fn a_sane_frame_round_trips_with_its_documented_layout() {
    let frame = airspeed(-12.5, -1234);
    let bytes = encode_one(&frame);
    assert_eq!(bytes.len(), 14 + AIRSPEED_PAYLOAD_LEN);
    assert_eq!(&bytes[..4], &[0xA5, 0x5A, 5, 6]);
    assert_eq!(&bytes[10..14], &(-12.5f32).to_le_bytes());
    assert_eq!(&bytes[14..16], &(-1234i16).to_le_bytes());
    assert_eq!(decode_frame(&bytes), Ok((frame, bytes.len())));
}

#[test]
fn decode_refuses_insane_pressures_under_a_valid_crc_naming_the_field() {
    for (bits, value) in [
        (8000.0f32.to_bits(), 8000.0),
        ((-7000.5f32).to_bits(), -7000.5),
        (f32::INFINITY.to_bits(), f64::INFINITY),
    ] {
        let err = decode_frame(&with_pressure_bits(bits)).unwrap_err();
        assert_eq!(
            err,
            DecodeError::OutOfRange(ValueOutOfRange {
                frame_type: FrameType::Airspeed,
                field: "diff_pressure_pa",
                value,
                min: -f64::from(AIRSPEED_MAX_ABS_PA),
                max: f64::from(AIRSPEED_MAX_ABS_PA),
            })
        );
        assert!(!err.is_crc());
        assert!(err.to_string().contains("diff_pressure_pa"), "{err}");
    }
    let nan = decode_frame(&with_pressure_bits(f32::NAN.to_bits())).unwrap_err();
    assert!(
        matches!(nan, DecodeError::OutOfRange(e) if e.field == "diff_pressure_pa" && e.value.is_nan()),
        "{nan:?}"
    );
    // The edge of the range is still a pressure the sensor class reads.
    assert!(decode_frame(&with_pressure_bits(AIRSPEED_MAX_ABS_PA.to_bits())).is_ok());
}

#[test]
fn decode_refuses_an_impossible_temperature() {
    let mut bytes = encode_one(&airspeed(0.0, 2000));
    bytes[14..16].copy_from_slice(&20_000i16.to_le_bytes());
    let end = bytes.len() - 4;
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI).checksum(&bytes[2..end]);
    bytes[end..].copy_from_slice(&crc.to_le_bytes());
    assert!(matches!(
        decode_frame(&bytes),
        Err(DecodeError::OutOfRange(ValueOutOfRange {
            field: "temperature_centi_c",
            ..
        }))
    ));
}

#[test]
fn the_encoder_refuses_what_the_decoder_would() {
    let mut out = [0u8; 64];
    assert!(matches!(
        encode(&airspeed(f32::NAN, 0), &mut out),
        Err(EncodeError::OutOfRange(ValueOutOfRange {
            field: "diff_pressure_pa",
            ..
        }))
    ));
    assert!(matches!(
        encode(&airspeed(0.0, -6000), &mut out),
        Err(EncodeError::OutOfRange(ValueOutOfRange {
            field: "temperature_centi_c",
            ..
        }))
    ));
}

#[test]
fn the_streaming_decoder_counts_an_insane_frame_malformed_and_sane_ones_per_type() {
    let mut decoder = Decoder::new();
    let mut bytes = encode_one(&airspeed(50.0, 2000));
    bytes.extend(with_pressure_bits(9000.0f32.to_bits()));
    bytes.extend(encode_one(&Frame {
        seq: 8,
        ..airspeed(60.0, 2000)
    }));
    let mut delivered = Vec::new();
    decoder.push(&bytes, 0, |f| delivered.push(f.payload));
    let stats = decoder.stats();
    assert_eq!(delivered.len(), 2);
    assert_eq!(stats.malformed, 1);
    assert_eq!(stats.crc_errors, 0);
    assert_eq!(stats.frames_by_type[FrameType::Airspeed.index()], 2);
    assert!(matches!(stats.last_error, Some(DecodeError::OutOfRange(_))));
    assert_eq!(
        rins_protocol::link_error(stats.last_error.as_ref()),
        ipc_types::LinkError::BadContent
    );
}
