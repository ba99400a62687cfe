//! Isolation descriptors (004 §5.6.2, after Gowda & Krishna): neighbour ranks `p_X(Y)`, the
//! mutual neighbour value `mnv(X, Y) = p_X(Y) + p_Y(X)`, the c-value (the smallest positive mnv
//! of `X`) and the most isolated object of a scene (the largest c-value; ties go to the object
//! furthest from the reference landmark, 004 §5.2).
//!
//! A qualitative map has no distances, but its EDC relation `XY:Z` says whether `Z` is nearer
//! to `X` than `Y` is (the circle about `X` through `Y`, 000 Fig. 3b), which is all a rank
//! needs (seed digest B.8). On a partial map a comparison may be open, so every rank, mnv and
//! c-value is an interval, and an object is "certainly most isolated" only when its lower
//! bound beats every other object's upper bound.

use crate::calculus::RelationSet;
use crate::edc::{self, Edc};
use crate::geometry::Point;
use crate::map::Hypergraph;

/// An integer known to lie in `low..=high`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bounds {
    pub low: u32,
    pub high: u32,
}

impl Bounds {
    pub const fn exact(value: u32) -> Bounds {
        Bounds {
            low: value,
            high: value,
        }
    }

    pub fn is_exact(self) -> bool {
        self.low == self.high
    }

    pub fn contains(self, value: u32) -> bool {
        (self.low..=self.high).contains(&value)
    }
}

impl std::ops::Add for Bounds {
    type Output = Bounds;
    fn add(self, other: Bounds) -> Bounds {
        Bounds {
            low: self.low + other.low,
            high: self.high + other.high,
        }
    }
}

impl std::fmt::Display for Bounds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.is_exact() {
            write!(f, "{}", self.low)
        } else {
            write!(f, "{}..{}", self.low, self.high)
        }
    }
}

/// What is known of "is `z` nearer to `x` than `y` is?".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    Nearer,
    Farther,
    Unknown,
}

/// A source of distance comparisons between landmarks `0..count()`: metric positions, or a
/// map's EDC relations.
pub trait Nearness: Sync {
    fn count(&self) -> usize;
    /// Whether `z` is nearer to `x` than `y` is (`x`, `y`, `z` distinct).
    fn order(&self, x: usize, y: usize, z: usize) -> Order;
}

/// Exact comparisons from known positions (the simulator's truth, 004's map-maker).
pub struct Positions<'a>(pub &'a [Point]);

impl Nearness for Positions<'_> {
    fn count(&self) -> usize {
        self.0.len()
    }

    fn order(&self, x: usize, y: usize, z: usize) -> Order {
        let p = self.0;
        if p[x].distance(p[z]) < p[x].distance(p[y]) {
            Order::Nearer
        } else {
            Order::Farther
        }
    }
}

/// Comparisons an EDC map proves; landmark `i` is the map's `i`-th landmark
/// ([`Hypergraph::landmarks`]).
pub struct MapNearness<'a> {
    map: &'a Hypergraph<Edc>,
    inside_circle: RelationSet,
}

impl<'a> MapNearness<'a> {
    pub fn new(map: &'a Hypergraph<Edc>) -> MapNearness<'a> {
        // Boundary 4 of `edc::SIGNS` is "outside the circle about A through B": negative means
        // |AC| < |AB|.
        let inside_circle = RelationSet::from_relations(
            (1..=edc::REGIONS).filter(|&r| edc::SIGNS[r as usize - 1][4] < 0),
        );
        MapNearness { map, inside_circle }
    }
}

impl Nearness for MapNearness<'_> {
    fn count(&self) -> usize {
        self.map.len()
    }

    fn order(&self, x: usize, y: usize, z: usize) -> Order {
        let relation = self.map.relation_at(x, y, z);
        if relation.is_subset(self.inside_circle) {
            Order::Nearer
        } else if relation.intersection(self.inside_circle).is_empty() {
            Order::Farther
        } else {
            Order::Unknown
        }
    }
}

/// The rank of every other landmark among `x`'s neighbours (1 for the nearest), over all
/// landmarks of `source`; entry `x` is `0`.
pub fn neighbour_ranks(source: &impl Nearness, x: usize) -> Vec<Bounds> {
    let n = source.count();
    (0..n)
        .map(|y| {
            if y == x {
                return Bounds::exact(0);
            }
            rank_within(source, x, y, (0..n).filter(|&z| z != x && z != y))
        })
        .collect()
}

/// `p_x(y)` among `others` (the landmarks other than `x` and `y` that compete for the rank).
fn rank_within(
    source: &impl Nearness,
    x: usize,
    y: usize,
    others: impl Iterator<Item = usize>,
) -> Bounds {
    let mut rank = Bounds::exact(1);
    for z in others {
        match source.order(x, y, z) {
            Order::Nearer => {
                rank.low += 1;
                rank.high += 1;
            }
            Order::Unknown => rank.high += 1,
            Order::Farther => {}
        }
    }
    rank
}

/// Neighbour ranks within a scene of objects (004's window content): `ranks[i][j]` bounds
/// `p_i(j)`, the rank of object `j` among object `i`'s neighbours in the scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneRanks {
    ranks: Vec<Vec<Bounds>>,
}

/// The scene's most isolated object, as far as the ranks tell.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MostIsolated {
    /// The object that is most isolated whatever the open comparisons turn out to be.
    pub certain: Option<usize>,
    /// Every object that may be the most isolated.
    pub possible: Vec<usize>,
}

impl SceneRanks {
    /// The ranks among `scene` (indices of `source`'s landmarks); object `i` of the result is
    /// `scene[i]`.
    pub fn new(source: &impl Nearness, scene: &[usize]) -> SceneRanks {
        let ranks = scene
            .iter()
            .map(|&x| {
                scene
                    .iter()
                    .map(|&y| {
                        if x == y {
                            Bounds::exact(0)
                        } else {
                            let others = scene.iter().copied().filter(|&z| z != x && z != y);
                            rank_within(source, x, y, others)
                        }
                    })
                    .collect()
            })
            .collect();
        SceneRanks { ranks }
    }

    /// Exact ranks, `ranks[i][j] = p_i(j)` with zeros on the diagonal (004 Fig. 20).
    pub fn from_matrix(ranks: &[Vec<u32>]) -> SceneRanks {
        SceneRanks {
            ranks: ranks
                .iter()
                .map(|row| row.iter().map(|&r| Bounds::exact(r)).collect())
                .collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.ranks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ranks.is_empty()
    }

    /// `p_i(j)`.
    pub fn rank(&self, i: usize, j: usize) -> Bounds {
        self.ranks[i][j]
    }

    /// `mnv(i, j) = p_i(j) + p_j(i)`, 0 on the diagonal.
    pub fn mnv(&self) -> Vec<Vec<Bounds>> {
        let n = self.len();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| self.ranks[i][j] + self.ranks[j][i])
                    .collect()
            })
            .collect()
    }

    /// Each object's c-value: its smallest mnv to another object (004 §5.6.2). An object alone
    /// has c-value 0.
    pub fn c_values(&self) -> Vec<Bounds> {
        let mnv = self.mnv();
        (0..self.len())
            .map(|i| {
                let others = (0..self.len()).filter(|&j| j != i);
                let low = others.clone().map(|j| mnv[i][j].low).min().unwrap_or(0);
                let high = others.map(|j| mnv[i][j].high).min().unwrap_or(0);
                Bounds { low, high }
            })
            .collect()
    }

    /// The most isolated object other than `reference` (the landmark the navigator stands at,
    /// which takes part in the ranks but is no candidate, seed digest B.3). Ties in c-value go
    /// to the object further from `reference` (004 §5.2); without a reference a tie is left
    /// open.
    pub fn most_isolated(&self, reference: Option<usize>) -> MostIsolated {
        let c = self.c_values();
        let candidates: Vec<usize> = (0..self.len()).filter(|&i| Some(i) != reference).collect();
        // Whether `t` is certainly / possibly further than `y` from the reference.
        let further = |t: usize, y: usize, certainly: bool| match reference {
            None => false,
            Some(r) => {
                let (rt, ry) = (self.ranks[r][t], self.ranks[r][y]);
                if certainly {
                    rt.low > ry.high
                } else {
                    rt.high > ry.low
                }
            }
        };
        let beats = |t: usize, y: usize, certainly: bool| {
            if certainly {
                c[t].low > c[y].high || (c[t].low == c[y].high && further(t, y, true))
            } else {
                c[t].high > c[y].low
                    || (c[t].high == c[y].low && (reference.is_none() || further(t, y, false)))
            }
        };
        let wins = |t: usize, certainly: bool| {
            candidates.iter().all(|&y| y == t || beats(t, y, certainly))
        };
        MostIsolated {
            certain: candidates.iter().copied().find(|&t| wins(t, true)),
            possible: candidates
                .iter()
                .copied()
                .filter(|&t| wins(t, false))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::testing::converged;
    use proptest::prelude::*;

    /// 004 Fig. 20, the rank matrix behind its printed mnv matrix (seed digest B.3).
    fn figure_20() -> SceneRanks {
        SceneRanks::from_matrix(&[
            vec![0, 2, 1, 3],
            vec![3, 0, 1, 2],
            vec![3, 1, 0, 2],
            vec![3, 1, 2, 0],
        ])
    }

    #[test]
    fn figure_20_mnv_c_values_and_most_isolated() {
        let ranks = figure_20();
        let mnv: Vec<Vec<u32>> = ranks
            .mnv()
            .iter()
            .map(|row| row.iter().map(|b| b.low).collect())
            .collect();
        assert_eq!(
            mnv,
            [[0, 5, 4, 6], [5, 0, 2, 3], [4, 2, 0, 4], [6, 3, 4, 0]]
        );
        let c: Vec<u32> = ranks.c_values().iter().map(|b| b.low).collect();
        assert_eq!(c, [4, 2, 2, 3]);
        assert_eq!(ranks.most_isolated(None).certain, Some(0));
        assert_eq!(ranks.most_isolated(None).possible, vec![0]);
    }

    fn field() -> impl Strategy<Value = Vec<Point>> {
        prop::collection::vec((-50.0..50.0f64, -50.0..50.0f64), 4..9)
            .prop_map(|v| v.into_iter().map(|(x, y)| Point::new(x, y)).collect())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]

        /// On a converged map the ranks read from EDC relations are the true ranks, and the
        /// qualitative most isolated is the metric one (seed digest B.9, test 7).
        #[test]
        fn map_ranks_equal_true_ranks_on_converged_maps(points in field()) {
            let map = converged::<Edc>(&points);
            let truth = Positions(&points);
            let from_map = MapNearness::new(&map);
            let all: Vec<usize> = (0..points.len()).collect();
            for x in 0..points.len() {
                prop_assert_eq!(neighbour_ranks(&from_map, x), neighbour_ranks(&truth, x));
            }
            let exact = SceneRanks::new(&truth, &all);
            prop_assert_eq!(SceneRanks::new(&from_map, &all), exact.clone());
            prop_assert_eq!(
                SceneRanks::new(&from_map, &all).most_isolated(Some(0)),
                exact.most_isolated(Some(0))
            );
        }

        /// Interval ranks contain the truth: an open comparison widens, never excludes.
        #[test]
        fn open_comparisons_keep_the_true_ranks_inside(points in field(), hidden in 0u64..u64::MAX) {
            struct Partial<'a> { truth: Positions<'a>, hidden: u64 }
            impl Nearness for Partial<'_> {
                fn count(&self) -> usize { self.truth.count() }
                fn order(&self, x: usize, y: usize, z: usize) -> Order {
                    if (self.hidden >> ((x * 7 + y * 3 + z) % 64)) & 1 == 1 {
                        Order::Unknown
                    } else {
                        self.truth.order(x, y, z)
                    }
                }
            }
            let partial = Partial { truth: Positions(&points), hidden };
            let all: Vec<usize> = (0..points.len()).collect();
            let exact = SceneRanks::new(&Positions(&points), &all);
            let open = SceneRanks::new(&partial, &all);
            let (c_exact, c_open) = (exact.c_values(), open.c_values());
            for i in 0..points.len() {
                prop_assert!(c_open[i].contains(c_exact[i].low));
                for j in 0..points.len() {
                    prop_assert!(open.rank(i, j).contains(exact.rank(i, j).low));
                }
            }
            let truth = exact.most_isolated(Some(0)).certain.expect("exact ranks decide");
            let verdict = open.most_isolated(Some(0));
            prop_assert!(verdict.possible.contains(&truth));
            prop_assert!(verdict.certain.is_none() || verdict.certain == Some(truth));
        }
    }
}
