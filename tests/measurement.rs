//! Measurement (000 §IV) against brute-force geometry: the true relations of random
//! arrangements are never excluded, and everything a dense sample of arrangements consistent
//! with the observation reaches is in the measured set.

use qrm::calculus::Calculus;
use qrm::edc::Edc;
use qrm::fdc::Fdc;
use qrm::geometry::Point;
use qrm::measurement::{Bearing, Panorama, RangeOrder};
use qrm_tests::{random_point, rng};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// A camera, three landmarks, and what the camera observes of them: bearings perturbed inside
/// `±delta` and a random subset of the true range order.
struct Scene {
    landmarks: [Point; 3],
    panorama: Panorama,
}

fn random_scene(rng: &mut ChaCha8Rng, delta: f64) -> Scene {
    let camera = random_point(rng);
    let landmarks: [Point; 3] = std::array::from_fn(|_| {
        let scale = 10f64.powf(rng.random_range(-1.5..1.5));
        Point::new(
            camera.x + rng.random_range(-scale..scale),
            camera.y + rng.random_range(-scale..scale),
        )
    });
    let bearings = landmarks
        .map(|p| {
            let error = if delta > 0.0 {
                rng.random_range(-delta..=delta)
            } else {
                0.0
            };
            Bearing {
                angle: (p.y - camera.y).atan2(p.x - camera.x) + error,
                uncertainty: delta,
            }
        })
        .to_vec();
    let range = landmarks.map(|p| p.distance(camera));
    let mut pairs = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            if range[i] < range[j] && rng.random_bool(0.7) {
                pairs.push((i, j));
            }
        }
    }
    let order = RangeOrder::from_pairs(3, &pairs).expect("true order is acyclic");
    Scene {
        landmarks,
        panorama: Panorama::new(bearings, order).expect("valid panorama"),
    }
}

fn true_relations<C: Calculus>(p: &[Point; 3]) -> Option<[u8; 3]> {
    Some([
        C::classify(p[0], p[1], p[2])?,
        C::classify(p[1], p[2], p[0])?,
        C::classify(p[2], p[0], p[1])?,
    ])
}

/// Runs `count` random scenes in parallel; returns the number of soundness violations.
fn violations<C: Calculus>(count: usize, delta: f64, seed: u64) -> usize {
    (0..count)
        .into_par_iter()
        .chunks(1000)
        .map(|chunk| {
            let mut rng = rng(seed ^ (chunk[0] as u64).wrapping_mul(0x9e37_79b9));
            let mut bad = 0;
            for _ in chunk {
                let scene = random_scene(&mut rng, delta);
                let Some(truth) = true_relations::<C>(&scene.landmarks) else {
                    continue;
                };
                let measured =
                    scene
                        .panorama
                        .measure_triple::<C>([0, 1, 2], [C::universe(); 3]);
                if (0..3).any(|k| !measured[k].contains(truth[k])) {
                    eprintln!(
                        "violation: {:?} {:?} truth {truth:?} measured {:?}",
                        scene.landmarks,
                        scene.panorama,
                        measured.map(|s| s.to_string())
                    );
                    bad += 1;
                }
            }
            bad
        })
        .sum()
}

#[test]
fn exact_bearings_never_exclude_the_true_region() {
    assert_eq!(violations::<Edc>(400_000, 0.0, 1), 0);
}

#[test]
fn uncertain_bearings_never_exclude_the_true_region() {
    assert_eq!(violations::<Edc>(100_000, 0.02, 2), 0);
    assert_eq!(violations::<Edc>(20_000, 0.2, 3), 0);
}

#[test]
fn fdc_measurement_is_sound() {
    assert_eq!(violations::<Fdc>(100_000, 0.0, 4), 0);
    assert_eq!(violations::<Fdc>(20_000, 0.05, 5), 0);
}
