//! `navigate`: routes and the hull of a saved map, the simulation's outputs, and clear errors
//! for landmarks the map lacks, maps without an RNG and bad options.

use super::pipeline;
use std::path::Path;

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// A simulated EDC map of 8 landmarks in `dir`, and the same as FDC.
fn maps(dir: &Path) {
    for (calculus, sub) in [("edc", "edc"), ("fdc", "fdc")] {
        let o = pipeline(&[
            "simulate",
            "single",
            "--landmarks",
            "8",
            "--stations",
            "20",
            "--calculus",
            calculus,
            "--out",
            dir.join(sub).to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

#[test]
fn plans_routes_and_reads_the_hull_of_a_saved_map() {
    let scratch = tempfile::tempdir().unwrap();
    maps(scratch.path());
    let edc = scratch.path().join("edc/map.json");
    let edc = edc.to_str().unwrap();
    let o = pipeline(&[
        "navigate", "plan", "--map", edc, "--from", "0", "--to", "7", "--routes", "3",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = stdout(&o);
    assert!(text.starts_with("route 1: 0 → "), "{text}");
    assert!(text.lines().next().unwrap().contains(" → 7  ("), "{text}");
    assert!(text.contains("route 2: "), "{text}");
    for map in [edc, scratch.path().join("fdc/map.json").to_str().unwrap()] {
        let o = pipeline(&["navigate", "hull", "--map", map]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(stdout(&o).contains("hull edges proven"), "{}", stdout(&o));
    }
    let fdc = scratch.path().join("fdc/map.json");
    for (bad, says) in [
        (
            vec![
                "navigate", "plan", "--map", edc, "--from", "0", "--to", "99",
            ],
            "landmark 99 is not in the map",
        ),
        (
            vec![
                "navigate", "plan", "--map", edc, "--from", "0", "--to", "1", "--routes", "0",
            ],
            "--routes",
        ),
        (
            vec![
                "navigate",
                "plan",
                "--map",
                edc,
                "--from",
                "0",
                "--to",
                "1",
                "--lambda=-1",
            ],
            "--lambda",
        ),
        (
            vec![
                "navigate",
                "plan",
                "--map",
                fdc.to_str().unwrap(),
                "--from",
                "0",
                "--to",
                "1",
            ],
            "no RNG estimate",
        ),
        (
            vec![
                "navigate",
                "plan",
                "--map",
                "/nonexistent/map.json",
                "--from",
                "0",
                "--to",
                "1",
            ],
            "cannot read",
        ),
    ] {
        let o = pipeline(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.starts_with("error: ") && stderr.contains(says),
            "{bad:?}: {stderr}"
        );
    }
}

#[test]
fn simulates_navigation_and_writes_its_outputs() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let o = pipeline(&[
        "navigate",
        "simulate",
        "--worlds",
        "2",
        "--landmarks",
        "12",
        "--pairs",
        "5",
        "--images",
        "6",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        stdout(&o).contains("10 trips over 2 fields of 12 landmarks"),
        "{}",
        stdout(&o)
    );
    for file in [
        "trips.csv",
        "summary.json",
        "flowfield.png",
        "flowfield.svg",
    ] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let csv = std::fs::read_to_string(dir.join("trips.csv")).unwrap();
    assert_eq!(csv.lines().count(), 11);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["summary"]["trips"], 10);
    for bad in [
        vec!["navigate", "simulate", "--worlds", "0"],
        vec!["navigate", "simulate", "--step", "0.9"],
        vec!["navigate", "simulate", "--landmarks", "2"],
        vec!["navigate", "simulate", "--nearest", "2", "--images", "3"],
    ] {
        let o = pipeline(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        assert!(
            String::from_utf8_lossy(&o.stderr).starts_with("error: "),
            "{bad:?}"
        );
    }
}

/// `navigate simulate` with several numbers of images and λ values runs a sweep: a row per
/// setting in sweep.csv, every trip in trips.csv, and the figure; λ values without images
/// are refused.
#[test]
fn sweeps_the_images_mapped_and_lambda() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let o = pipeline(&[
        "navigate",
        "simulate",
        "--worlds",
        "2",
        "--landmarks",
        "12",
        "--pairs",
        "5",
        "--images",
        "4,8",
        "--lambda",
        "0,10",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for file in [
        "trips.csv",
        "sweep.csv",
        "summary.json",
        "sweep.png",
        "sweep.svg",
    ] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let sweep = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = sweep.lines().skip(1).collect();
    assert_eq!(rows.len(), 4, "{sweep}");
    assert!(rows[0].starts_with("4,0,10,") && rows[3].starts_with("8,10,10,"));
    let trips = std::fs::read_to_string(dir.join("trips.csv")).unwrap();
    assert_eq!(trips.lines().count(), 1 + 4 * 10);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["settings"].as_array().unwrap().len(), 4);
    let o = pipeline(&["navigate", "simulate", "--lambda", "0,1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--images"));
}

/// The demo set mapped (and scored) into `dir/run`.
pub(super) fn demo_run(dir: &Path) -> std::path::PathBuf {
    let run = dir.join("run");
    let o = pipeline(&[
        "run",
        "--images",
        DEMO,
        "--out",
        run.to_str().unwrap(),
        "--quiet",
        "--panoramas",
        "none",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    run
}

pub(super) const DEMO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../datasets/demo");

/// `navigate locate` places panoramas against a run's map: every cell it claims holds against
/// the truth (a certain cell is the true one; a possible set holds it, or names a rock not
/// identified that may be nearer), its compute is timed over repeated runs, and a run's files
/// missing or a right-eye image are errors.
#[test]
fn locates_panoramas_against_a_run_soundly() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let run = demo_run(dir);
    let map = run.join("map.json");
    let images: Vec<String> = (0..16)
        .step_by(3)
        .map(|i| format!("{DEMO}/station_{i:03}_left.png"))
        .collect();
    let answers = dir.join("answers.json");
    let truth = format!("{DEMO}/truth.json");
    let mut args = vec![
        "navigate",
        "locate",
        "--map",
        map.to_str().unwrap(),
        "--image",
    ];
    args.extend(images.iter().map(String::as_str));
    args.extend(["--truth", &truth, "--json", answers.to_str().unwrap()]);
    args.extend(["--repeat", "2"]);
    let o = pipeline(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let answers: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&answers).unwrap()).unwrap();
    let answers = answers.as_array().unwrap();
    assert_eq!(answers.len(), images.len());
    for answer in answers {
        let verdict = answer["verdict"].as_str().unwrap();
        assert!(
            !["certain_wrong", "possible_misses"].contains(&verdict),
            "{answer}"
        );
        assert!(
            answer["identified"].as_array().unwrap().len() >= 3,
            "{answer}"
        );
    }
    assert!(stdout(&o).contains("over 6 panoramas"), "{}", stdout(&o));
    assert!(
        stdout(&o).contains("navigator compute over 6 panoramas")
            && stdout(&o).contains("fastest of 2 runs each"),
        "{}",
        stdout(&o)
    );

    std::fs::remove_file(run.join("landmarks.json")).unwrap();
    for (image, needle) in [
        ("station_000_left.png", "landmarks.json"),
        ("station_000_right.png", "right-eye image"),
    ] {
        let image = format!("{DEMO}/{image}");
        let o = pipeline(&[
            "navigate",
            "locate",
            "--map",
            map.to_str().unwrap(),
            "--image",
            &image,
        ]);
        assert_eq!(o.status.code(), Some(2));
        assert!(
            String::from_utf8_lossy(&o.stderr).contains(needle),
            "{image}"
        );
    }
}

/// `navigate drive` runs closed-loop trips through the demo set's rendered world and writes
/// its outputs; the navigator decides from the panoramas alone: with the truth that judges the
/// trips scrambled (which rock each landmark is), every path is the same step for step.
#[test]
fn drives_through_the_rendered_world_without_seeing_it() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let run = demo_run(dir);
    // Two trips of at most 12 steps each, and `extra` arguments.
    let two_trips = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "navigate",
            "drive",
            "--images",
            DEMO,
            "--run",
            run.to_str().unwrap(),
            "--trips",
            "2",
            "--max-steps",
            "12",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        pipeline(&args)
    };
    let drive = |out: &str| {
        let out = dir.join(out);
        let o = two_trips(&out, &[]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        for file in [
            "trips.json",
            "trips.csv",
            "summary.json",
            "drive.png",
            "drive.mcap",
        ] {
            assert!(out.join(file).is_file(), "{file}");
        }
        let csv = std::fs::read_to_string(out.join("trips.csv")).unwrap();
        assert_eq!(csv.lines().count(), 3, "{csv}");
        assert!(csv.starts_with("trip,start_x,start_y,goal,outcome,"));
        let trips: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("trips.json")).unwrap())
                .unwrap();
        // The per-step log holds every step of every trip, in order.
        let log = std::fs::read(out.join("drive.mcap")).unwrap();
        let messages: Vec<serde_json::Value> = mcap::MessageStream::new(&log)
            .unwrap()
            .map(|m| {
                let m = m.unwrap();
                assert_eq!(m.channel.topic, "/navigation/step");
                serde_json::from_slice(&m.data).unwrap()
            })
            .collect();
        let steps: usize = trips
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["navigator_seconds"].as_array().unwrap().len())
            .sum();
        assert_eq!(messages.len(), steps);
        if let Some(first) = messages.first() {
            assert_eq!(
                (first["trip"].as_u64(), first["step"].as_u64()),
                (Some(0), Some(0))
            );
            assert_eq!(first["position"], trips[0]["path"][0]);
        }
        // The A* reference: at least the straight distance to the goal's cell can be shorter
        // than to its rock, never longer than a generous detour.
        for t in trips.as_array().unwrap() {
            if let Some(reference) = t["reference_m"].as_f64() {
                assert!(
                    reference <= 3.0 * t["straight_m"].as_f64().unwrap() + 1.0,
                    "{t}"
                );
            }
        }
        trips
            .as_array()
            .unwrap()
            .iter()
            .map(|t| (t["path"].clone(), t["outcome"].clone(), t["route"].clone()))
            .collect::<Vec<_>>()
    };
    let honest = drive("a");
    assert_eq!(honest.len(), 2);
    // `--only` drives one trip of the seeded sequence again, exactly as the whole drive did.
    let only = |k: &str, out: &str| two_trips(&dir.join(out), &["--only", k]);
    let o = only("1", "only");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let again: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("only").join("trips.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(again.as_array().unwrap().len(), 1);
    assert_eq!(again[0]["number"], 1);
    assert_eq!(again[0]["path"], honest[1].0);
    let csv = std::fs::read_to_string(dir.join("only").join("trips.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().starts_with("1,"), "{csv}");
    // `--repeat` times the steps' perception as the fastest of several runs; the rover acts
    // as before.
    let o = two_trips(
        &dir.join("repeat"),
        &["--only", "1", "--repeat", "2", "--again-over", "0"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |file: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("repeat").join(file)).unwrap())
            .unwrap()
    };
    assert_eq!(read("trips.json")[0]["path"], honest[1].0);
    let timing = &read("summary.json")["navigator_seconds_per_step"];
    assert_eq!(timing["fastest_of_runs"], 2);
    assert_eq!(timing["trips_driven_again"], 1);
    assert!(timing["p99"].as_f64().unwrap() <= timing["max"].as_f64().unwrap());
    for bad in [["--repeat", "0"], ["--again-over", "inf"]] {
        let o = two_trips(&dir.join("bad"), &bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
    }
    let o = only("2", "beyond");
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("--only 2: the drive has trips 0 to 1"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let eval_path = run.join("eval.json");
    let mut eval: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&eval_path).unwrap()).unwrap();
    let rocks = eval["landmark_rocks"].as_object_mut().unwrap();
    let ids: Vec<serde_json::Value> = rocks.values().cloned().collect();
    for (k, value) in rocks.values_mut().enumerate() {
        *value = ids[(k + 1) % ids.len()].clone();
    }
    std::fs::write(&eval_path, eval.to_string()).unwrap();
    assert_eq!(drive("b"), honest, "the judging truth changed a decision");

    std::fs::remove_file(&eval_path).unwrap();
    let o = pipeline(&[
        "navigate",
        "drive",
        "--images",
        DEMO,
        "--run",
        run.to_str().unwrap(),
        "--out",
        dir.join("c").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("eval.json"));
}

/// `navigate flowfield` decides a heading (or arrival, or none) at every grid point clear of
/// the rocks from the panorama rendered there, and draws them with the trips; a goal the run
/// does not have is an error naming the landmarks it has.
#[test]
fn draws_the_closed_loop_flow_field() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let run = demo_run(dir);
    let eval: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("eval.json")).unwrap()).unwrap();
    let goal = eval["landmark_rocks"]
        .as_object()
        .unwrap()
        .keys()
        .next()
        .unwrap()
        .clone();
    let out = dir.join("flow");
    let flowfield = |goal: &str| {
        pipeline(&[
            "navigate",
            "flowfield",
            "--images",
            DEMO,
            "--run",
            run.to_str().unwrap(),
            "--goal",
            goal,
            "--grid",
            "4",
            "--trips",
            "1",
            "--max-steps",
            "6",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let o = flowfield(&goal);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for file in [
        "flowfield.png",
        "flowfield.svg",
        "headings.csv",
        "trips.json",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    let csv = std::fs::read_to_string(out.join("headings.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert!(!rows.is_empty() && rows.len() <= 16, "{csv}");
    for row in &rows {
        let commands = [
            "toward",
            "closing_in",
            "arrived",
            "start_unknown",
            "no_route",
            "lost",
        ];
        assert!(commands.contains(&row[2]), "{row:?}");
        // A heading exactly where the navigator moves.
        assert_eq!(
            !row[4].is_empty(),
            row[2] == "toward" || row[2] == "closing_in",
            "{row:?}"
        );
    }
    let o = flowfield("999");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("landmark 999"));
}

/// With the `rerun` feature, `navigate drive --rrd` adds `drive.rrd`. With
/// `QRM_RECORDING_SAMPLES=DIR` it is also copied to `DIR/drive.rrd`, for CI to check with
/// `rerun rrd verify`.
#[cfg(feature = "rerun")]
#[test]
fn records_a_drive_for_rerun() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let run = demo_run(dir);
    let out = dir.join("drive");
    let o = pipeline(&[
        "navigate",
        "drive",
        "--images",
        DEMO,
        "--run",
        run.to_str().unwrap(),
        "--trips",
        "1",
        "--max-steps",
        "4",
        "--rrd",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let size = std::fs::metadata(out.join("drive.rrd")).map_or(0, |m| m.len());
    assert!(size > 0, "drive.rrd missing or empty");
    if let Some(samples) = std::env::var_os("QRM_RECORDING_SAMPLES") {
        let samples = std::path::PathBuf::from(samples);
        std::fs::create_dir_all(&samples).unwrap();
        std::fs::copy(out.join("drive.rrd"), samples.join("drive.rrd")).unwrap();
    }
}
