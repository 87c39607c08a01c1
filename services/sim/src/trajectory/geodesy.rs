//! The tabulated latitude/longitude path over the WGS84 ellipsoid (radii from `rins_earth`).
//!
//! Latitude and longitude are the integral of the curvilinear kinematics over a non-rotating
//! ellipsoid, `φ̇ = v_N/(R_M(φ)+h)`, `λ̇ = v_E/((R_N(φ)+h) cos φ)`, so a navigator mechanised with
//! these equations reproduces the truth exactly. The integral is precomputed at construction on a
//! fixed grid and sampled by cubic Hermite interpolation (value and rate at both knots), which keeps
//! the sampled position's derivative consistent with the velocity to far below a millimetre.

use rins_earth::{meridian_radius, prime_vertical_radius};

/// (φ̇, λ̇) in rad/s for a north/east velocity at latitude φ and altitude h.
pub fn geodetic_rates(latitude_rad: f64, altitude_m: f64, v_north: f64, v_east: f64) -> [f64; 2] {
    [
        v_north / (meridian_radius(latitude_rad) + altitude_m),
        v_east / ((prime_vertical_radius(latitude_rad) + altitude_m) * latitude_rad.cos()),
    ]
}

/// Kinematic inputs of the position integral at one instant.
#[derive(Debug, Clone, Copy)]
pub struct Kinematics {
    /// North velocity, m/s.
    pub v_north: f64,
    /// East velocity, m/s.
    pub v_east: f64,
    /// Altitude above the ellipsoid, m.
    pub altitude_m: f64,
}

/// Latitude/longitude on a fixed time grid, interpolated between knots.
#[derive(Debug, Clone)]
pub struct GeodeticTable {
    start_s: f64,
    spacing_s: f64,
    /// Per knot: [φ, λ, φ̇, λ̇].
    knots: Vec<[f64; 4]>,
}

impl GeodeticTable {
    /// Integrates from `(lat0, lon0)` at `start_s` (the vehicle is at rest before it) to `end_s`
    /// with RK4 on a grid of `spacing_s`. Only the moving span is stored, so a long parked prefix
    /// costs nothing.
    pub fn integrate(
        lat0: f64,
        lon0: f64,
        start_s: f64,
        end_s: f64,
        spacing_s: f64,
        kinematics: impl Fn(f64) -> Kinematics,
    ) -> Self {
        let rates = |t: f64, lat: f64| {
            let k = kinematics(t);
            geodetic_rates(lat, k.altitude_m, k.v_north, k.v_east)
        };
        // Whole number of intervals covering the moving span (NaN and negative spans give one).
        let intervals = ((end_s - start_s).max(0.0) / spacing_s).ceil() as usize + 1;
        let mut knots = Vec::with_capacity(intervals + 1);
        let (mut lat, mut lon) = (lat0, lon0);
        let h = spacing_s;
        for i in 0..=intervals {
            let t = start_s + i as f64 * h;
            let k1 = rates(t, lat);
            knots.push([lat, lon, k1[0], k1[1]]);
            let k2 = rates(t + 0.5 * h, lat + 0.5 * h * k1[0]);
            let k3 = rates(t + 0.5 * h, lat + 0.5 * h * k2[0]);
            let k4 = rates(t + h, lat + h * k3[0]);
            lat += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]);
            lon += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]);
        }
        Self {
            start_s,
            spacing_s,
            knots,
        }
    }

    /// A table that stays at one point forever.
    pub fn fixed(lat: f64, lon: f64) -> Self {
        Self {
            start_s: 0.0,
            spacing_s: 1.0,
            knots: vec![[lat, lon, 0.0, 0.0]],
        }
    }

    /// (φ, λ) at time `t` seconds; holds the first knot before the table starts and the last
    /// after it ends.
    pub fn sample(&self, t: f64) -> [f64; 2] {
        let last = self.knots.len() - 1;
        let x = (t - self.start_s) / self.spacing_s;
        if x.is_nan() || x <= 0.0 {
            let k = &self.knots[0];
            return [k[0], k[1]];
        }
        if last == 0 || x >= last as f64 {
            let k = &self.knots[last];
            return [k[0], k[1]];
        }
        let i = x as usize;
        let u = x - i as f64;
        let (a, b) = (&self.knots[i], &self.knots[i + 1]);
        let u2 = u * u;
        let u3 = u2 * u;
        let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
        let h10 = u3 - 2.0 * u2 + u;
        let h01 = -2.0 * u3 + 3.0 * u2;
        let h11 = u3 - u2;
        let h = self.spacing_s;
        [
            h00 * a[0] + h10 * h * a[2] + h01 * b[0] + h11 * h * b[2],
            h00 * a[1] + h10 * h * a[3] + h01 * b[1] + h11 * h * b[3],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_north_velocity_advances_latitude_by_distance_over_radius() {
        let lat0 = 0.8;
        let table = GeodeticTable::integrate(lat0, 0.1, 0.0, 100.0, 0.01, |_| Kinematics {
            v_north: 10.0,
            v_east: 0.0,
            altitude_m: 0.0,
        });
        let [lat, lon] = table.sample(100.0);
        // Over 1 km R_M changes by ~1e-4 relative: the first-order estimate holds to ~1e-11 rad.
        let approx = lat0 + 1000.0 / meridian_radius(lat0 + 0.5 * 1000.0 / meridian_radius(lat0));
        assert!((lat - approx).abs() < 1e-11, "{lat} vs {approx}");
        assert_eq!(lon, 0.1);
        let mid = table.sample(50.005)[0];
        let expected_mid = lat0 + 500.05 / meridian_radius(lat0 + 250.0 / meridian_radius(lat0));
        assert!((mid - expected_mid).abs() < 1e-11);
    }
}
