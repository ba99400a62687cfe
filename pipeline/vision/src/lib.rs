//! qrm-vision: from a directory of rover panoramas to the qualitative map (000 §IV, §VI-C):
//! calibration, the survey's stations, rock detection, bearings and range cues, association
//! with the map's landmarks, the station-by-station run, and locating a new panorama against
//! a run's map.

pub mod association;
pub mod calib;
pub mod detection;
pub mod localization;
pub mod ranging;
pub mod run;
pub mod survey;
