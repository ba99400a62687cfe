//! The Monte Carlo study of 000 §VIII-B, Fig. 7: many random maps, mapped with the `n` nearest
//! landmarks at each imaging point, statistics per image number.

use super::mapping::{run, Step};
use super::scenario::Scenario;
use super::sensor::Sensor;
use crate::calculus::Calculus;
use rayon::prelude::*;
use std::fmt::Write;

/// A Monte Carlo study.
#[derive(Clone, Debug, PartialEq)]
pub struct MonteCarlo {
    pub maps: usize,
    pub landmarks: usize,
    pub stations: usize,
    /// Side of the square holding landmarks and stations.
    pub side: f64,
    /// One series per value: the `n` nearest landmarks used (`None`: all).
    pub nearest: Vec<Option<usize>>,
    /// Noise model; its `nearest` is replaced by each series' value.
    pub sensor: Sensor,
    pub seed: u64,
}

impl MonteCarlo {
    /// 000 Fig. 7: 100 maps × 30 landmarks × 50 imaging points, n ∈ {6, 9, 12, 18, 24, 30}.
    pub fn fig7() -> MonteCarlo {
        MonteCarlo {
            maps: 100,
            landmarks: 30,
            stations: 50,
            side: 100.0,
            nearest: [6, 9, 12, 18, 24, 30].map(Some).to_vec(),
            sensor: Sensor::exact(None),
            seed: 1,
        }
    }

    /// 003 §1.5.2, Fig. 1.6b: 15 landmarks, 49 random imaging points, all landmarks seen.
    pub fn dissertation_random() -> MonteCarlo {
        MonteCarlo {
            maps: 100,
            landmarks: 15,
            stations: 49,
            side: 100.0,
            nearest: vec![None],
            sensor: Sensor::exact(None),
            seed: 1,
        }
    }

    /// Number of mapping runs (`tick` is called once per finished run).
    pub fn runs(&self) -> usize {
        self.maps * self.nearest.len()
    }

    /// Maps random map number `map` of the study with the `nearest` landmarks seen: one run of
    /// [`MonteCarlo::run`], on its own so that a study can be split across processes or machines
    /// (the Python package's Dask sweeps) and give the same steps.
    pub fn run_one<C: Calculus>(&self, nearest: Option<usize>, map: usize) -> Vec<Step> {
        let seed = self.seed.wrapping_mul(1_000_003).wrapping_add(map as u64);
        let scenario = Scenario::random(seed, self.landmarks, self.stations, self.side);
        let sensor = Sensor {
            nearest,
            ..self.sensor
        };
        run::<C>(&scenario, &sensor, seed ^ 0x5eed).0
    }

    /// Runs every map for every series in parallel.
    pub fn run<C: Calculus>(&self, tick: &(dyn Fn() + Sync)) -> MonteCarloResult {
        let jobs: Vec<(usize, usize)> = (0..self.nearest.len())
            .flat_map(|s| (0..self.maps).map(move |m| (s, m)))
            .collect();
        let results: Vec<(usize, Vec<Step>)> = jobs
            .into_par_iter()
            .map(|(s, m)| {
                let steps = self.run_one::<C>(self.nearest[s], m);
                tick();
                (s, steps)
            })
            .collect();
        let series = self
            .nearest
            .iter()
            .enumerate()
            .map(|(s, &nearest)| {
                let runs: Vec<&Vec<Step>> = results
                    .iter()
                    .filter(|(k, _)| *k == s)
                    .map(|(_, steps)| steps)
                    .collect();
                Series::aggregate(nearest, &runs, self.stations)
            })
            .collect();
        MonteCarloResult {
            calculus: C::NAME,
            study: self.clone(),
            series,
        }
    }
}

/// Mean and standard deviation over the maps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Statistic {
    pub mean: f64,
    pub std: f64,
}

impl Statistic {
    fn of(values: impl Iterator<Item = f64>) -> Statistic {
        let v: Vec<f64> = values.collect();
        if v.is_empty() {
            return Statistic::default();
        }
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64;
        Statistic {
            mean,
            std: var.sqrt(),
        }
    }
}

/// Per-image statistics of one series (one `n`).
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub nearest: Option<usize>,
    pub removed_incorrect_pct: Vec<Statistic>,
    pub non_adjacent_open_pct: Vec<Statistic>,
    pub fully_constrained_pct: Vec<Statistic>,
    pub open_pct: Vec<Statistic>,
    pub rng_cost: Vec<Statistic>,
    pub seconds: Vec<Statistic>,
    /// Final RNG precision and recall over the maps.
    pub rng_precision: Statistic,
    pub rng_recall: Statistic,
    /// Rejected panoramas over all maps and images; relations that lost their true state,
    /// summed over the maps of each map's worst image.
    pub contradictions: usize,
    pub unsound_relations: usize,
}

impl Series {
    pub fn label(&self) -> String {
        match self.nearest {
            Some(n) => format!("n = {n}"),
            None => "all".to_string(),
        }
    }

    fn aggregate(nearest: Option<usize>, runs: &[&Vec<Step>], stations: usize) -> Series {
        let per_step = |f: &dyn Fn(&Step) -> f64| -> Vec<Statistic> {
            (0..stations)
                .map(|i| Statistic::of(runs.iter().map(|r| f(&r[i]))))
                .collect()
        };
        let last = |f: &dyn Fn(&Step) -> Option<f64>| {
            Statistic::of(runs.iter().filter_map(|r| r.last().and_then(f)))
        };
        Series {
            nearest,
            removed_incorrect_pct: per_step(&|s| s.metrics.removed_incorrect_pct),
            non_adjacent_open_pct: per_step(&|s| s.metrics.non_adjacent_open_pct),
            fully_constrained_pct: per_step(&|s| s.metrics.fully_constrained_pct),
            open_pct: per_step(&|s| s.metrics.open_pct),
            rng_cost: per_step(&|s| s.rng_cost.unwrap_or(0.0)),
            seconds: per_step(&|s| s.seconds),
            rng_precision: last(&|s| s.rng.map(|c| c.precision())),
            rng_recall: last(&|s| s.rng.map(|c| c.recall())),
            contradictions: runs
                .iter()
                .map(|r| r.iter().filter(|s| s.contradiction).count())
                .sum(),
            unsound_relations: runs
                .iter()
                .map(|r| {
                    r.iter()
                        .map(|s| s.metrics.unsound_relations)
                        .max()
                        .unwrap_or(0)
                })
                .sum(),
        }
    }
}

/// The outcome of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct MonteCarloResult {
    pub calculus: &'static str,
    pub study: MonteCarlo,
    pub series: Vec<Series>,
}

impl MonteCarloResult {
    /// One row per series and image: `n,image,` then mean and std of every metric.
    pub fn to_csv(&self) -> String {
        let mut out = String::from(
            "n,image,removed_incorrect_pct,removed_incorrect_pct_std,non_adjacent_open_pct,\
             non_adjacent_open_pct_std,fully_constrained_pct,fully_constrained_pct_std,open_pct,\
             open_pct_std,rng_cost,rng_cost_std,seconds,seconds_std\n",
        );
        for s in &self.series {
            let n = s.nearest.map_or("all".to_string(), |n| n.to_string());
            for i in 0..s.seconds.len() {
                let _ = write!(out, "{n},{}", i + 1);
                for stat in [
                    s.removed_incorrect_pct[i],
                    s.non_adjacent_open_pct[i],
                    s.fully_constrained_pct[i],
                    s.open_pct[i],
                    s.rng_cost[i],
                    s.seconds[i],
                ] {
                    let _ = write!(out, ",{:.6},{:.6}", stat.mean, stat.std);
                }
                out.push('\n');
            }
        }
        out
    }
}
