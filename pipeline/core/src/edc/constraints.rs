//! EDC regions as strict quadratic inequalities on symbolic points (000 Table II, Table III):
//! the input of every feasibility problem of the project.

use super::region::defining_boundaries;
use crate::feasibility::{Linear, Quadratic};
use crate::geometry::{boundary_values, Point2};

/// Constraints `q < 0` that hold exactly when `c` lies in `region` of `a → b`, for points whose
/// coordinates are affine in the unknowns.
pub fn region_constraints(
    a: &Point2<Linear>,
    b: &Point2<Linear>,
    c: &Point2<Linear>,
    region: u8,
) -> Vec<Quadratic> {
    let values = boundary_values(a, b, c);
    defining_boundaries(region)
        .into_iter()
        .map(|(boundary, sign)| {
            // Positive side wanted ⇒ −value < 0.
            let v = values[boundary as usize].clone();
            if sign > 0 {
                -v
            } else {
                v
            }
        })
        .collect()
}

/// A point with constant coordinates among `n` unknowns.
pub fn fixed_point(n: usize, x: f64, y: f64) -> Point2<Linear> {
    Point2::new(Linear::constant(n, x), Linear::constant(n, y))
}

/// The point `(x_i, x_j)` of unknowns `i`, `j`.
pub fn free_point(n: usize, i: usize, j: usize) -> Point2<Linear> {
    Point2::new(Linear::variable(n, i), Linear::variable(n, j))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edc::region::classify;
    use crate::geometry::Point;
    use rand::{Rng, SeedableRng};

    #[test]
    fn constraints_agree_with_the_classifier() {
        let a = fixed_point(2, 0.0, 0.0);
        let b = fixed_point(2, 0.0, 1.0);
        let c = free_point(2, 0, 1);
        let all: Vec<Vec<Quadratic>> = (1..=20)
            .map(|r| region_constraints(&a, &b, &c, r))
            .collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..20_000 {
            let x = [rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0)];
            let Some(r) = classify(
                Point::new(0.0, 0.0),
                Point::new(0.0, 1.0),
                Point::new(x[0], x[1]),
            ) else {
                continue;
            };
            for (i, cs) in all.iter().enumerate() {
                let inside = cs.iter().all(|q| q.eval(&x) < 0.0);
                assert_eq!(
                    inside,
                    i + 1 == r as usize,
                    "point {x:?} region {r} vs {}",
                    i + 1
                );
            }
        }
    }
}
