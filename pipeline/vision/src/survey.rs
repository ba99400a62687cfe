//! A directory of rover panoramas: which files make which station, and reading them.
//!
//! Stations are named by their files: `NAME_left.EXT` with `NAME_right.EXT` is a stereo
//! station, any other image `NAME.EXT` a mono one (`datasets/README.md`). Stations run in
//! natural order of their names (`station_2` before `station_10`), the order the rover took
//! them in. Only reading happens here; what a bad file means for the run is the caller's call.

use image::RgbImage;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Image extensions read as panoramas.
const EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

/// One imaging point: its primary (left or mono) panorama and, for stereo, the right one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Station {
    pub name: String,
    pub primary: PathBuf,
    pub right: Option<PathBuf>,
}

/// The stations of an image directory.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Survey {
    pub directory: PathBuf,
    pub stations: Vec<Station>,
    /// `NAME_right` files without a `NAME_left` partner: reported, not used.
    pub unpaired: Vec<PathBuf>,
    /// `NAME_left` files without a `NAME_right` partner: reported, mapped without stereo.
    pub without_right: Vec<PathBuf>,
    /// Images whose name leaves no station name (`_left.png`, `_right.png`): reported, not
    /// used. Hidden files (`.NAME`) are not panoramas and are passed over silently.
    pub unnamed: Vec<PathBuf>,
}

#[derive(Debug, Error)]
pub enum SurveyError {
    #[error("image directory {0} does not exist")]
    Missing(PathBuf),
    #[error("{0} is not a directory")]
    NotDirectory(PathBuf),
    // Not named `source`: the message holds it, and a chain printed with `{:#}` would repeat it.
    #[error("cannot list {path}: {error}")]
    List {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{0} holds no panoramas (.png, .jpg or .jpeg files)")]
    Empty(PathBuf),
    /// Panoramas, but none that makes a station: right ones without their left partner, or
    /// names that leave no station name.
    #[error(
        "{} holds no station: {}; a station is NAME_left with NAME_right, or NAME alone",
        .directory.display(),
        unused_files(.unpaired, .unnamed)
    )]
    NoStation {
        directory: PathBuf,
        unpaired: Vec<PathBuf>,
        unnamed: Vec<PathBuf>,
    },
}

/// Why each of these files makes no station, the first few named.
fn unused_files(unpaired: &[PathBuf], unnamed: &[PathBuf]) -> String {
    const NAMED: usize = 3;
    let name = |p: &PathBuf| {
        p.file_name()
            .unwrap_or(p.as_os_str())
            .to_string_lossy()
            .into_owned()
    };
    let all: Vec<String> = unpaired
        .iter()
        .map(|p| format!("{} has no _left partner", name(p)))
        .chain(
            unnamed
                .iter()
                .map(|p| format!("{} leaves no station name", name(p))),
        )
        .collect();
    let mut text = all[..all.len().min(NAMED)].join(", ");
    if all.len() > NAMED {
        text += &format!(" and {} more", all.len() - NAMED);
    }
    text
}

/// Why one image cannot be used.
#[derive(Debug, Error)]
pub enum ImageError {
    #[error("{path}: cannot decode: {source}")]
    Decode {
        path: PathBuf,
        source: image::ImageError,
    },
    #[error("{path}: a {bits}-bit PNG: too few levels to tell rocks from the ground (8 or 16 bits per channel needed)")]
    Depth { path: PathBuf, bits: u8 },
    #[error("{path}: {width}×{height} pixels, but the calibration is for {expected_width}×{expected_height}")]
    Size {
        path: PathBuf,
        width: u32,
        height: u32,
        expected_width: u32,
        expected_height: u32,
    },
}

impl Survey {
    /// Lists the stations in `directory`.
    pub fn open(directory: &Path) -> Result<Survey, SurveyError> {
        if !directory.exists() {
            return Err(SurveyError::Missing(directory.to_path_buf()));
        }
        if !directory.is_dir() {
            return Err(SurveyError::NotDirectory(directory.to_path_buf()));
        }
        let list_error = |error| SurveyError::List {
            path: directory.to_path_buf(),
            error,
        };
        let mut images = Vec::new();
        for entry in std::fs::read_dir(directory).map_err(list_error)? {
            let path = entry.map_err(list_error)?.path();
            let is_image = extension(&path).is_some_and(|e| EXTENSIONS.contains(&e.as_str()));
            if is_image && path.is_file() {
                images.push(path);
            }
        }
        let survey = Survey::from_files(directory, images);
        if survey.stations.is_empty() {
            if survey.unpaired.is_empty() && survey.unnamed.is_empty() {
                return Err(SurveyError::Empty(directory.to_path_buf()));
            }
            return Err(SurveyError::NoStation {
                directory: directory.to_path_buf(),
                unpaired: survey.unpaired,
                unnamed: survey.unnamed,
            });
        }
        Ok(survey)
    }

    /// Groups image paths into stations (pure: no file system access).
    pub fn from_files(directory: &Path, mut images: Vec<PathBuf>) -> Survey {
        images.retain(|p| !stem(p).starts_with('.'));
        images.sort_by(|a, b| natural_order(&stem(a), &stem(b)));
        let mut stations = Vec::new();
        let mut unpaired = Vec::new();
        let mut without_right = Vec::new();
        let mut unnamed = Vec::new();
        for path in &images {
            let name = stem(path);
            if name.is_empty() || name == "_left" || name == "_right" {
                unnamed.push(path.clone());
                continue;
            }
            if let Some(base) = name.strip_suffix("_right") {
                let has_left = images.iter().any(|p| stem(p) == format!("{base}_left"));
                if !has_left {
                    unpaired.push(path.clone());
                }
                continue;
            }
            let (station, right) = match name.strip_suffix("_left") {
                Some(base) => {
                    let right = images
                        .iter()
                        .find(|p| stem(p) == format!("{base}_right"))
                        .cloned();
                    if right.is_none() {
                        without_right.push(path.clone());
                    }
                    (base.to_string(), right)
                }
                None => (name.clone(), None),
            };
            stations.push(Station {
                name: station,
                primary: path.clone(),
                right,
            });
        }
        Survey {
            directory: directory.to_path_buf(),
            stations,
            unpaired,
            without_right,
            unnamed,
        }
    }
}

/// The extension of `path`, lower case.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// Whether `path` names a JPEG file.
pub fn is_jpeg(path: &Path) -> bool {
    extension(path).is_some_and(|e| e == "jpg" || e == "jpeg")
}

/// The bit depth in a PNG file's header (`IHDR`), if `bytes` are a PNG file's.
fn png_bit_depth(bytes: &[u8]) -> Option<u8> {
    let header = bytes.get(..26)?;
    (header[..8] == *b"\x89PNG\r\n\x1a\n" && header[12..16] == *b"IHDR").then_some(header[24])
}

/// `image` as 8-bit RGB; an 8-bit grayscale panorama by copying each level to the three
/// channels (the generic conversion goes through colour-space handling, a quarter of a
/// grayscale run's time).
fn into_rgb(image: image::DynamicImage) -> RgbImage {
    match image {
        image::DynamicImage::ImageLuma8(grey) => {
            let (width, height) = grey.dimensions();
            let raw = grey
                .into_raw()
                .into_iter()
                .flat_map(|v| [v, v, v])
                .collect();
            RgbImage::from_raw(width, height, raw).expect("three bytes per pixel")
        }
        other => other.into_rgb8(),
    }
}

/// A fingerprint of a file's bytes (`crc32:` and eight hex digits): `truth.json` records one
/// per image and `stations.json` one per file read, so that scoring refuses a truth file
/// written for other images, even ones of the same names and size.
pub fn digest(path: &Path) -> std::io::Result<String> {
    Ok(digest_of(&std::fs::read(path)?))
}

/// [`digest`] of a file's bytes already read.
fn digest_of(bytes: &[u8]) -> String {
    format!("crc32:{:08x}", crc32fast::hash(bytes))
}

/// One panorama read: its pixels and its file's fingerprint ([`digest`]).
pub struct Panorama {
    pub image: RgbImage,
    pub digest: String,
}

/// Reads one panorama as 8-bit RGB and checks its size against the calibration's.
pub fn read_image(path: &Path, expected: (u32, u32)) -> Result<RgbImage, ImageError> {
    read_panorama(path, expected).map(|p| p.image)
}

/// [`read_image`], with the fingerprint of the bytes it decoded (the file is read once).
pub fn read_panorama(path: &Path, expected: (u32, u32)) -> Result<Panorama, ImageError> {
    let io_error = |e| ImageError::Decode {
        path: path.to_path_buf(),
        source: image::ImageError::IoError(e),
    };
    let bytes = std::fs::read(path).map_err(io_error)?;
    // As `ImageReader::open`: the extension's format, unless the content says otherwise.
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes[..]));
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let reader = reader.with_guessed_format().map_err(io_error)?;
    let decode_error = |source| ImageError::Decode {
        path: path.to_path_buf(),
        source,
    };
    // A 1-, 2- or 4-bit panorama decodes to 8 bits, but with 2 to 16 levels the regolith's
    // shading and a rock's are one: the detector cannot use it. (The PNG decoder expands such
    // files without saying so; their header does.)
    if let Some(bits) = png_bit_depth(&bytes).filter(|&b| b < 8) {
        return Err(ImageError::Depth {
            path: path.to_path_buf(),
            bits,
        });
    }
    let image = reader.decode().map_err(decode_error).map(into_rgb)?;
    if image.dimensions() != expected {
        return Err(ImageError::Size {
            path: path.to_path_buf(),
            width: image.width(),
            height: image.height(),
            expected_width: expected.0,
            expected_height: expected.1,
        });
    }
    Ok(Panorama {
        image,
        digest: digest_of(&bytes),
    })
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Compares names with digit runs as numbers, so that `s_9` sorts before `s_10`.
fn natural_order(a: &str, b: &str) -> std::cmp::Ordering {
    fn chunks(s: &str) -> Vec<(bool, &str)> {
        let mut out = Vec::new();
        let mut start = 0;
        let bytes = s.as_bytes();
        for i in 1..=bytes.len() {
            if i == bytes.len() || bytes[i].is_ascii_digit() != bytes[start].is_ascii_digit() {
                out.push((bytes[start].is_ascii_digit(), &s[start..i]));
                start = i;
            }
        }
        out
    }
    let (ca, cb) = (chunks(a), chunks(b));
    for (x, y) in ca.iter().zip(&cb) {
        let ordering = match (x, y) {
            ((true, p), (true, q)) => {
                let (p, q) = (p.trim_start_matches('0'), q.trim_start_matches('0'));
                p.len().cmp(&q.len()).then_with(|| p.cmp(q))
            }
            ((_, p), (_, q)) => p.cmp(q),
        };
        if ordering.is_ne() {
            return ordering;
        }
    }
    ca.len().cmp(&cb.len()).then_with(|| a.cmp(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(names: &[&str]) -> Vec<PathBuf> {
        names.iter().map(|n| PathBuf::from("d").join(n)).collect()
    }

    #[test]
    fn pairs_stereo_and_keeps_mono_in_natural_order() {
        let survey = Survey::from_files(
            Path::new("d"),
            paths(&[
                "s_10_left.png",
                "s_10_right.png",
                "s_9_right.png",
                "s_9_left.png",
                "mono_2.jpg",
                "lonely_right.png",
            ]),
        );
        let names: Vec<_> = survey.stations.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["mono_2", "s_9", "s_10"]);
        assert_eq!(
            survey.stations[1].right,
            Some(PathBuf::from("d/s_9_right.png"))
        );
        assert_eq!(survey.stations[0].right, None);
        assert_eq!(survey.unpaired, vec![PathBuf::from("d/lonely_right.png")]);
        assert!(survey.without_right.is_empty() && survey.unnamed.is_empty());
    }

    /// Hidden files are not panoramas; names that leave no station name, and left panoramas
    /// without their right partner, are reported.
    #[test]
    fn hidden_unnamed_and_unpartnered_files_are_set_apart() {
        let survey = Survey::from_files(
            Path::new("d"),
            paths(&[
                ".hidden.png",
                "._s_1_left.png",
                "_left.png",
                "_right.png",
                "s_1_left.png",
                "s_1_right.png",
                "s_2_left.png",
            ]),
        );
        let names: Vec<_> = survey.stations.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["s_1", "s_2"]);
        assert_eq!(survey.unnamed, paths(&["_left.png", "_right.png"]));
        assert_eq!(survey.without_right, paths(&["s_2_left.png"]));
        assert!(survey.unpaired.is_empty());
    }

    #[test]
    fn natural_order_compares_numbers() {
        assert!(natural_order("station_2", "station_10").is_lt());
        assert!(natural_order("station_002", "station_010").is_lt());
        assert!(natural_order("a", "b").is_lt());
        assert!(natural_order("a1", "a1b").is_lt());
    }
}
