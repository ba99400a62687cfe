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
/// others they agree with: no rock can be told for them; or an outlier alone, `outliers`).
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
/// disagrees with every group so far starts another. A set that disagrees with itself leaves
/// the map, or only its outliers do, when it has them (`outliers`). A sighting no other
/// station can witness goes with the nearest one in time that is witnessed: association
/// tracked it from there.
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
    let outliers = outliers(&components(n, &agree), &disagree);
    let agree: Vec<(usize, usize)> = agree
        .into_iter()
        .filter(|(a, b)| !outliers.contains(a) && !outliers.contains(b))
        .collect();
    let component = components(n, &agree);
    let split = |a: usize, b: usize| component[a] == component[b];
    let mut retired_components: Vec<usize> = disagree
        .iter()
        .filter(|&&(a, b)| split(a, b))
        .map(|&(a, _)| component[a])
        .chain(outliers.iter().map(|&o| component[o]))
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

/// The sightings (indices) retired alone from their group (`component`, under agreement)
/// rather than with it: the one that takes part in every disagreement inside the group, when
/// there are several, or both sightings of the group's only disagreement. One sighting that
/// disagrees with several others that agree with each other is what is wrong. Retiring whole
/// groups threw away far more right sightings than wrong ones: over the 25 sets of stop 67,
/// marsyard seed 3's landmark 1 lost 44 stations' sightings of rock 19 for one sighting
/// (station 21) that three others disagreed with; grayscale marsyard seed 3's landmark 8, 8 of
/// rock 28 for the one of rock 1. In three of the four such groups the outlier was the wrong
/// sighting (a 26 000-pixel blob of shadow under rock 19 recognised as its landmark, rock 1's
/// sighting, a blob over three rocks), in the fourth a small far sighting of the right rock.
/// A single disagreement says nothing of which side is wrong, so both leave. At stop 67 the
/// group left with them (in 5 of 8 such groups the two sightings were of different rocks,
/// with up to 7 more wrong sightings that agreed with the rest); by stop 82 association mixed
/// far less, and 13 of the 18 landmarks retired whole over 53 sets held one rock only (colour
/// marsyard s67: 16 sightings of rock 14 for one disagreement against 119 agreements).
/// Retiring the pair alone raised the fused share of 10 of 53 sets by 0.4–5.2 points with no
/// relation unsound (docs/RUN.md, stop 82).
fn outliers(component: &[usize], disagree: &[(usize, usize)]) -> Vec<usize> {
    let mut groups: Vec<usize> = disagree
        .iter()
        .filter(|&&(a, b)| component[a] == component[b])
        .map(|&(a, _)| component[a])
        .collect();
    groups.sort_unstable();
    groups.dedup();
    groups
        .into_iter()
        .flat_map(|c| {
            let inside: Vec<(usize, usize)> = disagree
                .iter()
                .copied()
                .filter(|&(a, _)| component[a] == c)
                .filter(|&(a, b)| component[a] == component[b])
                .collect();
            let (a, b) = inside[0];
            if inside.len() == 1 {
                return vec![a, b];
            }
            [a, b]
                .into_iter()
                .find(|&x| inside.iter().all(|&(p, q)| p == x || q == x))
                .into_iter()
                .collect()
        })
        .collect()
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
    use super::super::test_drive::{seen, unsound, A, B, STATIONS};
    use super::super::Placed;
    use super::*;
    use qrm_core::edc::Edc;
    use qrm_core::map::Journal;
    use std::sync::Arc;

    /// The test drive with rock `B` fused as landmark `A` from station `wrong` on, unchecked:
    /// the journal and each station's frame.
    fn drive(wrong: usize) -> (Journal, Vec<(usize, Frame)>) {
        let mut map = qrm_core::map::Hypergraph::<Edc>::new();
        let mut journal = Journal::default();
        let mut frames = Vec::new();
        let label = |r: usize| {
            if r == B {
                A as LandmarkId
            } else {
                r as LandmarkId
            }
        };
        for step in 0..STATIONS {
            let seen = seen(step, wrong);
            let sightings = seen.sightings(label);
            map.fuse(&map.observations(&seen.view, &sightings))
                .expect("the injected association is quiet");
            journal.record(step, Arc::new(seen.view.clone()), &sightings);
            frames.push((step, seen.frame(label)));
        }
        (journal, frames)
    }

    fn sightings_of(landmark: LandmarkId, frames: &[(usize, Frame)]) -> Vec<(usize, &Frame)> {
        frames
            .iter()
            .filter(|(_, f)| f.landmarks.iter().any(|m| m.0 == landmark))
            .map(|(s, f)| (*s, f))
            .collect()
    }

    #[test]
    fn a_landmark_fused_from_two_rocks_is_split_and_the_map_made_sound_again() {
        let (journal, frames) = drive(12);
        let mixed = journal.replay::<Edc>(|_, l| Some(l));
        assert!(
            unsound(&mixed.map, |l| l as usize) > 0,
            "the injection is not quiet"
        );
        let regrouping = regroup(0, &sightings_of(0, &frames)).expect("the sightings disagree");
        // Rock A was seen up to station 11, rock B from 12 on, within 8 m.
        let a: Vec<usize> = (5..12).collect();
        let b: Vec<usize> = (12..=20).collect();
        assert_eq!(regrouping.groups, vec![b.clone(), a]);
        assert!(regrouping.retired.is_empty());
        let split = journal.replay::<Edc>(|station, l| {
            Some(if l == 0 && b.contains(&station) {
                100
            } else {
                l
            })
        });
        assert!(split.rejected.is_empty());
        let rock_of = |l: LandmarkId| if l == 100 { B } else { l as usize };
        assert_eq!(unsound(&split.map, rock_of), 0);
    }

    #[test]
    fn sightings_of_one_rock_stay_together() {
        let (_, frames) = drive(usize::MAX);
        assert_eq!(regroup(0, &sightings_of(0, &frames)), None);
    }

    /// Stations 8–12 seeing rock A, each station's frame placing it as `placed` says from its
    /// true place (`[x, y]`, station coordinates).
    fn rock_a_placed(placed: impl Fn(usize, [f64; 2]) -> Placed) -> Vec<(usize, Frame)> {
        (8..=12)
            .map(|step| {
                let mut frame = seen(step, usize::MAX).frame(|r| r as LandmarkId);
                let a = frame
                    .landmarks
                    .iter_mut()
                    .find(|m| m.0 == A as LandmarkId)
                    .expect("rock A within 8 m");
                a.1 = placed(step, a.1.point);
                (step, frame)
            })
            .collect()
    }

    /// Station 10 places rock A 1 m off: near enough to agree with the loose placements of
    /// stations 8 and 9, too far for the tight ones of 11 and 12, which agree with 8 and 9.
    /// Station 10's sighting alone takes part in both disagreements, and leaves the map
    /// alone; the others keep the landmark.
    #[test]
    fn one_sighting_that_several_disagree_with_is_retired_alone() {
        let frames = rock_a_placed(|step, [x, y]| match step {
            8 | 9 => Placed::disc([x, y], 1.2),
            10 => Placed::disc([x, y + 1.0], 0.3),
            _ => Placed::disc([x, y], 0.2),
        });
        let regrouping = regroup(A as LandmarkId, &sightings_of(A as LandmarkId, &frames))
            .expect("10 disagrees");
        assert_eq!(regrouping.retired, vec![10]);
        assert_eq!(regrouping.groups, vec![vec![8, 9, 11, 12]]);
    }

    /// Station 10 places rock A 1 m off again, now with station 11's placement loose as well:
    /// only station 12's disagrees with it. The group's only disagreement cannot say which of
    /// 10 and 12 is wrong; both leave the map, and the others keep the landmark.
    #[test]
    fn the_two_sightings_of_a_groups_only_disagreement_are_retired_alone() {
        let frames = rock_a_placed(|step, [x, y]| match step {
            10 => Placed::disc([x, y + 1.0], 0.3),
            12 => Placed::disc([x, y], 0.2),
            _ => Placed::disc([x, y], 1.2),
        });
        let regrouping = regroup(A as LandmarkId, &sightings_of(A as LandmarkId, &frames))
            .expect("10 and 12 disagree");
        assert_eq!(regrouping.retired, vec![10, 12]);
        assert_eq!(regrouping.groups, vec![vec![8, 9, 11]]);
    }

    #[test]
    fn outliers_take_part_in_every_disagreement_of_their_group() {
        // Nodes 0–4 agree; 2 disagrees with 0 and 4; 5 and 6 agree and disagree once.
        let component = [0, 0, 0, 0, 0, 5, 5];
        assert_eq!(
            outliers(&component, &[(0, 2), (2, 4), (5, 6)]),
            vec![2, 5, 6]
        );
        assert_eq!(outliers(&component, &[(0, 2), (1, 4)]), Vec::<usize>::new());
        assert_eq!(outliers(&component, &[(0, 2)]), vec![0, 2]);
    }

    #[test]
    fn components_join_what_agrees() {
        assert_eq!(components(5, &[(0, 1), (3, 4)]), vec![0, 0, 2, 3, 3]);
    }
}
