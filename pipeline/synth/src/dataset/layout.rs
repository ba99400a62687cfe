//! Where rocks lie and where the rover stops: the presets of the synthetic datasets (issue 4),
//! after the scenarios of 000 §VIII: random imaging points (§VIII-B) and a rover traverse that
//! stops every 1–2 m along a loop through a rock field (§VIII-C, the JPL Mars Yard).

use crate::Pose;
use qrm_core::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// A named scene layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// 30 rocks, partly clustered, in about 20 m × 20 m; a loop traverse stopping every 1–2 m.
    Marsyard,
    /// 30 rocks uniform in a 30 m square; 50 random imaging points.
    Random,
    /// 200 rocks over 200 m × 200 m; a long meandering traverse.
    SparseLarge,
}

/// Rock placements (ground position, characteristic radius) and imaging poses.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub rocks: Vec<(Point, f64)>,
    pub stations: Vec<Pose>,
}

/// Overrides of a preset's counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counts {
    pub rocks: Option<usize>,
    pub stations: Option<usize>,
}

/// Clearance kept between an imaging point and a rock's edge, metres: the rover cannot stand
/// on a rock, and a camera inside one would see nothing.
const CLEARANCE: f64 = 0.6;

impl Preset {
    pub fn name(self) -> &'static str {
        match self {
            Preset::Marsyard => "marsyard",
            Preset::Random => "random",
            Preset::SparseLarge => "sparse-large",
        }
    }

    /// The layout of this preset for `seed`.
    pub fn layout(self, seed: u64, counts: Counts) -> Layout {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x1a70_0117);
        match self {
            Preset::Marsyard => {
                let n = counts.rocks.unwrap_or(30);
                let rocks = clustered_field(&mut rng, n, 20.0, 3);
                let stations = loop_traverse(&mut rng, &rocks, 20.0, counts.stations.unwrap_or(50));
                Layout { rocks, stations }
            }
            Preset::Random => {
                let n = counts.rocks.unwrap_or(30);
                let rocks = uniform_field(&mut rng, n, 30.0, (0.15, 0.5));
                let stations =
                    random_stations(&mut rng, &rocks, 30.0, counts.stations.unwrap_or(50));
                Layout { rocks, stations }
            }
            Preset::SparseLarge => {
                let n = counts.rocks.unwrap_or(200);
                let rocks = uniform_field(&mut rng, n, 200.0, (0.3, 1.2));
                let stations =
                    meander_traverse(&mut rng, &rocks, 200.0, counts.stations.unwrap_or(120));
                Layout { rocks, stations }
            }
        }
    }
}

/// Rocks uniform in a `side` square, radii uniform in `sizes`, not overlapping.
fn uniform_field(
    rng: &mut ChaCha8Rng,
    n: usize,
    side: f64,
    sizes: (f64, f64),
) -> Vec<(Point, f64)> {
    let mut rocks: Vec<(Point, f64)> = Vec::with_capacity(n);
    while rocks.len() < n {
        let r = rng.random_range(sizes.0..sizes.1);
        let p = Point::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
        if rocks.iter().all(|&(q, s)| q.distance(p) > r + s + 0.3) {
            rocks.push((p, r));
        }
    }
    rocks
}

/// Half the rocks in `clusters` tight groups, the rest scattered (the Mars Yard's rock
/// clusters, 000 Fig. 8), in a `side` square.
fn clustered_field(
    rng: &mut ChaCha8Rng,
    n: usize,
    side: f64,
    clusters: usize,
) -> Vec<(Point, f64)> {
    let centres: Vec<Point> = (0..clusters)
        .map(|_| {
            Point::new(
                rng.random_range(0.25 * side..0.75 * side),
                rng.random_range(0.25 * side..0.75 * side),
            )
        })
        .collect();
    let mut rocks: Vec<(Point, f64)> = Vec::with_capacity(n);
    while rocks.len() < n {
        let r = rng.random_range(0.15..0.6);
        let p = if rocks.len() % 2 == 0 {
            let c = centres[rocks.len() / 2 % clusters];
            let (angle, dist) = (rng.random_range(0.0..TAU), rng.random_range(0.5..2.5));
            Point::new(c.x + dist * angle.cos(), c.y + dist * angle.sin())
        } else {
            Point::new(rng.random_range(0.0..side), rng.random_range(0.0..side))
        };
        if rocks.iter().all(|&(q, s)| q.distance(p) > r + s + 0.25) {
            rocks.push((p, r));
        }
    }
    rocks
}

/// Whether a rover at `p` keeps its clearance from every rock.
fn clear(p: Point, rocks: &[(Point, f64)]) -> bool {
    rocks.iter().all(|&(q, r)| q.distance(p) > r + CLEARANCE)
}

/// Random imaging points with random headings (000 §VIII-B), clear of rocks.
fn random_stations(rng: &mut ChaCha8Rng, rocks: &[(Point, f64)], side: f64, n: usize) -> Vec<Pose> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let p = Point::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
        if clear(p, rocks) {
            out.push(Pose {
                position: p,
                heading: rng.random_range(0.0..TAU),
            });
        }
    }
    out
}

/// Stops every 1–2 m along `path` (a closed or open polyline parameterised by arc length),
/// skipping stops that would be on a rock; the heading follows the path.
fn stops_along(
    rng: &mut ChaCha8Rng,
    rocks: &[(Point, f64)],
    n: usize,
    path: impl Fn(f64) -> Point,
) -> Vec<Pose> {
    let mut out = Vec::with_capacity(n);
    let mut s = 0.0;
    let mut guard = 0;
    while out.len() < n && guard < 100 * n {
        guard += 1;
        s += rng.random_range(1.0..2.0);
        let p = path(s);
        if !clear(p, rocks) {
            continue;
        }
        let ahead = path(s + 0.1);
        out.push(Pose {
            position: p,
            heading: (ahead.y - p.y).atan2(ahead.x - p.x),
        });
    }
    out
}

/// A loop around the middle of a `side` square (a rounded, wobbling circle), like the Mars
/// Yard traverse of 000 §VIII-C that returns near its start.
fn loop_traverse(rng: &mut ChaCha8Rng, rocks: &[(Point, f64)], side: f64, n: usize) -> Vec<Pose> {
    let centre = Point::new(side / 2.0, side / 2.0);
    let radius = 0.36 * side;
    let wobble = rng.random_range(0.0..TAU);
    // Arc length of one turn ≈ 2πR; stops spaced 1.5 m on average.
    let circumference = TAU * radius;
    stops_along(rng, rocks, n, move |s| {
        let t = s / circumference * TAU;
        // A slow inward spiral, so that a second lap passes beside the first, not on it.
        let r = radius * (1.0 + 0.12 * (3.0 * t + wobble).sin()) * (1.0 - 0.03 * t / TAU);
        Point::new(centre.x + r * t.cos(), centre.y + r * t.sin())
    })
}

/// A long meandering traverse across a `side` square.
fn meander_traverse(
    rng: &mut ChaCha8Rng,
    rocks: &[(Point, f64)],
    side: f64,
    n: usize,
) -> Vec<Pose> {
    let phase = rng.random_range(0.0..TAU);
    stops_along(rng, rocks, n, move |s| {
        let x = 0.1 * side + s * 0.9;
        Point::new(
            x.min(0.95 * side),
            side / 2.0 + 0.25 * side * (x / side * 3.0 * TAU / 2.0 + phase).sin(),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_have_their_counts_and_keep_stations_off_rocks() {
        for (preset, rocks, stations) in [
            (Preset::Marsyard, 30, 50),
            (Preset::Random, 30, 50),
            (Preset::SparseLarge, 200, 120),
        ] {
            let layout = preset.layout(7, Counts::default());
            assert_eq!(layout.rocks.len(), rocks, "{preset:?}");
            assert_eq!(layout.stations.len(), stations, "{preset:?}");
            for s in &layout.stations {
                assert!(clear(s.position, &layout.rocks), "{preset:?}");
            }
            assert_eq!(layout, preset.layout(7, Counts::default()), "deterministic");
        }
    }

    #[test]
    fn traverse_stops_are_one_to_two_metres_apart() {
        // Stops that would fall on a rock are skipped, so a few steps are longer.
        let layout = Preset::Marsyard.layout(3, Counts::default());
        let steps: Vec<f64> = layout
            .stations
            .windows(2)
            .map(|w| w[0].position.distance(w[1].position))
            .collect();
        let regular = steps.iter().filter(|&&d| (0.9..=2.0).contains(&d)).count();
        assert!(regular * 10 >= steps.len() * 8, "{steps:?}");
        assert!(steps.iter().all(|&d| d <= 10.0), "{steps:?}");
    }
}
