//! The synthetic renderer against geometry computed independently from the calibration: where a
//! rock's pixels fall (bearing, ground contact, stereo parallax), occlusion and determinism.

use qrm_core::geometry::Point;
use qrm_synth::{render, Eye, Lump, Pose, Render, Scenery, World};
use qrm_vision::calib::Calibration;
use std::f64::consts::TAU;

fn calibration() -> Calibration {
    qrm_synth::default_calibration()
}

/// A world of one ball of radius `r` per position, each sunk so that its centre is 5 cm below
/// the ground: symmetric about every vertical plane through its centre, touching the ground in
/// a circle with no overhang.
fn balls(positions: &[(Point, f64)]) -> World {
    let mut world = World::generate(11, positions);
    for rock in &mut world.rocks {
        let r = rock.size;
        rock.lumps = vec![Lump {
            center: [0.0, 0.0, r],
            radii: [r; 3],
            yaw: 0.3,
        }];
        rock.burial = r + 0.05;
    }
    world
}

/// Mean continuous column (pixel centres) of the pixels showing rock `id`, and the lowest
/// such row (largest index), or `None` if it is not visible.
fn footprint(image: &Render, id: u32) -> Option<(f64, usize)> {
    let w = image.width as usize;
    let (mut sum, mut count, mut lowest) = (0.0, 0usize, 0usize);
    for (i, &label) in image.rock_id.iter().enumerate() {
        if label == id + 1 {
            sum += (i % w) as f64 + 0.5;
            count += 1;
            lowest = lowest.max(i / w);
        }
    }
    (count > 0).then(|| (sum / count as f64, lowest))
}

fn rover_azimuth(pose: Pose, target: Point) -> f64 {
    let d = target - pose.position;
    (d.y.atan2(d.x) - pose.heading).rem_euclid(TAU)
}

const POSE: Pose = Pose {
    position: Point::new(0.4, -0.3),
    heading: 0.6,
};

/// Positions in front of the rover (away from the panorama seam behind it), 3–9 m away, whole
/// within the image (ground nearer than 2.1 m is below its bottom edge).
fn placements() -> Vec<(Point, f64)> {
    [
        (3.0, 0.2, 0.25),
        (3.5, -1.0, 0.3),
        (5.0, 2.5, 0.35),
        (7.5, -3.0, 0.3),
        (1.0, 3.0, 0.2),
    ]
    .iter()
    .map(|&(ahead, left, r)| {
        let (c, s) = (POSE.heading.cos(), POSE.heading.sin());
        (
            Point::new(
                POSE.position.x + ahead * c - left * s,
                POSE.position.y + ahead * s + left * c,
            ),
            r,
        )
    })
    .collect()
}

#[test]
fn centroid_column_is_the_true_bearing() {
    let calib = calibration();
    let world = balls(&placements());
    let image = render(&world, &calib, POSE, Eye::Mono);
    for rock in &world.rocks {
        let (column, _) = footprint(&image, rock.id).expect("in view");
        let expected = calib.column(rover_azimuth(POSE, rock.position));
        assert!(
            (column - expected).abs() <= 0.5,
            "rock {}: centroid column {column}, bearing column {expected}",
            rock.id
        );
    }
}

#[test]
fn irregular_rocks_centroids_stay_within_their_extent() {
    // Generated rocks are not symmetric; their centroid may sit off the bearing by at most the
    // angular reach of their lumps from the rock's position.
    let calib = calibration();
    let world = World::generate(5, &placements());
    let image = render(&world, &calib, POSE, Eye::Mono);
    for rock in &world.rocks {
        let (column, _) = footprint(&image, rock.id).expect("in view");
        let expected = calib.column(rover_azimuth(POSE, rock.position));
        let reach = rock
            .lumps
            .iter()
            .map(|l| l.center[0].hypot(l.center[1]) + l.radii[0].max(l.radii[1]))
            .fold(0.0, f64::max);
        let range = rock.position.distance(POSE.position);
        let allowance = 0.5 + (reach / range).asin() / calib.column_width();
        assert!(
            (column - expected).abs() <= allowance,
            "rock {}: {column} vs {expected} (allowance {allowance})",
            rock.id
        );
    }
}

#[test]
fn ground_contact_row_matches_the_range() {
    let calib = calibration();
    let world = balls(&placements());
    let image = render(&world, &calib, POSE, Eye::Mono);
    for rock in &world.rocks {
        let (_, lowest) = footprint(&image, rock.id).expect("in view");
        let range = rock.position.distance(POSE.position);
        let expected = calib.ground_row(range - world.contact_radius(rock.id));
        let row = lowest as f64 + 0.5;
        assert!(
            (row - expected).abs() <= 2.0,
            "rock {} at {range} m: lowest row {row}, contact row {expected}",
            rock.id
        );
    }
}

#[test]
fn stereo_disparity_matches_range_and_baseline() {
    let calib = calibration();
    let world = balls(&placements());
    let left = render(&world, &calib, POSE, Eye::Left);
    let right = render(&world, &calib, POSE, Eye::Right);
    for rock in &world.rocks {
        let (l, _) = footprint(&left, rock.id).expect("left sees it");
        let (r, _) = footprint(&right, rock.id).expect("right sees it");
        let measured =
            (calib.azimuth(r) - calib.azimuth(l) + TAU / 2.0).rem_euclid(TAU) - TAU / 2.0;
        let range = rock.position.distance(POSE.position);
        let expected = calib.stereo_disparity(range);
        assert!(
            (measured - expected).abs() <= calib.column_width(),
            "rock {} at {range} m: disparity {measured} rad, expected {expected} rad",
            rock.id
        );
    }
}

#[test]
fn rendering_is_deterministic() {
    let calib = calibration();
    let world = World::generate(3, &placements());
    let a = render(&world, &calib, POSE, Eye::Left);
    let b = render(&World::generate(3, &placements()), &calib, POSE, Eye::Left);
    assert!(a == b, "same seed, same bytes");
    let serial = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| render(&world, &calib, POSE, Eye::Left));
    assert!(a == serial, "the thread count does not matter");
    let c = render(&World::generate(4, &placements()), &calib, POSE, Eye::Left);
    assert!(a.rgb != c.rgb, "another seed, another image");
}

#[test]
fn the_near_rock_hides_the_far_one() {
    let calib = calibration();
    // From the 1.5 m mast, the boulder's top is 7.7° below the horizon and the far rock spans
    // 10°–12.6° below it, so the boulder covers it.
    let near = (Point::new(4.0, 0.0), 1.0);
    let far = (Point::new(7.0, 0.05), 0.3);
    let pose = Pose {
        position: Point::new(0.0, 0.0),
        heading: 0.0,
    };
    let both = render(&balls(&[near, far]), &calib, pose, Eye::Mono);
    let near_alone = render(&balls(&[near]), &calib, pose, Eye::Mono);
    let far_alone = render(
        &balls(&[near, far]).rocks_only(&[1]),
        &calib,
        pose,
        Eye::Mono,
    );
    let mut hidden = 0;
    for i in 0..both.rock_id.len() {
        if near_alone.rock_id[i] == 1 {
            assert_eq!(both.rock_id[i], 1, "the near rock is in front at pixel {i}");
            hidden += usize::from(far_alone.rock_id[i] == 2);
        }
    }
    assert!(
        hidden > 100,
        "the far rock is behind the near one ({hidden} pixels)"
    );
}

/// Ground pixels (no rock in either image) that `with` shows at least 15 % darker than
/// `without`, the same scene without its rocks: the rocks' cast shadows.
fn shadow_pixels(with: &Render, without: &Render) -> usize {
    let luminance = |r: &Render, i: usize| -> u32 {
        r.rgb[3 * i..3 * i + 3].iter().map(|&v| u32::from(v)).sum()
    };
    (0..with.rock_id.len())
        .filter(|&i| with.rock_id[i] == 0 && 100 * luminance(with, i) < 85 * luminance(without, i))
        .count()
}

#[test]
fn a_low_sun_casts_longer_shadows() {
    let calib = calibration().scaled(0.25).unwrap();
    let shadows = |elevation: f64| {
        let mut world = balls(&placements());
        Scenery {
            sun_elevation_deg: Some(elevation),
            ..Scenery::default()
        }
        .apply(&mut world);
        let with = render(&world, &calib, POSE, Eye::Mono);
        let without = render(&world.rocks_only(&[]), &calib, POSE, Eye::Mono);
        shadow_pixels(&with, &without)
    };
    let (high, low) = (shadows(40.0), shadows(8.0));
    // Shadows are h / tan(elevation) long: 6 times longer at 8° than at 40°; their pixels grow
    // less, as the far end of a shadow is seen smaller.
    assert!(high > 20 && low > 3 * high, "40°: {high} px, 8°: {low} px");
}

/// Mean colour (8-bit channels) of the pixels of `image` that `pick` selects.
fn mean_colour(image: &Render, pick: impl Fn(usize) -> bool) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for i in (0..image.rock_id.len()).filter(|&i| pick(i)) {
        for (total, &v) in sum.iter_mut().zip(&image.rgb[3 * i..3 * i + 3]) {
            *total += f64::from(v);
        }
        n += 1.0;
    }
    sum.map(|total| total / n)
}

/// How far each rock's hue lies from the soil's around it, averaged over the rocks: the summed
/// difference of the channels' shares of the mean colour. (Brightness is left out: lighting
/// makes a rock's sunlit faces brighter than flat ground whatever its albedo; the albedo
/// itself is checked in `qrm_synth`'s unit tests.)
fn hue_contrast(image: &Render, calib: &Calibration, ids: &[u32]) -> f64 {
    let width = image.width as usize;
    let below = calib.elevation.horizon_row.ceil() as usize * width;
    let shares = |c: [f64; 3]| c.map(|v| v / c.iter().sum::<f64>());
    let mut hue = 0.0;
    for &id in ids {
        let columns: Vec<bool> = (0..width)
            .map(|c| (0..image.height as usize).any(|r| image.rock_id[r * width + c] == id + 1))
            .collect();
        let rock = shares(mean_colour(image, |i| image.rock_id[i] == id + 1));
        let soil = shares(mean_colour(image, |i| {
            i >= below && image.rock_id[i] == 0 && columns[i % width]
        }));
        hue += (0..3).map(|k| (rock[k] - soil[k]).abs()).sum::<f64>();
    }
    hue / ids.len() as f64
}

#[test]
fn albedo_contrast_brings_rock_colour_to_the_soil() {
    let calib = calibration().scaled(0.25).unwrap();
    let contrast = |k: f64| {
        let mut world = World::generate(5, &placements());
        Scenery {
            rock_albedo_contrast: k,
            ..Scenery::default()
        }
        .apply(&mut world);
        let ids: Vec<u32> = world.rocks.iter().map(|r| r.id).collect();
        hue_contrast(&render(&world, &calib, POSE, Eye::Mono), &calib, &ids)
    };
    let (drawn, half, soil_like) = (contrast(1.0), contrast(0.5), contrast(0.0));
    assert!(
        soil_like < 0.25 * drawn && half < 0.75 * drawn,
        "hue contrast at 1: {drawn}, 0.5: {half}, 0: {soil_like}"
    );
}

/// A copy of the world keeping only the rocks with these ids.
trait RocksOnly {
    fn rocks_only(self, ids: &[u32]) -> World;
}

impl RocksOnly for World {
    fn rocks_only(mut self, ids: &[u32]) -> World {
        self.rocks.retain(|r| ids.contains(&r.id));
        self
    }
}
