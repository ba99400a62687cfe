//! `pipeline simulate probabilistic`: 002's Table I (Mor & Indelman, §IV) — random triplets
//! seen from three camera poses, estimated by the full, fast and baseline algorithms of
//! `qrm_core::probabilistic`, printed beside the paper's percentiles.

use super::output::stage_json;
use anyhow::{bail, Context, Result};
use clap::Args;
use qrm_atomic_file::OutputSet;
use qrm_core::probabilistic::study::{
    calibration, quartiles, run_study, Accuracy, Outcome, Score, StudySettings,
};
use qrm_core::probabilistic::Noise;
use qrm_plot::{write_panels, Curve, Panel};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct ProbabilisticArgs {
    /// Random triplets (002: 300).
    #[arg(long, default_value_t = 300)]
    scenarios: usize,
    /// Bearing noise s.d., degrees (002 Table I: 3).
    #[arg(long, default_value_t = 3.0)]
    bearing_noise: f64,
    /// Motion-command noise s.d., degrees (002 Table I: 7).
    #[arg(long, default_value_t = 7.0)]
    motion_noise: f64,
    #[arg(long, default_value_t = 4000)]
    full_particles: usize,
    #[arg(long, default_value_t = 300)]
    fast_particles: usize,
    /// Pose/ray samples per view of the baseline.
    #[arg(long, default_value_t = 2000)]
    baseline_samples: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also 002's Fig. 4: the study at each of these bearing-noise levels (degrees) with
    /// motion noise twice as large, drawn as fig4.png / fig4.svg (medians and quartiles of
    /// DMSE, gmd, entropy and the cameras' DMSE) with the numbers in fig4.json.
    #[arg(long, value_delimiter = ',')]
    noise_levels: Vec<f64>,
    /// Output directory: table1.json, outcomes.json (and the fig4 files).
    #[arg(long, default_value = "probabilistic")]
    out: PathBuf,
}

/// 002 Table I: 25th / 50th / 75th percentiles (DMSE, gmd, entropy) and median seconds
/// (MATLAB), per algorithm (baseline, full, fast).
const PAPER: [(&str, [[f64; 3]; 3], f64); 3] = [
    (
        "baseline",
        [[0.39, 0.63, 0.71], [0.28, 1.10, 2.30], [0.28, 0.66, 0.87]],
        26.0,
    ),
    (
        "full",
        [[0.0, 0.16, 0.63], [0.0, 0.25, 1.15], [0.0, 5e-3, 0.58]],
        18.0,
    ),
    (
        "fast",
        [[0.0, 0.21, 0.62], [0.0, 0.27, 1.16], [0.0, 0.07, 0.64]],
        0.05,
    ),
];

/// Algorithm `k` of [`PAPER`]'s order: baseline, full, fast.
fn pick(k: usize, o: &Outcome) -> &Score {
    match k {
        0 => &o.baseline,
        1 => &o.full,
        _ => &o.fast,
    }
}

pub fn run(args: &ProbabilisticArgs) -> Result<()> {
    if args.scenarios == 0 || args.full_particles == 0 || args.fast_particles == 0 {
        bail!("--scenarios and the particle counts must be positive");
    }
    let within = |value: f64, most: f64| value > 0.0 && value <= most;
    if !(within(args.bearing_noise, 30.0) && within(args.motion_noise, 60.0)) {
        bail!("--bearing-noise must be in (0, 30] and --motion-noise in (0, 60] degrees");
    }
    if args.noise_levels.iter().any(|&v| !within(v, 30.0))
        || args.noise_levels.windows(2).any(|w| w[0] >= w[1])
    {
        bail!("--noise-levels must increase, each in (0, 30] degrees");
    }
    let settings = StudySettings {
        scenarios: args.scenarios,
        views: 3,
        noise: Noise {
            bearing: args.bearing_noise.to_radians(),
            motion: args.motion_noise.to_radians(),
        },
        full_particles: args.full_particles,
        fast_particles: args.fast_particles,
        baseline_samples: args.baseline_samples,
        seed: args.seed,
    };
    let started = Instant::now();
    let bar = super::simulate::progress(args.scenarios as u64, "triplets");
    let outcomes = run_study(&settings, &|| bar.inc(1));
    bar.finish_and_clear();
    let mut rows = Vec::new();
    let mut cameras = Vec::new();
    println!(
        "002 Table I: {} triplets, 3 views, bearing noise {}°, motion noise {}° (25th / median / 75th percentile; paper in brackets)",
        args.scenarios, args.bearing_noise, args.motion_noise
    );
    println!(
        "{:<9} {:<34} {:<34} {:<34} {:>12}",
        "", "DMSE", "gmd (|AB| units)", "entropy (nats)", "median time"
    );
    for (k, (name, paper, paper_seconds)) in PAPER.iter().enumerate() {
        let [ours, camera] = accuracy_quartiles(&outcomes, k);
        cameras.push((name, camera));
        let mut seconds: Vec<f64> = outcomes.iter().map(|o| pick(k, o).seconds).collect();
        let median_seconds = quartiles(&mut seconds)[1];
        let failed = outcomes.iter().filter(|o| pick(k, o).failed).count();
        let cell = |m: usize| {
            format!(
                "{:.2} {:.2} {:.2} [{} {} {}]",
                ours[m][0], ours[m][1], ours[m][2], paper[m][0], paper[m][1], paper[m][2]
            )
        };
        println!(
            "{name:<9} {:<34} {:<34} {:<34} {:>9.2} ms [{paper_seconds} s MATLAB]",
            cell(0),
            cell(1),
            cell(2),
            median_seconds * 1e3
        );
        rows.push(json!({
            "algorithm": name,
            "dmse": ours[0], "gmd": ours[1], "entropy_nats": ours[2],
            "camera": {
                "dmse": cameras[k].1[0], "gmd": cameras[k].1[1], "entropy_nats": cameras[k].1[2],
            },
            "paper": {"dmse": paper[0], "gmd": paper[1], "entropy": paper[2], "median_seconds": paper_seconds},
            "median_seconds": median_seconds,
            "failed": failed,
        }));
    }
    println!(
        "qualitative camera localization (002 Eq. 10), AB:X of each of the 3 views (25th / median / 75th percentile; 002 gives no figures)"
    );
    for (name, [d, g, e]) in &cameras {
        let cell = |q: &[f64; 3]| format!("{:.2} {:.2} {:.2}", q[0], q[1], q[2]);
        println!("{name:<9} {:<34} {:<34} {:<34}", cell(d), cell(g), cell(e));
    }
    println!(
        "calibration of AB:C: beliefs by the probability of their most likely state (count, mean probability → how often it is the truth)"
    );
    let mut calibrations = Vec::new();
    for (k, (name, _, _)) in PAPER.iter().enumerate() {
        let bins = calibration(outcomes.iter().map(|o| &pick(k, o).landmark));
        let cells: Vec<String> = bins
            .iter()
            .filter(|b| b.beliefs > 0)
            .map(|b| {
                format!(
                    "[{:.1},{:.1}) {:>4}: {:.2} → {:.2}",
                    b.from, b.to, b.beliefs, b.mean_top_probability, b.truth_first
                )
            })
            .collect();
        println!("{name:<9} {}", cells.join("   "));
        calibrations.push(json!({"algorithm": name, "bins": bins}));
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut outputs = OutputSet::new();
    let table = json!({
        "format": "qrm-probabilistic-table1",
        "version": 1,
        "settings": settings,
        "rows": rows,
        "calibration": calibrations,
        "seconds": started.elapsed().as_secs_f64(),
    });
    stage_json(&mut outputs, &args.out.join("table1.json"), &table)?;
    stage_json(
        &mut outputs,
        &args.out.join("outcomes.json"),
        &serde_json::to_value(&outcomes)?,
    )?;
    if !args.noise_levels.is_empty() {
        figure_four(&mut outputs, args, &settings)?;
    }
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", args.out.display()))?;
    println!(
        "wrote {} ({:.1} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The 25th, 50th and 75th percentiles of DMSE, gmd and entropy of algorithm `k`: for
/// `AB:C` over the scenarios, and for the cameras' `AB:X` (Eq. 10) over every camera.
fn accuracy_quartiles(outcomes: &[Outcome], k: usize) -> [[[f64; 3]; 3]; 2] {
    let quartiles_of = |accuracies: Vec<&Accuracy>| {
        std::array::from_fn(|m| {
            let mut values: Vec<f64> = accuracies
                .iter()
                .map(|a| [a.dmse, a.gmd, a.entropy][m])
                .collect();
            quartiles(&mut values)
        })
    };
    [
        quartiles_of(outcomes.iter().map(|o| &pick(k, o).landmark).collect()),
        quartiles_of(outcomes.iter().flat_map(|o| &pick(k, o).cameras).collect()),
    ]
}

/// 002 Fig. 4: the study at every `--noise-levels` σ_v with σ_w = 2σ_v ("motion noise ×2");
/// stages fig4.png, fig4.svg and fig4.json.
fn figure_four(
    outputs: &mut OutputSet,
    args: &ProbabilisticArgs,
    base: &StudySettings,
) -> Result<()> {
    let bar = super::simulate::progress(
        (args.scenarios * args.noise_levels.len()) as u64,
        "Fig. 4 triplets",
    );
    // [level][algorithm][metric] → quartiles
    let mut quartile_table: Vec<[[[f64; 3]; 4]; 3]> = Vec::new();
    for &level in &args.noise_levels {
        let settings = StudySettings {
            noise: Noise {
                bearing: level.to_radians(),
                motion: (2.0 * level).to_radians(),
            },
            ..*base
        };
        let outcomes = run_study(&settings, &|| bar.inc(1));
        // Fig. 4's panels: DMSE, gmd and entropy of AB:C, and the cameras' DMSE.
        quartile_table.push(std::array::from_fn(|k| {
            let [landmark, camera] = accuracy_quartiles(&outcomes, k);
            [landmark[0], landmark[1], landmark[2], camera[0]]
        }));
    }
    bar.finish_and_clear();
    let titles = [
        ("(a) DMSE of AB:C", "DMSE"),
        ("(b) geometric mean distance of AB:C", "gmd [|AB|]"),
        ("(c) entropy of AB:C", "entropy [nats]"),
        ("(d) DMSE of the cameras' AB:X (Eq. 10)", "DMSE"),
    ];
    let panels: Vec<Panel> = titles
        .iter()
        .enumerate()
        .map(|(m, (title, y_label))| Panel {
            title: title.to_string(),
            y_label: y_label.to_string(),
            x: args.noise_levels.clone(),
            curves: PAPER
                .iter()
                .enumerate()
                .map(|(k, (name, _, _))| {
                    let q = |i: usize| quartile_table.iter().map(|l| l[k][m][i]).collect();
                    Curve {
                        label: format!("{name}: median, band 25th–75th percentile"),
                        mean: q(1),
                        std: Vec::new(),
                        band: Some((q(0), q(2))),
                    }
                })
                .collect(),
        })
        .collect();
    let x_label = "bearing noise σ_v [degrees]; motion noise 2σ_v";
    for name in ["fig4.png", "fig4.svg"] {
        let path = args.out.join(name);
        outputs.stage(&path, |temporary| write_panels(temporary, x_label, &panels))?;
    }
    let levels: Vec<serde_json::Value> = args
        .noise_levels
        .iter()
        .zip(&quartile_table)
        .map(|(&level, table)| {
            let algorithm = |k: usize| {
                json!({"dmse": table[k][0], "gmd": table[k][1], "entropy_nats": table[k][2], "camera_dmse": table[k][3]})
            };
            json!({
                "bearing_noise_deg": level,
                "motion_noise_deg": 2.0 * level,
                "baseline": algorithm(0), "full": algorithm(1), "fast": algorithm(2),
            })
        })
        .collect();
    stage_json(
        outputs,
        &args.out.join("fig4.json"),
        &json!({"format": "qrm-probabilistic-fig4", "version": 1, "scenarios": args.scenarios, "levels": levels}),
    )?;
    println!("002 Fig. 4, median DMSE of AB:C (baseline / full / fast) by bearing noise, motion noise twice that:");
    for (&level, table) in args.noise_levels.iter().zip(&quartile_table) {
        println!(
            "  σ_v {level:>4}°: {:.2} / {:.2} / {:.2}",
            table[0][0][1], table[1][0][1], table[2][0][1]
        );
    }
    Ok(())
}
