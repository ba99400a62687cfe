//! The qualitative map (000 §VI) against independent evidence: the true relations of random
//! point sets (brute-force geometry via `Calculus::classify`), a direct transcription of the
//! paper's update procedure (000 §VI-B steps 1–9) as a looser reference, and algebraic
//! invariants (order independence, transactions, JSON round trips).

use proptest::prelude::*;
use qrm_core::calculus::{Calculus, RelationSet};
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::geometry::Point;
use qrm_core::map::{ContradictionStage, Hypergraph, MapFormatError, Observation};
use qrm_tests::{random_point, rng};
use rand::seq::SliceRandom;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Random points with landmark ids `10 · index + 7` (ids unrelated to indices).
fn scene(rng: &mut ChaCha8Rng, n: usize) -> Vec<Point> {
    (0..n).map(|_| random_point(rng)).collect()
}

fn id(i: usize) -> u32 {
    10 * i as u32 + 7
}

/// The true relation `AB:C` of the points, `None` on degenerate configurations.
fn truth<C: Calculus>(points: &[Point], a: usize, b: usize, c: usize) -> Option<u8> {
    C::classify(points[a], points[b], points[c])
}

/// Distinct random indices.
fn random_triple(rng: &mut ChaCha8Rng, n: usize) -> [usize; 3] {
    loop {
        let t = [
            rng.random_range(0..n),
            rng.random_range(0..n),
            rng.random_range(0..n),
        ];
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            return t;
        }
    }
}

/// The true relation plus `extra` random other states.
fn loose<C: Calculus>(rng: &mut ChaCha8Rng, truth: u8, extra: usize) -> RelationSet {
    let universe: Vec<u8> = C::universe().iter().collect();
    let mut s = RelationSet::single(truth);
    for _ in 0..extra {
        s = s.with(universe[rng.random_range(0..universe.len())]);
    }
    s
}

/// Random batches of sound observations: random ordered triples, true state ∪ extras.
fn batches<C: Calculus>(
    rng: &mut ChaCha8Rng,
    points: &[Point],
    count: usize,
    size: usize,
    extra: usize,
) -> Vec<Vec<Observation>> {
    (0..count)
        .map(|_| {
            (0..size)
                .filter_map(|_| {
                    let [a, b, c] = random_triple(rng, points.len());
                    let t = truth::<C>(points, a, b, c)?;
                    Some(Observation::new(
                        id(a),
                        id(b),
                        id(c),
                        loose::<C>(rng, t, extra),
                    ))
                })
                .collect()
        })
        .collect()
}

/// Every stored relation of every ordering contains the true relation.
fn assert_sound<C: Calculus>(map: &Hypergraph<C>, points: &[Point]) {
    let n = points.len();
    for a in 0..n {
        for b in 0..n {
            for c in 0..n {
                if a == b || b == c || a == c {
                    continue;
                }
                let (Some(t), Some(s)) = (
                    truth::<C>(points, a, b, c),
                    map.relation(id(a), id(b), id(c)),
                ) else {
                    continue;
                };
                assert!(
                    s.contains(t),
                    "{}: {a}{b}:{c} stored {s} lacks true relation {t}",
                    C::NAME
                );
            }
        }
    }
}

fn soundness<C: Calculus>(seed: u64) {
    let mut rng = rng(seed);
    let n = rng.random_range(8..=15);
    let points = scene(&mut rng, n);
    let extra = rng.random_range(0..6);
    let mut map = Hypergraph::<C>::new();
    for batch in batches::<C>(&mut rng, &points, 6, 3 * n, extra) {
        map.fuse(&batch)
            .expect("true observations never contradict");
        assert_sound(&map, &points);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn edc_map_contains_the_true_relations(seed in any::<u64>()) {
        soundness::<Edc>(seed);
    }

    #[test]
    fn fdc_map_contains_the_true_relations(seed in any::<u64>()) {
        soundness::<Fdc>(seed);
    }

    #[test]
    fn batch_order_does_not_matter_and_merge_equals_fusing_both_streams(seed in any::<u64>()) {
        order_and_merge::<Edc>(seed);
        order_and_merge::<Fdc>(seed);
    }
}

fn order_and_merge<C: Calculus>(seed: u64) {
    let mut rng = rng(seed);
    let n = rng.random_range(6..=12);
    let points = scene(&mut rng, n);
    let mut all = batches::<C>(&mut rng, &points, 6, 2 * n, 4);
    let fuse_all = |bs: &[Vec<Observation>]| {
        let mut m = Hypergraph::<C>::new();
        for b in bs {
            m.fuse(b).unwrap();
        }
        m
    };
    let reference = fuse_all(&all);
    all.shuffle(&mut rng);
    for b in &mut all {
        b.shuffle(&mut rng);
    }
    let shuffled = fuse_all(&all);
    assert_eq!(shuffled, reference);
    // One batch with everything gives the same map too.
    assert_eq!(fuse_all(&[all.concat()]), reference);
    let (left, right) = all.split_at(3);
    let mut merged = fuse_all(left);
    merged.merge(&fuse_all(right)).unwrap();
    assert_eq!(merged, reference);
    let mut merged = fuse_all(right);
    merged.merge(&fuse_all(left)).unwrap();
    assert_eq!(merged, reference);
}

/// The paper's procedure (000 §VI-B): intersect, LEFT/RIGHT pseudo-measurements (step 7), and
/// only the composition pattern of step 8, `AB:X ← COMPOSE(AB:C, BC:X)` for the changed
/// `AB:C`, applied recursively (step 9). All six orderings are kept, INVERSE-synchronised.
struct PaperMap<C: Calculus> {
    n: usize,
    rel: Vec<RelationSet>,
    calculus: std::marker::PhantomData<C>,
}

impl<C: Calculus> PaperMap<C> {
    fn new(n: usize) -> Self {
        PaperMap {
            n,
            rel: vec![C::universe(); n * n * n],
            calculus: std::marker::PhantomData,
        }
    }

    fn at(&self, a: usize, b: usize, c: usize) -> RelationSet {
        self.rel[(a * self.n + b) * self.n + c]
    }

    fn measure(&mut self, a: usize, b: usize, c: usize, states: RelationSet) {
        let t = C::tables();
        let mut queue = vec![(a, b, c, states)];
        while let Some((a, b, c, s)) = queue.pop() {
            let current = self.at(a, b, c);
            let new = current.intersection(s);
            assert!(!new.is_empty(), "reference map contradiction");
            if new == current {
                continue;
            }
            let n = self.n;
            self.rel[(a * n + b) * n + c] = new;
            queue.push((b, a, c, t.inverse(new)));
            queue.push((b, c, a, t.left(new)));
            queue.push((c, a, b, t.right(new)));
            for x in 0..n {
                if x != a && x != b && x != c {
                    queue.push((a, b, x, t.compose(new, self.at(b, c, x))));
                }
            }
        }
    }
}

fn tighter_than_paper<C: Calculus>(seed: u64) -> bool {
    let mut rng = rng(seed);
    let n = 8;
    let points = scene(&mut rng, n);
    let mut map = Hypergraph::<C>::new();
    let mut paper = PaperMap::<C>::new(n);
    for batch in batches::<C>(&mut rng, &points, 4, 6, 3) {
        map.fuse(&batch).unwrap();
        for o in &batch {
            paper.measure(
                (o.a as usize - 7) / 10,
                (o.b as usize - 7) / 10,
                (o.c as usize - 7) / 10,
                o.states,
            );
        }
    }
    let mut strictly = false;
    for a in 0..n {
        for b in 0..n {
            for c in 0..n {
                if a == b || b == c || a == c {
                    continue;
                }
                let Some(mine) = map.relation(id(a), id(b), id(c)) else {
                    // Landmarks never observed: the paper map holds the universe there.
                    assert_eq!(paper.at(a, b, c), C::universe());
                    continue;
                };
                let theirs = paper.at(a, b, c);
                if let Some(t) = truth::<C>(&points, a, b, c) {
                    assert!(theirs.contains(t), "reference is unsound");
                }
                assert!(
                    mine.is_subset(theirs),
                    "{a}{b}:{c}: map {mine} ⊄ paper {theirs}"
                );
                strictly |= mine != theirs;
            }
        }
    }
    strictly
}

#[test]
fn path_consistency_is_at_least_as_tight_as_the_paper_procedure() {
    for calculus in ["EDC", "FDC"] {
        let strictly = (0..12u64).filter(|&s| match calculus {
            "EDC" => tighter_than_paper::<Edc>(s),
            _ => tighter_than_paper::<Fdc>(s),
        });
        assert!(strictly.count() > 0, "{calculus}: never strictly tighter");
    }
}

/// Exact singleton observations of every relation of `n` points.
fn exact<C: Calculus>(points: &[Point]) -> Vec<Observation> {
    let n = points.len();
    let mut out = Vec::new();
    for a in 0..n {
        for b in 0..n {
            for c in 0..n {
                if a != b && b != c && a != c {
                    if let Some(t) = truth::<C>(points, a, b, c) {
                        out.push(Observation::new(
                            id(a),
                            id(b),
                            id(c),
                            RelationSet::single(t),
                        ));
                    }
                }
            }
        }
    }
    out
}

fn determined<C: Calculus>(seed: u64) {
    let mut rng = rng(seed);
    let points = scene(&mut rng, 12);
    let observations = exact::<C>(&points);
    let mut map = Hypergraph::<C>::new();
    let report = map
        .fuse(&observations)
        .expect("a real configuration is consistent");
    assert_eq!(report.new_landmarks, 12);
    assert_eq!(report.relations_tightened, 3 * map.triple_count());
    for o in &observations {
        assert_eq!(map.relation(o.a, o.b, o.c), Some(o.states));
    }
    let before = map.clone();
    let again = map.fuse(&observations).unwrap();
    assert_eq!((again.relations_tightened, again.rounds), (0, 0));
    assert_eq!(map, before);
}

#[test]
fn a_completely_determined_configuration_is_consistent_and_stays_exact() {
    for seed in 0..4 {
        determined::<Edc>(seed);
        determined::<Fdc>(seed);
    }
}

#[test]
fn contradictions_leave_the_map_unchanged_and_name_the_triple() {
    let mut rng = rng(99);
    let points = scene(&mut rng, 6);
    let mut map = Hypergraph::<Edc>::new();
    map.fuse(&exact::<Edc>(&points)).unwrap();
    let before = map.clone();

    // Direct: a pinned relation observed without its true state, in a batch that also adds
    // a new landmark.
    let t = truth::<Edc>(&points, 1, 0, 2).unwrap();
    let batch = [
        Observation::new(id(0), id(1), 999, RelationSet::single(3)),
        Observation::new(id(1), id(0), id(2), Edc::universe().without(t)),
    ];
    let err = map.fuse(&batch).unwrap_err();
    assert_eq!(err.stage, ContradictionStage::Intersection);
    assert_eq!(map, before);
    assert_eq!(map.landmarks(), before.landmarks());
    assert!(!map.contains(999));
    let message = err.to_string();
    assert!(message.contains(&id(0).to_string()) && message.contains(&id(2).to_string()));
    assert_eq!(err.observations, vec![batch[1]]);

    // Derived: two new landmarks with individually possible but jointly impossible relations
    // to the pinned ones; found by trying singleton pairs until closure refutes one.
    let mut closure_refuted = false;
    'search: for r1 in 1..=20u8 {
        for r2 in 1..=20u8 {
            let batch = [
                Observation::new(id(0), id(1), 500, RelationSet::single(r1)),
                Observation::new(id(1), id(2), 500, RelationSet::single(r2)),
            ];
            if let Err(err) = map.fuse(&batch) {
                assert_eq!(map, before);
                assert_eq!(map.landmarks(), before.landmarks());
                assert_eq!(err.stage, ContradictionStage::Closure);
                assert!(err.to_string().contains("became empty"));
                closure_refuted = true;
                break 'search;
            } else {
                map = before.clone();
            }
        }
    }
    assert!(closure_refuted);

    // A repeated landmark is rejected before anything changes.
    let err = map
        .fuse(&[Observation::new(1, 1, 2, Edc::universe())])
        .unwrap_err();
    assert_eq!(err.stage, ContradictionStage::RepeatedLandmark);
    assert_eq!(map, before);
}

#[test]
fn merge_is_transactional() {
    let mut rng = rng(5);
    let points = scene(&mut rng, 7);
    let mut map = Hypergraph::<Fdc>::new();
    map.fuse(&exact::<Fdc>(&points)).unwrap();
    let before = map.clone();
    let t = truth::<Fdc>(&points, 2, 3, 4).unwrap();
    let mut other = Hypergraph::<Fdc>::new();
    other
        .fuse(&[
            Observation::new(id(2), id(3), id(4), Fdc::universe().without(t)),
            Observation::new(id(2), id(3), 12345, Fdc::universe()),
        ])
        .unwrap();
    let err = map.merge(&other).unwrap_err();
    assert_eq!(map, before);
    assert!(!map.contains(12345));
    assert_eq!(err.observations.len(), 3);
}

#[test]
fn relation_is_consistent_over_all_six_orderings() {
    let mut rng = rng(11);
    let points = scene(&mut rng, 9);
    let mut map = Hypergraph::<Edc>::new();
    for b in batches::<Edc>(&mut rng, &points, 3, 20, 4) {
        map.fuse(&b).unwrap();
    }
    let t = Edc::tables();
    let mut seen = 0;
    for (a, b, c, [ab_c, bc_a, ca_b]) in map.triples() {
        seen += 1;
        assert_eq!(map.relation(a, b, c), Some(ab_c));
        assert_eq!(map.relation(b, c, a), Some(bc_a));
        assert_eq!(map.relation(c, a, b), Some(ca_b));
        assert_eq!(map.relation(b, a, c), Some(t.inverse(ab_c)));
        assert_eq!(map.relation(c, b, a), Some(t.inverse(bc_a)));
        assert_eq!(map.relation(a, c, b), Some(t.inverse(ca_b)));
        // Closed under the unary operators: LEFT/RIGHT images contain the stored relations.
        assert!(bc_a.is_subset(t.left(ab_c)) && ca_b.is_subset(t.right(ab_c)));
        assert!(ab_c.is_subset(t.left(ca_b)) && bc_a.is_subset(t.right(ca_b)));
    }
    assert_eq!(seen, map.triple_count());
    let n = map.len();
    assert_eq!(map.triple_count(), n * (n - 1) * (n - 2) / 6);
    let first = map.landmarks()[0];
    let second = map.landmarks()[1];
    assert_eq!(map.relation(first, first, second), None);
    assert_eq!(map.relation(first, second, 123_456), None);
}

/// Landmarks added without relations (decided at a station that measured no triple) are
/// universal to everything and leave even a fully determined map closed: it reads back from
/// JSON, whose reader refuses any network that closing would change, and a later exact
/// measurement of the new landmark fuses without contradiction.
fn unrelated_landmarks<C: Calculus>(seed: u64) {
    let mut rng = rng(seed);
    let points = scene(&mut rng, 13);
    let observations = exact::<C>(&points[..12]);
    let mut map = Hypergraph::<C>::new();
    map.fuse(&observations).unwrap();
    map.add_landmarks(&[id(12), id(3), id(12)]);
    assert_eq!(map.len(), 13);
    assert!(map.contains(id(12)));
    assert_eq!(map.relation(id(0), id(1), id(12)), Some(C::universe()));
    let back = Hypergraph::<C>::from_json(&map.to_json()).expect("closed");
    assert_eq!(back, map);
    map.fuse(&exact::<C>(&points))
        .expect("the truth is consistent");
    assert_eq!(
        map.relation(id(0), id(1), id(12)).map(|r| r.len()),
        Some(1),
        "measured now"
    );
}

#[test]
fn landmarks_without_relations_keep_the_map_closed() {
    for seed in 0..3 {
        unrelated_landmarks::<Edc>(seed);
        unrelated_landmarks::<Fdc>(seed);
    }
}

#[test]
fn json_round_trip_is_loss_free() {
    let mut rng = rng(21);
    let points = scene(&mut rng, 10);
    let mut edc = Hypergraph::<Edc>::new();
    let mut fdc = Hypergraph::<Fdc>::new();
    for b in batches::<Edc>(&mut rng, &points, 3, 15, 3) {
        edc.fuse(&b).unwrap();
    }
    for b in batches::<Fdc>(&mut rng, &points, 3, 15, 3) {
        fdc.fuse(&b).unwrap();
    }
    let back = Hypergraph::<Edc>::from_json(&edc.to_json()).unwrap();
    assert_eq!(back, edc);
    assert_eq!(back.landmarks(), edc.landmarks());
    let back = Hypergraph::<Fdc>::from_json(&fdc.to_json()).unwrap();
    assert_eq!(back, fdc);
    assert!(edc
        .to_json()
        .starts_with(r#"{"format":"qrm-map","version":1,"calculus":"EDC""#));
    assert_eq!(
        Hypergraph::<Edc>::from_json(&Hypergraph::<Edc>::new().to_json()).unwrap(),
        Hypergraph::new()
    );
}

#[test]
fn malformed_json_is_rejected_with_a_reason() {
    let head = r#""format":"qrm-map","version":1,"calculus":"EDC""#;
    let doc = |landmarks: &str, triples: &str| {
        format!(r#"{{{head},"landmarks":{landmarks},"triples":[{triples}]}}"#)
    };
    let triple = |ids: &str, x: &str, y: &str, z: &str| {
        format!(r#"{{"ids":{ids},"ab_c":{x},"bc_a":{y},"ca_b":{z}}}"#)
    };
    let cases: Vec<(String, &str)> = vec![
        ("{".into(), "not a qrm map"),
        (doc("[1,2,3]", "").replace("qrm-map", "other"), "format"),
        (
            doc("[1,2,3]", "").replace(r#""version":1"#, r#""version":2"#),
            "version 2",
        ),
        (doc("[1,2,3]", "").replace("EDC", "FDC"), "calculus"),
        (doc("[1,2,1]", ""), "listed twice"),
        (
            doc("[1,2,3]", &triple("[1,2,4]", "[1]", "[17]", "[7]")),
            "not in",
        ),
        (
            doc("[1,2,3]", &triple("[1,2,2]", "[1]", "[17]", "[7]")),
            "not distinct",
        ),
        (
            doc(
                "[1,2,3]",
                &format!(
                    "{},{}",
                    triple("[1,2,3]", "[1]", "[17]", "[7]"),
                    triple("[3,2,1]", "[4]", "[20]", "[14]")
                ),
            ),
            "second entry",
        ),
        (
            doc("[1,2,3]", &triple("[1,2,3]", "[21]", "[17]", "[7]")),
            "relation 21",
        ),
        (
            doc("[1,2,3]", &triple("[1,2,3]", "[-1]", "[17]", "[7]")),
            "relation -1",
        ),
        (
            doc("[1,2,3]", &triple("[1,2,3]", "[]", "[17]", "[7]")),
            "empty",
        ),
        // AB:C = 1 forces BC:A = 17 (000 Table I): not closed.
        (
            doc("[1,2,3]", &triple("[1,2,3]", "[1]", "[2,17]", "[7]")),
            "not path consistent",
        ),
        (
            doc("[1,2,3]", "").replace(r#""triples""#, r#""extra":0,"triples""#),
            "unknown field",
        ),
    ];
    for (text, reason) in cases {
        let err: MapFormatError = Hypergraph::<Edc>::from_json(&text).unwrap_err();
        assert!(err.to_string().contains(reason), "{text}: {err}");
    }
    let fdc_five = r#"{"format":"qrm-map","version":1,"calculus":"FDC","landmarks":[1,2,3],"triples":[{"ids":[1,2,3],"ab_c":[5],"bc_a":[1],"ca_b":[1]}]}"#;
    let err = Hypergraph::<Fdc>::from_json(fdc_five).unwrap_err();
    assert!(err.to_string().contains("relation 5"), "{err}");
    // The consistent version of the same triple loads.
    let ok = doc("[1,2,3]", &triple("[1,2,3]", "[1]", "[17]", "[7]"));
    let map = Hypergraph::<Edc>::from_json(&ok).unwrap();
    assert_eq!(map.relation(2, 3, 1), Some(RelationSet::single(17)));
}

/// A map restricted to some landmarks holds exactly their relations as the whole map does
/// (a restriction of a path-consistent network is path consistent: nothing tightens).
#[test]
fn restriction_keeps_the_relations_among_the_kept_landmarks() {
    let mut rng = rng(41);
    let points = scene(&mut rng, 9);
    let mut map = Hypergraph::<Edc>::new();
    for batch in batches::<Edc>(&mut rng, &points, 6, 40, 3) {
        map.fuse(&batch)
            .expect("sound observations never contradict");
    }
    let keep = |l: u32| l % 3 != 1;
    let part = map.restricted(keep);
    assert!(part.landmarks().iter().all(|&l| keep(l)));
    let mut compared = 0;
    for (a, b, c, relations) in map.triples() {
        if keep(a) && keep(b) && keep(c) {
            assert_eq!(part.relation(a, b, c), Some(relations[0]));
            assert_eq!(part.relation(b, c, a), Some(relations[1]));
            compared += 1;
        }
    }
    assert_eq!(compared, part.triple_count());
    assert!(compared > 0);
}
