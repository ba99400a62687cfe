//! `drive.mcap`: the per-step log of `pipeline navigate drive` (issue 15): one JSON message per
//! step of every trip on `/navigation/step` (schema `schemas/navigation_step.json`), so that
//! Foxglove, the `mcap` CLI or any MCAP reader can replay what the navigator saw and decided.
//! Steps are logged one second apart, trip after trip.

use super::Problem;
use ::mcap::records::MessageHeader;
use qrm_synth::closed_loop::{StepLog, Trip};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// The topic of the steps.
pub const TOPIC: &str = "/navigation/step";

#[derive(Serialize)]
struct StepMessage<'a> {
    trip: usize,
    goal: u32,
    #[serde(flatten)]
    step: &'a StepLog,
}

/// Writes every step of `trips` to `path` (a temporary file; the caller moves it into place).
pub fn write_drive_log(path: &Path, trips: &[Trip]) -> Result<(), Problem> {
    let file = qrm_atomic_file::create_file(path)?;
    let mut writer = ::mcap::Writer::new(BufWriter::new(file))?;
    let schema = writer.add_schema(
        "qrm.NavigationStep",
        "jsonschema",
        include_bytes!("schemas/navigation_step.json"),
    )?;
    let channel = writer.add_channel(schema, TOPIC, "json", &BTreeMap::new())?;
    let steps = trips
        .iter()
        .flat_map(|t| t.steps.iter().map(move |s| (t.number, t.goal, s)));
    for (sequence, (trip, goal, step)) in steps.enumerate() {
        let data = serde_json::to_vec(&StepMessage { trip, goal, step })?;
        let nanoseconds = sequence as u64 * 1_000_000_000;
        writer.write_to_known_channel(
            &MessageHeader {
                channel_id: channel,
                sequence: sequence as u32,
                log_time: nanoseconds,
                publish_time: nanoseconds,
            },
            &data,
        )?;
    }
    writer.finish()?;
    Ok(())
}
