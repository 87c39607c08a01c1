//! Acquisition's per-frame path must not touch the heap: the streaming decoder taking serial bytes
//! in chunks of any size (frames split across reads), and the conversion of each decoded frame to
//! its IPC payload with its origin header.

use rins_acquisition::to_ipc::origin_header;
use rins_protocol::{BaroFrame, Decoder, Frame, ImuFrame, MagFrame, Payload, SensorFrame, encode};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

fn frame(seq: u32, device_time_us: u32, payload: Payload) -> Frame {
    Frame {
        seq: seq as u16,
        device_time_us,
        payload,
    }
}

/// A second of a four-gyro, four-accelerometer block at 1 kHz with its baro and magnetometer
/// frames, as the serial line carries it.
fn line_bytes() -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut buf = [0u8; 128];
    let imu = ImuFrame {
        n_gyro: 4,
        n_accel: 4,
        n_temperature: 1,
        valid_mask: 0x000f_000f,
        ..ImuFrame::default()
    };
    let baro = BaroFrame {
        pressure_pa: 95_000.0,
        temperature_centi_c: 2000,
    };
    let mag = MagFrame {
        field_nt: [20_000, 0, 40_000],
    };
    for k in 0..1000u32 {
        let t = k * 1000;
        let mut frames = vec![frame(k, t, Payload::Imu(imu))];
        if k % 20 == 0 {
            frames.push(frame(k / 20, t, Payload::Baro(baro)));
        }
        if k % 10 == 0 {
            frames.push(frame(k / 10, t, Payload::Mag(mag)));
        }
        for f in &frames {
            let n = encode(f, &mut buf).expect("a frame fits");
            bytes.extend_from_slice(&buf[..n]);
        }
    }
    bytes
}

#[test]
fn decoding_and_converting_frames_does_not_allocate() {
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    let bytes = line_bytes();
    let mut decoder = Decoder::new();
    let (mut imu, mut baro, mut mag) = (0u64, 0u64, 0u64);
    let allocations = allocations_during(|| {
        // Reads of awkward sizes, as a serial port returns them.
        for (i, chunk) in bytes.chunks(37).enumerate() {
            let rx_ns = i as u64 * 50_000;
            decoder.push(chunk, rx_ns, |decoded| {
                let header = origin_header(&decoded, rx_ns);
                match &decoded.payload {
                    Payload::Imu(f) => {
                        imu += std::hint::black_box(f.to_ipc(header)).header.origin_seq
                    }
                    Payload::Baro(f) => {
                        baro += std::hint::black_box(f.to_ipc(header)).header.origin_seq
                    }
                    Payload::Mag(f) => {
                        mag += std::hint::black_box(f.to_ipc(header)).header.origin_seq
                    }
                    Payload::Aux(_) | Payload::Airspeed(_) => {}
                }
            });
        }
    });
    assert_eq!(allocations, 0, "allocations in the per-frame path");
    // Every frame came through: the sums of the sequence numbers 0..n.
    assert_eq!(
        (imu, baro, mag),
        (999 * 1000 / 2, 49 * 50 / 2, 99 * 100 / 2)
    );
    assert_eq!(decoder.stats().crc_errors, 0);
}
