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

/// Association figures, given the truth rock of every `(station, detection)` matched to one.
pub(super) fn score(
    landmarks: &[LandmarkRecord],
    matched: &HashMap<(usize, usize), u32>,
) -> (AssociationScore, LandmarkRocks) {
    let mut rocks = LandmarkRocks::default();
    let mut a = AssociationScore {
        landmarks: landmarks.len(),
        ..AssociationScore::default()
    };
    for landmark in landmarks {
        let mut stations: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for s in &landmark.sightings {
            a.sightings += 1;
            match matched.get(s) {
                Some(&id) => stations.entry(id).or_default().push(s.0),
                None => a.unmatched_sightings += 1,
            }
        }
        let mut by_rock: Vec<(u32, Vec<usize>)> = stations.into_iter().collect();
        by_rock.sort_by_key(|(id, seen)| (std::cmp::Reverse(seen.len()), *id));
        if by_rock.len() > 1 {
            a.mixed_landmarks += 1;
            a.mixed.push(MixedLandmark {
                landmark: landmark.landmark,
                rocks: by_rock.clone(),
            });
        }
        if let Some((id, seen)) = by_rock.first() {
            let (id, count) = (*id, seen.len());
            a.correct_sightings += count;
            rocks.majority.insert(landmark.landmark, id);
            *rocks.landmarks_of_rock.entry(id).or_default() += 1;
        }
    }
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
        let (score, rocks) = score(&landmarks, &matched);
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
        let (score, _) = score(&landmarks, &matched);
        assert_eq!(
            (score.rocks_seen_thrice, score.rocks_seen_thrice_mapped),
            (2, 1)
        );
        assert!((score.mapped_fraction - 0.5).abs() < 1e-12);
        assert!((score.fused_fraction - 2.0 / 7.0).abs() < 1e-12);
    }
}
