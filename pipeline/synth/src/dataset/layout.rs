//! Where rocks lie and where the rover stops: the presets of the synthetic datasets (issue 4),
//! after the scenarios of 000 §VIII: random imaging points (§VIII-B) and a rover traverse that
//! stops every 1–2 m along a loop through a rock field (§VIII-C, the JPL Mars Yard).

use crate::Pose;
use qrm_core::geometry::Point;
use rand::seq::SliceRandom;
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
    /// A family, one member per seed (issue 13): the layout of `Marsyard` or `Random`, with
    /// scene, camera and calibration variations all drawn from the seed
    /// ([`super::Variant::stress`]).
    Stress,
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
            Preset::Stress => "stress",
        }
    }

    /// The preset whose layout `seed` uses: itself, or for `Stress` the layout it draws.
    pub fn layout_preset(self, seed: u64) -> Preset {
        match self {
            Preset::Stress => super::Variant::stress(seed).layout,
            preset => preset,
        }
    }

    /// The layout of this preset for `seed`.
    pub fn layout(self, seed: u64, counts: Counts) -> Layout {
        self.layout_clustered(seed, counts, 0.0)
    }

    /// The layout of this preset for `seed` with a `cluster` fraction of its rocks gathered
    /// into dense clusters ([`crate::Scenery::cluster`]). The rocks are moved with their own
    /// random stream before the imaging points are drawn, so that `cluster` 0 is exactly
    /// [`Preset::layout`] and imaging points keep their clearance from the moved rocks.
    pub fn layout_clustered(self, seed: u64, counts: Counts, cluster: f64) -> Layout {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x1a70_0117);
        match self {
            Preset::Marsyard => {
                let n = counts.rocks.unwrap_or(30);
                let rocks = gather(seed, clustered_field(&mut rng, n, 20.0, 3), cluster);
                let stations = loop_traverse(&mut rng, &rocks, 20.0, counts.stations.unwrap_or(50));
                Layout { rocks, stations }
            }
            Preset::Random => {
                let n = counts.rocks.unwrap_or(30);
                let rocks = gather(seed, uniform_field(&mut rng, n, 30.0, (0.15, 0.5)), cluster);
                let stations =
                    random_stations(&mut rng, &rocks, 30.0, counts.stations.unwrap_or(50));
                Layout { rocks, stations }
            }
            Preset::SparseLarge => {
                let n = counts.rocks.unwrap_or(200);
                let rocks = gather(seed, uniform_field(&mut rng, n, 200.0, (0.3, 1.2)), cluster);
                let stations =
                    meander_traverse(&mut rng, &rocks, 200.0, counts.stations.unwrap_or(120));
                Layout { rocks, stations }
            }
            Preset::Stress => self
                .layout_preset(seed)
                .layout_clustered(seed, counts, cluster),
        }
    }
}

/// Gathers a `fraction` of the rocks into dense clusters of about five, where each newcomer
/// touches or overlaps a rock already there: its centre lies 0.4–0.85 of the two radii from
/// that rock's (a rock's footprint reaches about 0.3–1.1 radii from its centre, so the two
/// meet or interpenetrate), and no nearer than 0.4 of the two radii to any rock, so that none
/// swallows another. The first rock of each cluster stays where it was; a rock that finds no
/// such place in 50 tries stays too. Drawn from a stream of its own, so that the preset's
/// other draws do not change.
fn gather(seed: u64, mut rocks: Vec<(Point, f64)>, fraction: f64) -> Vec<(Point, f64)> {
    let gathered = ((fraction * rocks.len() as f64).round() as usize).min(rocks.len());
    if gathered < 2 {
        return rocks;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xc1a5_7e25);
    let mut order: Vec<usize> = (0..rocks.len()).collect();
    order.shuffle(&mut rng);
    let cores = gathered.div_ceil(5);
    let mut clusters: Vec<Vec<usize>> = order[..cores].iter().map(|&i| vec![i]).collect();
    for (j, &i) in order[cores..gathered].iter().enumerate() {
        let cluster = &mut clusters[j % cores];
        let r = rocks[i].1;
        for _ in 0..50 {
            let (q, s) = rocks[cluster[rng.random_range(0..cluster.len())]];
            let angle = rng.random_range(0.0..TAU);
            let distance = (r + s) * rng.random_range(0.4..0.85);
            let p = Point::new(q.x + distance * angle.cos(), q.y + distance * angle.sin());
            let room = rocks
                .iter()
                .enumerate()
                .all(|(k, &(o, t))| k == i || o.distance(p) >= 0.4 * (r + t));
            if room {
                rocks[i].0 = p;
                cluster.push(i);
                break;
            }
        }
    }
    rocks
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

    /// Whether ground point (x, y) lies in the rock's footprint: inside one of its lumps.
    fn in_footprint(rock: &crate::Rock, x: f64, y: f64) -> bool {
        rock.lumps.iter().any(|l| {
            let (dx, dy) = (
                x - rock.position.x - l.center[0],
                y - rock.position.y - l.center[1],
            );
            let (c, s) = (l.yaw.cos(), l.yaw.sin());
            let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
            let w = (l.center[2] - rock.burial) / l.radii[2];
            (u / l.radii[0]).powi(2) + (v / l.radii[1]).powi(2) + w * w <= 1.0
        })
    }

    /// Pairs of rocks whose footprints overlap or come within 2 cm (sampled every centimetre).
    fn touching_pairs(world: &crate::World) -> usize {
        let rocks = &world.rocks;
        let mut pairs = 0;
        for (i, a) in rocks.iter().enumerate() {
            for b in &rocks[i + 1..] {
                let reach = 1.5 * (a.size + b.size);
                if a.position.distance(b.position) > reach {
                    continue;
                }
                let samples = |rock: &crate::Rock| -> Vec<Point> {
                    let n = (1.5 * rock.size / 0.01).ceil() as i32;
                    (-n..=n)
                        .flat_map(|i| (-n..=n).map(move |j| (i, j)))
                        .map(|(i, j)| {
                            Point::new(
                                rock.position.x + 0.01 * f64::from(i),
                                rock.position.y + 0.01 * f64::from(j),
                            )
                        })
                        .filter(|p| in_footprint(rock, p.x, p.y))
                        .collect()
                };
                let (sa, sb) = (samples(a), samples(b));
                if sa.iter().any(|p| sb.iter().any(|q| p.distance(*q) <= 0.02)) {
                    pairs += 1;
                }
            }
        }
        pairs
    }

    #[test]
    fn clusters_make_footprints_touch_and_keep_stations_clear() {
        for preset in [Preset::Marsyard, Preset::Random] {
            let plain = preset.layout(5, Counts::default());
            assert_eq!(preset.layout_clustered(5, Counts::default(), 0.0), plain);
            let packed = preset.layout_clustered(5, Counts::default(), 0.5);
            assert_eq!(packed.stations.len(), 50, "{preset:?}");
            for s in &packed.stations {
                assert!(clear(s.position, &packed.rocks), "{preset:?}");
            }
            let sizes = |l: &Layout| l.rocks.iter().map(|r| r.1).collect::<Vec<_>>();
            assert_eq!(sizes(&packed), sizes(&plain), "the same rocks, moved");
            let touching = |l: &Layout| touching_pairs(&crate::World::generate(5, &l.rocks));
            let (before, after) = (touching(&plain), touching(&packed));
            assert!(
                after >= before + 8,
                "{preset:?}: {before} → {after} touching pairs"
            );
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
