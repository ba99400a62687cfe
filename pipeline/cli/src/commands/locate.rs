//! `pipeline navigate locate --map RUN/map.json --image P`: which landmark's Voronoi cell a
//! panorama was taken in, against the map of an earlier run (`qrm_vision::localization`,
//! docs/NAVIGATION.md "Localization from one panorama"). With `--truth`, each answer is scored
//! against the renderer's truth.

use super::map::{calculus_of, read};
use super::output::write_atomic;
use super::quantile;
use super::run::ChannelsArg;
use anyhow::{bail, Context, Result};
use clap::Args;
use qrm_core::edc::Edc;
use qrm_core::map::{Hypergraph, LandmarkId};
use qrm_synth::dataset::Truth;
use qrm_vision::calib::Calibration;
use qrm_vision::localization::{KnownMap, Location, Whereabouts};
use qrm_vision::run::front_end::detect_station;
use qrm_vision::run::{LandmarkRecord, RunSettings, StationRecord};
use qrm_vision::survey::Station;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args, Debug)]
pub struct LocateArgs {
    /// The map of a `pipeline run` (its map.json); landmarks.json and stations.json beside it
    /// say what the landmarks look like and where the run saw them.
    #[arg(long)]
    map: PathBuf,
    /// Panoramas to place, each on its own: NAME_left.png (its NAME_right partner beside it
    /// gives stereo) or a mono NAME.png.
    #[arg(long, required = true, num_args = 1..)]
    image: Vec<PathBuf>,
    /// Camera calibration (default: calib.toml beside the first image).
    #[arg(long)]
    calib: Option<PathBuf>,
    /// As for `pipeline run`.
    #[arg(long, value_enum, default_value_t = ChannelsArg::Auto)]
    channels: ChannelsArg,
    /// Score each answer: the images' truth.json (the same world as the run's), with the run
    /// scored against its own truth (eval.json beside the map says which rock each landmark
    /// is).
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Also write every answer as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Time the navigator's compute on each panorama (detection in the stereo pair and
    /// locating against the map; decoding excluded) as the fastest of this many runs, and
    /// report its median, 90th percentile and worst over the panoramas: the fastest run is
    /// the code's own time, the others add what else the machine was doing.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    repeat: u32,
}

/// One panorama's answer, as written with `--json`.
#[derive(Serialize)]
struct Answer {
    image: String,
    #[serde(flatten)]
    location: Location,
    /// With `--truth`: the landmark whose rock is nearest to where the panorama was taken (of
    /// two landmarks the map made of that rock, the first; either is right).
    #[serde(skip_serializing_if = "Option::is_none")]
    true_cell: Option<LandmarkId>,
    #[serde(skip_serializing_if = "Option::is_none")]
    verdict: Option<Verdict>,
}

/// How an answer compares with the truth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
enum Verdict {
    CertainRight,
    CertainWrong,
    /// The true cell is among the possible landmarks.
    PossibleHolds,
    /// It is not, but a detection not identified may be nearer: the claim leaves room for
    /// the true cell (whether that detection is the true cell's rock is not checked).
    PossibleUnidentified,
    /// It is not, and nothing else may be nearer: a wrong claim.
    PossibleMisses,
    Unknown,
}

pub fn locate(args: &LocateArgs) -> Result<()> {
    let stations: Vec<Station> = args
        .image
        .iter()
        .map(|p| station_of(p))
        .collect::<Result<_>>()?;
    let known = load_run(&args.map)?;
    let calib_path = match &args.calib {
        Some(path) => path.clone(),
        None => args.image[0].with_file_name("calib.toml"),
    };
    if !calib_path.exists() {
        bail!(
            "no calibration: {} does not exist (give one with --calib FILE)",
            calib_path.display()
        );
    }
    let calib = Calibration::load(&calib_path)?;
    let scoring = match &args.truth {
        Some(truth) => Some(Scoring::new(&args.map, truth)?),
        None => None,
    };
    let mut settings = RunSettings::default();
    settings.detector.channels = args.channels.into();
    println!(
        "map {}: {} landmarks, {} of its stations serve as registration frames",
        args.map.display(),
        known.map.len(),
        known.frames()
    );
    let mut answers = Vec::new();
    let mut computes = Vec::new();
    for station in &stations {
        let directory = station.primary.parent().unwrap_or(Path::new("."));
        let mut fastest = Compute::default();
        let mut location = None;
        for _ in 0..args.repeat {
            let detected = detect_station(station, directory, &calib, &settings.detector);
            let detections = match detected.station {
                Ok(d) => d,
                Err(e) => bail!("{e}"),
            };
            let started = Instant::now();
            let located =
                known.locate(&detections, &calib, &settings.sensor, &settings.association);
            let run = Compute {
                detect: detected.detect_seconds,
                total: detected.detect_seconds + started.elapsed().as_secs_f64(),
            };
            if location.is_none() || run.total < fastest.total {
                fastest = run;
            }
            location = Some(located);
        }
        computes.push(fastest);
        let location = location.expect("at least one run");
        let image = station.primary.display().to_string();
        let true_cells = scoring.as_ref().map(|s| s.true_cells(&image)).transpose()?;
        let true_cell = true_cells.as_ref().and_then(|c| c.first().copied());
        let verdict = true_cells
            .as_ref()
            .map(|cells| verdict(&location.whereabouts, cells));
        println!("{}", describe(&station.name, &location, true_cell, verdict));
        answers.push(Answer {
            image,
            location,
            true_cell,
            verdict,
        });
    }
    if scoring.is_some() {
        let count = |v: Verdict| answers.iter().filter(|a| a.verdict == Some(v)).count();
        println!(
            "over {} panoramas: certain {} right, {} wrong; possible {} naming the true cell, {} leaving room for it through a detection not identified, {} wrong; unknown {}",
            answers.len(),
            count(Verdict::CertainRight),
            count(Verdict::CertainWrong),
            count(Verdict::PossibleHolds),
            count(Verdict::PossibleUnidentified),
            count(Verdict::PossibleMisses),
            count(Verdict::Unknown)
        );
    }
    if args.repeat > 1 {
        println!("{}", describe_compute(&computes, args.repeat));
    }
    if let Some(path) = &args.json {
        write_atomic(
            path,
            (serde_json::to_string_pretty(&answers)? + "\n").as_bytes(),
        )?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The navigator's compute on one panorama, seconds: detection, and detection to cell.
#[derive(Clone, Copy, Debug, Default)]
struct Compute {
    detect: f64,
    total: f64,
}

/// Median, 90th percentile and worst of the panoramas' compute, and the median detection.
fn describe_compute(computes: &[Compute], repeat: u32) -> String {
    let sorted = |seconds: fn(&Compute) -> f64| {
        let mut values: Vec<f64> = computes.iter().map(seconds).collect();
        values.sort_by(f64::total_cmp);
        values
    };
    let (total, detect) = (sorted(|c| c.total), sorted(|c| c.detect));
    format!(
        "navigator compute over {} panoramas (detection to cell, decoding excluded; fastest of {repeat} runs each): median {:.3} s, p90 {:.3} s, worst {:.3} s; detection median {:.3} s",
        computes.len(),
        quantile(&total, 0.5),
        quantile(&total, 0.9),
        quantile(&total, 1.0),
        quantile(&detect, 0.5),
    )
}

/// The run's map, landmarks and stations, from `map` and the files beside it.
pub(super) fn load_run(map_path: &Path) -> Result<KnownMap<Edc>> {
    let text = read(map_path)?;
    let calculus = calculus_of(map_path, &text)?;
    if calculus != "EDC" {
        bail!(
            "{}: a {calculus} map; locating needs a run's EDC map",
            map_path.display()
        );
    }
    let map = Hypergraph::<Edc>::from_json(&text)
        .with_context(|| format!("invalid map {}", map_path.display()))?;
    let beside = |name: &str| map_path.with_file_name(name);
    let landmarks: Vec<LandmarkRecord> = read_json(&beside("landmarks.json"), map_path)?;
    let records: Vec<StationRecord> = read_json(&beside("stations.json"), map_path)?;
    if let Some(l) = landmarks
        .iter()
        .find(|l| !map.landmarks().contains(&l.landmark))
    {
        bail!(
            "{} names landmark {} that {} does not hold: not the same run",
            beside("landmarks.json").display(),
            l.landmark,
            map_path.display()
        );
    }
    Ok(KnownMap::from_run(map, &landmarks, &records))
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path, map: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "cannot read {} (a run's outputs beside {} are needed)",
            path.display(),
            map.display()
        )
    })?;
    serde_json::from_str(&text)
        .with_context(|| format!("{} is not a run's file of its kind", path.display()))
}

/// The station of one image: its right partner beside it when it is a `_left` image.
fn station_of(path: &Path) -> Result<Station> {
    if !path.is_file() {
        bail!("{} does not exist or is not a file", path.display());
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    if stem.ends_with("_right") {
        bail!(
            "{} is a right-eye image: give the left (or mono) panorama",
            path.display()
        );
    }
    let (name, right) = match stem.strip_suffix("_left") {
        Some(name) => {
            let extension = path.extension().map(|e| e.to_string_lossy().to_string());
            let right = path.with_file_name(match extension {
                Some(e) => format!("{name}_right.{e}"),
                None => format!("{name}_right"),
            });
            (name.to_string(), right.is_file().then_some(right))
        }
        None => (stem, None),
    };
    Ok(Station {
        name,
        primary: path.to_path_buf(),
        right,
    })
}

/// The rock each landmark of the run in `run` stands for, from its eval.json (the run scored
/// against its truth).
pub(super) fn read_landmark_rocks(run: &Path) -> Result<BTreeMap<LandmarkId, u32>> {
    let eval_path = run.join("eval.json");
    let text = std::fs::read_to_string(&eval_path).with_context(|| {
        format!(
            "cannot read {} (score the run against its truth: pipeline eval)",
            eval_path.display()
        )
    })?;
    let eval: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not JSON", eval_path.display()))?;
    let by_name: BTreeMap<String, u32> = serde_json::from_value(eval["landmark_rocks"].clone())
        .with_context(|| {
            format!(
                "{} has no landmark_rocks: score the run again with this version",
                eval_path.display()
            )
        })?;
    by_name
        .into_iter()
        .map(|(landmark, rock)| {
            let landmark: LandmarkId = landmark
                .parse()
                .with_context(|| format!("{}: landmark {landmark:?}", eval_path.display()))?;
            Ok((landmark, rock))
        })
        .collect()
}

/// The truth of the images and the rock each of the run's landmarks stands for.
struct Scoring {
    truth: Truth,
    rocks: BTreeMap<LandmarkId, [f64; 2]>,
}

impl Scoring {
    fn new(map: &Path, truth_path: &Path) -> Result<Scoring> {
        let truth = super::eval::read_truth(truth_path)?;
        let mut rocks = BTreeMap::new();
        for (landmark, rock) in read_landmark_rocks(map.parent().unwrap_or(Path::new(".")))? {
            let Some(r) = truth.rocks.get(rock as usize) else {
                bail!(
                    "{} has no rock {rock}: not the world the run was scored in",
                    truth_path.display()
                );
            };
            rocks.insert(landmark, r.position);
        }
        Ok(Scoring { truth, rocks })
    }

    /// The landmarks whose rock is nearest to where `image` was taken, ascending: one, or
    /// several where the map made several landmarks of that rock (none when the map has no
    /// landmark with a rock).
    fn true_cells(&self, image: &str) -> Result<Vec<LandmarkId>> {
        let file = Path::new(image)
            .file_name()
            .map(|f| f.to_string_lossy().to_string())
            .unwrap_or_default();
        let Some(entry) = self.truth.images.iter().find(|i| i.file == file) else {
            bail!("the truth file has no image {file}");
        };
        let Some(station) = self.truth.stations.get(entry.station) else {
            bail!(
                "the truth file's image {file} names station {}, which it does not list",
                entry.station
            );
        };
        let at = station.position;
        let distance = |p: &[f64; 2]| (p[0] - at[0]).hypot(p[1] - at[1]);
        let nearest = self
            .rocks
            .values()
            .min_by(|a, b| distance(a).total_cmp(&distance(b)));
        Ok(self
            .rocks
            .iter()
            .filter(|(_, p)| Some(*p) == nearest)
            .map(|(&l, _)| l)
            .collect())
    }
}

impl Verdict {
    /// The verdict as written in the JSON.
    fn name(self) -> String {
        serde_json::to_value(self)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    }
}

/// How the located cell compares with the truth: `truth`, the landmarks of the rock nearest to
/// where the panorama was taken ([`Scoring::true_cells`]).
fn verdict(whereabouts: &Whereabouts, truth: &[LandmarkId]) -> Verdict {
    match whereabouts {
        Whereabouts::Certain { landmark } if truth.contains(landmark) => Verdict::CertainRight,
        Whereabouts::Certain { .. } => Verdict::CertainWrong,
        Whereabouts::Possible {
            landmarks,
            unidentified,
        } => {
            if truth.iter().any(|t| landmarks.contains(t)) {
                Verdict::PossibleHolds
            } else if *unidentified > 0 {
                Verdict::PossibleUnidentified
            } else {
                Verdict::PossibleMisses
            }
        }
        Whereabouts::Unknown => Verdict::Unknown,
    }
}

fn describe(
    name: &str,
    location: &Location,
    truth: Option<LandmarkId>,
    verdict: Option<Verdict>,
) -> String {
    let cell = match &location.whereabouts {
        Whereabouts::Certain { landmark } => format!("in landmark {landmark}'s cell"),
        Whereabouts::Possible {
            landmarks,
            unidentified,
        } => {
            let names: Vec<String> = landmarks.iter().map(|l| l.to_string()).collect();
            let more = match unidentified {
                0 => String::new(),
                n => format!(", or of a rock not identified ({n} may be nearer)"),
            };
            format!("in the cell of landmark {}{more}", names.join(" or "))
        }
        Whereabouts::Unknown => "cell unknown: the nearest rock is not identified".into(),
    };
    let scored = match (verdict, truth) {
        (Some(v), Some(t)) => format!(" [truth: landmark {t}; {}]", v.name()),
        (Some(v), None) => format!(" [{}]", v.name()),
        _ => String::new(),
    };
    format!(
        "{name}: {cell} ({} of {} detections identified, {} ambiguous){scored}",
        location.identified.len(),
        location.detections,
        location.ambiguous.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map that made two landmarks (5 and 31) of the rock nearest the rover: naming either is
    /// right.
    #[test]
    fn either_landmark_of_a_duplicated_rock_is_the_true_cell() {
        let truth = [5, 31];
        let certain = |landmark| Whereabouts::Certain { landmark };
        assert_eq!(verdict(&certain(31), &truth), Verdict::CertainRight);
        assert_eq!(verdict(&certain(5), &truth), Verdict::CertainRight);
        assert_eq!(verdict(&certain(7), &truth), Verdict::CertainWrong);
        let possible = |landmarks: Vec<LandmarkId>, unidentified| Whereabouts::Possible {
            landmarks,
            unidentified,
        };
        assert_eq!(
            verdict(&possible(vec![2, 31], 0), &truth),
            Verdict::PossibleHolds
        );
        assert_eq!(
            verdict(&possible(vec![2], 1), &truth),
            Verdict::PossibleUnidentified
        );
        assert_eq!(
            verdict(&possible(vec![2], 0), &truth),
            Verdict::PossibleMisses
        );
        assert_eq!(verdict(&Whereabouts::Unknown, &truth), Verdict::Unknown);
    }
}
