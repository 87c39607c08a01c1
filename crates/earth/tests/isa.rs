//! ISA pressure ↔ altitude.

use proptest::prelude::*;
use rins_earth::isa::{
    EXPONENT, HEIGHT_SCALE_M, altitude_per_pascal, altitude_to_pressure, pressure_to_altitude,
};

#[test]
fn exponent_and_scale_match_the_standard() {
    // The standard-atmosphere exponent (R = 8.31432).
    assert!((EXPONENT - 0.190263).abs() < 1e-6, "{EXPONENT}");
    assert!(
        (HEIGHT_SCALE_M - 44_330.77).abs() < 0.01,
        "{HEIGHT_SCALE_M}"
    );
}

#[test]
fn known_values() {
    assert_eq!(pressure_to_altitude(101_325.0, 101_325.0), 0.0);
    // ISA table: 1000 m ↔ 89 874.6 Pa.
    let h = pressure_to_altitude(89_874.6, 101_325.0);
    assert!((h - 1000.0).abs() < 0.1, "{h}");
    // ISA table: 11 000 m ↔ 22 632 Pa; 5000 m ↔ 54 019.9 Pa (the table uses R = 8.31432, hence 1 m).
    assert!((pressure_to_altitude(22_632.1, 101_325.0) - 11_000.0).abs() < 1.0);
    assert!((pressure_to_altitude(54_019.9, 101_325.0) - 5000.0).abs() < 1.0);
    // A higher QNH puts the same pressure higher: (T0/L)(1 − (p/QNH)^e) with QNH = 102 000.
    let expected = HEIGHT_SCALE_M * (1.0 - (89_874.6_f64 / 102_000.0).powf(EXPONENT));
    let h102 = pressure_to_altitude(89_874.6, 102_000.0);
    assert!((h102 - expected).abs() < 1e-9);
    // About 8.1 m per hPa at 1000 m: 675 Pa more QNH ≈ 55 m higher.
    assert!((h102 - h - 55.0).abs() < 1.0, "{}", h102 - h);
    // And the inverse: at QNH 102 000, 1000 m is at a proportionally higher pressure.
    let p = altitude_to_pressure(1000.0, 102_000.0);
    assert!((p - 89_874.6 * 102_000.0 / 101_325.0).abs() < 1.0, "{p}");
}

#[test]
fn invalid_inputs_do_not_pretend() {
    assert!(pressure_to_altitude(0.0, 101_325.0).is_nan());
    assert!(pressure_to_altitude(-5.0, 101_325.0).is_nan());
    assert!(pressure_to_altitude(f64::NAN, 101_325.0).is_nan());
    assert!(pressure_to_altitude(90_000.0, 0.0).is_nan());
    assert_eq!(altitude_to_pressure(50_000.0, 101_325.0), 0.0);
}

proptest! {
    #[test]
    fn round_trip(h in -500.0..11_000.0f64, qnh in 95_000.0..105_000.0f64) {
        let p = altitude_to_pressure(h, qnh);
        prop_assert!((pressure_to_altitude(p, qnh) - h).abs() < 1e-6);
        let p2 = altitude_to_pressure(pressure_to_altitude(p, qnh), qnh);
        prop_assert!((p2 - p).abs() < 1e-7 * p);
    }

    #[test]
    fn derivative_matches_finite_difference(h in -500.0..11_000.0f64) {
        let qnh = 101_325.0;
        let p = altitude_to_pressure(h, qnh);
        let dp = 1.0;
        let fd = (pressure_to_altitude(p + dp, qnh) - pressure_to_altitude(p - dp, qnh)) / (2.0 * dp);
        let d = altitude_per_pascal(p, qnh);
        prop_assert!(d < 0.0);
        prop_assert!((d - fd).abs() < 1e-6 * fd.abs(), "{} vs {}", d, fd);
    }
}

#[test]
fn density_is_the_standard_one_at_sea_level_and_thinner_aloft() {
    use rins_earth::isa::density_kg_m3;
    // U.S. Standard Atmosphere 1976: 1.2250 kg/m³ at sea level, 1.1117 at 1 km, 0.9093 at 3 km.
    for (h, rho) in [(0.0, 1.2250), (1000.0, 1.1117), (3000.0, 0.9093)] {
        let got = density_kg_m3(h, 101_325.0);
        assert!((got - rho).abs() < 5e-4, "{h} m: {got}");
    }
}
