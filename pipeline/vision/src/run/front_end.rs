//! The vision half of `pipeline run`: decode a station's panoramas and detect rocks in them.
//! A bad primary image costs the station (with a warning); a bad right image only the stereo
//! cue.

use crate::calib::Calibration;
use crate::detection::{detect, detect_right, Channels, DetectorSettings};
use crate::ranging::PrimaryEye;
use crate::run::StationDetections;
use crate::survey::{is_jpeg, read_panorama, Station};
use image::RgbImage;
use std::path::Path;
use std::time::Instant;

/// A station's detections with the decode and detection times (seconds, summed over its
/// images), or the reason it cannot be used.
pub struct FrontEndResult {
    pub station: Result<StationDetections, String>,
    pub decode_seconds: f64,
    pub detect_seconds: f64,
}

/// Decodes and detects one station.
pub fn detect_station(
    station: &Station,
    directory: &Path,
    calib: &Calibration,
    settings: &DetectorSettings,
) -> FrontEndResult {
    let size = (calib.image.width, calib.image.height);
    let name = |p: &Path| p.strip_prefix(directory).unwrap_or(p).display().to_string();
    let mut decode_seconds = 0.0;
    let mut detect_seconds = 0.0;
    let mut timed_read = |path: &Path| {
        let start = Instant::now();
        let panorama = read_panorama(path, size);
        decode_seconds += start.elapsed().as_secs_f64();
        panorama
    };
    let primary = match timed_read(&station.primary) {
        Ok(panorama) => panorama,
        Err(e) => {
            return FrontEndResult {
                station: Err(format!("station {} skipped: {e}", station.name)),
                decode_seconds,
                detect_seconds,
            }
        }
    };
    let mut warnings = Vec::new();
    let right = station
        .right
        .as_ref()
        .and_then(|path| match timed_read(path) {
            Ok(panorama) => Some(panorama),
            Err(e) => {
                warnings.push(format!(
                    "station {}: right panorama unusable, no stereo cue: {e}",
                    station.name
                ));
                None
            }
        });
    // The files read, with the fingerprints of the bytes decoded.
    let (mut files, mut digests) = (vec![name(&station.primary)], vec![primary.digest]);
    let right = match (station.right.as_deref(), right) {
        (Some(path), Some(panorama)) => {
            files.push(name(path));
            digests.push(panorama.digest);
            Some(panorama.image)
        }
        _ => None,
    };
    let primary = primary.image;
    let eye = if station.right.is_some() || is_left_image(&station.primary) {
        PrimaryEye::Left
    } else {
        PrimaryEye::Mono
    };
    let start = Instant::now();
    let mut detected = detect_panoramas(
        &station.name,
        &primary,
        right.as_ref(),
        eye,
        right.is_some() && is_jpeg(&station.primary),
        calib,
        settings,
    );
    detect_seconds += start.elapsed().as_secs_f64();
    warnings.append(&mut detected.warnings);
    FrontEndResult {
        station: Ok(StationDetections {
            files,
            digests,
            warnings,
            ..detected
        }),
        decode_seconds,
        detect_seconds,
    }
}

/// Detects the rocks of one station's decoded panoramas (`right`: the stereo partner of a
/// left `primary`); `jpeg`: the pair was JPEG-compressed, whose colour `Channels::Auto` does
/// not trust. The result names no files.
pub fn detect_panoramas(
    name: &str,
    primary: &RgbImage,
    right: Option<&RgbImage>,
    eye: PrimaryEye,
    jpeg: bool,
    calib: &Calibration,
    settings: &DetectorSettings,
) -> StationDetections {
    let channels = settings.channels_of(primary, right.is_some(), jpeg);
    let settings = &DetectorSettings {
        channels,
        ..settings.clone()
    };
    let mut warnings = Vec::new();
    if channels == Channels::Luminance && right.is_none() {
        warnings.push(format!(
            "station {name}: detected by luminance (a grayscale panorama, or --channels luminance) \
             without its right partner: rocks cannot be told from cast shadows without stereo, \
             so its detections are not used"
        ));
    }
    // Only the primary (left) panorama's blobs are separated by parallax: the right one's
    // detections only serve the stereo cue, which separated parts do not take. The two are
    // detected at once: a rover's navigator detects one station at a time.
    let (primary_detections, right_detections) = rayon::join(
        || detect(primary, right, calib, settings),
        || right.map(|r| detect_right(r, Some(primary), calib, settings)),
    );
    StationDetections {
        name: name.to_string(),
        files: Vec::new(),
        digests: Vec::new(),
        eye,
        channels,
        primary: primary_detections,
        right: right_detections,
        warnings,
    }
}

/// `NAME_left.EXT`: a left-eye panorama even when its right partner is missing.
fn is_left_image(path: &Path) -> bool {
    path.file_stem()
        .is_some_and(|s| s.to_string_lossy().ends_with("_left"))
}
