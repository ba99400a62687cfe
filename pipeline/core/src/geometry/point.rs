use std::ops::{Add, Sub};

/// A point whose coordinates are numbers (`f64`, exact rationals) or symbolic affine
/// expressions in unknowns (for building feasibility constraints).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
pub struct Point2<T> {
    pub x: T,
    pub y: T,
}

/// A numeric point in the plane.
pub type Point = Point2<f64>;

impl<T> Point2<T> {
    pub const fn new(x: T, y: T) -> Self {
        Point2 { x, y }
    }
}

impl Point {
    pub fn distance(self, other: Point) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }

    /// This point in the frame of the calculi (000 §II): `a` at `(0,0)`, `b` at `(0,1)`, by a
    /// rotation and a scaling (sidedness kept). `a` and `b` must differ.
    pub fn in_frame(self, a: Point, b: Point) -> Point {
        let (v, w) = (b - a, self - a);
        let length_sq = v.x * v.x + v.y * v.y;
        Point::new(
            (v.y * w.x - v.x * w.y) / length_sq,
            (v.x * w.x + v.y * w.y) / length_sq,
        )
    }
}

impl<T: Sub<Output = T>> Sub for Point2<T> {
    type Output = Point2<T>;
    fn sub(self, o: Self) -> Self {
        Point2::new(self.x - o.x, self.y - o.y)
    }
}

impl<T: Add<Output = T>> Add for Point2<T> {
    type Output = Point2<T>;
    fn add(self, o: Self) -> Self {
        Point2::new(self.x + o.x, self.y + o.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_frame_puts_a_at_the_origin_and_b_at_unit_y() {
        let (a, b) = (Point::new(2.0, -1.0), Point::new(-1.0, 3.0));
        let at = |p: Point| p.in_frame(a, b);
        assert!(at(a).distance(Point::new(0.0, 0.0)) < 1e-12);
        assert!(at(b).distance(Point::new(0.0, 1.0)) < 1e-12);
        // Left of a → b stays left (x < 0 in the frame).
        assert!(at(Point::new(-3.0, -2.0)).x < 0.0);
    }
}
