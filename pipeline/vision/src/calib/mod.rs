//! Camera calibration of a cylindrical 360° panorama on a mast (issue 4; 000 §IV assumption 2:
//! "vertical position in an image is proportional to distance in a flat environment").
//!
//! Columns map linearly to azimuth over the full turn; rows follow a cylindrical projection,
//! `row = horizon_row − focal_px · tan(elevation)`, so on flat ground a point at horizontal
//! range `d` appears at `row = horizon_row + focal_px · mast_height / d`. A stereo pair comes
//! from a rotating head: each column is seen by two cameras displaced ±baseline/2 across that
//! column's viewing direction, so parallax gives range in every direction.
//!
//! The calibration is a small TOML file (`calib/README.md`); every field is required and checked.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::path::Path;
use thiserror::Error;

/// Which way azimuth runs as the column index grows (seen from above).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnDirection {
    /// Azimuth grows with the column: the panorama is seen from inside, panning left.
    CounterClockwise,
    /// Azimuth shrinks with the column: panning right, as a viewer turning right sees it.
    Clockwise,
}

/// A panorama camera on a mast.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    pub image: ImageSize,
    pub azimuth: AzimuthAxis,
    pub elevation: ElevationAxis,
    pub mast: Mast,
    pub stereo: Stereo,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageSize {
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AzimuthAxis {
    /// Azimuth (degrees, counter-clockwise from the rover's +x axis) of the left edge of
    /// column 0.
    pub column0_deg: f64,
    pub direction: ColumnDirection,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElevationAxis {
    /// Row (continuous, 0 = top edge of the image) of the horizon.
    pub horizon_row: f64,
    /// Rows per unit of `tan(elevation)`.
    pub focal_px: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mast {
    /// Height of the optical centre above the ground, metres.
    pub height_m: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stereo {
    /// Distance between the left and right optical centres, metres (0: mono).
    pub baseline_m: f64,
}

/// A calibration that cannot be used, naming the file and the field.
#[derive(Debug, Error)]
pub enum CalibrationError {
    // Not named `source`: the message holds it, and a chain printed with `{:#}` would repeat it.
    #[error("cannot read calibration {path}: {error}")]
    Read { path: String, error: std::io::Error },
    #[error("calibration {path}: {message}")]
    Syntax { path: String, message: String },
    #[error("calibration {path}: field `{field}` {problem}")]
    Field {
        path: String,
        field: &'static str,
        problem: String,
    },
}

/// Largest ratio of a pixel's height to its width (or width to height) a calibration may
/// describe: `focal_px` (rows per unit of tan(elevation)) within this factor of the columns per
/// radian. The synthetic camera's pixels are square (ratio 1).
const MAX_PIXEL_ASPECT: f64 = 4.0;

/// Highest mast a calibration may describe, metres (rover masts are 1–2 m).
const MAX_MAST_M: f64 = 20.0;

impl Calibration {
    /// Reads and checks a calibration file.
    pub fn load(path: &Path) -> Result<Calibration, CalibrationError> {
        let text = std::fs::read_to_string(path).map_err(|error| CalibrationError::Read {
            path: path.display().to_string(),
            error,
        })?;
        Calibration::parse(&text, &path.display().to_string())
    }

    /// Parses and checks TOML text; `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Calibration, CalibrationError> {
        let calibration: Calibration =
            toml::from_str(text).map_err(|e| CalibrationError::Syntax {
                path: origin.to_string(),
                message: e.message().to_string() + &span_note(text, e.span()),
            })?;
        calibration.check(origin)?;
        Ok(calibration)
    }

    /// The same camera at `factor` times the image size (focal length and horizon row scaled
    /// with it), for quick low-resolution sets; checked like a file.
    pub fn scaled(&self, factor: f64) -> Result<Calibration, CalibrationError> {
        let mut c = *self;
        c.image.width = (f64::from(c.image.width) * factor).round() as u32;
        c.image.height = (f64::from(c.image.height) * factor).round() as u32;
        c.elevation.horizon_row *= factor;
        c.elevation.focal_px *= factor;
        c.check(&format!("the calibration scaled by {factor}"))?;
        Ok(c)
    }

    /// The calibration as TOML (what [`Calibration::parse`] reads back).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("plain numbers serialise")
    }

    fn check(&self, origin: &str) -> Result<(), CalibrationError> {
        let bad = |field: &'static str, problem: String| {
            Err(CalibrationError::Field {
                path: origin.to_string(),
                field,
                problem,
            })
        };
        let finite = |field: &'static str, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                bad(field, format!("must be a finite number, not {v}"))
            }
        };
        finite("azimuth.column0_deg", self.azimuth.column0_deg)?;
        finite("elevation.horizon_row", self.elevation.horizon_row)?;
        finite("elevation.focal_px", self.elevation.focal_px)?;
        finite("mast.height_m", self.mast.height_m)?;
        finite("stereo.baseline_m", self.stereo.baseline_m)?;
        if self.image.width < 8 || self.image.width > 1 << 16 {
            return bad(
                "image.width",
                format!("is {}; use 8..=65536", self.image.width),
            );
        }
        if self.image.height < 2 || self.image.height > 1 << 15 {
            return bad(
                "image.height",
                format!("is {}; use 2..=32768", self.image.height),
            );
        }
        let h = f64::from(self.image.height);
        if !(0.0..=h).contains(&self.elevation.horizon_row) {
            return bad(
                "elevation.horizon_row",
                format!(
                    "is {}; it must lie within the image rows 0..={h}",
                    self.elevation.horizon_row
                ),
            );
        }
        if self.elevation.focal_px <= 0.0 {
            return bad("elevation.focal_px", "must be positive".to_string());
        }
        if self.mast.height_m <= 0.0 {
            return bad("mast.height_m", "must be positive".to_string());
        }
        if self.stereo.baseline_m < 0.0 {
            return bad("stereo.baseline_m", "must not be negative".to_string());
        }
        // Plausibility from the camera's geometry: values that parse but describe no rover
        // camera (focal_px 1e300 or baseline_m 1e30 ran to an empty map, exit 0).
        let per_radian = f64::from(self.image.width) / std::f64::consts::TAU;
        let (low, high) = (per_radian / MAX_PIXEL_ASPECT, per_radian * MAX_PIXEL_ASPECT);
        if !(low..=high).contains(&self.elevation.focal_px) {
            return bad(
                "elevation.focal_px",
                format!(
                    "is {:?}, but {} columns over the full turn make {per_radian:.1} columns per \
                     radian, and a panorama's pixels are near square: use {low:.1}..={high:.1}",
                    self.elevation.focal_px, self.image.width
                ),
            );
        }
        if self.mast.height_m > MAX_MAST_M {
            return bad(
                "mast.height_m",
                format!(
                    "is {:?} m; a rover's mast is at most {MAX_MAST_M} m",
                    self.mast.height_m
                ),
            );
        }
        if self.stereo.baseline_m > 2.0 * self.mast.height_m {
            return bad(
                "stereo.baseline_m",
                format!(
                    "is {:?} m, more than twice the mast's height ({} m): the stereo head sits on the mast",
                    self.stereo.baseline_m, self.mast.height_m
                ),
            );
        }
        Ok(())
    }

    /// `+1` when columns grow counter-clockwise, `−1` when clockwise.
    pub fn column_sign(&self) -> f64 {
        match self.azimuth.direction {
            ColumnDirection::CounterClockwise => 1.0,
            ColumnDirection::Clockwise => -1.0,
        }
    }

    /// Radians of azimuth per column.
    pub fn column_width(&self) -> f64 {
        TAU / f64::from(self.image.width)
    }

    /// Azimuth (radians, in `[0, 2π)`) of continuous column coordinate `column` (0 = left edge
    /// of column 0; the centre of column `c` is `c + 0.5`).
    pub fn azimuth(&self, column: f64) -> f64 {
        (self.azimuth.column0_deg.to_radians() + self.column_sign() * column * self.column_width())
            .rem_euclid(TAU)
    }

    /// Continuous column coordinate (in `[0, width)`) of `azimuth` (radians).
    pub fn column(&self, azimuth: f64) -> f64 {
        let turns = self.column_sign() * (azimuth - self.azimuth.column0_deg.to_radians());
        (turns.rem_euclid(TAU) / self.column_width()).min(f64::from(self.image.width) - 1e-9)
    }

    /// Elevation (radians, up positive) of continuous row coordinate `row`.
    pub fn elevation(&self, row: f64) -> f64 {
        ((self.elevation.horizon_row - row) / self.elevation.focal_px).atan()
    }

    /// Continuous row coordinate of `elevation` (radians, within ±90°).
    pub fn row(&self, elevation: f64) -> f64 {
        self.elevation.horizon_row - self.elevation.focal_px * elevation.tan()
    }

    /// Horizontal range of the flat-ground point seen at `row`, or `None` at or above the
    /// horizon.
    pub fn ground_range(&self, row: f64) -> Option<f64> {
        let below = row - self.elevation.horizon_row;
        (below > 0.0).then(|| self.mast.height_m * self.elevation.focal_px / below)
    }

    /// Row at which flat ground at horizontal `range` appears.
    pub fn ground_row(&self, range: f64) -> f64 {
        self.elevation.horizon_row + self.elevation.focal_px * self.mast.height_m / range
    }

    /// Horizontal range from the stereo disparity (azimuth difference, radians) of a point,
    /// for a rotating head whose cameras sit ±baseline/2 across the viewing direction: the
    /// column of the left camera whose ray passes a point at range `d` looks `asin(b / 2d)` to
    /// one side of the point's bearing, the right camera's to the other, so
    /// disparity = 2·asin(b / 2d).
    pub fn stereo_range(&self, disparity: f64) -> Option<f64> {
        (disparity > 0.0 && disparity < std::f64::consts::PI && self.stereo.baseline_m > 0.0)
            .then(|| self.stereo.baseline_m / (2.0 * (disparity / 2.0).sin()))
    }

    /// The stereo disparity (radians) of a point at horizontal range `range` (at least half the
    /// baseline: nearer points are between the cameras).
    pub fn stereo_disparity(&self, range: f64) -> f64 {
        2.0 * (self.stereo.baseline_m / (2.0 * range)).min(1.0).asin()
    }
}

/// " (line L, column C)" for a byte span of `text`.
fn span_note(text: &str, span: Option<std::ops::Range<usize>>) -> String {
    let Some(span) = span else {
        return String::new();
    };
    let before = &text[..span.start.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    match field_at(text, span.start) {
        Some(field) => format!(" (field `{field}`, line {line}, column {column})"),
        None => format!(" (line {line}, column {column})"),
    }
}

/// The field (`section.key`) whose value holds byte `at` of `text`, if `at` lies after the `=`
/// of a `key = value` line: a value of the wrong type names the value only. (A missing field's
/// span is its table, which starts at a key: no field is named for it.)
fn field_at(text: &str, at: usize) -> Option<String> {
    let start = text.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    let (key, _) = text[start..at].split_once('=')?;
    let key = key.trim();
    if key.is_empty() || key.starts_with(['#', '[']) {
        return None;
    }
    let section = text[..start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_matches(['[', ']']).trim());
    Some(match section {
        Some(section) => format!("{section}.{key}"),
        None => key.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    pub const EXAMPLE: &str = include_str!("../../../../calib/default.toml");

    #[test]
    fn default_file_parses_and_round_trips() {
        let c = Calibration::parse(EXAMPLE, "default.toml").unwrap();
        assert_eq!(Calibration::parse(&c.to_toml(), "again").unwrap(), c);
    }

    #[test]
    fn projections_round_trip() {
        let mut c = Calibration::parse(EXAMPLE, "default.toml").unwrap();
        for direction in [
            ColumnDirection::Clockwise,
            ColumnDirection::CounterClockwise,
        ] {
            c.azimuth.direction = direction;
            for i in 0..1000 {
                let column = f64::from(i) * 4.0951;
                let back = c.column(c.azimuth(column));
                assert!(
                    (back - column).abs() < 1e-6,
                    "{direction:?} {column} {back}"
                );
                let row = f64::from(i) * 0.7;
                assert!((c.row(c.elevation(row)) - row).abs() < 1e-9);
            }
            for range in [0.5, 1.0, 3.7, 20.0, 150.0] {
                let row = c.ground_row(range);
                assert!((c.ground_range(row).unwrap() - range).abs() < 1e-9 * range);
                let d = c.stereo_disparity(range);
                assert!((c.stereo_range(d).unwrap() - range).abs() < 1e-9 * range);
            }
        }
        assert_eq!(c.ground_range(c.elevation.horizon_row), None);
    }

    #[test]
    fn ground_row_matches_the_depression_angle() {
        let c = Calibration::parse(EXAMPLE, "default.toml").unwrap();
        let range = 7.0;
        let depression = (c.mast.height_m / range).atan();
        assert!((c.row(-depression) - c.ground_row(range)).abs() < 1e-9);
    }

    #[test]
    fn errors_name_the_field() {
        let missing = EXAMPLE.replace("height_m = 1.5", "");
        let e = Calibration::parse(&missing, "x.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.toml") && e.contains("height_m"), "{e}");
        let bad = EXAMPLE.replace("focal_px = 652.0", "focal_px = -1.0");
        let e = Calibration::parse(&bad, "x.toml").unwrap_err().to_string();
        assert!(e.contains("elevation.focal_px"), "{e}");
        for (from, to, field) in [
            ("focal_px = 652.0", "focal_px = 1e300", "elevation.focal_px"),
            (
                "focal_px = 652.0",
                "focal_px = 1e-300",
                "elevation.focal_px",
            ),
            ("baseline_m = 0.3", "baseline_m = 1e30", "stereo.baseline_m"),
            ("height_m = 1.5", "height_m = 1e30", "mast.height_m"),
        ] {
            let implausible = EXAMPLE.replace(from, to);
            let e = Calibration::parse(&implausible, "x.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains(field), "{to}: {e}");
        }
        // Values of the wrong type: the message names the field, not only the value.
        for (from, to, field) in [
            (
                "focal_px = 652.0",
                "focal_px = \"652\"",
                "elevation.focal_px",
            ),
            ("width = 4096", "width = 4096.5", "image.width"),
            (
                "direction = \"clockwise\"",
                "direction = 1",
                "azimuth.direction",
            ),
        ] {
            let e = Calibration::parse(&EXAMPLE.replace(from, to), "x.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains(&format!("field `{field}`")), "{to}: {e}");
        }
        let unknown = format!("{EXAMPLE}\n[extra]\nfoo = 1\n");
        let e = Calibration::parse(&unknown, "x.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("extra"), "{e}");
        let e = Calibration::load(Path::new("/nonexistent/calib.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("/nonexistent/calib.toml"), "{e}");
    }
}
