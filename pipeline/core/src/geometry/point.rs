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
