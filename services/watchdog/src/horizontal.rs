//! Horizontal position against simulator truth: how far the truth travelled over the ground and
//! how far the navigation solution ended from it, the figure of a pedestrian walk (end-point
//! error, also as a share of the distance walked).

use crate::error_stats::ErrorStats;

/// A horizontal position, latitude and longitude in radians (WGS84), height in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Position {
    /// Latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Height, m (scales the radii; a walk's few metres hardly matter).
    pub height_m: f64,
}

impl Position {
    /// North and east offsets (m) from `self` to `other`, on the plane tangent at `self`: exact
    /// enough over the metres between two samples, and over a walk's end-point error.
    pub fn north_east_to(&self, other: &Position) -> [f64; 2] {
        let m = rins_earth::meridian_radius(self.lat_rad) + self.height_m;
        let n = rins_earth::prime_vertical_radius(self.lat_rad) + self.height_m;
        [
            (other.lat_rad - self.lat_rad) * m,
            (other.lon_rad - self.lon_rad) * n * self.lat_rad.cos(),
        ]
    }

    /// Horizontal distance to `other`, m.
    pub fn distance_to(&self, other: &Position) -> f64 {
        let [n, e] = self.north_east_to(other);
        n.hypot(e)
    }
}

/// The truth's path length and the latest horizontal error of the solution.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HorizontalTrack {
    last_truth: Option<Position>,
    distance_m: f64,
    end_error_m: Option<f64>,
    errors: ErrorStats,
    /// North/east error of the last sample, m.
    last_error_ne: Option<[f64; 2]>,
    /// Largest change of the north/east error from one sample to the next, m.
    largest_step_m: f64,
}

impl HorizontalTrack {
    /// Adds one navigation sample and the truth of its frame: the truth's step since the last
    /// one adds to the distance, the error replaces the last one.
    pub fn push(&mut self, truth: Position, nav: Position) {
        if let Some(last) = self.last_truth {
            self.distance_m += last.distance_to(&truth);
        }
        self.last_truth = Some(truth);
        let error = truth.distance_to(&nav);
        self.end_error_m = Some(error);
        self.errors.push(error);
        let ne = truth.north_east_to(&nav);
        if let Some([n, e]) = self.last_error_ne {
            self.largest_step_m = self.largest_step_m.max((ne[0] - n).hypot(ne[1] - e));
        }
        self.last_error_ne = Some(ne);
    }

    /// Largest jump of the solution from one sample to the next that the truth's motion does
    /// not explain (the change of the horizontal error vector), m; `None` before two samples.
    pub fn largest_step_m(&self) -> Option<f64> {
        (self.errors.count() > 1).then_some(self.largest_step_m)
    }

    /// RMS and largest horizontal error over every sample added.
    pub fn errors(&self) -> &ErrorStats {
        &self.errors
    }

    /// Horizontal distance the truth travelled while samples were added, m; `None` before the
    /// first sample.
    pub fn distance_m(&self) -> Option<f64> {
        self.last_truth.map(|_| self.distance_m)
    }

    /// Horizontal error of the last sample, m.
    pub fn end_error_m(&self) -> Option<f64> {
        self.end_error_m
    }

    /// The end error as a percentage of the distance; `None` when nothing moved (under a metre:
    /// a share of nothing means nothing).
    pub fn end_error_pct(&self) -> Option<f64> {
        match (self.end_error_m, self.distance_m()) {
            (Some(err), Some(d)) if d >= 1.0 => Some(100.0 * err / d),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(north_m: f64, east_m: f64) -> Position {
        let lat0 = 0.8_f64;
        let m = rins_earth::meridian_radius(lat0);
        let n = rins_earth::prime_vertical_radius(lat0);
        Position {
            lat_rad: lat0 + north_m / m,
            lon_rad: 0.15 + east_m / (n * lat0.cos()),
            height_m: 0.0,
        }
    }

    #[test]
    fn distance_adds_the_steps_and_the_error_is_the_last() {
        let mut t = HorizontalTrack::default();
        assert_eq!(t.distance_m(), None);
        assert_eq!(t.end_error_pct(), None);
        // Three sides of a 30 × 40 m rectangle: 100 m walked; the solution ends 3 m east, 4 m
        // north of the truth.
        for (truth, nav) in [
            (at(0.0, 0.0), at(0.0, 0.0)),
            (at(30.0, 0.0), at(30.0, 1.0)),
            (at(30.0, 40.0), at(31.0, 40.0)),
            (at(0.0, 40.0), at(4.0, 43.0)),
        ] {
            t.push(truth, nav);
        }
        assert!((t.distance_m().unwrap() - 100.0).abs() < 1e-2, "{t:?}");
        assert!((t.end_error_m().unwrap() - 5.0).abs() < 1e-3, "{t:?}");
        assert!((t.end_error_pct().unwrap() - 5.0).abs() < 1e-3, "{t:?}");
        // Errors 0, 1, 1, 5 m.
        assert!((t.errors().rms().unwrap() - (27.0f64 / 4.0).sqrt()).abs() < 1e-3);
        assert!((t.errors().max().unwrap() - 5.0).abs() < 1e-3);
        // Error vectors (n, e): (0, 0), (0, 1), (1, 0), (4, 3): the last change is the largest.
        assert!((t.largest_step_m().unwrap() - 3.0f64.hypot(3.0)).abs() < 1e-3);
    }

    #[test]
    fn standing_still_has_no_percentage() {
        let mut t = HorizontalTrack::default();
        t.push(at(0.0, 0.0), at(0.5, 0.0));
        t.push(at(0.0, 0.0), at(0.6, 0.0));
        assert_eq!(t.distance_m(), Some(0.0));
        assert!((t.end_error_m().unwrap() - 0.6).abs() < 1e-6);
        assert_eq!(t.end_error_pct(), None);
    }
}
