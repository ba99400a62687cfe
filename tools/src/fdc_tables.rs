//! FDC tables by exact rational enumeration (see `fdc::arrangement` for why it is complete).

use num_bigint::BigInt;
use num_rational::BigRational;
use qrm_core::calculus::{CompositionEntry, CompositionFile, EntryKind, RelationSet, UnaryFile};
use qrm_core::fdc::{candidate_third_points, classify_exact, faces_of_fourth_point, RELATIONS};
use qrm_core::geometry::Point2;
use rayon::prelude::*;
use std::collections::BTreeMap;

fn frame() -> (Point2<BigRational>, Point2<BigRational>) {
    let zero = BigRational::from_integer(BigInt::from(0));
    let one = BigRational::from_integer(BigInt::from(1));
    (
        Point2::new(zero.clone(), zero.clone()),
        Point2::new(zero, one),
    )
}

/// LEFT, RIGHT and INVERSE over all candidate positions of C. With C = B or C = A some frames
/// are degenerate and contribute nothing (LEFT(5) = RIGHT(11) = ∅).
pub fn fdc_unary() -> UnaryFile {
    let (a, b) = frame();
    let n = RELATIONS as usize;
    let mut file = UnaryFile {
        calculus: "FDC".into(),
        relations: RELATIONS,
        left: vec![RelationSet::EMPTY; n],
        right: vec![RelationSet::EMPTY; n],
        inverse: vec![RelationSet::EMPTY; n],
    };
    for c in candidate_third_points() {
        let r = classify_exact(&a, &b, &c).expect("A != B") as usize - 1;
        for (table, image) in [
            (&mut file.left, classify_exact(&b, &c, &a)),
            (&mut file.right, classify_exact(&c, &a, &b)),
            (&mut file.inverse, classify_exact(&b, &a, &c)),
        ] {
            if let Some(s) = image {
                table[r] = table[r].with(s);
            }
        }
    }
    file
}

/// The FDC composition table with an exact rational witness `x1 x2 x3 x4` (C, D) per entry.
pub fn fdc_composition() -> CompositionFile {
    let (a, b) = frame();
    type Found = ((u8, u8, u8), Vec<String>);
    let per_c: Vec<Vec<Found>> = candidate_third_points()
        .par_iter()
        .filter(|c| **c != b)
        .map(|c| {
            let r1 = classify_exact(&a, &b, c).expect("A != B");
            faces_of_fourth_point(&a, &b, c)
                .into_iter()
                .filter_map(|d| {
                    let r2 = classify_exact(&b, c, &d)?;
                    let r3 = classify_exact(&a, &b, &d)?;
                    let w = [&c.x, &c.y, &d.x, &d.y]
                        .iter()
                        .map(|v| v.to_string())
                        .collect();
                    Some(((r1, r2, r3), w))
                })
                .collect()
        })
        .collect();
    let mut found: BTreeMap<(u8, u8, u8), Vec<String>> = BTreeMap::new();
    for (key, witness) in per_c.into_iter().flatten() {
        found.entry(key).or_insert(witness);
    }
    CompositionFile {
        calculus: "FDC".into(),
        relations: RELATIONS,
        entries: found
            .into_iter()
            .map(|((ab_c, bc_d, ab_d), witness)| CompositionEntry {
                kind: EntryKind::Feasible,
                ab_c,
                bc_d,
                ab_d,
                witness,
            })
            .collect(),
    }
}
