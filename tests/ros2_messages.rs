//! rins's ROS 2 messages read back by an independent CDR reader: mcap-ros2-support's, from the
//! message definitions of ROS 2's own packages. Every field it decodes equals what rins encoded,
//! bit for bit.

mod common;

use ipc_types::{FusedImu, NavMode, NavState};
use rins_earth::LocalOrigin;
use rins_ros2_messages::encode;
use rins_ros2_messages::from_rins::{FrameNames, imu, nav_sat_fix, odometry};
use serde_json::Value;

/// The floats the script printed as their bits.
fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| f64::from_bits(x.as_u64().expect("a float's bits")))
        .collect()
}

#[test]
fn an_independent_cdr_reader_decodes_every_field() {
    let Some(python) = common::python::interpreter("an_independent_cdr_reader_decodes_every_field")
    else {
        return;
    };
    let origin = LocalOrigin::new(0.81, 0.15, 120.0);
    let [lat, lon, alt] = origin.geodetic([12.5, -3.25, -7.0]);
    let mut nav = NavState {
        mode: NavMode::Navigating as u8,
        quaternion: [0.9, 0.1, -0.2, 0.3],
        velocity_ned_mps: [1.0, 2.0, 3.0],
        latitude_rad: lat,
        longitude_rad: lon,
        altitude_m: alt,
        gyro_bias_rps: [0.001, -0.002, 0.003],
        ..NavState::default()
    };
    for (k, v) in nav.covariance_diag.iter_mut().enumerate() {
        *v = 0.01 * (k + 1) as f64;
    }
    let fused = FusedImu {
        rate_rps: [0.1, -0.2, 0.3],
        specific_force_mps2: [0.5, -0.25, -9.75],
        rate_var: [1e-5, 2e-5, 3e-5],
        specific_force_var: [1e-3, 2e-3, 3e-3],
        ..FusedImu::default()
    };
    let frames = FrameNames {
        world: "map",
        body: "base_link",
    };
    let o = odometry(&nav, &fused, &origin, frames, 1_700_000_000_123_456_789);
    let m = imu(&fused, Some(&nav), "base_link", 42);
    let f = nav_sat_fix(&nav, "base_link", 43);
    let dir = std::env::temp_dir().join(format!("rins-ros2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let mut paths = Vec::new();
    let mut buf = Vec::new();
    for (name, result) in [
        ("odometry", encode(&o, &mut buf).map(|()| buf.clone())),
        ("imu", encode(&m, &mut buf).map(|()| buf.clone())),
        ("navsatfix", encode(&f, &mut buf).map(|()| buf.clone())),
    ] {
        let path = dir.join(format!("{name}.cdr"));
        std::fs::write(&path, result.expect("encodes")).expect("written");
        paths.push(path.to_string_lossy().into_owned());
    }
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates/ros2-messages/tests/python/decode_ros2.py");
    let out = std::process::Command::new(python)
        .arg(script)
        .args(&paths)
        .output()
        .expect("cannot run python");
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read: Value = serde_json::from_slice(&out.stdout).expect("the script prints JSON");

    let od = &read["odometry"];
    assert_eq!(od["stamp"], serde_json::json!([1_700_000_000, 123_456_789]));
    assert_eq!(
        (od["frame_id"].as_str(), od["child_frame_id"].as_str()),
        (Some("map"), Some("base_link"))
    );
    let p = o.pose.pose;
    assert_eq!(
        floats(&od["position"]),
        [p.position.x, p.position.y, p.position.z]
    );
    let q = p.orientation;
    assert_eq!(floats(&od["orientation"]), [q.x, q.y, q.z, q.w]);
    assert_eq!(floats(&od["pose_covariance"]), o.pose.covariance.0);
    let t = o.twist.twist;
    assert_eq!(floats(&od["linear"]), [t.linear.x, t.linear.y, t.linear.z]);
    assert_eq!(
        floats(&od["angular"]),
        [t.angular.x, t.angular.y, t.angular.z]
    );
    assert_eq!(floats(&od["twist_covariance"]), o.twist.covariance.0);

    let im = &read["imu"];
    assert_eq!(im["frame_id"].as_str(), Some("base_link"));
    let q = m.orientation;
    assert_eq!(floats(&im["orientation"]), [q.x, q.y, q.z, q.w]);
    assert_eq!(
        floats(&im["orientation_covariance"]),
        m.orientation_covariance.0
    );
    let w = m.angular_velocity;
    assert_eq!(floats(&im["angular_velocity"]), [w.x, w.y, w.z]);
    let a = m.linear_acceleration;
    assert_eq!(floats(&im["linear_acceleration"]), [a.x, a.y, a.z]);
    assert_eq!(
        floats(&im["linear_acceleration_covariance"]),
        m.linear_acceleration_covariance.0
    );

    let fx = &read["navsatfix"];
    assert_eq!(fx["status"], serde_json::json!([0, 0]));
    assert_eq!(floats(&fx["lla"]), [f.latitude, f.longitude, f.altitude]);
    assert_eq!(floats(&fx["position_covariance"]), f.position_covariance.0);
    assert_eq!(fx["position_covariance_type"], 2);
}
