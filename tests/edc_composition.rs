//! The committed EDC composition table (000 §III-B) against independent evidence: its own
//! witnesses, the worked example of §III-C, a million random configurations, and regeneration.

use qrm_core::calculus::{Calculus, CompositionFile, EntryKind, RelationSet};
use qrm_core::edc::{classify, Edc, COMPOSITION_TABLE};
use qrm_core::feasibility::Settings;
use qrm_core::geometry::Point;
use qrm_tests::{random_point, rng, Similarity};
use qrm_tools::edc_composition_cell;
use rand::Rng;
use rayon::prelude::*;

fn file() -> CompositionFile {
    CompositionFile::parse(COMPOSITION_TABLE).expect("committed table parses")
}

fn set(rs: &[u8]) -> RelationSet {
    RelationSet::from_relations(rs.iter().copied())
}

#[test]
fn every_witness_classifies_to_its_triple() {
    let a = Point::new(0.0, 0.0);
    let b = Point::new(0.0, 1.0);
    for e in file()
        .entries
        .iter()
        .filter(|e| e.kind == EntryKind::Feasible)
    {
        let w: Vec<f64> = e.witness.iter().map(|v| v.parse().unwrap()).collect();
        let (c, d) = (Point::new(w[0], w[1]), Point::new(w[2], w[3]));
        assert_eq!(classify(a, b, c), Some(e.ab_c), "{e:?}");
        assert_eq!(classify(b, c, d), Some(e.bc_d), "{e:?}");
        assert_eq!(classify(a, b, d), Some(e.ab_d), "{e:?}");
    }
}

#[test]
fn no_undecided_entries_and_every_cell_nonempty() {
    let f = file();
    assert_eq!(f.undecided(), 0);
    let t = Edc::tables();
    for r1 in 1..=20 {
        for r2 in 1..=20 {
            assert!(
                !t.compose_base(r1, r2).is_empty(),
                "COMPOSE({r1},{r2}) empty"
            );
        }
    }
}

#[test]
fn worked_example_of_section_iii_c() {
    let t = Edc::tables();
    assert_eq!(t.compose_base(1, 5), set(&[1, 5, 11, 12, 17, 19]));
    assert_eq!(t.compose_base(5, 5), set(&[12, 17, 18, 19, 20]));
    assert_eq!(t.compose_base(11, 5), set(&[17, 18, 19, 20]));
    let x = set(&[6, 7]);
    let y = set(&[16]);
    assert_eq!(t.left(x), set(&[1, 5, 11]));
    assert_eq!(t.inverse(y), set(&[5]));
    assert_eq!(
        t.compose(t.left(x), t.inverse(y)),
        set(&[1, 5, 11, 12, 17, 18, 19, 20])
    );
}

/// Classifies `AB:C`, `BC:D`, `AB:D` of a configuration, if none is on a boundary.
fn triple(a: Point, b: Point, c: Point, d: Point) -> Option<(u8, u8, u8)> {
    Some((
        Edc::classify(a, b, c)?,
        Edc::classify(b, c, d)?,
        Edc::classify(a, b, d)?,
    ))
}

#[test]
fn a_million_random_configurations_fall_inside_the_table() {
    let t = Edc::tables();
    let chunks = 40u64;
    let per_chunk = 25_000;
    let misses: Vec<String> = (0..chunks)
        .into_par_iter()
        .flat_map_iter(|chunk| {
            let mut rng = rng(1000 + chunk);
            let mut out = Vec::new();
            for i in 0..per_chunk {
                let (a, b, c, d) = match i % 3 {
                    // Independent points at scales 10⁻³…10³.
                    0 => (
                        random_point(&mut rng),
                        random_point(&mut rng),
                        random_point(&mut rng),
                        random_point(&mut rng),
                    ),
                    // Canonical frame A=(0,0), B=(0,1) with C, D near it, under a random similarity:
                    // reaches every region pair, including the small lunes.
                    _ => {
                        let s = Similarity::random(&mut rng);
                        let spread = if i % 3 == 1 { 1.5 } else { 6.0 };
                        let mut p = || {
                            Point::new(
                                rng.random_range(-spread..spread),
                                rng.random_range(-spread..spread) + 0.5,
                            )
                        };
                        let (c, d) = (p(), p());
                        (
                            s.apply(Point::new(0.0, 0.0)),
                            s.apply(Point::new(0.0, 1.0)),
                            s.apply(c),
                            s.apply(d),
                        )
                    }
                };
                if let Some((r1, r2, r3)) = triple(a, b, c, d) {
                    if !t.compose_base(r1, r2).contains(r3) {
                        out.push(format!(
                            "AB:C={r1} BC:D={r2} AB:D={r3} at {a:?} {b:?} {c:?} {d:?}"
                        ));
                    }
                }
            }
            out
        })
        .collect();
    assert!(
        misses.is_empty(),
        "{} configurations outside the table, e.g. {:?}",
        misses.len(),
        &misses[..misses.len().min(5)]
    );
}

#[test]
fn configurations_sampled_inside_every_region_pair_fall_inside_the_table() {
    // For every (AB:C, BC:D) pair, draw C in AB:C and D in BC:D directly (D placed through the
    // similarity taking (0,0),(0,1) to B,C) and check AB:D.
    let t = Edc::tables();
    let a = Point::new(0.0, 0.0);
    let b = Point::new(0.0, 1.0);
    let mut rng = rng(77);
    let mut by_region: Vec<Vec<Point>> = vec![Vec::new(); 20];
    while by_region.iter().any(|v| v.len() < 400) {
        let s = 2f64.powf(rng.random_range(-3.0..4.0));
        let p = Point::new(rng.random_range(-s..s), rng.random_range(-s..s) + 0.5);
        if let Some(r) = classify(a, b, p) {
            if by_region[r as usize - 1].len() < 400 {
                by_region[r as usize - 1].push(p);
            }
        }
    }
    let mut checked = 0;
    for r1 in 1..=20usize {
        for r2 in 1..=20usize {
            for k in 0..400 {
                let c = by_region[r1 - 1][k];
                let pd = by_region[r2 - 1][(k * 7 + r1) % 400];
                let v = Point::new(c.x, c.y - 1.0);
                let d = Point::new(pd.x * v.y + pd.y * v.x, 1.0 - pd.x * v.x + pd.y * v.y);
                if let Some((x1, x2, x3)) = triple(a, b, c, d) {
                    assert_eq!((x1, x2), (r1 as u8, r2 as u8));
                    assert!(
                        t.compose_base(x1, x2).contains(x3),
                        "{x1} {x2} {x3} at {c:?} {d:?}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 150_000);
}

#[test]
fn regenerating_a_sample_of_cells_reproduces_the_committed_rows() {
    let f = file();
    let settings = Settings::default();
    // A spread of cells, including lune and far-away regions; CI-sized.
    let cells = [
        (1u8, 1u8),
        (2, 17),
        (5, 5),
        (7, 14),
        (8, 3),
        (11, 5),
        (13, 20),
        (14, 7),
        (16, 10),
        (20, 20),
    ];
    for (r1, r2) in cells {
        let (regenerated, _) = edc_composition_cell(r1, r2, &settings);
        let committed: Vec<_> = f
            .entries
            .iter()
            .filter(|e| e.ab_c == r1 && e.bc_d == r2)
            .cloned()
            .collect();
        assert_eq!(regenerated, committed, "cell ({r1},{r2})");
    }
}
