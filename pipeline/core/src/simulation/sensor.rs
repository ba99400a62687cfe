//! Simulated observations from true geometry (000 §VIII-B): bearings and range order of the `n`
//! nearest landmarks, optionally with bearing noise and range-order errors.

use crate::geometry::Point;
use crate::map::LandmarkId;
use crate::measurement::{Bearing, RangeOrder, StationView};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// How the simulated camera sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// Use only this many nearest landmarks (000 Fig. 7's `n`); all when `None`.
    pub nearest: Option<usize>,
    /// Bearing errors are uniform in `±bearing_noise` (radians) …
    pub bearing_noise: f64,
    /// … and the measurement is told they are within `±bearing_uncertainty`. Equal values make
    /// a correct error model; a smaller uncertainty than noise tests contradiction handling.
    pub bearing_uncertainty: f64,
    /// Range-order errors: walking the true order nearest first, each position is swapped with
    /// the one before it with this probability (so a landmark can drift several places).
    pub order_swap_probability: f64,
}

impl Sensor {
    /// Exact bearings and range order of the `nearest` landmarks.
    pub fn exact(nearest: Option<usize>) -> Sensor {
        Sensor {
            nearest,
            bearing_noise: 0.0,
            bearing_uncertainty: 0.0,
            order_swap_probability: 0.0,
        }
    }

    /// The landmarks seen from `station` (ids) and the panorama measured there.
    pub fn observe(
        &self,
        landmarks: &[Point],
        station: Point,
        rng: &mut ChaCha8Rng,
    ) -> (Vec<LandmarkId>, StationView) {
        let mut by_range: Vec<usize> = (0..landmarks.len()).collect();
        by_range.sort_by(|&i, &j| {
            landmarks[i]
                .distance(station)
                .total_cmp(&landmarks[j].distance(station))
        });
        by_range.truncate(self.nearest.unwrap_or(landmarks.len()));
        // Positions in the view follow the (possibly corrupted) range order, nearest first.
        let mut nearest_first: Vec<usize> = (0..by_range.len()).collect();
        for k in 1..nearest_first.len() {
            if rng.random_bool(self.order_swap_probability) {
                nearest_first.swap(k - 1, k);
            }
        }
        let bearings = by_range
            .iter()
            .map(|&i| {
                let p = landmarks[i];
                let error = if self.bearing_noise > 0.0 {
                    rng.random_range(-self.bearing_noise..=self.bearing_noise)
                } else {
                    0.0
                };
                Bearing {
                    angle: (p.y - station.y).atan2(p.x - station.x) + error,
                    uncertainty: self.bearing_uncertainty,
                }
            })
            .collect();
        let order = RangeOrder::total(&nearest_first).expect("a permutation is a chain");
        let panorama = StationView::new(bearings, order).expect("simulated bearings are valid");
        (
            by_range.iter().map(|&i| i as LandmarkId).collect(),
            panorama,
        )
    }
}
