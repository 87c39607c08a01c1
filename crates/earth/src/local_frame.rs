//! A local NED frame: north, east, down in metres from an origin (for the MAVLink local position
//! and odometry, and for plots: the first usable solution's position). A tangent plane at the
//! origin with the ellipsoid's radii of curvature there: for the few kilometres a small UAV flies, the error of the flat
//! approximation (distance² / 2R, 0.08 m at 1 km) is below the solution's own.

use crate::wgs84::{meridian_radius, prime_vertical_radius};

/// The origin of the local frame, a geodetic position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalOrigin {
    /// Latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Altitude above mean sea level, m.
    pub altitude_m: f64,
    /// Metres per radian of latitude at the origin.
    north_per_rad: f64,
    /// Metres per radian of longitude at the origin.
    east_per_rad: f64,
}

impl LocalOrigin {
    /// The frame with its origin at this position.
    pub fn new(latitude_rad: f64, longitude_rad: f64, altitude_m: f64) -> Self {
        Self {
            latitude_rad,
            longitude_rad,
            altitude_m,
            north_per_rad: meridian_radius(latitude_rad) + altitude_m,
            east_per_rad: (prime_vertical_radius(latitude_rad) + altitude_m) * latitude_rad.cos(),
        }
    }

    /// North, east, down of a geodetic position, m. Longitude differences are taken across the
    /// ±180° meridian the short way.
    pub fn ned(&self, latitude_rad: f64, longitude_rad: f64, altitude_m: f64) -> [f64; 3] {
        let mut dlon = longitude_rad - self.longitude_rad;
        if dlon > std::f64::consts::PI {
            dlon -= std::f64::consts::TAU;
        } else if dlon < -std::f64::consts::PI {
            dlon += std::f64::consts::TAU;
        }
        [
            (latitude_rad - self.latitude_rad) * self.north_per_rad,
            dlon * self.east_per_rad,
            self.altitude_m - altitude_m,
        ]
    }
}

impl LocalOrigin {
    /// The geodetic position `ned` metres (north, east, down) from the origin: the inverse of
    /// [`LocalOrigin::ned`].
    pub fn geodetic(&self, ned: [f64; 3]) -> [f64; 3] {
        [
            self.latitude_rad + ned[0] / self.north_per_rad,
            self.longitude_rad + ned[1] / self.east_per_rad,
            self.altitude_m - ned[2],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_origin_is_zero_and_steps_follow_the_radii() {
        let lat = 47.0f64.to_radians();
        let o = LocalOrigin::new(lat, 0.15, 500.0);
        assert_eq!(o.ned(lat, 0.15, 500.0), [0.0, 0.0, 0.0]);
        let d = 1e-4;
        let [n, e, down] = o.ned(lat + d, 0.15 + d, 510.0);
        assert!((n - d * (meridian_radius(lat) + 500.0)).abs() < 1e-9);
        assert!((e - d * (prime_vertical_radius(lat) + 500.0) * lat.cos()).abs() < 1e-9);
        assert_eq!(down, -10.0);
        // 1e-4 rad is about 636 m north at this latitude.
        assert!((n - 636.0).abs() < 2.0, "{n}");
    }

    #[test]
    fn longitude_wraps_across_the_antimeridian() {
        let o = LocalOrigin::new(0.0, std::f64::consts::PI - 1e-6, 0.0);
        let [_, e, _] = o.ned(0.0, -std::f64::consts::PI + 1e-6, 0.0);
        assert!((e - 2e-6 * 6_378_137.0).abs() < 1e-6, "{e}");
    }

    #[test]
    fn geodetic_is_the_inverse_of_ned() {
        let o = LocalOrigin::new(0.7, -1.2, 120.0);
        let [lat, lon, alt] = o.geodetic([350.0, -120.0, 4.5]);
        let back = o.ned(lat, lon, alt);
        for (b, want) in back.iter().zip([350.0, -120.0, 4.5]) {
            assert!((b - want).abs() < 1e-9, "{back:?}");
        }
    }
}
