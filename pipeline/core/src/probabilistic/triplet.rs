//! Qualitative estimation of one triplet `A, B, C` from bearings seen at a few camera poses
//! (002 §III; seed digest C.2–C.4, C.7), in the frame `A = (0,0)`, `B = (0,1)`.
//!
//! - [`estimate_full`]: the sampling algorithm (002 Algorithm 1). Each particle draws each
//!   view's bearings of `A` and `B` around the measured ones (their difference gives the
//!   inscribed-angle locus, the bearing of `A` the heading), the first pose uniform on its
//!   locus, each later pose where the ray of a noisy motion command meets that step's locus;
//!   it then resects `C` (the centroid of the pairwise intersections of its bearing rays) and
//!   is weighted by the likelihood of `C`'s bearings and by the area its poses' draw covers
//!   (so that the particles stand for 002's uniform prior over positions). The belief is the
//!   weighted histogram of `C`'s region (Eq. 9).
//! - [`estimate_fast`]: 002 §III-D, measurement noise neglected: every pose on its exact
//!   locus, weighted as the full one's; the motion command's noise is still drawn (see the
//!   function).
//! - [`estimate_baseline`]: 002 §III-F, after Padgett & Campbell: each view alone (pose on its
//!   locus, `C` anywhere along its bearing ray within the prior's support), views multiplied
//!   as if independent.
//!
//! Each returns an [`Estimate`]: the belief over `AB:C` (002 Eq. 9) and, for every view, the
//! belief over the camera's own state `AB:X_n` — the qualitative camera localization of
//! Eq. (7), (10) — from the same weighted particles.

use super::belief::{Belief, STATES};
use crate::edc;
use crate::geometry::Point;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::{PI, TAU};

/// One view of the triplet: bearings of `A`, `B`, `C` relative to the camera's heading
/// (radians), and the motion command that led here from the previous view (heading of the
/// displacement relative to the previous camera frame; `None` for the first view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub bearings: [f64; 3],
    pub motion: Option<f64>,
}

/// Noise the estimators assume: bearing and motion-command s.d., radians.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Noise {
    pub bearing: f64,
    pub motion: f64,
}

/// Where `C` may lie a priori, in the AB frame (002 leaves it open; seed digest C.7: the
/// simulation box mapped into the frame): a convex polygon, counter-clockwise.
#[derive(Clone, Debug, PartialEq)]
pub struct Prior {
    pub polygon: Vec<Point>,
}

impl Prior {
    fn contains(&self, p: Point) -> bool {
        let n = self.polygon.len();
        (0..n).all(|i| {
            let (a, b) = (self.polygon[i], self.polygon[(i + 1) % n]);
            (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) >= 0.0
        })
    }

    /// The parameter interval `[t0, t1]` (t ≥ 0) of the ray `origin + t·dir` inside the polygon.
    fn clip(&self, origin: Point, dir: Point) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        let n = self.polygon.len();
        for i in 0..n {
            let (a, b) = (self.polygon[i], self.polygon[(i + 1) % n]);
            // Inside: cross(b − a, p − a) ≥ 0, linear in t.
            let f0 = (b.x - a.x) * (origin.y - a.y) - (b.y - a.y) * (origin.x - a.x);
            let df = (b.x - a.x) * dir.y - (b.y - a.y) * dir.x;
            if df.abs() < 1e-15 {
                if f0 < 0.0 {
                    return None;
                }
            } else if df > 0.0 {
                t0 = t0.max(-f0 / df);
            } else {
                t1 = t1.min(-f0 / df);
            }
        }
        (t0 < t1 && t1.is_finite()).then_some((t0, t1))
    }
}

/// The beliefs an estimator returns: `AB:C` (Eq. 9) and `AB:X_n` for each view (Eq. 10).
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    pub landmark: Belief,
    pub cameras: Vec<Belief>,
}

/// One particle: `C`, the camera positions of the views, and the log-likelihood of `C`'s
/// bearings.
struct Particle {
    c: Point,
    cameras: Vec<Point>,
    log_weight: f64,
}

const A: Point = Point::new(0.0, 0.0);
const B: Point = Point::new(0.0, 1.0);

/// `angle` in `[−π, π)`.
pub(super) fn wrap(angle: f64) -> f64 {
    (angle + PI).rem_euclid(TAU) - PI
}

fn direction(angle: f64) -> Point {
    Point::new(angle.cos(), angle.sin())
}

/// The world angle of the direction from `from` to `to`.
pub(super) fn angle_to(from: Point, to: Point) -> f64 {
    (to.y - from.y).atan2(to.x - from.x)
}

/// The signed angle at `x` from the direction of `A` to that of `B`.
fn subtended(x: Point) -> f64 {
    wrap(angle_to(x, B) - angle_to(x, A))
}

/// The circle of the inscribed-angle locus of `gamma` (the arc where [`subtended`] is
/// `gamma`): centre `(−cot(γ)/2, 1/2)`, radius `1/(2|sin γ|)`. For `γ > 0` the camera is left
/// of `AB`; the centre is on its side when the angle is acute (the major arc), across `AB`
/// when obtuse.
fn locus_circle(gamma: f64) -> Option<(Point, f64)> {
    let s = gamma.sin();
    if s.abs() < 1e-9 {
        return None;
    }
    Some((Point::new(-0.5 * gamma.cos() / s, 0.5), 0.5 / s.abs()))
}

/// A point of the locus of `gamma`, at the circle parameter `t` if it lies on the locus arc.
fn locus_point(gamma: f64, t: f64) -> Option<Point> {
    let (c, r) = locus_circle(gamma)?;
    let x = Point::new(c.x + r * t.cos(), c.y + r * t.sin());
    ((subtended(x) - gamma).abs() < 1e-6).then_some(x)
}

/// Where the ray `origin + s·dir` (s > 0) meets the locus arc of `gamma`.
fn ray_meets_locus(origin: Point, dir: Point, gamma: f64) -> Vec<Point> {
    let Some((c, r)) = locus_circle(gamma) else {
        return Vec::new();
    };
    let o = origin - c;
    let b = o.x * dir.x + o.y * dir.y;
    let q = o.x * o.x + o.y * o.y - r * r;
    let disc = b * b - q;
    if disc < 0.0 {
        return Vec::new();
    }
    [-b - disc.sqrt(), -b + disc.sqrt()]
        .into_iter()
        .filter(|&s| s > 1e-9)
        .map(|s| Point::new(origin.x + s * dir.x, origin.y + s * dir.y))
        .filter(|&x| (subtended(x) - gamma).abs() < 1e-6)
        .collect()
}

/// The camera heading at `x` that puts `A` at relative bearing `phi_a`.
fn heading(x: Point, phi_a: f64) -> f64 {
    wrap(angle_to(x, A) - phi_a)
}

/// `C` as the centroid of the pairwise intersections (in front of both cameras) of its bearing
/// rays from `poses`; `None` if no pair meets.
fn resect(poses: &[(Point, f64)], phi_c: &[f64]) -> Option<Point> {
    let mut sum = (0.0, 0.0, 0usize);
    for i in 0..poses.len() {
        for j in i + 1..poses.len() {
            let (p, q) = (poses[i].0, poses[j].0);
            let (u, v) = (
                direction(poses[i].1 + phi_c[i]),
                direction(poses[j].1 + phi_c[j]),
            );
            let det = u.x * (-v.y) - u.y * (-v.x);
            if det.abs() < 1e-12 {
                continue;
            }
            let (dx, dy) = (q.x - p.x, q.y - p.y);
            let s = (dx * (-v.y) - dy * (-v.x)) / det;
            let t = (u.x * dy - u.y * dx) / det;
            if s > 0.0 && t > 0.0 {
                sum.0 += p.x + s * u.x;
                sum.1 += p.y + s * u.y;
                sum.2 += 1;
            }
        }
    }
    (sum.2 > 0).then(|| Point::new(sum.0 / sum.2 as f64, sum.1 / sum.2 as f64))
}

/// `ln` of the Gaussian likelihood of residual `x` (up to a constant).
fn log_gaussian(x: f64, sd: f64) -> f64 {
    -0.5 * (x / sd.max(1e-9)).powi(2)
}

/// The size of the gradient of the subtended angle [`subtended`] at `x`: how fast the locus
/// changes as the camera moves across it, `|(B − x)/|B − x|² − (A − x)/|A − x|²|`.
fn subtended_gradient(x: Point) -> f64 {
    let (da, db) = (x.distance(A).powi(2), x.distance(B).powi(2));
    ((B.x - x.x) / db - (A.x - x.x) / da).hypot((B.y - x.y) / db - (A.y - x.y) / da)
}

/// One particle's path: a pose on the locus of each view, drawn with `noise` (an s.d. of 0
/// draws the measured angle itself), `C` resected, and its log-weight: the likelihood of
/// `C`'s bearings at `bearing_sd` and the ratio of 002's prior (camera positions uniform in
/// the plane) to the density at which the poses were drawn.
///
/// Each view's bearings of `A` and `B` are drawn around the measured ones: their difference
/// gives the locus, and the bearing of `A` the camera's heading. The first pose is uniform
/// along its locus arc, a later one where a noisy motion ray meets its locus. Positions drawn
/// that way are not uniform in the plane: the density of a pose is that of the angles that
/// put it there, times the area those angles sweep, so each pose is weighted by that area —
/// the locus spacing `1 / |∇γ|` ([`subtended_gradient`]) times the arc's length for the first
/// pose, or the ray's reach per radian of heading (distance over the sine of the angle at
/// which it crosses the locus) for a later one, times the number of crossings of which one
/// was picked. Without these weights the particles crowd where the loci are dense, near `A`
/// and `B`.
fn particle(
    views: &[View],
    prior: &Prior,
    noise: Noise,
    bearing_sd: f64,
    rng: &mut impl Rng,
) -> Option<Particle> {
    let mut poses: Vec<(Point, f64)> = Vec::with_capacity(views.len());
    let mut log_area = 0.0;
    for view in views {
        let (x, alpha, area) = draw_pose(view, poses.last().copied(), noise, rng)?;
        if !prior.contains(x) {
            return None;
        }
        log_area += area;
        poses.push((x, alpha));
    }
    let phi_c: Vec<f64> = views.iter().map(|v| v.bearings[2]).collect();
    let c = resect(&poses, &phi_c).filter(|&c| prior.contains(c))?;
    let likelihood: f64 = poses
        .iter()
        .zip(&phi_c)
        .map(|(&(x, alpha), &phi)| log_gaussian(wrap(angle_to(x, c) - alpha - phi), bearing_sd))
        .sum();
    Some(Particle {
        c,
        cameras: poses.iter().map(|p| p.0).collect(),
        log_weight: likelihood + log_area,
    })
}

/// One pose of [`particle`]: the camera position and heading for `view`, after `previous`
/// (none for the first view), and the log of the area its draw covers.
fn draw_pose(
    view: &View,
    previous: Option<(Point, f64)>,
    noise: Noise,
    rng: &mut impl Rng,
) -> Option<(Point, f64, f64)> {
    let mut jitter = |sd: f64| {
        if sd > 0.0 {
            Normal::new(0.0, sd).expect("finite s.d.").sample(rng)
        } else {
            0.0
        }
    };
    let phi_a = view.bearings[0] + jitter(noise.bearing);
    let phi_b = view.bearings[1] + jitter(noise.bearing);
    let motion = view.motion.map(|psi| psi + jitter(noise.motion));
    let gamma = wrap(phi_b - phi_a);
    let (centre, radius) = locus_circle(gamma)?;
    let (x, reach) = match previous {
        // Uniform along the locus arc (off-arc draws are redrawn a few times), whose length
        // is the radius times its central angle, 2(π − |γ|).
        None => (
            (0..32).find_map(|_| locus_point(gamma, rng.random::<f64>() * TAU))?,
            radius * 2.0 * (PI - gamma.abs()),
        ),
        Some((previous, alpha)) => {
            let dir = direction(alpha + motion?);
            let hits = ray_meets_locus(previous, dir, gamma);
            let x = *hits.get(rng.random_range(0..hits.len().max(1)))?;
            let crossing = ((x.x - centre.x) * dir.x + (x.y - centre.y) * dir.y).abs() / radius;
            (
                x,
                previous.distance(x) / crossing.max(1e-9) * hits.len() as f64,
            )
        }
    };
    let log_area = (reach / subtended_gradient(x).max(1e-12)).ln();
    Some((x, heading(x, phi_a), log_area))
}

/// Adds `weight` to the region of `p` (nothing on a boundary).
fn add(weights: &mut [f64; STATES], p: Point, weight: f64) {
    if let Some(r) = edc::classify(A, B, p) {
        weights[r as usize - 1] += weight;
    }
}

/// The weighted histograms of `C`'s region and of each camera's over the particles (Eq. 9,
/// 10); `None` when no particle has weight. A camera whose particles all sit on boundaries
/// gets the uniform belief.
fn histogram(particles: &[Particle], views: usize) -> Option<Estimate> {
    let top = particles
        .iter()
        .map(|p| p.log_weight)
        .fold(f64::NEG_INFINITY, f64::max);
    let mut landmark = [0.0; STATES];
    let mut cameras = vec![[0.0; STATES]; views];
    for p in particles {
        let w = (p.log_weight - top).exp();
        add(&mut landmark, p.c, w);
        for (weights, &x) in cameras.iter_mut().zip(&p.cameras) {
            add(weights, x, w);
        }
    }
    Some(Estimate {
        landmark: Belief::from_weights(landmark)?,
        cameras: cameras
            .into_iter()
            .map(|w| Belief::from_weights(w).unwrap_or_else(Belief::uniform))
            .collect(),
    })
}

/// 002 Algorithm 1 with `particles` particles; `None` when no particle survives (no pose
/// chain or no resection).
pub fn estimate_full(
    views: &[View],
    prior: &Prior,
    noise: Noise,
    particles: usize,
    rng: &mut impl Rng,
) -> Option<Estimate> {
    let samples: Vec<Particle> = (0..particles)
        .filter_map(|_| particle(views, prior, noise, noise.bearing, rng))
        .collect();
    histogram(&samples, views.len())
}

/// 002 §III-D: measurement noise neglected — every pose on its exact locus, `C` resected
/// from the exact bearings — the particles weighted by the area of their draw and by `C`'s
/// bearings at `noise.bearing`. The motion command's noise is still drawn (`noise.motion`):
/// 002 neglects it too, but an exact motion ray misses the next locus in 16 % of Table I's
/// triplets (σ_w = 7°), which then get no belief at all, and at every noise level tried the
/// estimate is closer to the full one with it drawn (docs/PROBABILISTIC.md).
pub fn estimate_fast(
    views: &[View],
    prior: &Prior,
    noise: Noise,
    particles: usize,
    rng: &mut impl Rng,
) -> Option<Estimate> {
    let exact_loci = Noise {
        bearing: 0.0,
        motion: noise.motion,
    };
    let samples: Vec<Particle> = (0..particles)
        .filter_map(|_| particle(views, prior, exact_loci, noise.bearing, rng))
        .collect();
    histogram(&samples, views.len())
}

/// 002 §III-F: each view estimated alone — pose on its exact locus, `C` uniform along its
/// bearing ray within `prior` — and the views' beliefs multiplied. A view whose rays all miss
/// the prior is left out. Each view's histogram is floored at `1e-3` of its mass before the
/// product, so that one view's empty state does not veto the others (002 does not say). Each
/// camera's belief is its view's own: the poses on the locus whose ray meets the prior,
/// weighted as their `C` samples are (by the ray's length inside the prior).
pub fn estimate_baseline(
    views: &[View],
    prior: &Prior,
    samples_per_view: usize,
    rng: &mut impl Rng,
) -> Option<Estimate> {
    let mut product = [1.0; STATES];
    let mut used = 0;
    let mut cameras = Vec::with_capacity(views.len());
    for view in views {
        let gamma = wrap(view.bearings[1] - view.bearings[0]);
        let mut weights = [0.0; STATES];
        let mut camera = [0.0; STATES];
        for _ in 0..samples_per_view {
            let Some(x) = (0..32).find_map(|_| locus_point(gamma, rng.random::<f64>() * TAU))
            else {
                continue;
            };
            let dir = direction(heading(x, view.bearings[0]) + view.bearings[2]);
            if let Some((t0, t1)) = prior.clip(x, dir) {
                let t = t0 + rng.random::<f64>() * (t1 - t0);
                let c = Point::new(x.x + t * dir.x, x.y + t * dir.y);
                // Weighted by the ray's length inside the prior and the locus spacing at the
                // pose: uniform over the region the view allows.
                let w = (t1 - t0) / subtended_gradient(x).max(1e-12);
                add(&mut weights, c, w);
                add(&mut camera, x, w);
            }
        }
        cameras.push(Belief::from_weights(camera).unwrap_or_else(Belief::uniform));
        let Some(view_belief) = Belief::from_weights(weights) else {
            continue;
        };
        used += 1;
        for (p, q) in product.iter_mut().zip(view_belief.probabilities()) {
            *p *= q.max(1e-3 / STATES as f64);
        }
    }
    if used == 0 {
        return None;
    }
    Some(Estimate {
        landmark: Belief::from_weights(product)?,
        cameras,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Views of `c` from `poses` (position, heading) with exact bearings.
    fn views(c: Point, poses: &[(Point, f64)]) -> Vec<View> {
        poses
            .iter()
            .enumerate()
            .map(|(k, &(x, alpha))| View {
                bearings: [A, B, c].map(|l| wrap(angle_to(x, l) - alpha)),
                motion: (k > 0).then(|| {
                    let (prev, prev_alpha) = poses[k - 1];
                    wrap(angle_to(prev, x) - prev_alpha)
                }),
            })
            .collect()
    }

    #[test]
    fn the_locus_holds_the_camera() {
        let x = Point::new(1.3, -0.4);
        let gamma = subtended(x);
        let (c, r) = locus_circle(gamma).unwrap();
        assert!((c.distance(x) - r).abs() < 1e-9);
        let hits = ray_meets_locus(Point::new(3.0, -0.4), Point::new(-1.0, 0.0), gamma);
        assert!(hits.iter().any(|h| h.distance(x) < 1e-9), "{hits:?}");
    }

    /// The first pose of a noisy view, weighted by the area of its draw, follows the posterior
    /// of a camera uniform in a disc, `∝ N(γ(X); γ_measured, 2σ²)`, integrated independently
    /// on a grid; unweighted, it does not.
    #[test]
    fn weighted_first_poses_follow_the_posterior_of_a_uniform_camera() {
        let sigma = 3f64.to_radians();
        let camera = Point::new(1.8, -1.1);
        let view = View {
            bearings: [angle_to(camera, A) - 0.4, angle_to(camera, B) - 0.4, 0.0],
            motion: None,
        };
        let gamma = wrap(view.bearings[1] - view.bearings[0]);
        let radius = 4.0;
        let inside = |x: Point| x.distance(Point::new(0.0, 0.5)) < radius;
        let near_a = |x: Point| x.distance(A) < 1.5;
        // The grid: the posterior's mass near A, as a fraction of its mass in the disc.
        let (mut near, mut all) = (0.0, 0.0);
        let step = 0.01;
        for i in 0..(2.0 * radius / step) as usize {
            for j in 0..(2.0 * radius / step) as usize {
                let x = Point::new(
                    -radius + (i as f64 + 0.5) * step,
                    0.5 - radius + (j as f64 + 0.5) * step,
                );
                if inside(x) {
                    let w = log_gaussian(wrap(subtended(x) - gamma), sigma * 2f64.sqrt()).exp();
                    all += w;
                    near += if near_a(x) { w } else { 0.0 };
                }
            }
        }
        let grid = near / all;
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let noise = Noise {
            bearing: sigma,
            motion: 0.0,
        };
        let (mut weighted, mut unweighted) = ([0.0; 2], [0.0; 2]);
        for _ in 0..200_000 {
            let Some((x, _, log_area)) = draw_pose(&view, None, noise, &mut rng) else {
                continue;
            };
            if inside(x) {
                let k = usize::from(near_a(x));
                weighted[k] += log_area.exp();
                unweighted[k] += 1.0;
            }
        }
        let share = |w: [f64; 2]| w[1] / (w[0] + w[1]);
        assert!(
            (share(weighted) - grid).abs() < 0.02,
            "weighted {} against the grid's {grid}",
            share(weighted)
        );
        assert!(
            (share(unweighted) - grid).abs() > 0.05,
            "unweighted {} against the grid's {grid}",
            share(unweighted)
        );
    }

    #[test]
    fn exact_views_put_the_truth_first() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let c = Point::new(-1.2, 2.1);
        let truth = edc::classify(A, B, c).unwrap();
        let poses = [
            (Point::new(1.5, -0.5), 0.3),
            (Point::new(2.0, 1.5), 2.0),
            (Point::new(-0.5, 3.5), -1.0),
        ];
        let v = views(c, &poses);
        let prior = Prior {
            polygon: vec![
                Point::new(-6.0, -6.0),
                Point::new(6.0, -6.0),
                Point::new(6.0, 6.0),
                Point::new(-6.0, 6.0),
            ],
        };
        let noise = Noise {
            bearing: 0.5f64.to_radians(),
            motion: 1f64.to_radians(),
        };
        let fast = estimate_fast(&v, &prior, noise, 500, &mut rng).unwrap();
        assert_eq!(fast.landmark.most_likely(), truth);
        // Eq. (10): every camera's own region comes first too.
        for (belief, &(x, _)) in fast.cameras.iter().zip(&poses) {
            assert_eq!(belief.most_likely(), edc::classify(A, B, x).unwrap());
        }
        let full = estimate_full(
            &v,
            &prior,
            Noise {
                bearing: 0.5f64.to_radians(),
                motion: 1f64.to_radians(),
            },
            2000,
            &mut rng,
        )
        .unwrap();
        assert_eq!(full.landmark.most_likely(), truth);
        for (belief, &(x, _)) in full.cameras.iter().zip(&poses) {
            assert_eq!(belief.most_likely(), edc::classify(A, B, x).unwrap());
        }
        let baseline = estimate_baseline(&v, &prior, 2000, &mut rng).unwrap();
        assert!(baseline.landmark.probability(truth) > 0.0);
        assert_eq!(baseline.cameras.len(), 3);
        for (belief, &(x, _)) in baseline.cameras.iter().zip(&poses) {
            assert!(belief.probability(edc::classify(A, B, x).unwrap()) > 0.0);
        }
    }
}
