//! Shared helpers of the cross-crate tests: random configurations that are independent of the
//! code under test (plain coordinates, random similarity transforms, many scales).

use qrm_core::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A random point at a log-uniform scale between 10⁻³ and 10³ around a random centre.
pub fn random_point(rng: &mut ChaCha8Rng) -> Point {
    let scale = 10f64.powf(rng.random_range(-3.0..3.0));
    Point::new(
        rng.random_range(-scale..scale),
        rng.random_range(-scale..scale),
    )
}

/// A random similarity transform (rotation, scale 10⁻³…10³, translation) of the plane.
pub struct Similarity {
    cos: f64,
    sin: f64,
    scale: f64,
    shift: Point,
}

impl Similarity {
    pub fn random(rng: &mut ChaCha8Rng) -> Similarity {
        let angle = rng.random_range(0.0..std::f64::consts::TAU);
        Similarity {
            cos: angle.cos(),
            sin: angle.sin(),
            scale: 10f64.powf(rng.random_range(-3.0..3.0)),
            shift: Point::new(
                rng.random_range(-100.0..100.0),
                rng.random_range(-100.0..100.0),
            ),
        }
    }

    pub fn apply(&self, p: Point) -> Point {
        Point::new(
            self.shift.x + self.scale * (self.cos * p.x - self.sin * p.y),
            self.shift.y + self.scale * (self.sin * p.x + self.cos * p.y),
        )
    }
}
