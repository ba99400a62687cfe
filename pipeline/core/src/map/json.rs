//! Loss-free JSON files of a map (format in `docs/MAP_FORMAT.md`): the landmark list in
//! insertion order and the three stored relations `{AB:C, BC:A, CA:B}` of every edge
//! (000 §VI-A) that is not entirely unconstrained.

use super::hypergraph::Hypergraph;
use super::index::{locate, slot_order, unrank};
use super::kernel::Kernel;
use super::transaction::Transaction;
use super::update::LandmarkId;
use crate::calculus::{Calculus, RelationSet};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

const FORMAT: &str = "qrm-map";
const VERSION: u64 = 1;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    format: String,
    version: u64,
    calculus: String,
    landmarks: Vec<LandmarkId>,
    triples: Vec<TripleEntry>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TripleEntry {
    ids: [LandmarkId; 3],
    ab_c: Vec<i64>,
    bc_a: Vec<i64>,
    ca_b: Vec<i64>,
}

/// Why a JSON text is not a valid map of the expected calculus.
#[derive(Debug, thiserror::Error)]
pub enum MapFormatError {
    // Not a `#[from]` source: the message holds it, and a chain printed with `{:#}` would
    // repeat it.
    #[error("not a qrm map JSON document: {0}")]
    Json(serde_json::Error),
    #[error("\"format\" is {0:?}, expected \"qrm-map\"")]
    Format(String),
    #[error("unsupported version {0}, this reader knows version 1")]
    Version(u64),
    #[error("map is for calculus {found:?}, expected {expected}")]
    Calculus {
        expected: &'static str,
        found: String,
    },
    #[error("landmark {0} is listed twice")]
    DuplicateLandmark(LandmarkId),
    #[error("{0} landmarks: this reader accepts at most {MAX_LANDMARKS} (memory grows as n³)")]
    TooManyLandmarks(usize),
    #[error("triple {ids:?}: {reason}")]
    Triple {
        ids: [LandmarkId; 3],
        reason: String,
    },
    #[error(
        "map is not path consistent: closing it changes relation {} {}:{} from {stored} to {closed}",
        relation[0], relation[1], relation[2]
    )]
    NotClosed {
        relation: [LandmarkId; 3],
        stored: RelationSet,
        closed: RelationSet,
    },
}

/// Largest map [`Hypergraph::from_json`] loads: 1 000 landmarks are 166 M triples, 2 GB.
pub const MAX_LANDMARKS: usize = 1000;

fn to_numbers(s: RelationSet) -> Vec<i64> {
    s.iter().map(i64::from).collect()
}

impl<C: Calculus> Hypergraph<C> {
    /// The map as JSON (`docs/MAP_FORMAT.md`); edges whose three relations are all
    /// `C::universe()` are omitted.
    pub fn to_json(&self) -> String {
        let universe = C::universe();
        let file = MapFile {
            format: FORMAT.into(),
            version: VERSION,
            calculus: C::NAME.into(),
            landmarks: self.landmarks.clone(),
            triples: self
                .triples()
                .filter(|(_, _, _, r)| r.iter().any(|s| *s != universe))
                .map(|(a, b, c, [x, y, z])| TripleEntry {
                    ids: [a, b, c],
                    ab_c: to_numbers(x),
                    bc_a: to_numbers(y),
                    ca_b: to_numbers(z),
                })
                .collect(),
        };
        serde_json::to_string(&file).expect("serialising plain data cannot fail")
    }

    /// Reads a map written by [`Hypergraph::to_json`]. Checks: the header (format, version,
    /// calculus `C::NAME`), distinct landmark ids, for every triple distinct known ids (any
    /// order), no second entry for the same three landmarks, relation numbers that are
    /// possible between distinct landmarks (`C::universe()`), no empty relation; finally that
    /// the map is closed: the unary operators and the path-consistency closure change nothing.
    pub fn from_json(text: &str) -> Result<Hypergraph<C>, MapFormatError> {
        let (landmarks, entries) = parse_entries::<C>(text)?;
        let mut map = Hypergraph::<C>::new();
        for &id in &landmarks {
            map.push_landmark(id);
        }
        let kernel = Kernel::of::<C>();
        for (ids, relations) in entries {
            let [a, b, c] = ids.map(|id| map.index[&id]);
            let rank = locate(a, b, c).rank;
            let mut stored = map.edges[rank];
            for ([x, y, z], set) in [[a, b, c], [b, c, a], [c, a, b]].into_iter().zip(relations) {
                let loc = locate(x, y, z);
                stored[loc.slot] &= if loc.inverted {
                    kernel.inverse(set.bits())
                } else {
                    set.bits()
                };
            }
            if map.edges[rank] == [C::universe().bits(); 3] && stored != map.edges[rank] {
                map.mark_constrained(rank);
            }
            map.edges[rank] = stored;
        }
        map.check_closed()?;
        Ok(map)
    }

    /// Errors unless closing the map (unary operators per edge, then full path consistency)
    /// leaves every relation as it is.
    fn check_closed(&mut self) -> Result<(), MapFormatError> {
        let kernel = Kernel::of::<C>();
        let not_closed = |map: &Self, rank: usize, slot: usize, stored: u32, closed: u32| {
            MapFormatError::NotClosed {
                relation: slot_order(unrank(rank), slot).map(|x| map.landmarks[x]),
                stored: RelationSet::from_bits(stored),
                closed: RelationSet::from_bits(closed),
            }
        };
        for (rank, &edge) in self.edges.iter().enumerate() {
            let closed = kernel.close_edge(edge);
            if let Some(slot) = (0..3).find(|&s| closed[s] != edge[s]) {
                return Err(not_closed(self, rank, slot, edge[slot], closed[slot]));
            }
        }
        let before = self.clone();
        let len = self.len();
        let mut tx = Transaction::new(self, len);
        for rank in 0..tx.map.edges.len() {
            if tx.map.edges[rank] != [kernel.universe; 3] {
                tx.queue(rank);
            }
        }
        let outcome = super::closure::close(&mut tx);
        if let Err((rank, slot)) = outcome {
            let stored = before.edges[rank][slot];
            tx.rollback();
            return Err(not_closed(&before, rank, slot, stored, 0));
        }
        tx.commit();
        let changed = (0..self.edges.len())
            .flat_map(|r| (0..3).map(move |s| (r, s)))
            .find(|&(r, s)| self.edges[r][s] != before.edges[r][s]);
        match changed {
            None => Ok(()),
            Some((rank, slot)) => Err(not_closed(
                &before,
                rank,
                slot,
                before.edges[rank][slot],
                self.edges[rank][slot],
            )),
        }
    }
}

/// A map file's landmarks and its triples' relations `[AB:C, BC:A, CA:B]` for `ids = [a, b, c]`,
/// validated as [`Hypergraph::from_json`] describes, closure aside.
pub(super) type Entries = (Vec<LandmarkId>, Vec<([LandmarkId; 3], [RelationSet; 3])>);

pub(super) fn parse_entries<C: Calculus>(text: &str) -> Result<Entries, MapFormatError> {
    let file: MapFile = serde_json::from_str(text).map_err(MapFormatError::Json)?;
    if file.format != FORMAT {
        return Err(MapFormatError::Format(file.format));
    }
    if file.version != VERSION {
        return Err(MapFormatError::Version(file.version));
    }
    if file.calculus != C::NAME {
        return Err(MapFormatError::Calculus {
            expected: C::NAME,
            found: file.calculus,
        });
    }
    if file.landmarks.len() > MAX_LANDMARKS {
        return Err(MapFormatError::TooManyLandmarks(file.landmarks.len()));
    }
    let mut known = HashSet::new();
    for &id in &file.landmarks {
        if !known.insert(id) {
            return Err(MapFormatError::DuplicateLandmark(id));
        }
    }
    let universe = C::universe();
    let mut seen = HashSet::new();
    let mut entries = Vec::with_capacity(file.triples.len());
    for entry in &file.triples {
        let ids = entry.ids;
        let bad = |reason: String| MapFormatError::Triple { ids, reason };
        if let Some(id) = ids.iter().find(|id| !known.contains(id)) {
            return Err(bad(format!("landmark {id} is not in \"landmarks\"")));
        }
        let [a, b, c] = ids;
        if a == b || b == c || a == c {
            return Err(bad("landmark ids are not distinct".into()));
        }
        let mut sorted = ids;
        sorted.sort_unstable();
        if !seen.insert(sorted) {
            return Err(bad("a second entry for the same three landmarks".into()));
        }
        let mut relations = [RelationSet::EMPTY; 3];
        let named = [
            (&entry.ab_c, "ab_c"),
            (&entry.bc_a, "bc_a"),
            (&entry.ca_b, "ca_b"),
        ];
        for (set, (numbers, name)) in relations.iter_mut().zip(named) {
            for &r in numbers {
                match u8::try_from(r) {
                    Ok(r) if universe.contains(r) => *set = set.with(r),
                    _ => {
                        return Err(bad(format!(
                            "{name}: relation {r} is not possible between distinct landmarks in {} (possible: {universe})",
                            C::NAME
                        )))
                    }
                }
            }
            if set.is_empty() {
                return Err(bad(format!("{name} is empty")));
            }
        }
        entries.push((ids, relations));
    }
    Ok((file.landmarks, entries))
}
