//! EDC tables by feasibility (000 §III-B): A=(0,0), B=(0,1), C=(x1,x2), D=(x3,x4); a triple of
//! regions is possible exactly when the conjunction of their constraints has a solution.
//!
//! Each cell `(AB:C, BC:D)` is decided as one multi-alternative search over the 20 candidate
//! `AB:D` regions. Witnesses are first looked for by sampling configurations directly inside the
//! two given regions (cheap, and most possible triples are found this way); the branch and bound
//! then proves the rest impossible or finds their witnesses.

use crate::calculus::{CompositionEntry, CompositionFile, EntryKind, RelationSet, UnaryFile};
use crate::edc::{classify, fixed_point, free_point, region_constraints, REGIONS};
use crate::feasibility::{BranchAndBound, Outcome, Problem, Settings};
use crate::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Half-width of the search box for every coordinate: large compared with |AB| = 1, as 000
/// §III-B requires. The Monte Carlo test checks configurations up to 10³ times larger.
pub const EDC_SEARCH_HALF_WIDTH: f64 = 8.0;

/// Direct samples per composition cell before branch and bound.
const SAMPLES_PER_CELL: usize = 3000;

fn search_box(n: usize) -> (Vec<f64>, Vec<f64>) {
    (vec![-EDC_SEARCH_HALF_WIDTH; n], vec![EDC_SEARCH_HALF_WIDTH; n])
}

/// A random point of `region` in the frame A=(0,0), B=(0,1), at a random scale.
fn sample_region(rng: &mut ChaCha8Rng, region: u8) -> Point {
    let a = Point::new(0.0, 0.0);
    let b = Point::new(0.0, 1.0);
    loop {
        let scale = 2f64.powf(rng.random_range(-2.0..3.0));
        let p = Point::new(
            rng.random_range(-scale..scale),
            rng.random_range(-scale..scale) + 0.5,
        );
        if classify(a, b, p) == Some(region) {
            return p;
        }
    }
}

/// Shortest decimal rendering (4, 6 or 9 decimals, else full precision) that still satisfies.
fn tidy_witness(x: &[f64], ok: impl Fn(&[f64]) -> bool) -> Vec<String> {
    for digits in [4, 6, 9] {
        let k = 10f64.powi(digits);
        let rounded: Vec<f64> = x.iter().map(|v| (v * k).round() / k).collect();
        if ok(&rounded) {
            return rounded.iter().map(|v| format!("{v}")).collect();
        }
    }
    x.iter().map(|v| format!("{v}")).collect()
}

fn entry(kind: EntryKind, ab_c: u8, bc_d: u8, ab_d: u8, witness: Vec<String>) -> CompositionEntry {
    CompositionEntry {
        kind,
        ab_c,
        bc_d,
        ab_d,
        witness,
    }
}

/// Work and outcome counts of a composition run.
#[derive(Clone, Debug, Default)]
pub struct CompositionReport {
    pub sampled: usize,
    pub searched_feasible: usize,
    pub proved_infeasible: usize,
    pub undecided: usize,
    pub boxes: usize,
}

/// Decides one cell: every `AB:D` compatible with `AB:C = ab_c`, `BC:D = bc_d`.
pub fn edc_composition_cell(ab_c: u8, bc_d: u8, settings: &Settings) -> (Vec<CompositionEntry>, CompositionReport) {
    let n = 4;
    let a = fixed_point(n, 0.0, 0.0);
    let b = fixed_point(n, 0.0, 1.0);
    let c = free_point(n, 0, 1);
    let d = free_point(n, 2, 3);
    let mut common = region_constraints(&a, &b, &c, ab_c);
    common.extend(region_constraints(&b, &c, &d, bc_d));
    let (lower, upper) = search_box(n);
    let full = Problem {
        lower,
        upper,
        common,
        alternatives: (1..=REGIONS).map(|r| region_constraints(&a, &b, &d, r)).collect(),
    };
    let mut report = CompositionReport::default();
    let mut witnesses: Vec<Option<Vec<String>>> = vec![None; REGIONS as usize];

    // Direct sampling: C in AB:C, D placed in BC:D by the similarity taking (0,0),(0,1) to B,C.
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed ^ ((ab_c as u64) << 8 | bc_d as u64));
    for _ in 0..SAMPLES_PER_CELL {
        let pc = sample_region(&mut rng, ab_c);
        let pd = sample_region(&mut rng, bc_d);
        let v = Point::new(pc.x, pc.y - 1.0);
        let dx = pd.x * v.y + pd.y * v.x;
        let dy = 1.0 - pd.x * v.x + pd.y * v.y;
        let x = [pc.x, pc.y, dx, dy];
        let Some(r3) = classify(Point::new(0.0, 0.0), Point::new(0.0, 1.0), Point::new(dx, dy)) else {
            continue;
        };
        let k = r3 as usize - 1;
        if witnesses[k].is_none() && full.satisfies(k, &x) {
            witnesses[k] = Some(tidy_witness(&x, |w| full.satisfies(k, w)));
            report.sampled += 1;
        }
    }

    // Branch and bound on the rest.
    let rest: Vec<usize> = (0..REGIONS as usize).filter(|&k| witnesses[k].is_none()).collect();
    let mut undecided = vec![false; REGIONS as usize];
    if !rest.is_empty() {
        let problem = Problem {
            lower: full.lower.clone(),
            upper: full.upper.clone(),
            common: full.common.clone(),
            alternatives: rest.iter().map(|&k| full.alternatives[k].clone()).collect(),
        };
        let (outcomes, stats) = BranchAndBound::new(settings.clone()).solve(&problem);
        report.boxes += stats.boxes;
        for (&k, outcome) in rest.iter().zip(outcomes) {
            match outcome {
                Outcome::Feasible(x) => {
                    witnesses[k] = Some(tidy_witness(&x, |w| full.satisfies(k, w)));
                    report.searched_feasible += 1;
                }
                Outcome::Infeasible => report.proved_infeasible += 1,
                Outcome::Undecided => {
                    undecided[k] = true;
                    report.undecided += 1;
                }
            }
        }
    }
    let entries = (0..REGIONS as usize)
        .filter_map(|k| {
            let r3 = k as u8 + 1;
            match (&witnesses[k], undecided[k]) {
                (Some(w), _) => Some(entry(EntryKind::Feasible, ab_c, bc_d, r3, w.clone())),
                (None, true) => Some(entry(EntryKind::Undecided, ab_c, bc_d, r3, Vec::new())),
                (None, false) => None,
            }
        })
        .collect();
    (entries, report)
}

/// The full EDC composition table; `progress` is called once per finished cell.
pub fn edc_composition(settings: &Settings, progress: impl Fn() + Sync) -> (CompositionFile, CompositionReport) {
    let cells: Vec<(u8, u8)> = (1..=REGIONS)
        .flat_map(|r1| (1..=REGIONS).map(move |r2| (r1, r2)))
        .collect();
    let results: Vec<(Vec<CompositionEntry>, CompositionReport)> = cells
        .par_iter()
        .map(|&(r1, r2)| {
            let out = edc_composition_cell(r1, r2, settings);
            progress();
            out
        })
        .collect();
    let mut total = CompositionReport::default();
    let mut entries = Vec::new();
    for (e, r) in results {
        entries.extend(e);
        total.sampled += r.sampled;
        total.searched_feasible += r.searched_feasible;
        total.proved_infeasible += r.proved_infeasible;
        total.undecided += r.undecided;
        total.boxes += r.boxes;
    }
    (
        CompositionFile {
            calculus: "EDC".into(),
            relations: REGIONS,
            entries,
        },
        total,
    )
}

/// LEFT, RIGHT and INVERSE from geometry: for C in each region of `AB`, which regions can `BC:A`,
/// `CA:B`, `BA:C` take? Two unknowns (C); `undecided` counts entries kept without proof.
pub fn edc_unary(settings: &Settings) -> (UnaryFile, usize) {
    let n = 2;
    let a = fixed_point(n, 0.0, 0.0);
    let b = fixed_point(n, 0.0, 1.0);
    let c = free_point(n, 0, 1);
    let engine = BranchAndBound::new(settings.clone());
    let (lower, upper) = search_box(n);
    let mut undecided = 0;
    let mut solve_for = |r: u8, target: &dyn Fn(u8) -> Vec<crate::feasibility::Quadratic>| {
        let problem = Problem {
            lower: lower.clone(),
            upper: upper.clone(),
            common: region_constraints(&a, &b, &c, r),
            alternatives: (1..=REGIONS).map(target).collect(),
        };
        let (outcomes, _) = engine.solve(&problem);
        let mut set = RelationSet::EMPTY;
        for (k, o) in outcomes.iter().enumerate() {
            if o.possibly_feasible() {
                set = set.with(k as u8 + 1);
            }
            undecided += usize::from(matches!(o, Outcome::Undecided));
        }
        set
    };
    let mut file = UnaryFile {
        calculus: "EDC".into(),
        relations: REGIONS,
        left: Vec::new(),
        right: Vec::new(),
        inverse: Vec::new(),
    };
    for r in 1..=REGIONS {
        file.left.push(solve_for(r, &|s| region_constraints(&b, &c, &a, s)));
        file.right.push(solve_for(r, &|s| region_constraints(&c, &a, &b, s)));
        file.inverse.push(solve_for(r, &|s| region_constraints(&b, &a, &c, s)));
    }
    (file, undecided)
}

