//! After the fact: a landmark whose sightings disagree with each other across stations.
//!
//! Association checks a station's matches against the stations of the last few minutes
//! ([`super::agreement`]) before they are fused. A wrong match can still get in: with too few
//! landmarks shared with those stations to say, or by a registration whose every pair is
//! wrong in the same way. The map need not contradict it: a loose map takes a look-alike's
//! relations, and path consistency then derives false ones from them. Later stations may
//! share enough landmarks with both kinds of sighting to tell them apart; then the landmark
//! is split into the rocks its sightings show, and the map is rebuilt from its journal
//! ([`qrm_core::map::Journal`]) so that what the mixed landmark brought is reverted.

use super::agreement::witness;
use super::registration::Frame;
use qrm_core::map::LandmarkId;

/// How one landmark's sightings are shared out once some are found to show another rock:
/// `groups[0]` keeps the landmark, each further group becomes a landmark of its own, and the
/// sightings of `retired` stations leave the map (stations whose sightings disagree with
/// others they agree with: no rock can be told for them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Regrouping {
    pub landmark: LandmarkId,
    /// Stations, in the order of `sightings`.
    pub groups: Vec<Vec<usize>>,
    pub retired: Vec<usize>,
}

/// The regrouping of `landmark`'s sightings, `(station, its frame)` in the order they were
/// fused, if two of them disagree on where it is ([`witness`]). Sightings that agree, directly
/// or through others, show one rock; the largest such set keeps the landmark, and a set that
/// disagrees with every group so far starts another. A sighting no other station can witness
/// goes with the nearest one in time that is witnessed: association tracked it from there.
pub fn regroup(landmark: LandmarkId, sightings: &[(usize, &Frame)]) -> Option<Regrouping> {
    let n = sightings.len();
    let mut agree = Vec::new();
    let mut disagree = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            match witness(sightings[i].1, sightings[j].1, landmark) {
                Some(true) => agree.push((i, j)),
                Some(false) => disagree.push((i, j)),
                None => {}
            }
        }
    }
    if disagree.is_empty() {
        return None;
    }
    let component = components(n, &agree);
    let split = |a: usize, b: usize| component[a] == component[b];
    let mut retired_components: Vec<usize> = disagree
        .iter()
        .filter(|&&(a, b)| split(a, b))
        .map(|&(a, _)| component[a])
        .collect();
    retired_components.sort_unstable();
    retired_components.dedup();
    let witnessed: Vec<bool> = (0..n)
        .map(|i| {
            agree
                .iter()
                .chain(&disagree)
                .any(|&(a, b)| a == i || b == i)
        })
        .collect();
    // Each sighting's component, those without a witness taking their nearest witnessed one's.
    let owner: Vec<usize> = (0..n)
        .map(|i| {
            if witnessed[i] {
                return component[i];
            }
            let nearest = (0..n)
                .filter(|&j| witnessed[j])
                .min_by_key(|&j| (i.abs_diff(j), j))
                .expect("a disagreement has witnesses");
            component[nearest]
        })
        .collect();
    // Components, largest first, each into the first group it does not disagree with.
    let mut kept: Vec<usize> = owner
        .iter()
        .copied()
        .filter(|c| !retired_components.contains(c))
        .collect();
    kept.sort_unstable();
    kept.dedup();
    let size = |c: usize| owner.iter().filter(|&&o| o == c).count();
    kept.sort_by_key(|&c| (std::cmp::Reverse(size(c)), c));
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for c in kept {
        let clash = |group: &Vec<usize>| {
            disagree.iter().any(|&(a, b)| {
                (component[a] == c && group.contains(&component[b]))
                    || (component[b] == c && group.contains(&component[a]))
            })
        };
        match groups.iter_mut().find(|g| !clash(g)) {
            Some(group) => group.push(c),
            None => groups.push(vec![c]),
        }
    }
    let stations = |pick: &dyn Fn(usize) -> bool| -> Vec<usize> {
        (0..n)
            .filter(|&i| pick(owner[i]))
            .map(|i| sightings[i].0)
            .collect()
    };
    Some(Regrouping {
        landmark,
        groups: groups
            .iter()
            .map(|g| stations(&|c| g.contains(&c)))
            .collect(),
        retired: stations(&|c| retired_components.contains(&c)),
    })
}

/// The connected component of each of `n` nodes under `edges`, as its smallest member.
fn components(n: usize, edges: &[(usize, usize)]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for &(a, b) in edges {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra.max(rb)] = ra.min(rb);
    }
    (0..n).map(|i| root(&mut parent, i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::association::Placed;
    use qrm_core::calculus::Calculus;
    use qrm_core::edc::Edc;
    use qrm_core::geometry::Point;
    use qrm_core::map::{Journal, Sighting};
    use qrm_core::measurement::{Bearing, RangeOrder, StationView};
    use std::sync::Arc;

    /// Rocks `A` and `B` (1.5 m apart, indices 0 and 1), then rocks on both sides of a drive
    /// along the x axis.
    const ROCKS: [[f64; 2]; 16] = [
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

    /// The drive, one station a metre, seeing the rocks within 8 m (bearings ±0.02 rad, exact
    /// range order, placements 0.3 m), with wrong associations injected: from x = `wrong`
    /// on, rock `A` is hidden and rock `B` is fused as landmark `A`, with no check. Returns
    /// the journal and each fused station's frame.
    fn drive(wrong: usize) -> (Journal, Vec<(usize, Frame)>) {
        let rocks: Vec<Point> = ROCKS.iter().map(|&[x, y]| Point::new(x, y)).collect();
        let mut map = qrm_core::map::Hypergraph::<Edc>::new();
        let mut journal = Journal::default();
        let mut frames = Vec::new();
        for step in 0..=24 {
            let station = Point::new(step as f64, 0.0);
            let hidden = if step >= wrong { 0 } else { 1 };
            let mut seen: Vec<usize> = (0..rocks.len())
                .filter(|&r| r != hidden && rocks[r].distance(station) <= 8.0)
                .collect();
            seen.sort_by(|&i, &j| {
                rocks[i]
                    .distance(station)
                    .total_cmp(&rocks[j].distance(station))
            });
            // Rock B is landmark A: the injected association.
            let label = |r: usize| if r == 1 { 0 } else { r as LandmarkId };
            let view = Arc::new(
                StationView::new(
                    seen.iter()
                        .map(|&r| Bearing {
                            angle: (rocks[r].y - station.y).atan2(rocks[r].x - station.x),
                            uncertainty: 0.02,
                        })
                        .collect(),
                    RangeOrder::total(&(0..seen.len()).collect::<Vec<_>>()).unwrap(),
                )
                .unwrap(),
            );
            let sightings: Vec<Sighting> = seen
                .iter()
                .enumerate()
                .map(|(k, &r)| Sighting::new(k, label(r)))
                .collect();
            map.fuse(&map.observations(&view, &sightings))
                .expect("the injected association is quiet");
            journal.record(step, view, &sightings);
            let placed = |r: usize| Placed {
                point: [rocks[r].x - station.x, rocks[r].y - station.y],
                radius: 0.3,
            };
            frames.push((
                step,
                Frame {
                    accumulated: false,
                    departed: Vec::new(),
                    landmarks: seen.iter().map(|&r| (label(r), placed(r))).collect(),
                },
            ));
        }
        (journal, frames)
    }

    /// The unsound relations of `map`, landmark `l` being rock `l` but for `b_landmark`, rock B.
    fn unsound(map: &qrm_core::map::Hypergraph<Edc>, b_landmark: Option<LandmarkId>) -> usize {
        let p = |l: LandmarkId| {
            let r = if Some(l) == b_landmark { 1 } else { l as usize };
            Point::new(ROCKS[r][0], ROCKS[r][1])
        };
        let truth = |a, b, c| Edc::classify(p(a), p(b), p(c));
        qrm_core::metrics::evaluate(map, truth, map.len()).unsound_relations
    }

    #[test]
    fn a_landmark_fused_from_two_rocks_is_split_and_the_map_made_sound_again() {
        let (journal, frames) = drive(12);
        let mixed = journal.replay::<Edc>(|_, l| Some(l));
        assert!(unsound(&mixed.map, None) > 0, "the injection is not quiet");
        let sightings: Vec<(usize, &Frame)> = frames
            .iter()
            .filter(|(_, f)| f.landmarks.iter().any(|m| m.0 == 0))
            .map(|(s, f)| (*s, f))
            .collect();
        let regrouping = regroup(0, &sightings).expect("the sightings disagree");
        // Rock A was seen up to station 11, rock B from 12 on, within 8 m.
        let a: Vec<usize> = (5..12).collect();
        let b: Vec<usize> = (12..=20).collect();
        assert_eq!(regrouping.groups, vec![b.clone(), a]);
        assert!(regrouping.retired.is_empty());
        let split = journal.replay::<Edc>(|station, l| {
            Some(if l == 0 && b.contains(&station) { 100 } else { l })
        });
        assert!(split.rejected.is_empty());
        assert_eq!(unsound(&split.map, Some(100)), 0);
    }

    #[test]
    fn sightings_of_one_rock_stay_together() {
        let (_, frames) = drive(usize::MAX);
        let sightings: Vec<(usize, &Frame)> = frames
            .iter()
            .filter(|(_, f)| f.landmarks.iter().any(|m| m.0 == 0))
            .map(|(s, f)| (*s, f))
            .collect();
        assert_eq!(regroup(0, &sightings), None);
    }

    #[test]
    fn components_join_what_agrees() {
        assert_eq!(components(5, &[(0, 1), (3, 4)]), vec![0, 0, 2, 3, 3]);
    }
}
