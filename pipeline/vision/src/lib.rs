//! qrm-vision: from a directory of rover panoramas to the qualitative map (000 §IV, §VI-C):
//! calibration, the survey's stations, rock detection, bearings and range cues, association
//! with the map's landmarks, and the station-by-station run.

pub mod association;
pub mod calib;
pub mod detection;
pub mod ranging;
pub mod run;
pub mod survey;
