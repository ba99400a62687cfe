//! Simulated mapping with ground truth (000 §VIII-B; 003 §1.5.2): landmark fields, a camera
//! model that measures from true geometry, mapping runs scored after every image, and the
//! Monte Carlo study of Fig. 7.

pub mod beliefs;
mod mapping;
mod montecarlo;
mod navigation;
mod navigation_study;
mod scenario;
mod sensor;

pub use mapping::{run, Step};
pub use montecarlo::{MonteCarlo, MonteCarloResult, Series, Statistic};
pub use navigation::{drive, nearest, Controller, Drive, Leg, Outcome, Trip};
pub use navigation_study::{
    jittered_grid, Layout, NavigationStudy, NavigationSummary, RngSource, TripRecord,
};
pub use scenario::Scenario;
pub use sensor::Sensor;
