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
    /// Association errors: each sighting is, with this probability, reported as a landmark
    /// not seen at this station (a look-alike from elsewhere in the field), drawn uniformly.
    pub wrong_association_probability: f64,
}

impl Sensor {
    /// Exact bearings and range order of the `nearest` landmarks.
    pub fn exact(nearest: Option<usize>) -> Sensor {
        Sensor {
            nearest,
            bearing_noise: 0.0,
            bearing_uncertainty: 0.0,
            order_swap_probability: 0.0,
            wrong_association_probability: 0.0,
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
        let mut ids: Vec<LandmarkId> = by_range.iter().map(|&i| i as LandmarkId).collect();
        // No draws at probability 0: runs without association errors are those of before.
        if self.wrong_association_probability > 0.0 {
            for k in 0..ids.len() {
                if rng.random_bool(self.wrong_association_probability) {
                    let unseen: Vec<LandmarkId> = (0..landmarks.len() as LandmarkId)
                        .filter(|&id| !by_range.contains(&(id as usize)) && !ids.contains(&id))
                        .collect();
                    if !unseen.is_empty() {
                        ids[k] = unseen[rng.random_range(0..unseen.len())];
                    }
                }
            }
        }
        (ids, panorama)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Every wrong association names a landmark the station does not see, each once, and
    /// the view (bearings, order) is the true one; without errors the ids are the nearest.
    #[test]
    fn wrong_associations_name_landmarks_out_of_view() {
        let landmarks: Vec<Point> = (0..12)
            .map(|k| Point::new(f64::from(k), f64::from(k * k % 7)))
            .collect();
        let station = Point::new(0.5, 0.5);
        let exact = Sensor::exact(Some(5));
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let (nearest, view) = exact.observe(&landmarks, station, &mut rng);
        let wrong = Sensor {
            wrong_association_probability: 1.0,
            ..exact
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let (ids, wrong_view) = wrong.observe(&landmarks, station, &mut rng);
        assert_eq!(wrong_view, view);
        assert_eq!(ids.len(), 5);
        assert!(ids.iter().all(|id| !nearest.contains(id)), "{ids:?}");
        let mut unique = ids.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), 5);
    }
}
