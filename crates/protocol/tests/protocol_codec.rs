//! Single-frame encoding and decoding: layout, limits and error reporting.

mod common;

use common::{encode_one, example_imu_frame};
use rins_protocol::{
    AuxFrame, BaroFrame, DecodeError, EncodeError, Frame, ImuContentError, ImuFrame, MAX_FRAME_LEN,
    MAX_PAYLOAD_LEN, MagFrame, Payload, decode_frame, encode, peek_frame_len,
};

/// The worked example of `docs/protocol.md`, byte for byte.
const EXAMPLE_HEX: &str = "A5 5A 01 1D 34 12 40 E2 01 00 04 04 02 02 00 0F 00 0F 00 64 00 9C FF FF \
                           07 00 F8 00 00 01 00 FF FF 00 02 D0 09 0C FE 1C C2 23 6C";

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

/// Bitwise CRC-32C (reflected polynomial 0x82F63B78), independent of the `crc` crate.
fn crc32c_reference(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                (c >> 1) ^ 0x82F6_3B78
            } else {
                c >> 1
            };
        }
    }
    !c
}

/// Rewrites the CRC trailer after a test has edited a frame, so that content checks are reached.
fn fix_crc(frame: &mut [u8]) {
    let end = frame.len() - 4;
    let crc = crc32c_reference(&frame[2..end]);
    frame[end..].copy_from_slice(&crc.to_le_bytes());
}

fn full_imu() -> ImuFrame {
    ImuFrame {
        n_gyro: 16,
        n_accel: 16,
        n_temperature: 4,
        ..ImuFrame::default()
    }
}

#[test]
fn reference_crc_matches_the_castagnoli_check_value() {
    assert_eq!(crc32c_reference(b"123456789"), 0xE306_9283);
}

#[test]
fn documented_imu_example_is_what_the_encoder_produces() {
    let bytes = encode_one(&example_imu_frame());
    assert_eq!(bytes, hex(EXAMPLE_HEX));
    assert_eq!(
        u32::from_le_bytes(bytes[39..].try_into().unwrap()),
        crc32c_reference(&bytes[2..39])
    );
    let (frame, used) = decode_frame(&bytes).unwrap();
    assert_eq!((frame, used), (example_imu_frame(), 43));
}

#[test]
fn max_frame_len_is_a_full_imu_frame() {
    assert_eq!(MAX_PAYLOAD_LEN, 9 + 2 * (16 + 16 + 4));
    assert_eq!(MAX_FRAME_LEN, 10 + MAX_PAYLOAD_LEN + 4);
    let frame = Frame {
        seq: 0,
        device_time_us: 0,
        payload: Payload::Imu(full_imu()),
    };
    assert_eq!(frame.encoded_len(), MAX_FRAME_LEN);
    assert_eq!(encode_one(&frame).len(), MAX_FRAME_LEN);
}

#[test]
fn fixed_payloads_are_laid_out_little_endian() {
    let cases = [
        (
            Payload::Baro(BaroFrame {
                pressure_pa: 101_325.0,
                temperature_centi_c: -1234,
            }),
            [
                101_325.0f32.to_le_bytes().as_slice(),
                &(-1234i16).to_le_bytes(),
            ]
            .concat(),
        ),
        (
            Payload::Mag(MagFrame {
                field_nt: [1, -2, 0x0102_0304],
            }),
            hex("01 00 00 00 FE FF FF FF 04 03 02 01"),
        ),
        (
            Payload::Aux(AuxFrame {
                foot_pressure: 0xBEEF,
            }),
            hex("EF BE"),
        ),
    ];
    for (payload, expected) in cases {
        let frame = Frame {
            seq: 0xFFFE,
            device_time_us: 0xDEAD_BEEF,
            payload,
        };
        let bytes = encode_one(&frame);
        assert_eq!(bytes[..2], [0xA5, 0x5A]);
        assert_eq!(bytes[2], payload.frame_type() as u8);
        assert_eq!(usize::from(bytes[3]), expected.len());
        assert_eq!(bytes[4..10], hex("FE FF EF BE AD DE")[..]);
        assert_eq!(bytes[10..10 + expected.len()], expected[..]);
        assert_eq!(bytes.len(), 14 + expected.len());
        assert_eq!(decode_frame(&bytes).unwrap(), (frame, bytes.len()));
    }
}

#[test]
fn nan_pressure_keeps_its_bits() {
    let nan = f32::from_bits(0x7FC0_1234);
    let frame = Frame {
        seq: 1,
        device_time_us: 2,
        payload: Payload::Baro(BaroFrame {
            pressure_pa: nan,
            temperature_centi_c: 0,
        }),
    };
    let (decoded, _) = decode_frame(&encode_one(&frame)).unwrap();
    let Payload::Baro(b) = decoded.payload else {
        panic!("expected a baro frame, got {decoded:?}");
    };
    assert_eq!(b.pressure_pa.to_bits(), 0x7FC0_1234);
}

#[test]
fn encode_rejects_a_short_buffer() {
    let frame = example_imu_frame();
    let mut buf = [0u8; 42];
    assert_eq!(
        encode(&frame, &mut buf),
        Err(EncodeError::BufferTooSmall {
            needed: 43,
            available: 42
        })
    );
    let mut exact = [0u8; 43];
    assert_eq!(encode(&frame, &mut exact), Ok(43));
}

#[test]
fn encode_rejects_counts_outside_12_bits_and_too_many_channels() {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let mut imu = full_imu();
    imu.accel_counts[7] = 2048;
    let err = encode(&frame_of(imu), &mut buf).unwrap_err();
    assert_eq!(
        err,
        EncodeError::Content(ImuContentError::CountOutOfRange {
            field: "accel_counts",
            index: 7,
            value: 2048
        })
    );
    assert!(err.to_string().contains("accel_counts[7] = 2048"));

    let mut imu = full_imu();
    imu.gyro_counts[0] = -2049;
    assert!(matches!(
        encode(&frame_of(imu), &mut buf),
        Err(EncodeError::Content(ImuContentError::CountOutOfRange {
            field: "gyro_counts",
            index: 0,
            value: -2049
        }))
    ));

    // Entries past the channel count are not sent, so they are not checked either.
    let mut imu = full_imu();
    imu.n_gyro = 3;
    imu.gyro_counts[3] = i16::MAX;
    assert!(encode(&frame_of(imu), &mut buf).is_ok());

    for (field, imu) in [
        (
            "n_gyro",
            ImuFrame {
                n_gyro: 17,
                ..full_imu()
            },
        ),
        (
            "n_accel",
            ImuFrame {
                n_accel: 17,
                ..full_imu()
            },
        ),
        (
            "n_temperature",
            ImuFrame {
                n_temperature: 5,
                ..full_imu()
            },
        ),
    ] {
        match encode(&frame_of(imu), &mut buf) {
            Err(EncodeError::Content(ImuContentError::TooManyChannels { field: f, .. })) => {
                assert_eq!(f, field)
            }
            other => panic!("{field}: expected TooManyChannels, got {other:?}"),
        }
    }
}

fn frame_of(imu: ImuFrame) -> Frame {
    Frame {
        seq: 0,
        device_time_us: 0,
        payload: Payload::Imu(imu),
    }
}

#[test]
fn decode_reports_each_kind_of_defect() {
    let good = encode_one(&example_imu_frame());

    assert_eq!(decode_frame(&good[1..]), Err(DecodeError::NoSync));
    assert_eq!(
        decode_frame(&good[..1]),
        Err(DecodeError::Incomplete { needed: 10 })
    );
    assert_eq!(
        decode_frame(&good[..42]),
        Err(DecodeError::Incomplete { needed: 43 })
    );
    assert_eq!(peek_frame_len(&good[..4]), Ok(43));

    let mut unknown = good.clone();
    unknown[2] = 9;
    assert_eq!(
        decode_frame(&unknown[..3]),
        Err(DecodeError::UnknownFrameType { value: 9 })
    );

    // An even IMU length can never be 9 + 2k.
    let mut even = good.clone();
    even[3] = 30;
    assert!(matches!(
        decode_frame(&even[..4]),
        Err(DecodeError::BadPayloadLength { len: 30, .. })
    ));

    let mut flipped = good.clone();
    flipped[20] ^= 0x10;
    assert!(decode_frame(&flipped).unwrap_err().is_crc());

    // Content checks run on frames whose CRC is right.
    let mut out_of_range = good.clone();
    out_of_range[19..21].copy_from_slice(&2048i16.to_le_bytes()); // gyro 0
    fix_crc(&mut out_of_range);
    assert_eq!(
        decode_frame(&out_of_range),
        Err(DecodeError::Content(ImuContentError::CountOutOfRange {
            field: "gyro_counts",
            index: 0,
            value: 2048
        }))
    );

    let mut too_many = good.clone();
    too_many[10] = 17; // n_gyro
    fix_crc(&mut too_many);
    assert!(matches!(
        decode_frame(&too_many),
        Err(DecodeError::Content(ImuContentError::TooManyChannels {
            field: "n_gyro",
            value: 17,
            ..
        }))
    ));

    // Channel counts that disagree with the length byte: 5 gyros need 2 more bytes than sent.
    let mut mismatch = good.clone();
    mismatch[10] = 5;
    fix_crc(&mut mismatch);
    assert!(matches!(
        decode_frame(&mismatch),
        Err(DecodeError::BadPayloadLength { len: 29, .. })
    ));
}
