//! Landmark fields and imaging points for simulated mapping (000 §VIII-B; 003 §1.5.2).

use crate::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Ground truth of one simulated mapping run: landmark `i` has id `i`.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    pub landmarks: Vec<Point>,
    /// Imaging points in the order they are visited.
    pub stations: Vec<Point>,
}

impl Scenario {
    /// Landmarks and imaging points uniform in a `side × side` square (000 §VIII-B).
    pub fn random(seed: u64, landmarks: usize, stations: usize, side: f64) -> Scenario {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut point = || Point::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
        let landmarks = (0..landmarks).map(|_| point()).collect();
        let stations = (0..stations).map(|_| point()).collect();
        Scenario {
            landmarks,
            stations,
        }
    }
}
