//! The layout of every payload and nested struct, declared with `layout!`.

// Every payload is described here: all of them are in scope, so a new one is its `layout!` entry
// alone.
use ipc_types::*;

use super::description::{FieldKind, StructLayout};
use super::field_type::{FieldType, field_of, layout};

layout! {
    /// [`Header`], nested in every pipeline payload.
    pub static HEADER: Header = "Header" {
        origin_seq, origin_device_time_us, origin_rx_ns, stage_pub_ns,
    }

    /// [`RawImu`], on [`ipc_types::names::RAW_IMU`].
    pub static RAW_IMU: RawImu = "RawImu" {
        version, n_gyro, n_accel, n_temperature, _pad as pad0, status, valid_mask, header,
        gyro_counts, accel_counts, temperature_c,
    }

    /// [`RawBaro`], on [`ipc_types::names::RAW_BARO`].
    pub static RAW_BARO: RawBaro = "RawBaro" {
        version, _pad as pad0, header, pressure_pa, temperature_c, _pad2 as pad1,
    }

    /// [`RawMag`], on [`ipc_types::names::RAW_MAG`].
    pub static RAW_MAG: RawMag = "RawMag" {
        version, _pad as pad0, header, field_ut, _pad2 as pad1,
    }

    /// [`RawAux`], on [`ipc_types::names::RAW_AUX`].
    pub static RAW_AUX: RawAux = "RawAux" {
        version, _pad as pad0, header, foot_pressure, _pad2 as pad1,
    }

    /// [`RawAirspeed`], on [`ipc_types::names::RAW_AIRSPEED`].
    pub static RAW_AIRSPEED: RawAirspeed = "RawAirspeed" {
        version, _pad as pad0, header, diff_pressure_pa, temperature_c,
    }

    /// [`GnssFix`], on [`ipc_types::names::GNSS`].
    pub static GNSS_FIX: GnssFix = "GnssFix" {
        version, fix_type, satellites, protocol, velocity_valid, accuracy_reported,
        _pad as pad0, header, receiver_time_us, latitude_rad, longitude_rad, altitude_m,
        velocity_ned_mps, horizontal_accuracy_m, vertical_accuracy_m, speed_accuracy_mps, hdop,
    }

    /// [`FusedImu`], on [`ipc_types::names::FUSED_IMU`].
    pub static FUSED_IMU: FusedImu = "FusedImu" {
        version, n_gyro, n_accel, flags, header, rate_rps, specific_force_mps2, rate_var,
        specific_force_var, gyro_state, accel_state, gyro_reason, accel_reason,
        gyro_test_statistic, accel_test_statistic,
    }

    /// [`Altitude`], on [`ipc_types::names::ALTITUDE`].
    pub static ALTITUDE: Altitude = "Altitude" {
        version, valid, _pad as pad0, header, height_m, vertical_speed_mps, height_var,
    }

    /// [`NavState`], on both navigator lanes ([`ipc_types::names::NAV_LANES`]).
    pub static NAV_STATE: NavState = "NavState" {
        version, mode, lane, aiding, header, quaternion, velocity_ned_mps, latitude_rad,
        longitude_rad, altitude_m, covariance_diag, aiding_accepted, aiding_rejected,
        solution_start_seq, gyro_bias_rps, accel_bias_mps2, integrity, _pad as pad0,
        integrity_reasons,
    }

    /// [`Truth`], on [`ipc_types::names::TRUTH`].
    pub static TRUTH: Truth = "Truth" {
        version, _pad as pad0, header, quaternion, velocity_ned_mps, latitude_rad,
        longitude_rad, altitude_m,
    }

    /// [`Health`], on [`ipc_types::names::HEARTBEAT`].
    pub static HEALTH: Health = "Health" {
        version, service, _pad as pad0, pid, now_ns, received, published, crc_errors, lost,
        malformed, duplicates, late, seq_jumps, time_rebases, resync_bytes, reconnects,
        rejected, stale_input_episodes, bytes_received, valid_frames, input_stale,
        last_decode_error, _pad2 as pad1,
    }

    /// [`ServiceHealth`], nested in [`HealthReport`].
    pub static SERVICE_HEALTH: ServiceHealth = "ServiceHealth" {
        service, state, input_stale, _pad as pad0, pid, restarts, heartbeat_age_ms,
        output_rate_hz, _pad2 as pad1,
    }

    /// [`LinkReport`], nested in [`HealthReport`].
    pub static LINK_REPORT: LinkReport = "LinkReport" {
        heard, last_decode_error, _pad as pad0, bytes_received, valid_frames, discarded_bytes,
        crc_errors, malformed, reconnects,
    }

    /// [`RedundancyReport`], nested in [`HealthReport`].
    pub static REDUNDANCY_REPORT: RedundancyReport = "RedundancyReport" {
        heard, n_gyro, n_accel, _pad as pad0, flags, gyro_state, accel_state, gyro_reason,
        accel_reason, gyro_test_statistic, accel_test_statistic, age_ms, _pad2 as pad1,
    }

    /// [`NavReport`], nested in [`HealthReport`].
    pub static NAV_REPORT: NavReport = "NavReport" {
        heard, mode, lane, integrity, aiding, integrity_reasons, age_ms,
    }

    /// [`GnssLinkReport`], on [`ipc_types::names::GNSS_LINK`] and nested in [`HealthReport`].
    pub static GNSS_LINK_REPORT: GnssLinkReport = "GnssLinkReport" {
        version, heard, silent, quiet, _pad as pad0, now_ns, bytes, reconnects, sentences_used,
        ubx_frames_used, unused_gsv, unused_gsa, unused_zda, unused_txt, unused_gbs,
        unused_other_nmea, unused_proprietary, unused_other_messages, nothing_to_use,
        checksum_errors, without_checksum, malformed, oversized, wrong_length, resyncs,
        unframed_bytes, lines_crlf, lines_lf, epochs, epochs_without_fix, published,
        publish_failures, ubx_late, nmea_epochs_superseded, silent_episodes,
    }

    /// [`HealthReport`], on [`ipc_types::names::HEALTH`].
    pub static HEALTH_REPORT: HealthReport = "HealthReport" {
        version, count, _pad as pad0, now_ns, uptime_ms, services, link, redundancy, nav, gnss,
    }

    /// [`FaultApplied`], on [`ipc_types::names::SIM_FAULT_APPLIED`].
    pub static FAULT_APPLIED: FaultApplied = "FaultApplied" {
        version, sensor, channel, fault, outcome, _pad as pad0, device_time_us, param,
    }

    /// [`SimControl`], on [`ipc_types::names::SIM_CONTROL`].
    pub static SIM_CONTROL: SimControl = "SimControl" {
        version, sensor, channel, fault, _pad as pad0, param,
    }

    /// [`FusionControl`], on [`ipc_types::names::FUSION_CONTROL`].
    pub static FUSION_CONTROL: FusionControl = "FusionControl" {
        version, sensor, channel, request_id,
    }

    /// [`FusionReply`], on [`ipc_types::names::FUSION_REPLY`].
    pub static FUSION_REPLY: FusionReply = "FusionReply" {
        version, sensor, channel, request_id, outcome, reason, _pad as pad0, pid,
    }
}
