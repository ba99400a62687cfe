//! Synthetic datasets (issue 4) against their own geometry: what `truth.json` says each image
//! shows agrees with the calibration — centroid columns with true bearings, ground-contact rows
//! with ranges, left/right disparity with range and baseline — and the files are what the
//! format promises.

use qrm_synth::dataset::{write_dataset, Counts, Preset, Request, Truth, Variant, VisibleRock};
use qrm_synth::{render as render_image, Capture, Encoding, Eye, Scenery, World};
use qrm_vision::calib::{AzimuthAxis, Calibration, ColumnDirection};
use std::f64::consts::TAU;

fn calibration(scale: f64) -> Calibration {
    qrm_synth::default_calibration().scaled(scale).unwrap()
}

fn render(preset: Preset, stations: usize, stereo: bool, name: &str) -> (Truth, Calibration) {
    let scratch = tempfile::Builder::new()
        .prefix(&format!("qrm-dataset-{name}-"))
        .tempdir()
        .unwrap();
    let dir = scratch.path();
    let calib = calibration(0.5);
    let truth = write_dataset(
        dir,
        &calib,
        Request {
            preset,
            seed: 4,
            counts: Counts {
                rocks: None,
                stations: Some(stations),
            },
            stereo,
            scenery: Scenery::default(),
            capture: Capture::default(),
            encoding: Encoding::default(),
        },
        &|| {},
    )
    .unwrap();
    let text = std::fs::read_to_string(dir.join("truth.json")).unwrap();
    let reread: Truth = serde_json::from_str(&text).unwrap();
    assert_eq!(reread, truth);
    let reread_calib = Calibration::load(&dir.join("calib.toml")).unwrap();
    assert_eq!(reread_calib, calib);
    for image in &truth.images {
        assert!(dir.join(&image.file).is_file(), "{}", image.file);
    }
    (truth, calib)
}

/// Well-seen rocks: enough pixels that shape and pixel quantisation average out.
fn well_seen(rock: &VisibleRock) -> bool {
    rock.pixels >= 200
}

fn column_difference(a: f64, b: f64, width: f64) -> f64 {
    let d = (a - b).rem_euclid(width);
    d.min(width - d)
}

#[test]
fn centroids_follow_bearings_and_contacts_follow_ranges() {
    let (truth, calib) = render(Preset::Random, 4, false, "mono");
    check_centroids_and_contacts(&truth, &calib);
}

/// Every well-seen rock's visible centroid lies at its true bearing's column, and its lowest
/// visible row at its ground contact's row.
fn check_centroids_and_contacts(truth: &Truth, calib: &Calibration) {
    let width = f64::from(calib.image.width);
    let mut checked = 0;
    for image in &truth.images {
        // Rocks whose ground contact falls below the image's bottom edge are cut off there.
        let in_view = |r: &&VisibleRock| r.contact[1] < f64::from(calib.image.height) - 1.0;
        for rock in image.rocks.iter().filter(|r| well_seen(r)).filter(in_view) {
            // Irregular rocks: the visible centroid may sit off the ground position by a part
            // of the rock's angular size.
            let size = truth.rocks[rock.id as usize].size;
            let angular = (size / rock.range).atan() / calib.column_width();
            let off = column_difference(rock.centroid[0], rock.bearing_column, width);
            assert!(
                off <= 0.5 + 0.6 * angular,
                "rock {} off by {off} px",
                rock.id
            );
            // The lowest visible row is where the rock meets the ground nearest the camera,
            // unless something nearer hides it.
            let bottom = f64::from(rock.bbox[3]) + 1.0;
            assert!(
                (bottom - rock.contact[1]).abs()
                    <= 2.0 + 0.2 * (bottom - calib.elevation.horizon_row),
                "rock {} bottom {bottom} contact {}",
                rock.id,
                rock.contact[1]
            );
            checked += 1;
        }
    }
    assert!(checked >= 10, "only {checked} rocks checked");
}

/// Under a counter-clockwise calibration with column 0 elsewhere, the truth's bearing columns
/// are where the calibration's definition puts them (computed here by hand), and the rendered
/// rock pixels are there.
#[test]
fn counter_clockwise_calibration_truth_matches_the_pixels() {
    let scratch = tempfile::tempdir().unwrap();
    let mut calib = calibration(0.5);
    calib.azimuth = AzimuthAxis {
        column0_deg: 37.0,
        direction: ColumnDirection::CounterClockwise,
    };
    let truth = write_dataset(
        scratch.path(),
        &calib,
        Request {
            preset: Preset::Random,
            seed: 4,
            counts: Counts {
                rocks: None,
                stations: Some(4),
            },
            stereo: false,
            scenery: Scenery::default(),
            capture: Capture::default(),
            encoding: Encoding::default(),
        },
        &|| {},
    )
    .unwrap();
    assert_eq!(
        Calibration::load(&scratch.path().join("calib.toml")).unwrap(),
        calib
    );
    let width = f64::from(calib.image.width);
    for image in &truth.images {
        let station = &truth.stations[image.station];
        for rock in &image.rocks {
            // Azimuth grows with the column from 37° at column 0's left edge.
            let [x, y] = truth.rocks[rock.id as usize].position;
            let bearing = ((y - station.position[1]).atan2(x - station.position[0])
                - station.heading)
                .rem_euclid(TAU);
            assert!((bearing - rock.bearing).abs() < 1e-9);
            let by_hand = (bearing - 37f64.to_radians()).rem_euclid(TAU) / TAU * width;
            assert!(
                column_difference(rock.bearing_column, by_hand, width) < 1e-6,
                "rock {}: {} vs {by_hand}",
                rock.id,
                rock.bearing_column
            );
        }
    }
    check_centroids_and_contacts(&truth, &calib);
}

/// Pairs of 4-neighbouring pixels showing two different rocks: where rocks touch in the image.
fn touching_pixels(image: &qrm_synth::Render) -> usize {
    let w = image.width as usize;
    let id = &image.rock_id;
    (0..id.len())
        .filter(|&i| {
            let different = |j: usize| id[j] != 0 && id[i] != 0 && id[j] != id[i];
            (i % w + 1 < w && different(i + 1)) || (i + w < id.len() && different(i + w))
        })
        .count()
}

#[test]
fn clustered_rocks_touch_in_the_panoramas() {
    let calib = calibration(0.25);
    let touching = |cluster: f64| -> usize {
        let layout = Preset::Marsyard.layout_clustered(4, Counts::default(), cluster);
        let world = World::generate(4, &layout.rocks);
        layout.stations[..10]
            .iter()
            .map(|&pose| touching_pixels(&render_image(&world, &calib, pose, Eye::Mono)))
            .sum()
    };
    let (plain, clustered) = (touching(0.0), touching(0.6));
    assert!(
        clustered > 2 * plain,
        "touching pixel pairs: {plain} as laid out, {clustered} clustered"
    );
}

/// A `stress` member with the camera scaled down further by `scale`.
fn stress(seed: u64, scale: f64, dir: &std::path::Path) -> (Variant, Truth) {
    let variant = Variant::stress(seed);
    let calib = variant.calibration(&calibration(scale)).unwrap();
    let truth = write_dataset(
        dir,
        &calib,
        two_stations(Preset::Stress, seed, &variant),
        &|| {},
    )
    .unwrap();
    (variant, truth)
}

/// Two stereo stations of `preset` with `variant`'s scene, camera and encoding.
fn two_stations(preset: Preset, seed: u64, variant: &Variant) -> Request {
    Request {
        preset,
        seed,
        counts: Counts {
            rocks: None,
            stations: Some(2),
        },
        stereo: true,
        scenery: variant.scenery,
        capture: variant.capture,
        encoding: variant.encoding,
    }
}

fn same_files(a: &std::path::Path, b: &std::path::Path, truth: &Truth) -> bool {
    truth
        .images
        .iter()
        .map(|i| i.file.as_str())
        .chain(["calib.toml"])
        .all(|f| std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap())
}

/// A `stress` member is the same bytes every time, records its draws in `truth.json`, and is
/// exactly its layout preset rendered with the drawn options.
#[test]
fn stress_members_are_reproducible_and_record_their_draws() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = |name: &str| scratch.path().join(name);
    for seed in [2, 5] {
        let (variant, truth) = stress(seed, 0.2, &dir("a"));
        let (_, again) = stress(seed, 0.2, &dir("b"));
        assert_eq!(truth, again);
        assert!(same_files(&dir("a"), &dir("b"), &truth));
        let record = truth
            .variant
            .clone()
            .expect("stress sets record their variant");
        let calib = Calibration::load(&dir("a").join("calib.toml")).unwrap();
        assert_eq!(truth.preset, "stress");
        assert_eq!(record.layout, variant.layout.name());
        assert_eq!(
            Some(record.sun_elevation_deg),
            variant.scenery.sun_elevation_deg
        );
        assert_eq!(
            (record.rock_albedo_contrast, record.cluster),
            (
                variant.scenery.rock_albedo_contrast,
                variant.scenery.cluster
            )
        );
        assert_eq!(
            (
                record.gamma,
                record.noise,
                record.blur_px,
                record.jpeg_quality
            ),
            (
                variant.capture.gamma,
                variant.capture.noise,
                variant.capture.blur_px,
                variant.encoding.jpeg_quality
            )
        );
        assert_eq!(
            (record.column_direction, record.column0_deg),
            (calib.azimuth.direction, calib.azimuth.column0_deg)
        );
        assert_eq!(calib.azimuth, variant.column_axis);
        assert_eq!(
            (record.width, record.height),
            (calib.image.width, calib.image.height)
        );
        // The layout preset with the same options renders the same member.
        let layout = write_dataset(
            &dir("layout"),
            &calib,
            two_stations(variant.layout, seed, &variant),
            &|| {},
        )
        .unwrap();
        assert_eq!(
            (&layout.rocks, &layout.stations, &layout.images),
            (&truth.rocks, &truth.stations, &truth.images)
        );
        assert!(same_files(&dir("a"), &dir("layout"), &truth));
    }
    let (_, other) = stress(5, 0.2, &dir("c"));
    let (_, first) = stress(2, 0.2, &dir("d"));
    assert_ne!(other.variant, first.variant);
    assert_ne!(other.rocks, first.rocks);
}

/// Every truth bearing and range follows the camera model of calib/README.md, recomputed here
/// by hand: the eye sits baseline/2 across the viewing direction of the column that sees the
/// rock (left of it for the left eye), so the ray of the bearing's column, from that column's
/// optical centre, passes through the rock, and the range is measured from that centre. (The
/// truth once placed the eye across the station-to-rock direction instead: bearings off by up
/// to 0.03° and ranges by 1.5 cm on the demo.)
#[test]
fn truth_bearings_and_ranges_follow_the_camera_model() {
    let (truth, calib) = render(Preset::Marsyard, 3, true, "camera-model");
    let mut checked = 0;
    for image in &truth.images {
        let station = &truth.stations[image.station];
        let s = match image.eye.as_str() {
            "left" => 0.5 * calib.stereo.baseline_m,
            "right" => -0.5 * calib.stereo.baseline_m,
            _ => 0.0,
        };
        for rock in &image.rocks {
            let azimuth = station.heading + rock.bearing;
            let (along, across) = (
                [azimuth.cos(), azimuth.sin()],
                [-azimuth.sin(), azimuth.cos()],
            );
            let centre = [
                station.position[0] + s * across[0],
                station.position[1] + s * across[1],
            ];
            let p = truth.rocks[rock.id as usize].position;
            let to_rock = [p[0] - centre[0], p[1] - centre[1]];
            let off_ray = along[0] * to_rock[1] - along[1] * to_rock[0];
            let ahead = along[0] * to_rock[0] + along[1] * to_rock[1];
            assert!(
                off_ray.abs() < 1e-9 && ahead > 0.0,
                "{} rock {}: {off_ray} m off the ray",
                image.file,
                rock.id
            );
            assert!(
                (to_rock[0].hypot(to_rock[1]) - rock.range).abs() < 1e-9,
                "{} rock {}: range",
                image.file,
                rock.id
            );
            checked += 1;
        }
    }
    assert!(checked >= 50, "only {checked} rocks checked");
}

#[test]
fn stereo_disparity_matches_range_and_baseline() {
    let (truth, calib) = render(Preset::Marsyard, 3, true, "stereo");
    let width = f64::from(calib.image.width);
    let mut checked = 0;
    for pair in truth.images.chunks(2) {
        let (left, right) = (&pair[0], &pair[1]);
        assert_eq!((left.eye.as_str(), right.eye.as_str()), ("left", "right"));
        for l in left.rocks.iter().filter(|r| well_seen(r)) {
            let Some(r) = right.rocks.iter().find(|r| r.id == l.id && well_seen(r)) else {
                continue;
            };
            let measured =
                column_difference(l.centroid[0], r.centroid[0], width) * calib.column_width();
            let expected = calib.stereo_disparity(0.5 * (l.range + r.range));
            // Near irregular rocks show each eye a different side: allow a tenth of the rock's
            // angular size on top of 1.5 pixels.
            let size = truth.rocks[l.id as usize].size;
            let angular = 2.0 * (size / l.range).atan();
            assert!(
                (measured - expected).abs() <= 1.5 * calib.column_width() + 0.1 * angular,
                "rock {}: disparity {measured} vs {expected}",
                l.id
            );
            checked += 1;
        }
    }
    assert!(checked >= 5, "only {checked} rocks checked");
}

/// The committed demo dataset is exactly what `pipeline synth --preset marsyard --seed 1
/// --stations 16 --scale 0.25 --out datasets/demo` renders: the renderer is deterministic.
#[test]
fn committed_demo_dataset_is_reproduced_byte_for_byte() {
    let committed = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../datasets/demo");
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let calib = calibration(0.25);
    let truth = write_dataset(
        dir,
        &calib,
        Request {
            preset: Preset::Marsyard,
            seed: 1,
            counts: Counts {
                rocks: None,
                stations: Some(16),
            },
            stereo: true,
            scenery: Scenery::default(),
            capture: Capture::default(),
            encoding: Encoding::default(),
        },
        &|| {},
    )
    .unwrap();
    let mut files: Vec<String> = truth.images.iter().map(|i| i.file.clone()).collect();
    files.extend(["truth.json".to_string(), "calib.toml".to_string()]);
    for file in &files {
        let fresh = std::fs::read(dir.join(file)).unwrap();
        let old = std::fs::read(committed.join(file))
            .unwrap_or_else(|e| panic!("datasets/demo/{file}: {e}"));
        assert!(
            fresh == old,
            "datasets/demo/{file} differs from a fresh render"
        );
    }
}

/// A grayscale JPEG dataset, as a monochrome navigation camera's archive would hold it: `.jpg`
/// files named in `truth.json`, one 8-bit channel of the calibration's size, and the luminance
/// of the colour render within JPEG's error.
#[test]
fn grayscale_jpeg_datasets_are_written_as_asked() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let calib = calibration(0.25);
    let request = |encoding| Request {
        preset: Preset::Random,
        seed: 2,
        counts: Counts {
            rocks: None,
            stations: Some(2),
        },
        stereo: false,
        scenery: Scenery::default(),
        capture: Capture::default(),
        encoding,
    };
    let colour = write_dataset(
        &dir.join("png"),
        &calib,
        request(Encoding::default()),
        &|| {},
    )
    .unwrap();
    let grey = Encoding {
        grayscale: true,
        jpeg_quality: Some(85),
    };
    let truth = write_dataset(&dir.join("jpg"), &calib, request(grey), &|| {}).unwrap();
    assert_eq!(truth.images.len(), 2);
    for (image, png) in truth.images.iter().zip(&colour.images) {
        assert!(image.file.ends_with(".jpg"), "{}", image.file);
        assert_eq!(
            image.rocks, png.rocks,
            "truth does not depend on the encoding"
        );
        let decoded = image::open(dir.join("jpg").join(&image.file)).unwrap();
        assert_eq!(decoded.color(), image::ColorType::L8);
        assert_eq!(
            (decoded.width(), decoded.height()),
            (calib.image.width, calib.image.height)
        );
        let luma = image::open(dir.join("png").join(&png.file))
            .unwrap()
            .into_luma8();
        let decoded = decoded.into_luma8();
        let mean_error = decoded
            .as_raw()
            .iter()
            .zip(luma.as_raw())
            .map(|(&a, &b)| f64::from(a.abs_diff(b)))
            .sum::<f64>()
            / luma.as_raw().len() as f64;
        assert!(mean_error < 3.0, "mean error {mean_error}");
    }
}
