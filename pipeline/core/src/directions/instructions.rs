//! A route turned into instructions a navigator can check (004 §5.5, §6.3), rotation
//! invariant. 004's verification reads each object's QOC (how many of the four quadrant
//! windows around it hold another object); a rover has no compass, so the signature here is
//! the landmark's RNG degree, which the map proves or bounds (seed digest B.8).
//!
//! - **Detectable** (004 §6.3.1): the target's signature is known and none of the objects that
//!   could be reached by mistake (the scene's other members) can have it: item `(q,-)`.
//! - **Recoverable** (004 §6.3.2, conditions 1–3): the target is detectable; a mistaken
//!   landmark's own signature is known and told apart from every other candidate's; and the
//!   map holds a leg from it to the target. Item `(q, D)`: "reached a landmark with signature
//!   `q`? From there, seek `D`".
//! - A **side cue** where the map proves it: the target lies left or right of the line from the
//!   reference landmark to its nearest landmark (EDC sidedness, 000 §II).

use super::custom_map::{Adjust, CustomMap, Descriptor as Grammar, Entry, Item};
use super::isolation::Bounds;
use super::legs::{Descriptor, Leg};
use crate::map::LandmarkId;
use crate::neighborhood::RngEstimate;

/// A mistaken landmark the navigator can recognize and recover from.
#[derive(Clone, Debug, PartialEq)]
pub struct Recovery {
    pub signature: u32,
    /// The leg from the mistaken landmark to the target.
    pub leg: Leg,
}

/// Which side of the line from a leg's start to `towards` (its nearest landmark) the target
/// lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SideCue {
    pub towards: usize,
    pub left: bool,
}

/// One leg with its checks.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub leg: Leg,
    /// The target's signature, when it tells the target from every confusable landmark.
    pub verify: Option<u32>,
    pub recover: Vec<Recovery>,
    pub side: Option<SideCue>,
}

/// Each landmark's RNG degree (by position in `landmarks`): certain edges below, every
/// surviving edge above.
pub fn rng_degrees(landmarks: &[LandmarkId], rng: &RngEstimate) -> Vec<Bounds> {
    let mut degrees = vec![Bounds::exact(0); landmarks.len()];
    let position = |id: LandmarkId| landmarks.iter().position(|&l| l == id);
    for edge in &rng.edges {
        for end in [edge.a, edge.b] {
            if let Some(i) = position(end) {
                degrees[i].high += 1;
                if edge.cost == 0.0 {
                    degrees[i].low += 1;
                }
            }
        }
    }
    degrees
}

/// The steps of a route (its legs, in order). `legs` are all the map's legs (recovery uses a
/// proven leg from a mistaken landmark to the target); `signatures` each landmark's signature;
/// `nearest(r)` the landmark the map proves nearest to `r`, if any; `left(r, n, t)` whether
/// `t` is certainly left (`Some(true)`) or right of the line `r → n`.
pub fn steps(
    route: &[&Leg],
    legs: &[Leg],
    signatures: &[Bounds],
    nearest: impl Fn(usize) -> Option<usize>,
    left: impl Fn(usize, usize, usize) -> Option<bool>,
) -> Vec<Step> {
    route
        .iter()
        .map(|&leg| {
            let target = signatures[leg.to];
            let verify = (target.is_exact()
                && leg
                    .confusable()
                    .all(|y| !signatures[y].contains(target.low)))
            .then_some(target.low);
            let recover = match verify {
                None => Vec::new(),
                Some(_) => leg
                    .confusable()
                    .filter_map(|y| {
                        let q = signatures[y];
                        let unique = q.is_exact()
                            && leg
                                .confusable()
                                .filter(|&z| z != y)
                                .all(|z| !signatures[z].contains(q.low));
                        let back = legs
                            .iter()
                            .find(|l| l.from == y && l.to == leg.to && l.is_proven())?;
                        unique.then(|| Recovery {
                            signature: q.low,
                            leg: back.clone(),
                        })
                    })
                    .collect(),
            };
            let side = nearest(leg.from)
                .filter(|&n| n != leg.to)
                .and_then(|n| left(leg.from, n, leg.to).map(|left| SideCue { towards: n, left }));
            Step {
                leg: leg.clone(),
                verify,
                recover,
                side,
            }
        })
        .collect()
}

fn grammar(leg: &Leg) -> Grammar {
    match leg.descriptor() {
        Descriptor::Obvious => Grammar::Obvious,
        Descriptor::Isolated => Grammar::Isol(Some(leg.objects())),
    }
}

/// The steps in 004's custom-map grammar, rotation-invariant form.
pub fn custom_map(steps: &[Step]) -> CustomMap {
    let entries = steps
        .iter()
        .enumerate()
        .map(|(k, step)| {
            let mut items: Vec<Item> = step
                .recover
                .iter()
                .map(|r| Item::Recover {
                    signature: r.signature,
                    corner: None,
                    seek: grammar(&r.leg),
                })
                .collect();
            if let Some(signature) = step.verify {
                items.push(Item::Verify { signature });
            }
            Entry {
                descriptor: grammar(&step.leg),
                trajectory: None,
                items,
                adjust: if k + 1 == steps.len() {
                    Adjust::Null
                } else {
                    Adjust::Cell
                },
            }
        })
        .collect();
    CustomMap { entries }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leg(from: usize, to: usize, scene: &[usize]) -> Leg {
        Leg {
            from,
            to,
            scene: scene.to_vec(),
            rank: Bounds::exact(1),
            confusable: scene[1..].iter().copied().filter(|&y| y != to).collect(),
            support: 1.0,
            proven: true,
        }
    }

    #[test]
    fn detectable_and_recoverable_targets() {
        // Leg 0 → 3 in scene {0, 1, 2, 3}; degrees: 1 has 2, 2 has 1..2, 3 has 4.
        let signatures = [
            Bounds::exact(3),
            Bounds::exact(2),
            Bounds { low: 1, high: 2 },
            Bounds::exact(4),
        ];
        let legs = vec![leg(0, 3, &[0, 1, 2, 3]), leg(1, 3, &[1, 3])];
        let steps = steps(
            &[&legs[0]],
            &legs,
            &signatures,
            |_| Some(1),
            |_, _, _| Some(true),
        );
        let step = &steps[0];
        assert_eq!(step.verify, Some(4));
        // 1's signature 2 is also possible for 2: no recovery from 1; 2's is not exact.
        assert!(step.recover.is_empty());
        assert_eq!(
            step.side,
            Some(SideCue {
                towards: 1,
                left: true
            })
        );
        assert_eq!(custom_map(&steps).to_string(), "((Isol/4,(4,-),-))");

        let signatures = [
            Bounds::exact(3),
            Bounds::exact(2),
            Bounds::exact(1),
            Bounds::exact(4),
        ];
        let steps = super::steps(
            &[&legs[0], &legs[1]],
            &legs,
            &signatures,
            |_| None,
            |_, _, _| Some(true),
        );
        assert_eq!(steps[0].recover.len(), 1);
        assert_eq!(steps[0].recover[0].leg.from, 1);
        assert_eq!(steps[0].side, None);
        assert_eq!(
            custom_map(&steps).to_string(),
            "((Isol/4,(2,Obvious),(4,-),cell), (Obvious,(4,-),-))"
        );
    }

    #[test]
    fn an_undetectable_target_gets_no_items() {
        let signatures = [Bounds::exact(1), Bounds::exact(2), Bounds::exact(2)];
        let legs = vec![leg(0, 2, &[0, 1, 2])];
        let steps = steps(&[&legs[0]], &legs, &signatures, |_| None, |_, _, _| None);
        assert_eq!(steps[0].verify, None);
        assert!(steps[0].recover.is_empty());
    }
}
