//! Earth-centred, earth-fixed (ECEF) coordinates, as UBX NAV-SOL reports them, as geodetic
//! (WGS84) latitude, longitude and height, and ECEF velocity as north-east-down.

/// WGS84 semi-major axis, m.
const A: f64 = 6_378_137.0;
/// WGS84 flattening.
const F: f64 = 1.0 / 298.257_223_563;

/// Geodetic latitude and longitude (radians) and height above the ellipsoid (m) of the ECEF
/// point `xyz` (m). Heikkinen's closed form (Heikkinen 1982; Zhu 1994): exact to well under a
/// millimetre anywhere a receiver can be. Not numbers (NaN) for points near the earth's centre,
/// which no receiver reports: the caller's plausibility check sets such a fix aside.
pub fn geodetic_from_ecef(xyz: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = xyz;
    let b = A * (1.0 - F);
    let e2 = F * (2.0 - F);
    let ep2 = (A * A - b * b) / (b * b);
    let p = x.hypot(y);
    let ff = 54.0 * b * b * z * z;
    let g = p * p + (1.0 - e2) * z * z - e2 * (A * A - b * b);
    let c = e2 * e2 * ff * p * p / (g * g * g);
    let s = (1.0 + c + (c * c + 2.0 * c).sqrt()).cbrt();
    let k = s + 1.0 + 1.0 / s;
    let pp = ff / (3.0 * k * k * g * g);
    let q = (1.0 + 2.0 * e2 * e2 * pp).sqrt();
    let r0 = -pp * e2 * p / (1.0 + q)
        + (A * A / 2.0 * (1.0 + 1.0 / q)
            - pp * (1.0 - e2) * z * z / (q * (1.0 + q))
            - pp * p * p / 2.0)
            .sqrt();
    let t = p - e2 * r0;
    let u = (t * t + z * z).sqrt();
    let v = (t * t + (1.0 - e2) * z * z).sqrt();
    let z0 = b * b * z / (A * v);
    let height = u * (1.0 - b * b / (A * v));
    [(z + ep2 * z0).atan2(p), y.atan2(x), height]
}

/// The ECEF velocity `v` (m/s) as north, east, down at latitude `lat` and longitude `lon`
/// (radians).
pub fn ned_from_ecef_velocity(v: [f64; 3], lat: f64, lon: f64) -> [f64; 3] {
    let (sin_lat, cos_lat) = lat.sin_cos();
    let (sin_lon, cos_lon) = lon.sin_cos();
    let [vx, vy, vz] = v;
    let along_meridian = cos_lon * vx + sin_lon * vy;
    [
        -sin_lat * along_meridian + cos_lat * vz,
        -sin_lon * vx + cos_lon * vy,
        -cos_lat * along_meridian - sin_lat * vz,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ECEF point of a geodetic position (the textbook forward formula).
    fn ecef_from_geodetic(lat: f64, lon: f64, h: f64) -> [f64; 3] {
        let e2 = F * (2.0 - F);
        let n = A / (1.0 - e2 * lat.sin().powi(2)).sqrt();
        [
            (n + h) * lat.cos() * lon.cos(),
            (n + h) * lat.cos() * lon.sin(),
            (n * (1.0 - e2) + h) * lat.sin(),
        ]
    }

    #[test]
    fn geodetic_positions_come_back_from_their_ecef_points() {
        for (lat_deg, lon_deg, h) in [
            (0.0, 0.0, 0.0),
            (53.5, -113.4, 635.0),
            (-33.87, 151.21, 58.0),
            (89.9, 45.0, 12_000.0),
            (-89.99, -179.9, -400.0),
            (45.2, 5.8, 49_000.0),
        ] {
            let (lat, lon) = (f64::to_radians(lat_deg), f64::to_radians(lon_deg));
            let [lat2, lon2, h2] = geodetic_from_ecef(ecef_from_geodetic(lat, lon, h));
            // 1e-10 rad is 0.6 mm on the ground.
            assert!(
                (lat2 - lat).abs() < 1e-10,
                "{lat_deg}: {}",
                lat2.to_degrees()
            );
            assert!(
                (lon2 - lon).abs() < 1e-10,
                "{lon_deg}: {}",
                lon2.to_degrees()
            );
            assert!((h2 - h).abs() < 1e-3, "{h}: {h2}");
        }
    }

    #[test]
    fn a_receivers_ecef_fix_reads_as_gpsd_reads_it() {
        // u-blox LEA-4T of the GPSD project's regression logs: NAV-SOL ECEF in cm, gpsd's
        // geodetic decode of the same epoch.
        let [lat, lon, h] = geodetic_from_ecef([-1_510_299.52, -3_483_497.94, 5_108_533.23]);
        assert!((lat.to_degrees() - 53.563256267).abs() < 2e-9);
        assert!((lon.to_degrees() - -113.439544853).abs() < 2e-9);
        assert!((h - 635.459).abs() < 2e-3);
    }

    #[test]
    fn velocity_axes_turn_with_the_place() {
        // At 0° N 0° E: ECEF x is up, y east, z north.
        let ned = ned_from_ecef_velocity([1.0, 2.0, 3.0], 0.0, 0.0);
        for (got, want) in ned.iter().zip([3.0, 2.0, -1.0]) {
            assert!((got - want).abs() < 1e-12, "{ned:?}");
        }
        // At the north pole on the 90° E meridian: ECEF z is up, north is along -y, east
        // along -x.
        let ned = ned_from_ecef_velocity([1.0, 2.0, 3.0], 90f64.to_radians(), 90f64.to_radians());
        for (got, want) in ned.iter().zip([-2.0, -1.0, -3.0]) {
            assert!((got - want).abs() < 1e-12, "{ned:?}");
        }
        // The speed is kept anywhere.
        let v = [3.0, -4.0, 12.0];
        let ned = ned_from_ecef_velocity(v, 0.7, -2.1);
        let norm = |a: [f64; 3]| a.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((norm(ned) - norm(v)).abs() < 1e-12);
    }
}
