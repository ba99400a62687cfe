//! What goes into a map update and what comes out: measurements `\widehat{AB:C}` (000 §VI-B),
//! the statistics of one update, and the contradiction that rejects an update.

use crate::calculus::RelationSet;
use std::fmt;

/// User identifier of a landmark (a node `p_i` of 000 §VI-A).
pub type LandmarkId = u32;

/// A measurement "`AB:C ∈ states`" for landmarks `a`, `b`, `c` (000 §VI-B step 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Observation {
    pub a: LandmarkId,
    pub b: LandmarkId,
    pub c: LandmarkId,
    pub states: RelationSet,
}

impl Observation {
    pub fn new(a: LandmarkId, b: LandmarkId, c: LandmarkId, states: RelationSet) -> Observation {
        Observation { a, b, c, states }
    }

    /// The relations `[AB:C, BC:A, CA:B]` of the triple `[a, b, c]` as three observations.
    pub fn of_triple([a, b, c]: [LandmarkId; 3], states: [RelationSet; 3]) -> [Observation; 3] {
        [
            Observation::new(a, b, c, states[0]),
            Observation::new(b, c, a, states[1]),
            Observation::new(c, a, b, states[2]),
        ]
    }

    /// Whether the observation is about the three landmarks `ids`, in any order.
    pub fn is_about(&self, ids: [LandmarkId; 3]) -> bool {
        let mut mine = [self.a, self.b, self.c];
        let mut theirs = ids;
        mine.sort_unstable();
        theirs.sort_unstable();
        mine == theirs
    }
}

impl fmt::Display for Observation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}:{} ∈ {}", self.a, self.b, self.c, self.states)
    }
}

/// Statistics of one successful update (one `fuse` or `merge` transaction).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UpdateReport {
    /// Landmarks added by the update.
    pub new_landmarks: usize,
    /// Stored relations (three per edge) that differ from their value before the update
    /// (for new edges: from the universe).
    pub relations_tightened: usize,
    /// Edges with at least one tightened relation.
    pub triples_changed: usize,
    /// `COMPOSE(AB:C, BC:D)` evaluations during closure (those with an unconstrained input
    /// are skipped and not counted).
    pub compositions: u64,
    /// Worklist rounds of the closure (each round revises every edge changed in the round
    /// before).
    pub rounds: usize,
}

/// At which stage an update emptied a relation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContradictionStage {
    /// An observation names a landmark twice: no relation among distinct landmarks holds.
    RepeatedLandmark,
    /// Intersecting the observations (or the relations of a merged map) into the edge, with
    /// the unary operators (000 §VI-B steps 4–7).
    Intersection,
    /// Path-consistency closure (composition, 000 §VI-B steps 8–9).
    Closure,
}

/// An update was rejected because some relation became empty; the map is unchanged.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct Contradiction {
    /// The ordered relation `AB:C` that became empty, as landmark ids `[a, b, c]`.
    pub relation: [LandmarkId; 3],
    pub stage: ContradictionStage,
    /// The observations of the rejected update about the same three landmarks (any order);
    /// for a merge, the other map's relations on them. Empty when the contradiction was
    /// derived by closure from relations of other triples: then the update as a whole
    /// contradicts the map, and the closure does not track which observations were used.
    pub observations: Vec<Observation>,
    /// Number of observations in the rejected update (for a merge: three per edge of the
    /// other map).
    pub batch_len: usize,
}

impl fmt::Display for Contradiction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [a, b, c] = self.relation;
        let stage = match self.stage {
            ContradictionStage::RepeatedLandmark => "an observation names a landmark twice",
            ContradictionStage::Intersection => "intersecting observations",
            ContradictionStage::Closure => "path-consistency closure",
        };
        write!(
            f,
            "contradiction: relation {a} {b}:{c} (landmarks {a}, {b}, {c}) became empty during {stage}"
        )?;
        if self.observations.is_empty() {
            write!(
                f,
                "; derived from the {} observations of the update together with the map",
                self.batch_len
            )
        } else {
            f.write_str("; observations on these landmarks: ")?;
            for (i, o) in self.observations.iter().enumerate() {
                if i > 0 {
                    f.write_str(", ")?;
                }
                write!(f, "{o}")?;
            }
            Ok(())
        }
    }
}
