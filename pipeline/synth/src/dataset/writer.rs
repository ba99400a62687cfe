//! Rendering a preset into a dataset directory (`datasets/README.md`): the calibration, the
//! panoramas and `truth.json`, each file written atomically.

use super::layout::{Counts, Layout, Preset};
use super::truth::{
    visible_rocks, ImageTruth, RockTruth, StationTruth, Truth, VariantTruth, FORMAT, VERSION,
};
use crate::{render, Capture, Encoding, Eye, Render, Scenery, World};
use qrm_vision::calib::Calibration;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum DatasetError {
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot encode {path}: {source}")]
    Encode {
        path: PathBuf,
        source: image::ImageError,
    },
    #[error("cannot read back {path} for its fingerprint: {source}")]
    ReadBack {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// What to render.
#[derive(Clone, Copy, Debug)]
pub struct Request {
    pub preset: Preset,
    pub seed: u64,
    pub counts: Counts,
    /// A left and a right panorama per station, or one mono panorama.
    pub stereo: bool,
    /// Sun, rock colours and clustering (all default: the preset's own scene).
    pub scenery: Scenery,
    /// Camera effects on every image (noise drawn per image from the seed).
    pub capture: Capture,
    pub encoding: Encoding,
}

/// Renders `request` with `calib` into `dir`; `tick` is called after each station.
pub fn write_dataset(
    dir: &Path,
    calib: &Calibration,
    request: Request,
    tick: &(dyn Fn() + Sync),
) -> Result<Truth, DatasetError> {
    std::fs::create_dir_all(dir).map_err(|source| DatasetError::Write {
        path: dir.to_path_buf(),
        source,
    })?;
    let Layout { rocks, stations } =
        request
            .preset
            .layout_clustered(request.seed, request.counts, request.scenery.cluster);
    let mut world = World::generate(request.seed, &rocks);
    request.scenery.apply(&mut world);
    let eyes: &[(Eye, &str)] = if request.stereo {
        &[(Eye::Left, "left"), (Eye::Right, "right")]
    } else {
        &[(Eye::Mono, "mono")]
    };
    let names: Vec<String> = (0..stations.len())
        .map(|i| format!("station_{i:03}"))
        .collect();
    let per_station: Vec<Vec<ImageTruth>> = stations
        .par_iter()
        .enumerate()
        .map(|(i, &pose)| {
            let images = eyes
                .iter()
                .enumerate()
                .map(|(k, &(eye, label))| {
                    let image = render(&world, calib, pose, eye);
                    let image_seed = request.seed ^ ((i * eyes.len() + k) as u64).rotate_left(32);
                    let recorded = request.capture.apply(&image, image_seed);
                    let extension = request.encoding.extension();
                    let file = if request.stereo {
                        format!("{}_{label}.{extension}", names[i])
                    } else {
                        format!("{}.{extension}", names[i])
                    };
                    let path = dir.join(&file);
                    write_image(&path, &recorded, request.encoding)?;
                    let digest = qrm_vision::survey::digest(&path).map_err(|source| {
                        DatasetError::ReadBack {
                            path: path.clone(),
                            source,
                        }
                    })?;
                    Ok(ImageTruth {
                        file,
                        station: i,
                        eye: label.to_string(),
                        rocks: visible_rocks(&world, calib, pose, eye, &image),
                        digest: Some(digest),
                    })
                })
                .collect::<Result<Vec<_>, DatasetError>>();
            tick();
            images
        })
        .collect::<Result<_, _>>()?;
    let truth = Truth {
        format: FORMAT.to_string(),
        version: VERSION,
        preset: request.preset.name().to_string(),
        seed: request.seed,
        rocks: (0..world.rocks.len() as u32)
            .map(|id| RockTruth::of(&world, id))
            .collect(),
        stations: stations
            .iter()
            .zip(&names)
            .map(|(pose, name)| StationTruth {
                name: name.clone(),
                position: [pose.position.x, pose.position.y],
                heading: pose.heading,
            })
            .collect(),
        images: per_station.into_iter().flatten().collect(),
        variant: varied(&request).then(|| VariantTruth {
            layout: request
                .preset
                .layout_preset(request.seed)
                .name()
                .to_string(),
            sun_elevation_deg: request
                .scenery
                .sun_elevation_deg
                .unwrap_or(world.sun_elevation.to_degrees()),
            rock_albedo_contrast: request.scenery.rock_albedo_contrast,
            cluster: request.scenery.cluster,
            exposure_ev: request.capture.exposure_ev,
            gamma: request.capture.gamma,
            vignetting: request.capture.vignetting,
            blur_px: request.capture.blur_px,
            noise: request.capture.noise,
            grayscale: request.encoding.grayscale,
            jpeg_quality: request.encoding.jpeg_quality,
            column_direction: calib.azimuth.direction,
            column0_deg: calib.azimuth.column0_deg,
            width: calib.image.width,
            height: calib.image.height,
        }),
    };
    let json = serde_json::to_string_pretty(&truth).expect("plain data serialises") + "\n";
    write_file(&dir.join("truth.json"), json.as_bytes())?;
    write_file(&dir.join("calib.toml"), calib.to_toml().as_bytes())?;
    Ok(truth)
}

/// Whether `request` departs from its preset's own look, so that `truth.json` records how.
fn varied(request: &Request) -> bool {
    request.preset == Preset::Stress
        || !request.scenery.is_default()
        || !request.capture.is_identity()
        || request.encoding != Encoding::default()
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), DatasetError> {
    qrm_atomic_file::write_bytes(path, bytes).map_err(|source| DatasetError::Write {
        path: path.to_path_buf(),
        source,
    })
}

fn write_image(path: &Path, image: &Render, encoding: Encoding) -> Result<(), DatasetError> {
    qrm_atomic_file::write_via_temporary(
        path,
        |temporary| {
            image
                .save(temporary, encoding)
                .map_err(|source| DatasetError::Encode {
                    path: path.to_path_buf(),
                    source,
                })
        },
        |source| DatasetError::Write {
            path: path.to_path_buf(),
            source,
        },
    )
}
