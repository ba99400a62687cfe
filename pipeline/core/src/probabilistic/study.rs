//! 002's simulation (§IV; seed digest C.7, C.9): random triplets seen from three random camera
//! poses with noisy bearings and motion commands, estimated by the full, fast and baseline
//! algorithms, scored by DMSE, gmd and entropy; Table I's percentiles.

use super::belief::Belief;
use super::metrics::{dmse, entropy, gmd};
use super::tensor::RegionCentroids;
use super::triplet::{
    angle_to, estimate_baseline, estimate_fast, estimate_full, wrap, Noise, Prior, View,
};
use crate::edc;
use crate::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::time::Instant;

/// 002 §IV's world: `x ∈ [−3, 3]`, `y ∈ [−3, 4]`.
pub const BOX: [Point; 4] = [
    Point::new(-3.0, -3.0),
    Point::new(3.0, -3.0),
    Point::new(3.0, 4.0),
    Point::new(-3.0, 4.0),
];

/// How a study is run.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct StudySettings {
    pub scenarios: usize,
    /// Views per triplet (002: 3 time steps).
    pub views: usize,
    /// Bearing and motion noise s.d., radians (002 Table I: 3°, 7°).
    pub noise: Noise,
    pub full_particles: usize,
    pub fast_particles: usize,
    pub baseline_samples: usize,
    pub seed: u64,
}

/// One algorithm's scores on one scenario.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Score {
    pub dmse: f64,
    pub gmd: f64,
    pub entropy: f64,
    pub seconds: f64,
    /// The estimator returned nothing (no particle survived): scored as the uniform belief.
    pub failed: bool,
}

/// The three algorithms' scores on one scenario.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Outcome {
    pub truth: u8,
    pub baseline: Score,
    pub full: Score,
    pub fast: Score,
}

/// A random triplet and camera poses in the box, the views with noise, the truth `AB:C`, and
/// the box in the AB frame (the baseline's prior).
pub fn scenario(settings: &StudySettings, rng: &mut impl Rng) -> (Vec<View>, u8, Prior) {
    let point = |rng: &mut dyn rand::RngCore| {
        Point::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..4.0))
    };
    loop {
        let (a, b, c) = (point(rng), point(rng), point(rng));
        let Some(truth) = edc::classify(a, b, c) else {
            continue;
        };
        let poses: Vec<(Point, f64)> = (0..settings.views)
            .map(|_| (point(rng), rng.random_range(0.0..TAU)))
            .collect();
        let bearing_noise = Normal::new(0.0, settings.noise.bearing).expect("finite s.d.");
        let motion_noise = Normal::new(0.0, settings.noise.motion).expect("finite s.d.");
        let views: Vec<View> = poses
            .iter()
            .enumerate()
            .map(|(k, &(x, alpha))| View {
                bearings: [a, b, c]
                    .map(|l| wrap(angle_to(x, l) - alpha + bearing_noise.sample(rng))),
                motion: (k > 0).then(|| {
                    let (prev, prev_alpha) = poses[k - 1];
                    wrap(angle_to(prev, x) - prev_alpha + motion_noise.sample(rng))
                }),
            })
            .collect();
        // The box in the frame A = (0,0), B = (0,1).
        let polygon = BOX.iter().map(|p| p.in_frame(a, b)).collect();
        return (views, truth, Prior { polygon });
    }
}

fn score(run: impl FnOnce() -> Option<Belief>, truth: u8, centroids: &RegionCentroids) -> Score {
    let started = Instant::now();
    let belief = run();
    let seconds = started.elapsed().as_secs_f64();
    let failed = belief.is_none();
    let belief = belief.unwrap_or_else(Belief::uniform);
    Score {
        dmse: dmse(&belief, truth),
        gmd: gmd(&belief, truth, centroids),
        entropy: entropy(&belief),
        seconds,
        failed,
    }
}

/// Every scenario of the study, in parallel, reproducible from the seed.
pub fn run_study(settings: &StudySettings, progress: &(dyn Fn() + Sync)) -> Vec<Outcome> {
    let centroids = RegionCentroids::committed();
    (0..settings.scenarios)
        .into_par_iter()
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
            rng.set_stream(k as u64);
            let (views, truth, prior) = scenario(settings, &mut rng);
            let baseline = score(
                || estimate_baseline(&views, &prior, settings.baseline_samples, &mut rng),
                truth,
                &centroids,
            );
            let full = score(
                || {
                    estimate_full(
                        &views,
                        &prior,
                        settings.noise,
                        settings.full_particles,
                        &mut rng,
                    )
                },
                truth,
                &centroids,
            );
            let fast = score(
                || {
                    estimate_fast(
                        &views,
                        &prior,
                        settings.noise.bearing,
                        settings.fast_particles,
                        &mut rng,
                    )
                },
                truth,
                &centroids,
            );
            progress();
            Outcome {
                truth,
                baseline,
                full,
                fast,
            }
        })
        .collect()
}

/// The 25th, 50th and 75th percentiles (nearest rank) of `values`.
pub fn quartiles(values: &mut [f64]) -> [f64; 3] {
    values.sort_by(f64::total_cmp);
    let at = |q: f64| {
        let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
        values[rank - 1]
    };
    [at(0.25), at(0.5), at(0.75)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_noise_the_full_and_fast_estimates_beat_the_baseline() {
        let settings = StudySettings {
            scenarios: 40,
            views: 3,
            noise: Noise {
                bearing: 1e-4,
                motion: 1e-4,
            },
            full_particles: 400,
            fast_particles: 100,
            baseline_samples: 400,
            seed: 2,
        };
        let outcomes = run_study(&settings, &|| {});
        let median = |f: &dyn Fn(&Outcome) -> f64| {
            let mut v: Vec<f64> = outcomes.iter().map(f).collect();
            quartiles(&mut v)[1]
        };
        let (full, fast, base) = (
            median(&|o| o.full.dmse),
            median(&|o| o.fast.dmse),
            median(&|o| o.baseline.dmse),
        );
        assert!(full < 0.05 && fast < 0.05, "full {full}, fast {fast}");
        assert!(base > full, "baseline {base}");
        assert_eq!(quartiles(&mut [4.0, 1.0, 3.0, 2.0]), [1.0, 2.0, 3.0]);
    }
}
