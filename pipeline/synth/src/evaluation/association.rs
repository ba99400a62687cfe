//! Scoring association: each landmark stands for the rock most of its sightings show.

use super::detection::ratio;
use super::AssociationScore;
use qrm_core::map::LandmarkId;
use qrm_vision::run::LandmarkRecord;
use std::collections::{BTreeMap, HashMap};

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

/// Association figures, given the truth rock of every matched `(station, detection)`.
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
        let mut votes: HashMap<u32, usize> = HashMap::new();
        for s in &landmark.sightings {
            a.sightings += 1;
            match matched.get(s) {
                Some(&id) => *votes.entry(id).or_default() += 1,
                None => a.unmatched_sightings += 1,
            }
        }
        if votes.len() > 1 {
            a.mixed_landmarks += 1;
        }
        if let Some((&id, &count)) = votes
            .iter()
            .max_by_key(|(id, c)| (**c, std::cmp::Reverse(**id)))
        {
            a.correct_sightings += count;
            rocks.majority.insert(landmark.landmark, id);
            *rocks.landmarks_of_rock.entry(id).or_default() += 1;
        }
    }
    a.duplicated_rocks = rocks.landmarks_of_rock.values().filter(|&&n| n > 1).count();
    a.accuracy = ratio(a.correct_sightings, a.sightings);
    (a, rocks)
}
