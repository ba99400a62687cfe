//! EDC tables by feasibility (000 §III-B): A=(0,0), B=(0,1), C=(x1,x2), D=(x3,x4); a triple of
//! regions is possible exactly when the conjunction of their constraints has a solution.
//!
//! For each cell `(AB:C, BC:D)`, witnesses are first looked for by sampling configurations
//! directly inside the two given regions (cheap; most possible triples are found this way); then
//! each remaining candidate `AB:D` gets its own branch and bound, which proves it impossible for
//! C, D in `[−R, R]²` or finds a witness. Witnesses found by sampling may lie outside that box:
//! a witness proves possibility wherever it is.

use qrm_core::calculus::{CompositionEntry, CompositionFile, EntryKind, RelationSet, UnaryFile};
use qrm_core::edc::{
    classify, fixed_point, free_point, is_left, mirror, region_constraints, REGIONS,
};
use qrm_core::feasibility::{BranchAndBound, Linear, Outcome, Problem, Quadratic, Settings};
use qrm_core::geometry::{Point, Point2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Half-width of the search box for every coordinate: large compared with |AB| = 1, as 000
/// §III-B requires. The Monte Carlo test checks configurations up to 10³ times larger.
pub const EDC_SEARCH_HALF_WIDTH: f64 = 8.0;

/// Direct samples per composition cell before branch and bound.
const SAMPLES_PER_CELL: usize = 3000;

fn search_box(n: usize) -> (Vec<f64>, Vec<f64>) {
    (
        vec![-EDC_SEARCH_HALF_WIDTH; n],
        vec![EDC_SEARCH_HALF_WIDTH; n],
    )
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

/// Whether `x = (C, D)` realises the triple `(AB:C, BC:D, AB:D)` by direct classification.
fn witness_classifies(x: &[f64], ab_c: u8, bc_d: u8, ab_d: u8) -> bool {
    let (a, b) = (Point::new(0.0, 0.0), Point::new(0.0, 1.0));
    let (c, d) = (Point::new(x[0], x[1]), Point::new(x[2], x[3]));
    classify(a, b, c) == Some(ab_c)
        && classify(b, c, d) == Some(bc_d)
        && classify(a, b, d) == Some(ab_d)
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
    /// Wall time of each searched cell, slowest first (full-table runs only).
    pub slowest_cells: Vec<((u8, u8), f64)>,
}

impl CompositionReport {
    /// Adds another run's counts (not its cell timings).
    fn add(&mut self, other: &CompositionReport) {
        self.sampled += other.sampled;
        self.searched_feasible += other.searched_feasible;
        self.proved_infeasible += other.proved_infeasible;
        self.undecided += other.undecided;
        self.boxes += other.boxes;
    }
}

/// Decides one cell: every `AB:D` compatible with `AB:C = ab_c`, `BC:D = bc_d`. Cells with C
/// right of AB are the mirror images of cells with C left of it (reflection across AB swaps
/// left and right in every frame), so only the left half is searched.
pub fn edc_composition_cell(
    ab_c: u8,
    bc_d: u8,
    settings: &Settings,
) -> (Vec<CompositionEntry>, CompositionReport) {
    if is_left(ab_c) {
        return search_cell(ab_c, bc_d, settings);
    }
    let (entries, report) = search_cell(mirror(ab_c), mirror(bc_d), settings);
    (mirror_cell(ab_c, bc_d, entries), report)
}

/// The entries of cell `(ab_c, bc_d)` from those of its mirror image: regions mirrored,
/// witnesses reflected (x ↦ −x).
fn mirror_cell(ab_c: u8, bc_d: u8, entries: Vec<CompositionEntry>) -> Vec<CompositionEntry> {
    let negate = |v: &String| match v.strip_prefix('-') {
        Some(positive) => positive.to_string(),
        None if v.parse::<f64>() == Ok(0.0) => v.clone(),
        None => format!("-{v}"),
    };
    let mut mirrored: Vec<CompositionEntry> = entries
        .into_iter()
        .map(|e| CompositionEntry {
            kind: e.kind,
            ab_c,
            bc_d,
            ab_d: mirror(e.ab_d),
            witness: e
                .witness
                .iter()
                .enumerate()
                .map(|(i, v)| if i % 2 == 0 { negate(v) } else { v.clone() })
                .collect(),
        })
        .collect();
    mirrored.sort_by_key(|e| e.ab_d);
    mirrored
}

fn search_cell(
    ab_c: u8,
    bc_d: u8,
    settings: &Settings,
) -> (Vec<CompositionEntry>, CompositionReport) {
    let n = 4;
    let a = fixed_point(n, 0.0, 0.0);
    let b = fixed_point(n, 0.0, 1.0);
    let c = free_point(n, 0, 1);
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
        let Some(r3) = classify(
            Point::new(0.0, 0.0),
            Point::new(0.0, 1.0),
            Point::new(dx, dy),
        ) else {
            continue;
        };
        let k = r3 as usize - 1;
        // Rounding in the placement of D may move C or D across a boundary: re-check.
        if witnesses[k].is_none() && witness_classifies(&x, ab_c, bc_d, r3) {
            witnesses[k] = Some(tidy_witness(&x, |w| witness_classifies(w, ab_c, bc_d, r3)));
            report.sampled += 1;
        }
    }

    // Branch and bound on the rest, one candidate at a time, alternating two parametrisations
    // of D with growing budgets. The boundaries of the two frames touch either at D = B, a fixed
    // point when D itself is the unknown, or at D = C, a fixed point (W = 0) when W = D − C is.
    // Boxes that end exactly on a touching point are refuted at once instead of shrinking
    // towards it forever; each problem is easy in one of the two.
    let small = Settings {
        max_boxes: settings.max_boxes / 50,
        ..settings.clone()
    };
    let passes = [
        (false, &small),
        (true, &small),
        (false, settings),
        (true, settings),
    ];
    let mut undecided = vec![false; REGIONS as usize];
    let open: Vec<usize> = (0..REGIONS as usize)
        .filter(|&k| witnesses[k].is_none())
        .collect();
    for k in open {
        let r3 = k as u8 + 1;
        let mut decided = false;
        for (relative_to_c, pass_settings) in passes {
            let d = if relative_to_c {
                Point2::new(
                    c.x.clone() + Linear::variable(n, 2),
                    c.y.clone() + Linear::variable(n, 3),
                )
            } else {
                free_point(n, 2, 3)
            };
            let reach = if relative_to_c { 2.0 } else { 1.0 } * EDC_SEARCH_HALF_WIDTH;
            let (mut lower, mut upper) = search_box(n);
            lower[2..].fill(-reach);
            upper[2..].fill(reach);
            let mut constraints = region_constraints(&a, &b, &c, ab_c);
            constraints.extend(region_constraints(&b, &c, &d, bc_d));
            constraints.extend(region_constraints(&a, &b, &d, r3));
            if relative_to_c {
                // Keep D in the same box as the first parametrisation, so that "impossible"
                // means one thing: no configuration with C and D in [−R, R]².
                let r = Linear::constant(n, EDC_SEARCH_HALF_WIDTH);
                for coordinate in [&d.x, &d.y] {
                    constraints.push(Quadratic::from_linear(&(coordinate.clone() - r.clone())));
                    constraints.push(Quadratic::from_linear(
                        &(coordinate.scaled(-1.0) - r.clone()),
                    ));
                }
            }
            let problem = Problem::single(lower, upper, constraints);
            let (mut outcomes, stats) = BranchAndBound::new(pass_settings.clone()).solve(&problem);
            report.boxes += stats.boxes;
            match outcomes.remove(0) {
                Outcome::Feasible(x) => {
                    // Back to (C, D) coordinates for the table.
                    let x = if relative_to_c {
                        vec![x[0], x[1], x[0] + x[2], x[1] + x[3]]
                    } else {
                        x
                    };
                    if witness_classifies(&x, ab_c, bc_d, r3) {
                        witnesses[k] =
                            Some(tidy_witness(&x, |w| witness_classifies(w, ab_c, bc_d, r3)));
                        report.searched_feasible += 1;
                        decided = true;
                        break;
                    }
                }
                Outcome::Infeasible => {
                    report.proved_infeasible += 1;
                    decided = true;
                    break;
                }
                Outcome::Undecided => {}
            }
        }
        if !decided {
            undecided[k] = true;
            report.undecided += 1;
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
pub fn edc_composition(
    settings: &Settings,
    progress: impl Fn() + Sync,
) -> (CompositionFile, CompositionReport) {
    // Search the left half in parallel, then fill every cell (mirroring the right half).
    let left: Vec<(u8, u8)> = (1..=REGIONS)
        .filter(|&r1| is_left(r1))
        .flat_map(|r1| (1..=REGIONS).map(move |r2| (r1, r2)))
        .collect();
    type Searched = ((u8, u8), (Vec<CompositionEntry>, CompositionReport), f64);
    let searched: Vec<Searched> = left
        .par_iter()
        .map(|&cell| {
            let start = std::time::Instant::now();
            let out = search_cell(cell.0, cell.1, settings);
            progress();
            (cell, out, start.elapsed().as_secs_f64())
        })
        .collect();
    let mut total = CompositionReport::default();
    let mut entries = Vec::new();
    let mut by_cell = std::collections::HashMap::new();
    for (cell, (e, r), seconds) in searched {
        total.slowest_cells.push((cell, seconds));
        total.add(&r);
        by_cell.insert(cell, e);
    }
    total.slowest_cells.sort_by(|a, b| b.1.total_cmp(&a.1));
    for r1 in 1..=REGIONS {
        for r2 in 1..=REGIONS {
            let e = match by_cell.get(&(r1, r2)) {
                Some(e) => e.clone(),
                None => mirror_cell(r1, r2, by_cell[&(mirror(r1), mirror(r2))].clone()),
            };
            entries.extend(e);
        }
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
    let mut solve_for = |r: u8, target: &dyn Fn(u8) -> Vec<Quadratic>| {
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
        file.left
            .push(solve_for(r, &|s| region_constraints(&b, &c, &a, s)));
        file.right
            .push(solve_for(r, &|s| region_constraints(&c, &a, &b, s)));
        file.inverse
            .push(solve_for(r, &|s| region_constraints(&b, &a, &c, s)));
    }
    (file, undecided)
}
