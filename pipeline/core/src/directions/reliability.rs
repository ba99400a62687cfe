//! How reliably a navigator picks the intended landmark (004 §6.1.2), refitted for a rover.
//!
//! 004 models the chance that the "most isolated object in the window" is the intended one as
//! Eq. (1), `R(n, σ) = (Aσ + B)/n − Cσ + D`, with `n` the objects in view (counting the
//! reference landmark) and `σ` the error of position estimates; the constants were fitted in
//! Mathematica and not printed. Fig. 30's per-leg values fix `R(n) = 0.7153/n + 0.7379` at the
//! paper's σ (seed digest B.4), kept as [`ReliabilityModel::FIG_30`].
//!
//! For a rover the selection is simulated ([`selection_rate`]): it stands near landmark `R`
//! (anywhere within half the distance to `R`'s nearest landmark, so inside `R`'s Voronoi
//! cell), perceives every other landmark's bearing with Gaussian error and its range with a
//! log-normal relative error `σ`, takes itself for `R` (the rock at its feet is not seen in a
//! panorama) and, with its `n − 1` perceived nearest landmarks, as the scene, and heads for
//! the scene's most isolated member; it succeeds when that is the one the
//! map-maker meant (the most isolated of the true scene). Eq. (1) is then fitted by least
//! squares over `n` and `σ` ([`ReliabilityModel::fit`]).

use super::isolation::{Positions, SceneRanks};
use crate::geometry::Point;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;

/// The least reliability a leg is given, so that `−ln R` stays finite when the fitted line
/// runs below 0 for large scenes.
const LEAST_RELIABILITY: f64 = 1e-3;

/// 004 Eq. (1): `R(n, σ) = (aσ + b)/n − cσ + d`, clamped to `[0.001, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ReliabilityModel {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
}

impl ReliabilityModel {
    /// `R(n) = 0.7153/n + 0.7379`, recovered from 004 Fig. 30 (σ folded in).
    pub const FIG_30: ReliabilityModel = ReliabilityModel {
        a: 0.0,
        b: 0.7153,
        c: 0.0,
        d: 0.7379,
    };

    /// The fit for this project's rover: [`selection_rate`] with bearing error s.d. 0.5° and
    /// standoff 1 over `n = 2..=8` and `σ ∈ {0.05, 0.1, 0.2, 0.3}` (20 000 trials each, seed 1),
    /// as printed by `pipeline simulate directions` (docs/DIRECTIONS.md).
    pub const ROVER: ReliabilityModel = ReliabilityModel {
        a: 1.3435,
        b: 0.9019,
        c: 1.3128,
        d: 0.3303,
    };

    /// `R(n, σ)` for a scene of `objects` (counting the reference).
    pub fn reliability(&self, objects: usize, sigma: f64) -> f64 {
        let n = objects as f64;
        ((self.a * sigma + self.b) / n - self.c * sigma + self.d).clamp(LEAST_RELIABILITY, 1.0)
    }

    /// A leg's unreliability `u = −ln R` (004 §7.2.2: "measured by −log(R)").
    pub fn unreliability(&self, objects: usize, sigma: f64) -> f64 {
        -self.reliability(objects, sigma).ln()
    }

    /// Eq. (1) fitted by least squares to measured selection rates; `None` with fewer than
    /// four distinct `(n, σ)` settings to fit four constants.
    pub fn fit(rates: &[SelectionRate]) -> Option<ReliabilityModel> {
        let rows: Vec<[f64; 4]> = rates
            .iter()
            .map(|r| {
                let n = r.objects as f64;
                [r.sigma / n, 1.0 / n, -r.sigma, 1.0]
            })
            .collect();
        let x = DMatrix::from_fn(rows.len(), 4, |i, j| rows[i][j]);
        if x.rank(1e-9) < 4 {
            return None;
        }
        let y = DVector::from_iterator(rates.len(), rates.iter().map(SelectionRate::rate));
        let solution = x.svd(true, true).solve(&y, 1e-12).ok()?;
        Some(ReliabilityModel {
            a: solution[0],
            b: solution[1],
            c: solution[2],
            d: solution[3],
        })
    }
}

/// The rover's perception errors.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ViewNoise {
    /// Standard deviation of a bearing, radians.
    pub bearing_sd: f64,
    /// Standard deviation of `ln(measured range / true range)` (Eq. (1)'s σ).
    pub range_sd: f64,
    /// How far from `R` the rover may stand, taking its own position for `R`'s: a fraction of
    /// half the distance from `R` to its nearest landmark (1: anywhere in that disc, which
    /// lies in `R`'s Voronoi cell; 0: on `R`).
    pub standoff: f64,
}

/// How often the intended landmark was selected in one setting.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SelectionRate {
    pub objects: usize,
    pub sigma: f64,
    pub successes: usize,
    pub trials: usize,
}

impl SelectionRate {
    pub fn rate(&self) -> f64 {
        self.successes as f64 / self.trials as f64
    }
}

/// Landmarks of each simulated field: uniform in a square, the reference taken near the
/// centre, so that scenes of up to a dozen objects never reach the border.
const FIELD_LANDMARKS: usize = 80;

/// The most isolated member of `at`'s scene of `objects` (it and its `objects − 1` nearest) as
/// positions `seen` show them; `None` when fewer landmarks exist.
pub fn most_isolated_seen(seen: &[Point], at: usize, objects: usize) -> Option<usize> {
    if objects < 2 || objects > seen.len() {
        return None;
    }
    let mut others: Vec<usize> = (0..seen.len()).filter(|&i| i != at).collect();
    others.sort_by(|&i, &j| {
        seen[at]
            .distance(seen[i])
            .total_cmp(&seen[at].distance(seen[j]))
    });
    let scene: Vec<usize> = std::iter::once(at)
        .chain(others.into_iter().take(objects - 1))
        .collect();
    let choice = SceneRanks::new(&Positions(seen), &scene)
        .most_isolated(Some(0))
        .certain?;
    Some(scene[choice])
}

/// Where a rover standing near landmark `at` of `world` perceives every landmark: from a point
/// uniform in the disc of `noise.standoff` times half the distance to `at`'s nearest landmark,
/// bearings and ranges with `noise`. The rock it stands at is not seen (too near the camera, as in rendered
/// panoramas): the rover takes its own position for it.
pub fn perceive(world: &[Point], at: usize, noise: ViewNoise, rng: &mut impl Rng) -> Vec<Point> {
    let nearest = world
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != at)
        .map(|(_, p)| p.distance(world[at]))
        .fold(f64::INFINITY, f64::min);
    let radius = 0.5 * noise.standoff * nearest * rng.random::<f64>().sqrt();
    let angle = rng.random::<f64>() * std::f64::consts::TAU;
    let rover = Point::new(
        world[at].x + radius * angle.cos(),
        world[at].y + radius * angle.sin(),
    );
    let bearing = Normal::new(0.0, noise.bearing_sd).expect("a finite s.d. ≥ 0");
    let range = Normal::new(0.0, noise.range_sd).expect("a finite s.d. ≥ 0");
    world
        .iter()
        .enumerate()
        .map(|(i, p)| {
            if i == at {
                return rover;
            }
            let v = *p - rover;
            let theta = v.y.atan2(v.x) + bearing.sample(rng);
            let r = v.x.hypot(v.y) * range.sample(rng).exp();
            Point::new(rover.x + r * theta.cos(), rover.y + r * theta.sin())
        })
        .collect()
}

/// A random field and the landmark nearest its centre.
pub fn random_field(rng: &mut impl Rng) -> (Vec<Point>, usize) {
    let world: Vec<Point> = (0..FIELD_LANDMARKS)
        .map(|_| Point::new(rng.random::<f64>(), rng.random::<f64>()))
        .collect();
    let centre = Point::new(0.5, 0.5);
    let at = (0..world.len())
        .min_by(|&i, &j| {
            world[i]
                .distance(centre)
                .total_cmp(&world[j].distance(centre))
        })
        .expect("the field has landmarks");
    (world, at)
}

/// Monte Carlo of 004's isolated-landmark selection for scenes of `objects` with `noise`:
/// `trials` random fields, in parallel; reproducible from `seed`.
pub fn selection_rate(objects: usize, noise: ViewNoise, trials: usize, seed: u64) -> SelectionRate {
    let successes = (0..trials)
        .into_par_iter()
        .filter(|&trial| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(trial as u64);
            let (world, at) = random_field(&mut rng);
            let seen = perceive(&world, at, noise, &mut rng);
            let intended = most_isolated_seen(&world, at, objects);
            intended.is_some() && most_isolated_seen(&seen, at, objects) == intended
        })
        .count();
    SelectionRate {
        objects,
        sigma: noise.range_sd,
        successes,
        trials,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figure_30_legs() {
        // 004 Fig. 30's LOGPROB per leg for n = 2..5 (seed digest B.4).
        for (n, printed) in [(2, 0.000), (3, 0.024), (4, 0.087), (5, 0.127)] {
            let u = ReliabilityModel::FIG_30.unreliability(n, 0.0);
            assert!((u - printed).abs() < 0.001, "n = {n}: {u} vs {printed}");
        }
    }

    #[test]
    fn the_fit_recovers_a_known_model() {
        let truth = ReliabilityModel {
            a: -0.4,
            b: 0.9,
            c: 0.5,
            d: 0.5,
        };
        let rates: Vec<SelectionRate> = (2..=8)
            .flat_map(|n| [0.05, 0.1, 0.2].map(|sigma| (n, sigma)))
            .map(|(objects, sigma)| SelectionRate {
                objects,
                sigma,
                successes: (truth.reliability(objects, sigma) * 1e6).round() as usize,
                trials: 1_000_000,
            })
            .collect();
        let fit = ReliabilityModel::fit(&rates).expect("enough settings");
        for (got, want) in [
            (fit.a, truth.a),
            (fit.b, truth.b),
            (fit.c, truth.c),
            (fit.d, truth.d),
        ] {
            assert!((got - want).abs() < 1e-3, "{fit:?}");
        }
        assert!(ReliabilityModel::fit(&rates[..3]).is_none());
    }

    #[test]
    fn exact_sensing_always_selects_the_intended_landmark() {
        let exact = ViewNoise {
            bearing_sd: 0.0,
            range_sd: 0.0,
            standoff: 0.0,
        };
        for objects in 2..=6 {
            assert_eq!(selection_rate(objects, exact, 200, 3).successes, 200);
        }
    }

    /// The committed rover model is what the simulation measures: a fresh, smaller Monte
    /// Carlo run (its own seed) fits a model that predicts within 0.03 of it everywhere.
    #[test]
    fn the_rover_model_is_the_simulations_fit() {
        let rates: Vec<SelectionRate> = (2..=8)
            .flat_map(|n| [0.05, 0.1, 0.2, 0.3].map(|sigma| (n, sigma)))
            .map(|(objects, range_sd)| {
                let noise = ViewNoise {
                    bearing_sd: 0.5f64.to_radians(),
                    range_sd,
                    standoff: 1.0,
                };
                selection_rate(objects, noise, 4000, 7)
            })
            .collect();
        let fresh = ReliabilityModel::fit(&rates).expect("28 settings");
        for r in &rates {
            let (committed, refit) = (
                ReliabilityModel::ROVER.reliability(r.objects, r.sigma),
                fresh.reliability(r.objects, r.sigma),
            );
            assert!(
                (committed - refit).abs() < 0.03,
                "n = {}, σ = {}: committed {committed:.3}, refit {refit:.3} ({fresh:?})",
                r.objects,
                r.sigma
            );
        }
    }
}
