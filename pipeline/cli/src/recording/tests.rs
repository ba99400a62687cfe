//! The recorders on synthetic stations: every channel, one message per station, messages that
//! match their schemas, and nothing at the target unless `finish` succeeded.
//!
//! With `QRM_RECORDING_SAMPLES=DIR` the finished recordings are also copied to `DIR`
//! (`sample.mcap`, `sample.rrd`), for CI to check them with the independent Python tools.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::*;
use qrm_vision::detection::Channels;
use qrm_vision::run::{
    Association, DetectionRecord, Exclusion, FusionRecord, LateSighting, MetricsRecord,
    RangeRecord, RegistrationRecord, StageSeconds,
};

const STATIONS: usize = 16;

const TOPICS: [&str; 7] = [
    "/detections",
    "/bearings",
    "/range_order",
    "/association",
    "/measurements",
    "/map_metrics",
    "/rng",
];

fn station(index: usize) -> StationRecord {
    let count = 2 + index % 4;
    let detections = (0..count)
        .map(|k| {
            let column = (k * 1000 + index * 37) as u32;
            DetectionRecord {
                // The last detection of odd stations wraps around the seam.
                bbox: [
                    column,
                    300,
                    column + if k == 3 { 4200 - column } else { 60 },
                    420,
                ],
                centroid: [f64::from(column) + 30.0, 360.0],
                contact_row: 420.0,
                contact_slack_rows: 0.0,
                flat: false,
                pixels: 5000 + k as u32,
                stereo_column: (k % 2 == 0).then_some(f64::from(column) + 22.5),
                bearing: k as f64 * 1.5 - 3.0,
                bearing_uncertainty: 0.01,
                range: RangeRecord {
                    ground: Some([2.0 + k as f64, 4.0 + k as f64]),
                    stereo: (k % 2 == 0).then_some([2.5, 3.5]),
                    size: (k == 1).then_some([10.0, f64::INFINITY]),
                    fused: [2.5, if k == 1 { f64::INFINITY } else { 3.5 }],
                    conflict: k == 1,
                },
                association: match k {
                    0 => Association::Matched { landmark: 7 },
                    1 => Association::New {
                        landmark: 12 + index as u32,
                    },
                    2 => Association::HeldBack {
                        candidates: vec![3, 5],
                    },
                    3 => Association::default(),
                    _ => Association::Unused {
                        reason: Some(Exclusion::Touching),
                    },
                },
            }
        })
        .collect();
    StationRecord {
        index,
        station: format!("station_{index:03}"),
        files: vec![
            format!("station_{index:03}_left.png"),
            format!("station_{index:03}_right.png"),
        ],
        digests: Vec::new(),
        channels: Channels::Colour,
        detections,
        order: vec![(0, 1), (0, 2)],
        // The sketch registered and was believed; station 0's frame, from station 2 on, fitted
        // a motion chance explains.
        registrations: std::iter::once(RegistrationRecord {
            frame: None,
            pairs: vec![(0, 7)],
            nfa: Some(1e-4),
            believed: true,
        })
        .chain((index >= 2).then_some(RegistrationRecord {
            frame: Some(0),
            pairs: vec![(0, 7), (1, 4)],
            nfa: None,
            believed: false,
        }))
        .collect(),
        fusion: FusionRecord {
            usable: count,
            landmarks: count,
            triples: count * (count - 1) * (count - 2) / 6,
            relations_tightened: index,
            resolved_held_back: index % 2,
            recognised: Vec::new(),
            revisited: (index == 3)
                .then_some(LateSighting {
                    station: 1,
                    detection: 0,
                    landmark: 2,
                })
                .into_iter()
                .collect(),
            contradiction: (index == 5).then(|| "triple (1, 2, 3) emptied".to_string()),
            splits: Vec::new(),
        },
        metrics: MetricsRecord {
            landmarks: 3 + index,
            triples: 10 * index,
            open_fraction: 1.0 / (1.0 + index as f64),
            fully_constrained_fraction: index as f64 / STATIONS as f64,
            rng_certain: index,
            rng_uncertain: 2,
            rng_cost: 2.5,
        },
        seconds: StageSeconds {
            decode: 0.1,
            detect: 0.2,
            range: 0.01,
            associate: 0.02,
            map: 0.5,
            metrics: 0.05,
            recording: 0.0,
        },
        warnings: if index == 5 {
            vec!["map rejected the panorama".to_string()]
        } else {
            Vec::new()
        },
    }
}

fn drawing(index: usize) -> RngDrawing {
    let landmarks: Vec<_> = (0..3 + index as u32)
        .map(|id| (id, [f64::from(id).cos() * 10.0, f64::from(id).sin() * 10.0]))
        .collect();
    let edges = landmarks
        .windows(2)
        .map(|w| (w[0].0, w[1].0, f64::from(w[0].0 % 3) / 2.0))
        .collect();
    RngDrawing { landmarks, edges }
}

/// A 4096×1024 panorama like the rover's: smooth shading plus sensor-like noise, so the `.rrd`
/// size is near a real run's.
#[cfg(feature = "rerun")]
fn panorama() -> image::RgbImage {
    let mut state = 0x9e37_79b9_u32;
    image::RgbImage::from_fn(4096, 1024, |x, y| {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let noise = (state % 16) as u8;
        image::Rgb([
            (x / 16) as u8 / 2 + noise,
            (y / 4) as u8 / 2 + noise,
            100 + noise,
        ])
    })
}

fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("qrm-recording-{name}-"))
        .tempdir()
        .unwrap()
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    names
}

fn record(mut recorder: Box<dyn Recorder>, stations: usize, panorama: &image::RgbImage) {
    for index in 0..stations {
        recorder.station(&station(index), panorama).unwrap();
        recorder.rng(index, &drawing(index)).unwrap();
    }
    recorder.finish().unwrap().commit().unwrap();
}

/// Copies a finished recording to `$QRM_RECORDING_SAMPLES/sample.<extension>`.
fn keep_sample(path: &Path) {
    if let Some(dir) = std::env::var_os("QRM_RECORDING_SAMPLES") {
        let dir = PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        let extension = path.extension().unwrap().to_str().unwrap();
        std::fs::copy(path, dir.join(format!("sample.{extension}"))).unwrap();
    }
}

/// Checks `value` against the parts of JSON Schema that `schemas/*.json` use.
fn check(value: &Value, schema: &Value, root: &Value, at: &str) {
    if let Some(reference) = schema["$ref"].as_str() {
        let name = reference.strip_prefix("#/$defs/").unwrap();
        return check(value, &root["$defs"][name], root, at);
    }
    let kind = match value {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(n) if n.is_u64() || n.is_i64() => "integer",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    };
    let allows = |t: &Value| t == kind || (t == "number" && kind == "integer");
    match &schema["type"] {
        Value::Null => {}
        Value::Array(types) => assert!(types.iter().any(allows), "{at}: {kind} not in {types:?}"),
        t => assert!(allows(t), "{at}: {kind} is not {t}"),
    }
    if let Some(options) = schema["enum"].as_array() {
        assert!(options.contains(value), "{at}: {value} not in {options:?}");
    }
    match value {
        Value::Object(fields) => {
            for key in schema["required"].as_array().into_iter().flatten() {
                assert!(fields.contains_key(key.as_str().unwrap()), "{at}: no {key}");
            }
            for (key, field) in fields {
                let field_schema = &schema["properties"][key];
                assert!(!field_schema.is_null(), "{at}: {key} not in the schema");
                check(field, field_schema, root, &format!("{at}.{key}"));
            }
        }
        Value::Array(items) => {
            if let Some(n) = schema["minItems"].as_u64() {
                assert!(items.len() as u64 >= n, "{at}: too few items");
            }
            if let Some(n) = schema["maxItems"].as_u64() {
                assert!(items.len() as u64 <= n, "{at}: too many items");
            }
            for (i, item) in items.iter().enumerate() {
                check(item, &schema["items"], root, &format!("{at}[{i}]"));
            }
        }
        _ => {}
    }
}

/// The JSON of an MCAP message, checked against the JSON Schema its channel carries.
fn checked(message: &::mcap::Message) -> Value {
    let channel = &message.channel;
    assert_eq!(channel.message_encoding, "json");
    let schema = channel.schema.as_ref().unwrap();
    assert_eq!(schema.encoding, "jsonschema");
    let schema: Value = serde_json::from_slice(&schema.data).unwrap();
    let value: Value = serde_json::from_slice(&message.data).unwrap();
    check(&value, &schema, &schema, &channel.topic);
    value
}

/// Records `STATIONS` stations into `dir/file` with recorders from `create`, after checking
/// that a recording dropped unfinished leaves nothing behind; returns the finished file.
fn record_whole(
    dir: &Path,
    file: &str,
    create: impl Fn(&Path) -> Box<dyn Recorder>,
    panorama: &image::RgbImage,
) -> PathBuf {
    let path = dir.join(file);
    let mut recorder = create(&path);
    recorder.station(&station(0), panorama).unwrap();
    assert!(!path.exists(), "the target appears only on finish");
    drop(recorder);
    assert!(
        names_in(dir).is_empty(),
        "an unfinished recording leaves nothing"
    );
    record(create(&path), STATIONS, panorama);
    assert_eq!(names_in(dir), [file]);
    keep_sample(&path);
    path
}

#[test]
fn mcap_has_every_channel_once_per_station_matching_its_schema() {
    let dir = scratch("mcap");
    let path = record_whole(
        dir.path(),
        "run.mcap",
        |path| Box::new(McapRecorder::create(path).unwrap()),
        &image::RgbImage::new(8, 2),
    );

    let bytes = std::fs::read(&path).unwrap();
    let summary = ::mcap::Summary::read(&bytes).unwrap().unwrap();
    let topics: BTreeSet<_> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    assert_eq!(topics, TOPICS.into_iter().collect());
    let stats = summary.stats.unwrap();
    assert_eq!(stats.message_count, (STATIONS * TOPICS.len()) as u64);
    assert_eq!(
        stats.message_end_time,
        (STATIONS as u64 - 1) * 1_000_000_000
    );

    let mut indices: BTreeMap<String, Vec<u64>> = BTreeMap::new();
    for message in ::mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        let channel = &message.channel;
        let value = checked(&message);
        let index = value["index"].as_u64().unwrap();
        assert_eq!(message.log_time, index * 1_000_000_000);
        assert_eq!(message.publish_time, message.log_time);
        let expected = station(index as usize);
        match channel.topic.as_str() {
            "/detections" => {
                assert_eq!(value["station"], expected.station);
                let detections = value["detections"].as_array().unwrap();
                assert_eq!(detections.len(), expected.detections.len());
                assert_eq!(detections[1]["stereo_column"], Value::Null);
            }
            "/range_order" => {
                // JSON has no infinity: an unbounded interval ends in null.
                assert_eq!(value["ranges"][1]["fused"][1], Value::Null);
                assert_eq!(value["nearer"], serde_json::json!([[0, 1], [0, 2]]));
            }
            "/association" => {
                let decisions = &value["associations"];
                assert_eq!(decisions[0]["decision"], "matched");
                assert_eq!(decisions[0]["landmark"], 7);
                if expected.detections.len() > 2 {
                    assert_eq!(decisions[2]["candidates"], serde_json::json!([3, 5]));
                }
                let registrations = value["registrations"].as_array().unwrap();
                assert_eq!(registrations.len(), expected.registrations.len());
                assert_eq!(
                    registrations[0],
                    serde_json::json!({"frame": null, "pairs": [[0, 7]], "nfa": 1e-4, "believed": true})
                );
                if index >= 2 {
                    // An unbounded NFA is written as null, as JSON has no infinity.
                    assert_eq!(registrations[1]["frame"], 0);
                    assert_eq!(registrations[1]["nfa"], Value::Null);
                    assert_eq!(registrations[1]["believed"], false);
                }
            }
            "/measurements" => {
                assert_eq!(
                    value["contradiction"].as_str(),
                    expected.fusion.contradiction.as_deref()
                );
            }
            "/map_metrics" => assert_eq!(value["landmarks"], expected.metrics.landmarks),
            "/rng" => {
                assert_eq!(
                    value["landmarks"].as_array().unwrap().len(),
                    3 + index as usize
                )
            }
            _ => {}
        }
        indices
            .entry(channel.topic.clone())
            .or_default()
            .push(index);
    }
    let every_station: Vec<u64> = (0..STATIONS as u64).collect();
    assert_eq!(indices.len(), TOPICS.len());
    for (topic, seen) in indices {
        assert_eq!(seen, every_station, "{topic}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Trip `number` of `steps` logged steps toward `goal`, every optional field set on odd steps
/// only.
fn trip(number: usize, goal: u32, steps: usize) -> qrm_synth::closed_loop::Trip {
    use qrm_synth::closed_loop::{Outcome, StepLog, Trip};
    let commands = ["toward", "closing_in", "arrived", "lost"];
    Trip {
        number,
        start: [1.0, -2.0],
        goal,
        outcome: Outcome::Arrived,
        route: vec![3, goal],
        replans: 1,
        path: (0..=steps).map(|k| [k as f64 * 0.5, -2.0]).collect(),
        collisions: 0,
        avoided: 1,
        navigator_seconds: vec![0.1; steps],
        in_goal_cell: true,
        length_m: steps as f64 * 0.5,
        straight_m: 3.0,
        reference_m: None,
        steps: (0..steps)
            .map(|k| StepLog {
                step: k,
                position: [k as f64 * 0.5, -2.0],
                heading_deg: -90.0 + k as f64,
                identified: (0..k as u32).collect(),
                detections: 2 * k,
                cell: (k % 2 == 1).then_some(3),
                command: commands[k % commands.len()],
                target: (k % 2 == 1).then_some(goal),
                bearing_deg: (k % 2 == 1).then_some(12.5),
                replans: k / 2,
                avoided: k == 1,
                navigator_seconds: 0.1,
                detect_seconds: 0.05,
            })
            .collect(),
    }
}

/// drive.mcap: one message per step of every trip, in order, one second apart, each matching
/// the schema the file carries (no field missing and none it does not describe).
#[test]
fn drive_log_has_one_message_per_step_matching_its_schema() {
    let dir = scratch("drive");
    let path = dir.path().join("drive.mcap");
    let trips = [trip(0, 7, 5), trip(1, 9, 3)];
    navigation_log::write_drive_log(&path, &trips).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let mut seen = Vec::new();
    for (sequence, message) in ::mcap::MessageStream::new(&bytes).unwrap().enumerate() {
        let message = message.unwrap();
        assert_eq!(message.channel.topic, navigation_log::TOPIC);
        let value = checked(&message);
        assert_eq!(message.log_time, sequence as u64 * 1_000_000_000);
        seen.push((
            value["trip"].as_u64().unwrap(),
            value["goal"].as_u64().unwrap(),
            value["step"].as_u64().unwrap(),
        ));
    }
    let expected: Vec<(u64, u64, u64)> = (0..5)
        .map(|k| (0, 7, k))
        .chain((0..3).map(|k| (1, 9, k)))
        .collect();
    assert_eq!(seen, expected);
    std::fs::remove_dir_all(dir.path()).ok();
}

#[test]
fn recording_errors_name_the_target() {
    let path = Path::new("/nonexistent-qrm-dir/run.mcap");
    let error = McapRecorder::create(path).err().unwrap();
    assert_eq!(error.path, path);
    assert!(error
        .to_string()
        .starts_with("recording /nonexistent-qrm-dir/run.mcap: "));
}

#[cfg(feature = "rerun")]
#[test]
fn rrd_is_written_whole_on_finish_only() {
    let dir = scratch("rrd");
    let path = record_whole(
        dir.path(),
        "run.rrd",
        |path| Box::new(RerunRecorder::create(path).unwrap()),
        &panorama(),
    );
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..4], b"RRF2", "an rrd stream header");
    // 16 halved panoramas of 2048×512 RGB are 50 MB raw; rerun's compression keeps them smaller.
    assert!(bytes.len() < 60_000_000, "{} bytes", bytes.len());
}
