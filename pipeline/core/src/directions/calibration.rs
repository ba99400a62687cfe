//! Does the predicted reliability of a route come true? Routes are planned on the exact leg
//! graph of random fields and followed leg by leg with the rover's noisy perception
//! ([`super::reliability::perceive`]); a route succeeds when every leg's selection is the
//! intended landmark (no recovery). Predicted `R = e^−U` against the measured success rate,
//! binned, is the calibration plot (docs/DIRECTIONS.md).

use super::criteria::Criterion;
use super::isolation::Positions;
use super::legs::LegGraph;
use super::reliability::{most_isolated_seen, perceive, ReliabilityModel, ViewNoise};
use crate::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CalibrationSettings {
    /// Landmarks of each random field (uniform in the unit square).
    pub landmarks: usize,
    /// Largest scene a leg may use (objects, counting the reference).
    pub max_objects: usize,
    pub noise: ViewNoise,
    pub model: ReliabilityModel,
    pub criterion: Criterion,
}

/// One route followed.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Followed {
    /// `e^−U` of the planned route.
    pub predicted: f64,
    pub legs: usize,
    pub succeeded: bool,
}

/// Routes of predicted reliability in one bin, and how many succeeded.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CalibrationBin {
    pub predicted: f64,
    pub measured: f64,
    pub routes: usize,
    /// Wilson 95 % interval of `measured`.
    pub low: f64,
    pub high: f64,
}

/// Attempts to find a start and goal with a route, per field, before drawing a new field.
const PAIR_ATTEMPTS: usize = 50;

/// `count` routes, each in its own field, in parallel; reproducible from `seed`.
pub fn follow_routes(settings: &CalibrationSettings, count: usize, seed: u64) -> Vec<Followed> {
    (0..count)
        .into_par_iter()
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(k as u64);
            loop {
                if let Some(followed) = follow_one(settings, &mut rng) {
                    return followed;
                }
            }
        })
        .collect()
}

/// A random field, a random start/goal pair with a route of at least one leg, the route
/// followed; `None` when the field has no such pair.
fn follow_one(settings: &CalibrationSettings, rng: &mut ChaCha8Rng) -> Option<Followed> {
    let world: Vec<Point> = (0..settings.landmarks)
        .map(|_| Point::new(rng.random::<f64>(), rng.random::<f64>()))
        .collect();
    let graph = LegGraph::new(
        &Positions(&world),
        settings.max_objects,
        &settings.model,
        settings.noise.range_sd,
    );
    for _ in 0..PAIR_ATTEMPTS {
        let (from, to) = (
            rng.random_range(0..world.len()),
            rng.random_range(0..world.len()),
        );
        if from == to {
            continue;
        }
        let Some(routes) = graph.routes(from, to) else {
            continue;
        };
        let path = routes.get(settings.criterion);
        let legs = graph.legs_of(path);
        let succeeded = legs.iter().all(|leg| {
            let seen = perceive(&world, leg.from, settings.noise, rng);
            most_isolated_seen(&seen, leg.from, leg.objects()) == Some(leg.to)
        });
        return Some(Followed {
            predicted: path.reliability(),
            legs: legs.len(),
            succeeded,
        });
    }
    None
}

/// `followed` in `bins` equal bins of predicted reliability over `[0, 1]`; empty bins left out.
pub fn calibration_bins(followed: &[Followed], bins: usize) -> Vec<CalibrationBin> {
    (0..bins)
        .filter_map(|b| {
            let (low, high) = (b as f64 / bins as f64, (b + 1) as f64 / bins as f64);
            let inside: Vec<&Followed> = followed
                .iter()
                .filter(|f| f.predicted >= low && (f.predicted < high || b + 1 == bins))
                .collect();
            if inside.is_empty() {
                return None;
            }
            let n = inside.len() as f64;
            let successes = inside.iter().filter(|f| f.succeeded).count() as f64;
            let (low, high) = wilson(successes, n);
            Some(CalibrationBin {
                predicted: inside.iter().map(|f| f.predicted).sum::<f64>() / n,
                measured: successes / n,
                routes: inside.len(),
                low,
                high,
            })
        })
        .collect()
}

/// Wilson score interval (95 %) of a binomial proportion.
fn wilson(successes: f64, n: f64) -> (f64, f64) {
    let z = 1.96f64;
    let p = successes / n;
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / (1.0 + z * z / n);
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_sensing_follows_every_route() {
        let settings = CalibrationSettings {
            landmarks: 25,
            max_objects: 5,
            noise: ViewNoise {
                bearing_sd: 0.0,
                range_sd: 0.0,
                standoff: 0.0,
            },
            model: ReliabilityModel::FIG_30,
            criterion: Criterion::Compromise,
        };
        let followed = follow_routes(&settings, 40, 2);
        assert_eq!(followed.len(), 40);
        assert!(followed.iter().all(|f| f.succeeded && f.legs >= 1));
    }

    #[test]
    fn bins_count_every_route_once() {
        let followed: Vec<Followed> = (0..100)
            .map(|k| Followed {
                predicted: k as f64 / 99.0,
                legs: 1,
                succeeded: k % 3 != 0,
            })
            .collect();
        let bins = calibration_bins(&followed, 10);
        assert_eq!(bins.iter().map(|b| b.routes).sum::<usize>(), 100);
        for b in &bins {
            assert!(b.low <= b.measured && b.measured <= b.high);
        }
    }
}
