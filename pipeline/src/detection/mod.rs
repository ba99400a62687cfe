//! STUB (not committed): the helper's detector replaces this.
use crate::calib::Calibration;
use serde::{Deserialize, Serialize};
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DetectorSettings { pub min_width_m: f64, pub max_range_m: f64 }
impl Default for DetectorSettings { fn default() -> Self { DetectorSettings { min_width_m: 0.12, max_range_m: 30.0 } } }
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Detection { pub centroid: [f64; 2], pub bbox: [u32; 4], pub pixels: u32, pub contact_row: f64, pub appearance: Appearance }
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Appearance { pub colour: [f32; 3], pub brightness: f32, pub texture: f32, pub dark_fraction: f32 }
pub fn detect(_image: &image::RgbImage, _calib: &Calibration, _settings: &DetectorSettings) -> Vec<Detection> { Vec::new() }
