use super::Point2;
use std::ops::{Add, Sub};

/// A coordinate type whose pairwise products form a ring (`Product`): numbers multiply to
/// numbers, affine expressions multiply to quadratic forms. Every boundary function of the
/// double-cross calculi is a sum of such products, so one definition serves classification and
/// constraint generation alike.
pub trait Coordinate: Clone + Sub<Output = Self> {
    type Product: Clone + Add<Output = Self::Product> + Sub<Output = Self::Product>;
    fn mul(&self, other: &Self) -> Self::Product;
}

impl Coordinate for f64 {
    type Product = f64;
    fn mul(&self, other: &Self) -> f64 {
        self * other
    }
}

impl Coordinate for num_rational::BigRational {
    type Product = num_rational::BigRational;
    fn mul(&self, other: &Self) -> Self::Product {
        self * other
    }
}

/// The six dichotomies that split the plane around the directed segment AB (000 Fig. 3a).
/// Each boundary function is positive on the side named by the variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Boundary {
    /// C is left of AB: cross(B−A, C−A) > 0 (003 App. C: −c1).
    Left,
    /// C is in front of A: (B−A)·(C−A) > 0 (the c2 of 003 App. C, despite its label).
    FrontOfA,
    /// C is in front of B: (B−A)·(C−B) > 0 (the c3 of 003 App. C, despite its label).
    FrontOfB,
    /// C is nearer to B than to A: |AC|² − |BC|² > 0 (−c4).
    NearerToB,
    /// C is outside the circle about A through B: |AC|² − |AB|² > 0 (−c5).
    OutsideCircleA,
    /// C is outside the circle about B through A: |BC|² − |AB|² > 0 (−c6).
    OutsideCircleB,
}

impl Boundary {
    pub const ALL: [Boundary; 6] = [
        Boundary::Left,
        Boundary::FrontOfA,
        Boundary::FrontOfB,
        Boundary::NearerToB,
        Boundary::OutsideCircleA,
        Boundary::OutsideCircleB,
    ];
}

fn dot<T: Coordinate>(u: &Point2<T>, v: &Point2<T>) -> T::Product {
    u.x.mul(&v.x) + u.y.mul(&v.y)
}

fn cross<T: Coordinate>(u: &Point2<T>, v: &Point2<T>) -> T::Product {
    u.x.mul(&v.y) - u.y.mul(&v.x)
}

/// The six boundary functions of C relative to AB, in the order of [`Boundary::ALL`].
pub fn boundary_values<T: Coordinate>(
    a: &Point2<T>,
    b: &Point2<T>,
    c: &Point2<T>,
) -> [T::Product; 6] {
    let ab = Point2::new(b.x.clone() - a.x.clone(), b.y.clone() - a.y.clone());
    let ac = Point2::new(c.x.clone() - a.x.clone(), c.y.clone() - a.y.clone());
    let bc = Point2::new(c.x.clone() - b.x.clone(), c.y.clone() - b.y.clone());
    let ab2 = dot(&ab, &ab);
    let ac2 = dot(&ac, &ac);
    let bc2 = dot(&bc, &bc);
    [
        cross(&ab, &ac),
        dot(&ab, &ac),
        dot(&ab, &bc),
        ac2.clone() - bc2.clone(),
        ac2 - ab2.clone(),
        bc2 - ab2,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_in_the_canonical_frame() {
        // A=(0,0), B=(0,1): a point far up-left is left, in front of both, nearer B,
        // outside both circles.
        let a = Point2::new(0.0, 0.0);
        let b = Point2::new(0.0, 1.0);
        let v = boundary_values(&a, &b, &Point2::new(-2.0, 3.0));
        assert!(v.iter().all(|&x| x > 0.0), "{v:?}");
        // Just behind A on the right: only "outside the circle about B" holds.
        let v = boundary_values(&a, &b, &Point2::new(0.3, -0.2));
        let signs: Vec<bool> = v.iter().map(|&x| x > 0.0).collect();
        assert_eq!(signs, [false, false, false, false, false, true], "{v:?}");
    }
}
