//! The 20 regions of the Extended Double Cross and their numbering (000 §II, Fig. 3b).
//!
//! The figure is missing from the text; the numbering is pinned down by the constraint sets of
//! 003 Appendix C (e.g. state 1: left, in front of B, outside the circle about B; state 7: left,
//! inside the circle about A, nearer to B), the worked example for state 2 in 000 §III-B, and the
//! lune states {7, 8, 13, 14} of §VII-A. With A=(0,0), B=(0,1) the regions run row by row from
//! the front of B to behind A:
//!
//! ```text
//!  y > 1        1 | 3  ‖ 4 | 2           (outer left | inside circle B ‖ …)
//!  ½ < y < 1    5 | 6 | 7 ‖ 8 | 9 | 10   (outside both | circle B only | lune ‖ …)
//!  0 < y < ½   11 |12 |13 ‖14 |15 | 16   (outside both | circle A only | lune ‖ …)
//!  y < 0       19 |17  ‖ 18 | 20         (outside circle A | inside circle A ‖ …)
//! ```
//! Table I of 000 is reproduced from this numbering by sampling in the tests.

use crate::geometry::{boundary_values, Boundary, Point};

/// Number of EDC regions.
pub const REGIONS: u8 = 20;

/// Sign (+1 / −1) of each boundary function of [`Boundary::ALL`] inside each region `1..=20`:
/// `[Left, FrontOfA, FrontOfB, NearerToB, OutsideCircleA, OutsideCircleB]`.
pub const SIGNS: [[i8; 6]; 20] = [
    [1, 1, 1, 1, 1, 1],      // 1
    [-1, 1, 1, 1, 1, 1],     // 2
    [1, 1, 1, 1, 1, -1],     // 3
    [-1, 1, 1, 1, 1, -1],    // 4
    [1, 1, -1, 1, 1, 1],     // 5
    [1, 1, -1, 1, 1, -1],    // 6
    [1, 1, -1, 1, -1, -1],   // 7
    [-1, 1, -1, 1, -1, -1],  // 8
    [-1, 1, -1, 1, 1, -1],   // 9
    [-1, 1, -1, 1, 1, 1],    // 10
    [1, 1, -1, -1, 1, 1],    // 11
    [1, 1, -1, -1, -1, 1],   // 12
    [1, 1, -1, -1, -1, -1],  // 13
    [-1, 1, -1, -1, -1, -1], // 14
    [-1, 1, -1, -1, -1, 1],  // 15
    [-1, 1, -1, -1, 1, 1],   // 16
    [1, -1, -1, -1, -1, 1],  // 17
    [-1, -1, -1, -1, -1, 1], // 18
    [1, -1, -1, -1, 1, 1],   // 19
    [-1, -1, -1, -1, 1, 1],  // 20
];

/// The lune of A and B (inside both circles): the regions that rule out an RNG edge (§VII-A).
pub const LUNE: [u8; 4] = [7, 8, 13, 14];

/// The region whose sign vector is `signs`, if any.
pub fn region_of_signs(signs: [i8; 6]) -> Option<u8> {
    let index = signs
        .iter()
        .enumerate()
        .fold(0usize, |acc, (i, &s)| acc | (usize::from(s > 0) << i));
    match REGION_BY_SIGN_BITS[index] {
        0 => None,
        r => Some(r),
    }
}

/// [`SIGNS`] inverted: bit `i` of the index set when boundary `i` is positive; 0 for sign
/// vectors that no region has (measurement classifies millions of samples).
const REGION_BY_SIGN_BITS: [u8; 64] = {
    let mut table = [0u8; 64];
    let mut r = 0;
    while r < SIGNS.len() {
        let mut index = 0;
        let mut i = 0;
        while i < 6 {
            if SIGNS[r][i] > 0 {
                index |= 1 << i;
            }
            i += 1;
        }
        table[index] = r as u8 + 1;
        r += 1;
    }
    table
};

/// Whether `region` lies left of AB.
pub fn is_left(region: u8) -> bool {
    SIGNS[region as usize - 1][0] > 0
}

/// The region's mirror image across the line AB (left and right swapped): reflection maps a
/// configuration with `AB:C = r` to one with `AB:C = mirror(r)` in every frame at once.
pub fn mirror(region: u8) -> u8 {
    let mut signs = SIGNS[region as usize - 1];
    signs[0] = -signs[0];
    region_of_signs(signs).expect("every region has a mirror image")
}

/// The EDC region of `c` relative to `a → b`, or `None` if `c` lies on a boundary (or the
/// triple is degenerate).
pub fn classify(a: Point, b: Point, c: Point) -> Option<u8> {
    if a == b {
        return None;
    }
    let values = boundary_values(&a, &b, &c);
    let mut signs = [0i8; 6];
    for (s, v) in signs.iter_mut().zip(values) {
        if v == 0.0 || !v.is_finite() {
            return None;
        }
        *s = if v > 0.0 { 1 } else { -1 };
    }
    region_of_signs(signs)
}

/// The smallest boundary conditions that define `region` on their own: a condition is dropped
/// while no other region agrees with `region` on the conditions left (003 App. C lists 3 or 4
/// per region, as here).
pub fn defining_boundaries(region: u8) -> Vec<(Boundary, i8)> {
    let own = SIGNS[region as usize - 1];
    let mut kept: Vec<usize> = (0..6).collect();
    for candidate in 0..6 {
        let trial: Vec<usize> = kept.iter().copied().filter(|&k| k != candidate).collect();
        let ambiguous = SIGNS
            .iter()
            .enumerate()
            .any(|(i, s)| i + 1 != region as usize && trial.iter().all(|&k| s[k] == own[k]));
        if !ambiguous {
            kept = trial;
        }
    }
    kept.into_iter()
        .map(|k| (Boundary::ALL[k], own[k]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_are_distinct_and_definitions_minimal() {
        for (i, s) in SIGNS.iter().enumerate() {
            assert_eq!(region_of_signs(*s), Some(i as u8 + 1));
            let d = defining_boundaries(i as u8 + 1);
            assert!(
                (2..=4).contains(&d.len()),
                "region {} uses {}",
                i + 1,
                d.len()
            );
        }
    }

    proptest::proptest! {
        /// Regions are invariant under rotation, scaling and translation, and swap under
        /// reflection exactly as `mirror` says.
        #[test]
        fn regions_are_similarity_invariant(
            x in -3.0f64..3.0, y in -3.0f64..3.0,
            angle in 0.0f64..6.3, scale in 0.01f64..100.0, tx in -50.0f64..50.0, ty in -50.0f64..50.0,
        ) {
            let a = Point::new(0.0, 0.0);
            let b = Point::new(0.0, 1.0);
            let c = Point::new(x, y);
            // Stay clear of boundaries, where rounding may legitimately flip a sign.
            let values = boundary_values(&a, &b, &c);
            proptest::prop_assume!(values.iter().all(|v| v.abs() > 1e-6));
            let r = classify(a, b, c).unwrap();
            let t = |p: Point| Point::new(
                tx + scale * (angle.cos() * p.x - angle.sin() * p.y),
                ty + scale * (angle.sin() * p.x + angle.cos() * p.y),
            );
            proptest::prop_assert_eq!(classify(t(a), t(b), t(c)), Some(r));
            let m = |p: Point| t(Point::new(-p.x, p.y));
            proptest::prop_assert_eq!(classify(m(a), m(b), m(c)), Some(mirror(r)));
        }
    }

    #[test]
    fn worked_example_of_state_2() {
        // 000 §III-B: AB:C = 2 ⇔ α > 0, β − 1 > 0, α² + β² − 2β > 0.
        let d = defining_boundaries(2);
        assert_eq!(
            d,
            vec![
                (Boundary::Left, -1),
                (Boundary::FrontOfB, 1),
                (Boundary::OutsideCircleB, 1)
            ]
        );
        let a = Point::new(0.0, 0.0);
        let b = Point::new(0.0, 1.0);
        assert_eq!(classify(a, b, Point::new(1.5, 2.5)), Some(2));
        assert_eq!(classify(a, b, Point::new(0.0, 2.5)), None);
    }
}
