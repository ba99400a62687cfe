//! Scoring association: each landmark stands for the rock most of its sightings show.

use super::detection::ratio;
use super::{AssociationScore, MixedLandmark};
use qrm_core::map::LandmarkId;
use qrm_vision::run::LandmarkRecord;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Which truth rock each landmark stands for.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct LandmarkRocks {
    majority: HashMap<LandmarkId, u32>,
    landmarks_of_rock: HashMap<u32, usize>,
}

impl LandmarkRocks {
    /// The rock most of the landmark's sightings show.
    pub fn majority(&self, l: LandmarkId) -> Option<u32> {
        self.majority.get(&l).copied()
    }

    /// Every landmark's rock.
    pub fn all(&self) -> BTreeMap<LandmarkId, u32> {
        self.majority.iter().map(|(&l, &r)| (l, r)).collect()
    }

    /// The landmark's rock if no other landmark stands for it: the landmarks with a truth.
    pub fn defined(&self, l: LandmarkId) -> Option<u32> {
        self.majority(l)
            .filter(|r| self.landmarks_of_rock.get(r) == Some(&1))
    }
}

/// Association figures, given the truth rock of every `(station, detection)` matched to one
/// and the other rocks a matched detection also shows (`detection::also_shown`).
pub(super) fn score(
    landmarks: &[LandmarkRecord],
    matched: &HashMap<(usize, usize), u32>,
    also_shows: &HashMap<(usize, usize), Vec<u32>>,
) -> (AssociationScore, LandmarkRocks) {
    let mut rocks = LandmarkRocks::default();
    let mut a = AssociationScore {
        landmarks: landmarks.len(),
        ..AssociationScore::default()
    };
    let mut correct_by_centroid = 0;
    for landmark in landmarks {
        a.sightings += landmark.sightings.len();
        let shown: Vec<((usize, usize), u32)> = landmark
            .sightings
            .iter()
            .filter_map(|s| matched.get(s).map(|&id| (*s, id)))
            .collect();
        a.unmatched_sightings += landmark.sightings.len() - shown.len();
        let credited = credited_counts(&shown);
        let Some(rock) = landmark_rock(&shown, &credited, also_shows) else {
            continue;
        };
        correct_by_centroid += credited.values().copied().max().unwrap_or(0);
        let mut stations: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for &(s, id) in &shown {
            let shows = id == rock || also_shows.get(&s).is_some_and(|r| r.contains(&rock));
            if shows && id != rock {
                a.credited_by_measurement += 1;
            }
            stations
                .entry(if shows { rock } else { id })
                .or_default()
                .push(s.0);
        }
        let mut by_rock: Vec<(u32, Vec<usize>)> = stations.into_iter().collect();
        by_rock.sort_by_key(|(id, seen)| (*id != rock, std::cmp::Reverse(seen.len()), *id));
        if by_rock.len() > 1 {
            a.mixed_landmarks += 1;
            a.mixed.push(MixedLandmark {
                landmark: landmark.landmark,
                rocks: by_rock.clone(),
            });
        }
        a.correct_sightings += by_rock[0].1.len();
        rocks.majority.insert(landmark.landmark, rock);
        *rocks.landmarks_of_rock.entry(rock).or_default() += 1;
    }
    a.purity_nearest_centroid = ratio(correct_by_centroid, a.sightings - a.unmatched_sightings);
    a.duplicated_rocks = rocks.landmarks_of_rock.values().filter(|&&n| n > 1).count();
    a.accuracy = ratio(a.correct_sightings, a.sightings);
    a.purity = ratio(a.correct_sightings, a.sightings - a.unmatched_sightings);
    a.fused_fraction = ratio(a.correct_sightings, matched.len());
    let mut stations_of_rock: HashMap<u32, BTreeSet<usize>> = HashMap::new();
    for (&(station, _), &rock) in matched {
        stations_of_rock.entry(rock).or_default().insert(station);
    }
    let thrice: Vec<u32> = stations_of_rock
        .into_iter()
        .filter(|(_, stations)| stations.len() >= 3)
        .map(|(rock, _)| rock)
        .collect();
    a.rocks_seen_thrice = thrice.len();
    a.rocks_seen_thrice_mapped = thrice
        .iter()
        .filter(|r| rocks.landmarks_of_rock.contains_key(r))
        .count();
    a.mapped_fraction = ratio(a.rocks_seen_thrice_mapped, a.rocks_seen_thrice);
    (a, rocks)
}

/// How many of `shown` (sighting, credited rock) each rock is credited with.
fn credited_counts(shown: &[((usize, usize), u32)]) -> BTreeMap<u32, usize> {
    let mut counts = BTreeMap::new();
    for &(_, id) in shown {
        *counts.entry(id).or_default() += 1;
    }
    counts
}

/// The rock a landmark stands for: the one the most of its sightings show, credited with it or
/// also showing it (a blob over touching rocks, stress clusters: the map's relations of the
/// landmark hold for the rock its measurements hold); among as many, the one credited with
/// more (`credited`, by [`credited_counts`]), then the lowest id.
fn landmark_rock(
    shown: &[((usize, usize), u32)],
    credited: &BTreeMap<u32, usize>,
    also_shows: &HashMap<(usize, usize), Vec<u32>>,
) -> Option<u32> {
    let mut showing: BTreeMap<u32, usize> = BTreeMap::new();
    for &(s, id) in shown {
        *showing.entry(id).or_default() += 1;
        for &other in also_shows.get(&s).into_iter().flatten() {
            *showing.entry(other).or_default() += 1;
        }
    }
    showing
        .into_iter()
        .max_by_key(|&(id, n)| {
            (
                n,
                credited.get(&id).copied().unwrap_or(0),
                std::cmp::Reverse(id),
            )
        })
        .map(|(id, _)| id)
}

#[cfg(test)]
mod tests {
    use super::*;
    use qrm_vision::association::Profile;
    use qrm_vision::detection::Appearance;

    fn landmark(landmark: LandmarkId, sightings: &[(usize, usize)]) -> LandmarkRecord {
        LandmarkRecord {
            landmark,
            sightings: sightings.to_vec(),
            profile: Profile {
                landmark,
                appearance: Appearance {
                    colour: [0.4, 0.33, 0.27],
                    brightness: 1.0,
                    texture: 0.2,
                    dark_fraction: 0.1,
                },
                width: None,
                sightings: sightings.len() as u32,
            },
        }
    }

    #[test]
    fn a_mixed_landmark_lists_the_stations_of_each_rock_majority_first() {
        // Landmark 0 is rock 7 at stations 0–2 and rock 9 at station 5; landmark 1 is rock 8.
        let matched: HashMap<(usize, usize), u32> = [
            ((0, 0), 7),
            ((1, 0), 7),
            ((2, 1), 7),
            ((5, 3), 9),
            ((0, 1), 8),
            ((1, 1), 8),
        ]
        .into_iter()
        .collect();
        let landmarks = [
            landmark(0, &[(0, 0), (1, 0), (5, 3), (2, 1)]),
            landmark(1, &[(0, 1), (1, 1), (4, 2)]),
        ];
        let (score, rocks) = score(&landmarks, &matched, &HashMap::new());
        assert_eq!(score.mixed_landmarks, 1);
        assert_eq!(
            score.mixed,
            vec![MixedLandmark {
                landmark: 0,
                rocks: vec![(7, vec![0, 1, 2]), (9, vec![5])],
            }]
        );
        assert_eq!((score.correct_sightings, score.unmatched_sightings), (5, 1));
        // 7 sightings: the false detection lowers accuracy, not purity.
        assert!((score.accuracy - 5.0 / 7.0).abs() < 1e-12);
        assert!((score.purity - 5.0 / 6.0).abs() < 1e-12);
        assert_eq!((rocks.majority(0), rocks.majority(1)), (Some(7), Some(8)));
        // 5 of the 6 detections of rocks reached their rock's landmark; rock 7 alone was
        // detected at three stations, and landmark 0 stands for it.
        assert!((score.fused_fraction - 5.0 / 6.0).abs() < 1e-12);
        assert_eq!(
            (score.rocks_seen_thrice, score.rocks_seen_thrice_mapped),
            (1, 1)
        );
    }

    #[test]
    fn a_rock_seen_thrice_without_a_landmark_of_its_own_is_not_mapped() {
        // Rock 3 is detected at stations 0, 1 and 2, but its only sighting went to landmark 0,
        // which stands for rock 4.
        let matched: HashMap<(usize, usize), u32> = [
            ((0, 0), 3),
            ((1, 0), 3),
            ((2, 0), 3),
            ((0, 1), 4),
            ((1, 1), 4),
            ((2, 1), 4),
            ((3, 1), 4),
        ]
        .into_iter()
        .collect();
        let landmarks = [landmark(0, &[(0, 1), (1, 1), (2, 0)])];
        let (score, _) = score(&landmarks, &matched, &HashMap::new());
        assert_eq!(
            (score.rocks_seen_thrice, score.rocks_seen_thrice_mapped),
            (2, 1)
        );
        assert!((score.mapped_fraction - 0.5).abs() < 1e-12);
        assert!((score.fused_fraction - 2.0 / 7.0).abs() < 1e-12);
    }

    #[test]
    fn a_blob_over_touching_rocks_counts_for_the_rock_of_its_landmark_its_measurement_holds() {
        // Landmark 0 is a blob over rocks 7 and 17: credited with 17 at stations 2, 3, 4 and 6,
        // with 7 (the nearer centroid) at stations 0, 1 and 5, though at 0 and 1 its
        // measurement holds 17 too; at station 5 it does not. At station 3 it holds 7 as well,
        // so 7 is shown 4 times and 17 6 times: the landmark stands for 17.
        let matched: HashMap<(usize, usize), u32> = [
            ((0, 0), 7),
            ((1, 0), 7),
            ((2, 0), 17),
            ((3, 0), 17),
            ((4, 0), 17),
            ((5, 0), 7),
            ((6, 0), 17),
        ]
        .into_iter()
        .collect();
        let also: HashMap<(usize, usize), Vec<u32>> =
            [((0, 0), vec![17]), ((1, 0), vec![9, 17]), ((3, 0), vec![7])]
                .into_iter()
                .collect();
        let sightings = [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (5, 0), (6, 0)];
        let (score, rocks) = score(&[landmark(0, &sightings)], &matched, &also);
        assert_eq!(rocks.majority(0), Some(17));
        assert_eq!(score.correct_sightings, 6);
        assert_eq!(score.credited_by_measurement, 2);
        assert!((score.purity - 6.0 / 7.0).abs() < 1e-12);
        assert!((score.purity_nearest_centroid - 4.0 / 7.0).abs() < 1e-12);
        assert_eq!(
            score.mixed,
            vec![MixedLandmark {
                landmark: 0,
                rocks: vec![(17, vec![0, 1, 2, 3, 4, 6]), (7, vec![5])],
            }]
        );
    }

    /// A blob over three touching rocks whose credited rock changes with the viewpoint, and
    /// whose every measurement holds the middle one: the landmark stands for the middle rock.
    #[test]
    fn a_landmark_stands_for_the_rock_most_of_its_measurements_hold() {
        let matched: HashMap<(usize, usize), u32> = [
            ((0, 0), 20),
            ((1, 0), 20),
            ((2, 0), 20),
            ((3, 0), 1),
            ((4, 0), 1),
            ((5, 0), 3),
        ]
        .into_iter()
        .collect();
        let also: HashMap<(usize, usize), Vec<u32>> =
            (0..5).map(|station| ((station, 0), vec![3])).collect();
        let sightings = [(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (5, 0)];
        let (score, rocks) = score(&[landmark(0, &sightings)], &matched, &also);
        assert_eq!(rocks.majority(0), Some(3));
        assert_eq!(
            (score.correct_sightings, score.credited_by_measurement),
            (6, 5)
        );
        assert!((score.purity - 1.0).abs() < 1e-12);
        assert!((score.purity_nearest_centroid - 0.5).abs() < 1e-12);
        assert_eq!(score.mixed_landmarks, 0);
    }
}
