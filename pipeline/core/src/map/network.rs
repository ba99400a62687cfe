//! Constraint networks from outside, as a SparQ user has them for `a-closure`: relations on
//! landmark triples, not yet closed. [`Network::close`] closes one into a map (the unary
//! operators and full path consistency, as fusing does); when closing finds it inconsistent,
//! [`Network::minimal_conflict`] names a smallest set of its constraints that closing finds
//! inconsistent on its own: every proper subset of it closes.
//!
//! The text format (`docs/MAP_FORMAT.md`): one constraint `A B C {r,…}` per line (`AB:C` is one
//! of the relations), landmark ids as non-negative integers, `#` starts a comment.

use super::json::{parse_entries, MapFormatError};
use super::{Contradiction, Hypergraph, LandmarkId, Observation};
use crate::calculus::{Calculus, RelationSet};
use std::marker::PhantomData;
use thiserror::Error;

/// A constraint network over landmarks, in the order they were listed.
#[derive(Clone, Debug, PartialEq)]
pub struct Network<C: Calculus> {
    pub landmarks: Vec<LandmarkId>,
    pub constraints: Vec<Observation>,
    calculus: PhantomData<fn() -> C>,
}

/// A line of a text network that is not a constraint.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("line {line}: {reason}")]
pub struct NetworkTextError {
    pub line: usize,
    pub reason: String,
}

impl<C: Calculus> Network<C> {
    pub fn new(landmarks: Vec<LandmarkId>, constraints: Vec<Observation>) -> Network<C> {
        Network {
            landmarks,
            constraints,
            calculus: PhantomData,
        }
    }

    /// A map file (`Hypergraph::to_json`'s format) read as constraints, closed or not: each
    /// triple's three relations that are not the universe.
    pub fn from_json(text: &str) -> Result<Network<C>, MapFormatError> {
        let (landmarks, entries) = parse_entries::<C>(text)?;
        let universe = C::universe();
        let constraints = entries
            .into_iter()
            .flat_map(|([a, b, c], [ab_c, bc_a, ca_b])| {
                [
                    Observation::new(a, b, c, ab_c),
                    Observation::new(b, c, a, bc_a),
                    Observation::new(c, a, b, ca_b),
                ]
            })
            .filter(|o| o.states != universe)
            .collect();
        Ok(Network::new(landmarks, constraints))
    }

    /// The text format: `A B C {r,…}` per line.
    pub fn from_text(text: &str) -> Result<Network<C>, NetworkTextError> {
        let universe = C::universe();
        let mut landmarks: Vec<LandmarkId> = Vec::new();
        let mut constraints = Vec::new();
        for (n, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let bad = |reason: String| NetworkTextError {
                line: n + 1,
                reason,
            };
            let mut parts = line.splitn(4, char::is_whitespace);
            let mut id = |what: &str| -> Result<LandmarkId, NetworkTextError> {
                let part = parts.next().unwrap_or("");
                part.parse().map_err(|_| {
                    bad(format!(
                        "{what} {part:?} is not a landmark id (a non-negative integer)"
                    ))
                })
            };
            let ids = [id("A")?, id("B")?, id("C")?];
            let states: RelationSet = parts
                .next()
                .unwrap_or("")
                .trim()
                .parse()
                .map_err(|e| bad(format!("{e}")))?;
            if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
                return Err(bad("the three landmarks are not distinct".into()));
            }
            if states.is_empty() {
                return Err(bad(
                    "the relation set is empty: the network is inconsistent as written".into(),
                ));
            }
            if !states.is_subset(universe) {
                return Err(bad(format!(
                    "{states} names a relation outside {} (possible: {universe})",
                    C::NAME
                )));
            }
            for id in ids {
                if !landmarks.contains(&id) {
                    landmarks.push(id);
                }
            }
            constraints.push(Observation::new(ids[0], ids[1], ids[2], states));
        }
        Ok(Network::new(landmarks, constraints))
    }

    /// The closed map of the network, or the contradiction closing meets.
    pub fn close(&self) -> Result<Hypergraph<C>, Contradiction> {
        close_all::<C>(&self.landmarks, &self.constraints)
    }

    /// How many constraints `closed` (this network's closed map) holds tighter than given.
    pub fn tightened(&self, closed: &Hypergraph<C>) -> usize {
        self.constraints
            .iter()
            .filter(|o| closed.relation(o.a, o.b, o.c) != Some(o.states))
            .count()
    }

    /// A smallest set of constraints that closing finds inconsistent on its own (each one is
    /// needed), or `None` if the network closes. Found by deletion: each constraint is dropped
    /// in turn and kept out while the rest stays inconsistent.
    pub fn minimal_conflict(&self) -> Option<Vec<Observation>> {
        self.close().err()?;
        let mut kept = self.constraints.clone();
        let mut i = 0;
        while i < kept.len() {
            let mut without = kept.clone();
            without.remove(i);
            if close_all::<C>(&self.landmarks, &without).is_err() {
                kept = without;
            } else {
                i += 1;
            }
        }
        Some(kept)
    }
}

fn close_all<C: Calculus>(
    landmarks: &[LandmarkId],
    constraints: &[Observation],
) -> Result<Hypergraph<C>, Contradiction> {
    let mut map = Hypergraph::new();
    map.add_landmarks(landmarks);
    map.fuse(constraints)?;
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edc::Edc;
    use crate::fdc::Fdc;
    use crate::geometry::Point;

    /// The true relations of four points, as text.
    fn true_network(points: &[Point]) -> String {
        let mut text = String::from("# four points\n");
        for (a, b, c) in [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)] {
            let r = Edc::classify(points[a], points[b], points[c]).unwrap();
            text += &format!("{a} {b} {c} {{{r}}}\n");
        }
        text
    }

    const POINTS: [Point; 4] = [
        Point { x: 0.0, y: 0.0 },
        Point { x: 4.0, y: 1.0 },
        Point { x: 1.5, y: 5.0 },
        Point { x: -2.0, y: 3.0 },
    ];

    #[test]
    fn a_true_network_closes_and_its_closure_is_a_map() {
        let network = Network::<Edc>::from_text(&true_network(&POINTS)).unwrap();
        assert_eq!(network.landmarks, [0, 1, 2, 3]);
        assert_eq!(network.constraints.len(), 4);
        let map = network.close().unwrap();
        // Closing derived the relations the text did not state.
        let truth = Edc::classify(POINTS[1], POINTS[2], POINTS[0]).unwrap();
        assert_eq!(map.relation(1, 2, 0).unwrap(), RelationSet::single(truth));
        assert!(network.minimal_conflict().is_none());
        // Its JSON reads back as the same map, and as a network that closes to it.
        let again = Network::<Edc>::from_json(&map.to_json())
            .unwrap()
            .close()
            .unwrap();
        assert_eq!(again.to_json(), map.to_json());
    }

    /// A wrong relation among true ones: the minimal conflict holds it, and removing any of
    /// its constraints makes the network close.
    #[test]
    fn a_contradiction_is_narrowed_to_the_constraints_that_make_it() {
        let mut text = true_network(&POINTS);
        let wrong = crate::edc::mirror(Edc::classify(POINTS[0], POINTS[1], POINTS[2]).unwrap());
        text += &format!("0 1 2 {{{wrong}}}\n5 6 7 {{1,2,3}}\n");
        let network = Network::<Edc>::from_text(&text).unwrap();
        assert!(network.close().is_err());
        let conflict = network.minimal_conflict().unwrap();
        assert!(conflict.len() < network.constraints.len());
        assert!(conflict
            .iter()
            .any(|o| o.states == RelationSet::single(wrong)));
        for i in 0..conflict.len() {
            let mut fewer = conflict.clone();
            fewer.remove(i);
            assert!(Network::<Edc>::new(network.landmarks.clone(), fewer)
                .close()
                .is_ok());
        }
    }

    #[test]
    fn bad_lines_name_their_line_and_problem() {
        let cases = [
            ("0 1 {1}", "line 1", "not a landmark id"),
            ("# ok\n0 0 1 {1}", "line 2", "not distinct"),
            ("0 1 2 {}", "line 1", "empty"),
            ("0 1 2 {21}", "line 1", "outside EDC"),
            ("0 1 2 {1,x}", "line 1", "not a relation number"),
            ("a 1 2 {1}", "line 1", "\"a\""),
        ];
        for (text, line, says) in cases {
            let error = Network::<Edc>::from_text(text).unwrap_err().to_string();
            assert!(
                error.starts_with(line) && error.contains(says),
                "{text:?}: {error}"
            );
        }
        assert!(Network::<Fdc>::from_text("0 1 2 {15}").is_ok());
        assert!(Network::<Fdc>::from_text("0 1 2 {16}").is_err());
    }
}
