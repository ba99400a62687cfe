//! The probabilistic map of 002 beside the deterministic one: every triple seen together at
//! two or more stations gets a belief over its 20 EDC states from the first few of those
//! views (002 Algorithm 1, full or fast), whoever supplies the views — the simulator
//! (`crate::simulation::beliefs`) or `pipeline run` on panoramas.
//!
//! What 002 assumes and the deterministic map does not: a motion command between two views,
//! the heading of the displacement in the earlier camera's frame ([`Heading`]). A triple's
//! views are chained through stations between which one is known. The prior is a disc of
//! [`PRIOR_RADIUS`] `|AB|` about AB's midpoint: without metric positions no box is known in
//! the frame of a triple.

use super::belief::{Belief, STATES};
use super::metrics::dmse;
use super::study::quartiles;
use super::triplet::{estimate_fast, estimate_full, Noise, Prior, View};
use crate::calculus::RelationSet;
use crate::edc::Edc;
use crate::geometry::Point;
use crate::map::{Hypergraph, LandmarkId};
use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::TAU;

/// Radius of the prior disc, in `|AB|`.
pub const PRIOR_RADIUS: f64 = 1000.0;

/// Which of 002's estimators makes the beliefs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Variant {
    Full,
    Fast,
}

impl Variant {
    /// `full` or `fast`, as in the settings of a beliefs file.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Full => "full",
            Variant::Fast => "fast",
        }
    }
}

/// How a triple's belief is estimated.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Estimator {
    pub variant: Variant,
    /// Views used per triple: the first ones that see it (002: 3 time steps).
    pub views: usize,
    pub particles: usize,
}

/// 002's motion command from one station to a later one: the heading of the displacement in
/// the earlier camera's frame (radians, the bearings' convention) and its s.d.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Heading {
    pub angle: f64,
    pub sd: f64,
}

/// Where the motion commands come from: `(from, to, rng)` for two station indices, `from`
/// earlier; `None` when the displacement is not known. `rng` is the triple's own stream, for
/// a simulator that draws the command's noise.
pub type Motions<'a> = dyn Fn(usize, usize, &mut dyn RngCore) -> Option<Heading> + Sync + 'a;

/// The belief over `AB:C` of landmarks `a < b < c` (ids), from `views` views.
#[derive(Clone, Debug, PartialEq)]
pub struct TripleBelief {
    pub ids: [LandmarkId; 3],
    pub views: usize,
    pub belief: Belief,
}

/// Every co-observed triple's belief (a triple seen at one station only gets none: 002 needs
/// two views to resect `C`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BeliefMap {
    pub triples: Vec<TripleBelief>,
    /// Triples seen together at two or more stations: those without a belief had no two
    /// views linked by a motion command.
    pub seen_twice: usize,
}

/// The beliefs of every triple seen together at two or more of `stations` (each: landmark →
/// bearing relative to the camera's heading, radians), bearings of s.d. `bearing_sd`.
///
/// A triple's views are the first stations that see it in which each next one is reached
/// from the one before by a known [`Heading`] (up to `estimator.views`); its motion noise is
/// the largest s.d. along that chain. Reproducible from `seed`: each triple draws from its
/// own stream.
pub fn beliefs(
    stations: &[BTreeMap<LandmarkId, f64>],
    motions: &Motions,
    bearing_sd: f64,
    estimator: &Estimator,
    seed: u64,
) -> BeliefMap {
    let mut seen_at: BTreeMap<[LandmarkId; 3], Vec<usize>> = BTreeMap::new();
    for (s, station) in stations.iter().enumerate() {
        let ids: Vec<LandmarkId> = station.keys().copied().collect();
        for i in 0..ids.len() {
            for j in i + 1..ids.len() {
                for k in j + 1..ids.len() {
                    seen_at.entry([ids[i], ids[j], ids[k]]).or_default().push(s);
                }
            }
        }
    }
    let seen_twice: Vec<([LandmarkId; 3], Vec<usize>)> = seen_at
        .into_iter()
        .filter(|(_, at)| at.len() >= 2)
        .collect();
    let count = seen_twice.len();
    let triples: Vec<TripleBelief> = seen_twice
        .into_par_iter()
        .filter_map(|(ids, at)| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xbe11ef);
            let stream = ids.iter().fold(0u64, |h, &id| {
                h.wrapping_mul(1_000_003).wrapping_add(u64::from(id))
            });
            rng.set_stream(stream);
            let mut chain: Vec<usize> = vec![at[0]];
            let mut views = vec![View {
                bearings: ids.map(|id| stations[at[0]][&id]),
                motion: None,
            }];
            let mut motion_sd = 0.0f64;
            for &s in &at[1..] {
                if views.len() == estimator.views {
                    break;
                }
                let Some(heading) = motions(*chain.last().expect("one view"), s, &mut rng) else {
                    continue;
                };
                motion_sd = motion_sd.max(heading.sd);
                chain.push(s);
                views.push(View {
                    bearings: ids.map(|id| stations[s][&id]),
                    motion: Some(heading.angle),
                });
            }
            if views.len() < 2 {
                return None;
            }
            let prior = disc_prior();
            let noise = Noise {
                bearing: bearing_sd,
                motion: motion_sd,
            };
            let estimate = match estimator.variant {
                Variant::Full => {
                    estimate_full(&views, &prior, noise, estimator.particles, &mut rng)
                }
                Variant::Fast => {
                    estimate_fast(&views, &prior, noise, estimator.particles, &mut rng)
                }
            }?;
            Some(TripleBelief {
                ids,
                views: views.len(),
                belief: estimate.landmark,
            })
        })
        .collect();
    BeliefMap {
        triples,
        seen_twice: count,
    }
}

/// The prior: a 32-gon of radius [`PRIOR_RADIUS`] about AB's midpoint.
fn disc_prior() -> Prior {
    Prior {
        polygon: (0..32)
            .map(|k| {
                let t = TAU * f64::from(k) / 32.0;
                Point::new(PRIOR_RADIUS * t.cos(), 0.5 + PRIOR_RADIUS * t.sin())
            })
            .collect(),
    }
}

/// What [`conditioned`] adds to every state of the deterministic set: finite particles can
/// miss a state that sound constraints still allow.
pub const FLOOR: f64 = 1e-3;

/// The probabilistic map's belief of a relation: the estimate restricted to the deterministic
/// map's `set` (sound within the sensor's error model), [`FLOOR`] added to each state of the
/// set, renormalized. Its support is exactly `set`: the set view of the probabilistic
/// map is the deterministic map, and the belief ranks its states. An empty set (which a
/// consistent map never holds) gives the estimate unchanged.
pub fn conditioned(belief: &Belief, set: RelationSet) -> Belief {
    let mut weights = [0.0; STATES];
    for r in set.iter() {
        weights[r as usize - 1] = belief.probability(r) + FLOOR;
    }
    Belief::from_weights(weights).unwrap_or(*belief)
}

/// How the beliefs and the deterministic map's sets compare with the truth, over the triples
/// that have a belief and a known true state.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BeliefComparison {
    pub triples: usize,
    /// The truth is the most likely state.
    pub truth_most_likely: usize,
    /// The truth has positive belief (the belief's support, as a set, is sound).
    pub truth_in_support: usize,
    /// Median DMSE of the beliefs.
    pub median_dmse: f64,
    /// The deterministic map's relation holds the truth (sound).
    pub truth_in_set: usize,
    /// Mean number of states in the deterministic relation, and in the belief's support.
    pub mean_set_size: f64,
    pub mean_support_size: f64,
    /// The belief's most likely state lies in the deterministic relation.
    pub most_likely_in_set: usize,
    /// Beliefs conditioned on the deterministic map (restricted to its set, renormalized):
    /// the truth is then the most likely state.
    pub conditioned_truth_most_likely: usize,
}

/// Compares `beliefs` and the deterministic `map` with `truth`, the true `AB:C` of landmarks
/// `[a, b, c]` (`None`: unknown, the triple is not counted).
pub fn compare(
    beliefs: &BeliefMap,
    map: &Hypergraph<Edc>,
    truth: &dyn Fn([LandmarkId; 3]) -> Option<u8>,
) -> BeliefComparison {
    let mut c = BeliefComparison::default();
    let mut dmses = Vec::new();
    let (mut set_sizes, mut support_sizes) = (0usize, 0usize);
    for t in &beliefs.triples {
        let Some(truth) = truth(t.ids) else {
            continue;
        };
        let set = map
            .relation(t.ids[0], t.ids[1], t.ids[2])
            .unwrap_or_else(|| RelationSet::all(STATES));
        c.triples += 1;
        let top = t.belief.most_likely();
        c.truth_most_likely += usize::from(top == truth);
        c.truth_in_support += usize::from(t.belief.probability(truth) > 0.0);
        c.truth_in_set += usize::from(set.contains(truth));
        c.most_likely_in_set += usize::from(set.contains(top));
        c.conditioned_truth_most_likely +=
            usize::from(conditioned(&t.belief, set).most_likely() == truth);
        set_sizes += set.len();
        support_sizes += t.belief.support().len();
        dmses.push(dmse(&t.belief, truth));
    }
    if c.triples > 0 {
        c.mean_set_size = set_sizes as f64 / c.triples as f64;
        c.mean_support_size = support_sizes as f64 / c.triples as f64;
        c.median_dmse = quartiles(&mut dmses)[1];
    }
    c
}

/// A beliefs file that cannot be read.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("not a qrm-beliefs file (version 1): {0}")]
pub struct BeliefsFileError(String);

impl BeliefMap {
    /// Reads [`BeliefMap::to_json`]'s output back (`seen_twice` is not in the file: 0).
    pub fn from_json(text: &str) -> Result<BeliefMap, BeliefsFileError> {
        #[derive(serde::Deserialize)]
        struct File {
            format: String,
            version: u32,
            triples: Vec<Entry>,
        }
        #[derive(serde::Deserialize)]
        struct Entry {
            a: LandmarkId,
            b: LandmarkId,
            c: LandmarkId,
            views: usize,
            ab_c: Vec<f64>,
        }
        let file: File = serde_json::from_str(text).map_err(|e| BeliefsFileError(e.to_string()))?;
        if file.format != "qrm-beliefs" || file.version != 1 {
            return Err(BeliefsFileError(format!(
                "format {:?} version {}",
                file.format, file.version
            )));
        }
        let triples = file
            .triples
            .into_iter()
            .map(|e| {
                let weights: [f64; STATES] = e.ab_c.as_slice().try_into().map_err(|_| {
                    BeliefsFileError(format!(
                        "triple {} {} {} has {} probabilities, not {STATES}",
                        e.a,
                        e.b,
                        e.c,
                        e.ab_c.len()
                    ))
                })?;
                let belief = Belief::from_weights(weights).ok_or_else(|| {
                    BeliefsFileError(format!(
                        "triple {} {} {}: probabilities must be non-negative, not all 0",
                        e.a, e.b, e.c
                    ))
                })?;
                Ok(TripleBelief {
                    ids: [e.a, e.b, e.c],
                    views: e.views,
                    belief,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(BeliefMap {
            triples,
            seen_twice: 0,
        })
    }

    /// The beliefs as JSON (docs/MAP_FORMAT.md, "Beliefs"): per triple `a < b < c`, the
    /// number of views and `P(AB:C = r)` for r = 1..=20; `settings` says how they were made.
    pub fn to_json(&self, settings: &impl serde::Serialize) -> String {
        let triples: Vec<serde_json::Value> = self
            .triples
            .iter()
            .map(|t| {
                serde_json::json!({
                    "a": t.ids[0], "b": t.ids[1], "c": t.ids[2],
                    "views": t.views,
                    "ab_c": t.belief.probabilities(),
                })
            })
            .collect();
        let value = serde_json::json!({
            "format": "qrm-beliefs",
            "version": 1,
            "calculus": "EDC",
            "settings": settings,
            "triples": triples,
        });
        serde_json::to_string_pretty(&value).expect("JSON values serialise") + "\n"
    }
}

#[cfg(test)]
mod tests {
    use super::super::triplet::angle_to;
    use super::*;
    use crate::edc;

    /// Four landmarks seen from three stations with exact bearings (cameras facing +x).
    fn stations() -> (Vec<Point>, Vec<Point>, Vec<BTreeMap<LandmarkId, f64>>) {
        let landmarks = vec![
            Point::new(0.0, 0.0),
            Point::new(1.0, 3.0),
            Point::new(-2.0, 2.5),
            Point::new(2.5, 1.0),
        ];
        let at = vec![
            Point::new(-1.5, -3.0),
            Point::new(3.0, -2.0),
            Point::new(4.0, 4.0),
        ];
        let seen = at
            .iter()
            .map(|x| {
                (0..landmarks.len() as LandmarkId)
                    .map(|id| (id, angle_to(*x, landmarks[id as usize])))
                    .collect()
            })
            .collect();
        (landmarks, at, seen)
    }

    #[test]
    fn views_are_chained_only_through_known_motions() {
        let (landmarks, at, seen) = stations();
        let estimator = Estimator {
            variant: Variant::Fast,
            views: 3,
            particles: 4000,
        };
        // Only the displacement from station 0 to station 2 is known.
        let motions = |from: usize, to: usize, _: &mut dyn RngCore| {
            ((from, to) == (0, 2)).then(|| Heading {
                angle: angle_to(at[0], at[2]),
                sd: 0.01,
            })
        };
        let map = beliefs(&seen, &motions, 0.2f64.to_radians(), &estimator, 5);
        assert_eq!(map.seen_twice, 4);
        assert_eq!(map.triples.len(), 4);
        for t in &map.triples {
            assert_eq!(t.views, 2, "stations 0 and 2 only");
            // Two views leave the first pose free along its locus (C's two rays always
            // meet): the truth is possible, not necessarily first.
            let [a, b, c] = t.ids.map(|id| landmarks[id as usize]);
            assert!(t.belief.probability(edc::classify(a, b, c).unwrap()) > 0.0);
        }
        let none = beliefs(&seen, &|_, _, _| None, 0.01, &estimator, 5);
        assert_eq!((none.seen_twice, none.triples.len()), (4, 0));
    }

    #[test]
    fn beliefs_files_read_back() {
        let (_, at, seen) = stations();
        let estimator = Estimator {
            variant: Variant::Fast,
            views: 3,
            particles: 100,
        };
        let motions = |from: usize, to: usize, _: &mut dyn RngCore| {
            Some(Heading {
                angle: angle_to(at[from], at[to]),
                sd: 0.01,
            })
        };
        let map = beliefs(&seen, &motions, 0.01, &estimator, 1);
        let read = BeliefMap::from_json(&map.to_json(&estimator)).unwrap();
        assert_eq!(read.triples.len(), map.triples.len());
        for (r, m) in read.triples.iter().zip(&map.triples) {
            assert_eq!((r.ids, r.views), (m.ids, m.views));
            for (p, q) in r
                .belief
                .probabilities()
                .iter()
                .zip(m.belief.probabilities())
            {
                assert!((p - q).abs() < 1e-12);
            }
        }
        for bad in [
            r#"{"format": "qrm-map", "version": 1, "triples": []}"#,
            r#"{"format": "qrm-beliefs", "version": 1, "triples": [{"a": 0, "b": 1, "c": 2, "views": 2, "ab_c": [1.0]}]}"#,
            "[",
        ] {
            assert!(BeliefMap::from_json(bad).is_err(), "{bad}");
        }
    }
}
