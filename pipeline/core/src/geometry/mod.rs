//! Plane geometry shared by the calculi: points over any coordinate ring and the six boundary
//! functions of the Extended Double Cross (000 §II, Fig. 3a; 003 Appendix C, c1..c6).

mod boundary;
mod point;

pub use boundary::{boundary_values, Boundary, Coordinate};
pub use point::{Point, Point2};
