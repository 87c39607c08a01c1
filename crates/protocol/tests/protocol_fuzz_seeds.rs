//! The seed corpus of the `decoder` fuzz target (fuzz/corpus/decoder) is made of real encoded
//! frames. These tests check that the committed seeds are what the current encoder produces; after a
//! protocol change, regenerate them with
//! `RINS_WRITE_FUZZ_SEEDS=1 cargo test -p rins-protocol --test protocol_fuzz_seeds`.

mod common;

use std::path::PathBuf;

use common::{encode_one, example_imu_frame, push_chunked};
use rins_protocol::{
    AuxFrame, BaroFrame, Decoder, Frame, ImuFrame, MAX_FRAME_LEN, MagFrame, Payload,
};

/// Seeds in the fuzz target's input layout: [k, k chunk sizes, stream].
/// Each seed with the number of frames the decoder must recover from it.
fn seeds() -> Vec<(&'static str, Vec<u8>, usize)> {
    let imu = example_imu_frame();
    let full = Frame {
        seq: u16::MAX,
        device_time_us: u32::MAX,
        payload: Payload::Imu(ImuFrame {
            n_gyro: 16,
            n_accel: 16,
            n_temperature: 4,
            gyro_counts: [2047; 16],
            accel_counts: [-2048; 16],
            ..ImuFrame::default()
        }),
    };
    let baro = Frame {
        seq: 1,
        device_time_us: 1_000,
        payload: Payload::Baro(BaroFrame {
            pressure_pa: 101_325.0,
            temperature_centi_c: 2_150,
        }),
    };
    let mag = Frame {
        seq: 2,
        device_time_us: 2_000,
        payload: Payload::Mag(MagFrame {
            field_nt: [21_000, -1_500, 43_000],
        }),
    };
    let aux = Frame {
        seq: 3,
        device_time_us: 3_000,
        payload: Payload::Aux(AuxFrame {
            foot_pressure: 40_000,
        }),
    };
    let all: Vec<u8> = [imu, full, baro, mag, aux]
        .iter()
        .flat_map(encode_one)
        .collect();
    let mut corrupt = encode_one(&imu);
    corrupt[20] ^= 0x04;
    corrupt.extend(encode_one(&baro));
    let mut garbage = vec![0xA5, 0x5A, 0x01, 81, 0x00, 0xA5];
    garbage.extend(encode_one(&mag));
    garbage.extend([0xFF; 7]);
    garbage.extend(encode_one(&aux));
    // Enough trailing bytes to resolve the fake header's candidate.
    garbage.extend([0u8; MAX_FRAME_LEN]);

    // Device time stepping back 1 s (re-based), a sequence number far behind (a jump), repeated
    // and reordered numbers (withheld).
    let at = |seq: u16, device_time_us: u32| Frame {
        seq,
        device_time_us,
        payload: Payload::Aux(AuxFrame { foot_pressure: 7 }),
    };
    let stream_of = |frames: &[Frame]| -> Vec<u8> { frames.iter().flat_map(encode_one).collect() };
    let time_back = stream_of(&[at(5, 1_000_000), at(6, 0), at(7, 1_000)]);
    let seq_far_back = stream_of(&[at(5_000, 0), at(100, 1), at(101, 2), at(5_000, 3)]);
    let repeated_and_late =
        stream_of(&[at(1, 0), at(3, 2), at(3, 2), at(2, 1), at(2, 1), at(4, 3)]);

    let with_chunks = |sizes: &[u8], stream: &[u8]| {
        let mut v = vec![sizes.len() as u8];
        v.extend(sizes);
        v.extend(stream);
        v
    };
    // The full IMU frame's number is 4 661 behind the example's and nothing continues it: too far
    // behind to tell late from a restarted counter, and no next frame says, so it is withheld.
    // In `seq_far_back`, 100 is withheld until 101 confirms the restart.
    vec![
        ("imu_whole", with_chunks(&[], &encode_one(&imu)), 1),
        ("all_types_whole", with_chunks(&[], &all), 4),
        ("all_types_bytewise", with_chunks(&[1], &all), 4),
        ("all_types_ragged", with_chunks(&[7, 0, 50, 3], &all), 4),
        ("bit_flip_then_baro", with_chunks(&[5, 11], &corrupt), 1),
        (
            "fake_sync_in_garbage",
            with_chunks(&[2, 9, 40], &garbage),
            2,
        ),
        ("time_back_rebased", with_chunks(&[], &time_back), 3),
        ("seq_far_back_jump", with_chunks(&[16], &seq_far_back), 3),
        ("repeated_and_late", with_chunks(&[], &repeated_and_late), 3),
    ]
}

#[test]
fn seeds_decode_to_the_frames_they_were_made_from() {
    for (name, seed, expected) in seeds() {
        let (sizes, stream) = seed[1..].split_at(usize::from(seed[0]));
        let chunks: Vec<usize> = sizes.iter().map(|&s| usize::from(s)).collect();
        let mut decoder = Decoder::new();
        let got = push_chunked(&mut decoder, stream, &chunks);
        assert_eq!(got.len(), expected, "{name}");
    }
}

#[test]
fn committed_seeds_match_the_encoder() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus/decoder");
    let write = std::env::var_os("RINS_WRITE_FUZZ_SEEDS").is_some();
    if write {
        std::fs::create_dir_all(&dir).unwrap();
    }
    for (name, seed, _) in seeds() {
        let path = dir.join(name);
        if write {
            std::fs::write(&path, &seed).unwrap();
        }
        let committed = std::fs::read(&path)
            .unwrap_or_else(|e| panic!("{}: {e}; regenerate the seeds", path.display()));
        assert_eq!(committed, seed, "{name} is stale; regenerate the seeds");
    }
}
