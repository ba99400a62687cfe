//! 002's simulation (§IV; seed digest C.7, C.9): random triplets seen from three random camera
//! poses with noisy bearings and motion commands, estimated by the full, fast and baseline
//! algorithms, scored by DMSE, gmd and entropy; Table I's percentiles. The cameras' own states
//! (Eq. 10) are scored the same way.

use super::belief::Belief;
use super::metrics::{dmse, entropy, gmd};
use super::tensor::RegionCentroids;
use super::triplet::{
    angle_to, estimate_baseline, estimate_fast, estimate_full, wrap, Estimate, Noise, Prior, View,
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

/// How close one belief is to the truth.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Accuracy {
    /// The probability of the most likely state, and whether that state is the truth: over
    /// many triplets drawn from the estimators' own prior, a calibrated belief is right as
    /// often as it says ([`calibration`]).
    pub top_probability: f64,
    pub truth_first: bool,
    pub dmse: f64,
    pub gmd: f64,
    pub entropy: f64,
}

impl Accuracy {
    fn of(belief: &Belief, truth: u8, centroids: &RegionCentroids) -> Accuracy {
        Accuracy {
            top_probability: belief.probability(belief.most_likely()),
            truth_first: belief.most_likely() == truth,
            dmse: dmse(belief, truth),
            gmd: gmd(belief, truth, centroids),
            entropy: entropy(belief),
        }
    }
}

/// One algorithm's scores on one scenario: `AB:C`, and each camera's `AB:X_n`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Score {
    pub landmark: Accuracy,
    pub cameras: Vec<Accuracy>,
    pub seconds: f64,
    /// The estimator returned nothing (no particle survived): scored as the uniform belief.
    pub failed: bool,
}

/// The three algorithms' scores on one scenario.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Outcome {
    pub truth: u8,
    /// The true `AB:X_n` of each camera.
    pub cameras: Vec<u8>,
    pub baseline: Score,
    pub full: Score,
    pub fast: Score,
}

/// One scenario: the views with noise, the truth `AB:C` and each camera's `AB:X_n`, and the
/// box in the AB frame (the estimators' prior).
pub struct Triplet {
    pub views: Vec<View>,
    pub truth: u8,
    pub cameras: Vec<u8>,
    pub prior: Prior,
}

/// A random triplet and camera poses in the box (none on a region boundary).
pub fn scenario(settings: &StudySettings, rng: &mut impl Rng) -> Triplet {
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
        let Some(cameras) = poses
            .iter()
            .map(|&(x, _)| edc::classify(a, b, x))
            .collect::<Option<Vec<u8>>>()
        else {
            continue;
        };
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
        return Triplet {
            views,
            truth,
            cameras,
            prior: Prior { polygon },
        };
    }
}

/// Runs one estimator and scores it; a failed estimate counts as uniform beliefs.
fn score(
    run: impl FnOnce() -> Option<Estimate>,
    triplet: &Triplet,
    centroids: &RegionCentroids,
) -> Score {
    let started = Instant::now();
    let estimate = run();
    let seconds = started.elapsed().as_secs_f64();
    let failed = estimate.is_none();
    let estimate = estimate.unwrap_or_else(|| Estimate {
        landmark: Belief::uniform(),
        cameras: vec![Belief::uniform(); triplet.cameras.len()],
    });
    Score {
        landmark: Accuracy::of(&estimate.landmark, triplet.truth, centroids),
        cameras: estimate
            .cameras
            .iter()
            .zip(&triplet.cameras)
            .map(|(belief, &truth)| Accuracy::of(belief, truth, centroids))
            .collect(),
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
            let triplet = scenario(settings, &mut rng);
            let (views, prior) = (&triplet.views, &triplet.prior);
            let baseline = score(
                || estimate_baseline(views, prior, settings.baseline_samples, &mut rng),
                &triplet,
                &centroids,
            );
            let full = score(
                || {
                    estimate_full(
                        views,
                        prior,
                        settings.noise,
                        settings.full_particles,
                        &mut rng,
                    )
                },
                &triplet,
                &centroids,
            );
            let fast = score(
                || {
                    estimate_fast(
                        views,
                        prior,
                        settings.noise,
                        settings.fast_particles,
                        &mut rng,
                    )
                },
                &triplet,
                &centroids,
            );
            progress();
            Outcome {
                truth: triplet.truth,
                cameras: triplet.cameras,
                baseline,
                full,
                fast,
            }
        })
        .collect()
}

/// The beliefs whose most likely state has a probability in `[from, to)`: how many, their
/// mean top probability, and how often that state is the truth.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CalibrationBin {
    pub from: f64,
    pub to: f64,
    pub beliefs: usize,
    pub mean_top_probability: f64,
    pub truth_first: f64,
}

/// The reliability of the most likely state in five bins of its probability (the last one
/// closed at 1). The scenarios are drawn from the estimators' own prior (the box), so an
/// estimator that computes the posterior is right as often as it says: a bin's
/// `truth_first` near its `mean_top_probability`. An independent check of the sampler,
/// which Table I's medians are not.
pub fn calibration<'a>(accuracies: impl IntoIterator<Item = &'a Accuracy>) -> Vec<CalibrationBin> {
    const BINS: usize = 5;
    let mut sums = [(0usize, 0.0, 0usize); BINS];
    for a in accuracies {
        let bin = ((a.top_probability * BINS as f64) as usize).min(BINS - 1);
        sums[bin].0 += 1;
        sums[bin].1 += a.top_probability;
        sums[bin].2 += usize::from(a.truth_first);
    }
    sums.iter()
        .enumerate()
        .map(|(k, &(n, top, first))| CalibrationBin {
            from: k as f64 / BINS as f64,
            to: (k + 1) as f64 / BINS as f64,
            beliefs: n,
            mean_top_probability: if n > 0 { top / n as f64 } else { 0.0 },
            truth_first: if n > 0 { first as f64 / n as f64 } else { 0.0 },
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
            median(&|o| o.full.landmark.dmse),
            median(&|o| o.fast.landmark.dmse),
            median(&|o| o.baseline.landmark.dmse),
        );
        assert!(full < 0.05 && fast < 0.05, "full {full}, fast {fast}");
        assert!(base > full, "baseline {base}");
        // Eq. (10): without noise the cameras are localized as well.
        let camera = |f: &dyn Fn(&Outcome) -> &Score| {
            let mut v: Vec<f64> = outcomes
                .iter()
                .flat_map(|o| f(o).cameras.iter().map(|a| a.dmse))
                .collect();
            quartiles(&mut v)[1]
        };
        assert!(camera(&|o| &o.full) < 0.05 && camera(&|o| &o.fast) < 0.05);
        assert_eq!(quartiles(&mut [4.0, 1.0, 3.0, 2.0]), [1.0, 2.0, 3.0]);
    }

    /// At Table I's noise the full estimator's beliefs are nearly calibrated: the triplets
    /// come from the estimators' own prior, so where the most likely state has probability p
    /// it should be the truth about p of the time. Averaged over the beliefs, the full
    /// estimator overstates it by at most 0.15 (0.10–0.13 on seeds 7–10; one `C` per
    /// hypothesis, 002's resection heuristic, makes it a little sure), less than the
    /// baseline, which multiplies its views as if they were independent.
    #[test]
    fn the_full_estimators_beliefs_are_right_about_as_often_as_they_say() {
        let settings = StudySettings {
            scenarios: 400,
            views: 3,
            noise: Noise {
                bearing: 3f64.to_radians(),
                motion: 7f64.to_radians(),
            },
            full_particles: 2000,
            fast_particles: 100,
            baseline_samples: 1000,
            seed: 7,
        };
        let outcomes = run_study(&settings, &|| {});
        let overconfidence = |pick: fn(&Outcome) -> &Accuracy| {
            calibration(outcomes.iter().map(pick))
                .iter()
                .map(|b| b.beliefs as f64 * (b.mean_top_probability - b.truth_first))
                .sum::<f64>()
                / outcomes.len() as f64
        };
        let full = overconfidence(|o| &o.full.landmark);
        let baseline = overconfidence(|o| &o.baseline.landmark);
        assert!(full.abs() <= 0.15, "full overconfident by {full}");
        assert!(baseline > full, "baseline {baseline}, full {full}");
    }
}
