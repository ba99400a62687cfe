//! Navigation over the qualitative map (000 §VII-B): landmark routes over the RNG estimate,
//! which landmark's Voronoi cell a panorama is taken in, the convex hull of the landmarks, and
//! the leg-following controller driven by observations alone.

mod cell;
mod hull;
mod leg;
mod route;

pub use cell::{cell_of, Cell};
pub use hull::{convex_hull, Hull};
pub use leg::{Command, LegFollower};
pub use route::{PlanError, Route, RouteCost, RouteGraph};
