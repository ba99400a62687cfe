//! A drive for tests of wrong associations: a rover along the x axis, one station a metre,
//! past rocks `A` and `B` (1.5 m apart) and rocks on both sides, seeing those within 8 m with
//! bearings to ±0.02 rad and an exact range order. From station `wrong` on, rock `A` is hidden
//! and rock `B` is reported as landmark `A`; before it, `B` is hidden. Landmark ids are rock
//! indices.

use super::{Frame, Placed};
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::geometry::Point;
use qrm_core::map::{Hypergraph, LandmarkId, Sighting};
use qrm_core::measurement::{Bearing, RangeOrder, StationView};

pub const A: usize = 0;
pub const B: usize = 1;
pub const STATIONS: usize = 25;

/// Rocks `A` and `B`, then rocks on both sides of the drive.
pub const ROCKS: [[f64; 2]; 16] = [
    [12.0, 3.0],
    [13.2, 3.9],
    [2.0, 4.0],
    [4.0, -3.0],
    [6.0, 5.0],
    [8.0, -5.0],
    [9.0, 2.0],
    [11.0, -2.0],
    [14.0, 6.5],
    [15.0, -4.0],
    [17.0, -3.0],
    [18.0, 5.0],
    [20.0, 1.5],
    [22.0, -4.0],
    [23.0, 4.0],
    [5.0, 1.5],
];

/// What one station sees, nearest first.
pub struct Seen {
    pub rocks: Vec<usize>,
    pub view: StationView,
    /// Each rock placed around the station, 0.3 m radius.
    pub placed: Vec<Placed>,
}

fn rock(r: usize) -> Point {
    Point::new(ROCKS[r][0], ROCKS[r][1])
}

/// Station `step` of the drive whose wrong association starts at `wrong`.
pub fn seen(step: usize, wrong: usize) -> Seen {
    let station = Point::new(step as f64, 0.0);
    let hidden = if step >= wrong { A } else { B };
    let mut rocks: Vec<usize> = (0..ROCKS.len())
        .filter(|&r| r != hidden && rock(r).distance(station) <= 8.0)
        .collect();
    rocks.sort_by(|&i, &j| {
        rock(i)
            .distance(station)
            .total_cmp(&rock(j).distance(station))
    });
    let view = StationView::new(
        rocks
            .iter()
            .map(|&r| Bearing {
                angle: (rock(r).y - station.y).atan2(rock(r).x - station.x),
                uncertainty: 0.02,
            })
            .collect(),
        RangeOrder::total(&(0..rocks.len()).collect::<Vec<_>>()).expect("a total order"),
    )
    .expect("a valid view");
    let placed = rocks
        .iter()
        .map(|&r| Placed::disc([rock(r).x - station.x, rock(r).y - station.y], 0.3))
        .collect();
    Seen {
        rocks,
        view,
        placed,
    }
}

impl Seen {
    /// The station's sightings, each rock as `label` calls it.
    pub fn sightings(&self, label: impl Fn(usize) -> LandmarkId) -> Vec<Sighting> {
        self.rocks
            .iter()
            .enumerate()
            .map(|(k, &r)| Sighting::new(k, label(r)))
            .collect()
    }

    /// The station's frame, each rock as `label` calls it.
    pub fn frame(&self, label: impl Fn(usize) -> LandmarkId) -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: self
                .rocks
                .iter()
                .zip(&self.placed)
                .map(|(&r, &p)| (label(r), p))
                .collect(),
        }
    }
}

/// The relations of `map` that exclude the truth, landmark `l` being rock `rock_of(l)`.
pub fn unsound(map: &Hypergraph<Edc>, rock_of: impl Fn(LandmarkId) -> usize) -> usize {
    let p = |l| rock(rock_of(l));
    let truth = |a, b, c| Edc::classify(p(a), p(b), p(c));
    qrm_core::metrics::evaluate(map, truth, map.len()).unsound_relations
}
