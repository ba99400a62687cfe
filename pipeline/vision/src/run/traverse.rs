//! `pipeline run` as library calls: [`detect_survey`] decodes and detects every station of a
//! survey in parallel, then [`map_stations`] maps them in order (000 §IV–§VI). Progress and
//! warnings go through [`Progress`], so that the CLI can draw bars and a library user can
//! ignore them; each mapped station is handed to a callback (the CLI's recorders).

use super::front_end::{detect_station, FrontEndResult};
use super::mapper::Mapper;
use super::record::StationRecord;
use super::summary::RunSummary;
use crate::association::AssociationSettings;
use crate::calib::Calibration;
use crate::detection::DetectorSettings;
use crate::ranging::SensorModel;
use crate::survey::Survey;
use qrm_core::calculus::Calculus;
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;
use thiserror::Error;

/// The stages of a run that report progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Decoding and detection, station by station in parallel.
    Detect,
    /// Ranging, association and fusion, station by station in order.
    Map,
}

/// What a run reports as it goes. Detection calls it from worker threads.
pub trait Progress: Sync {
    /// `stage` begins with `stations` stations to do.
    fn begin(&self, _stage: Stage, _stations: usize) {}
    /// One more station of the current stage is done.
    fn advance(&self) {}
    /// The current stage is over.
    fn end(&self) {}
    /// A station was skipped, or mapped with a problem (too few detections, a contradiction).
    fn warn(&self, _message: &str) {}
}

/// Reports nothing.
pub struct Quiet;

impl Progress for Quiet {}

/// The settings of every stage of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSettings {
    pub detector: DetectorSettings,
    pub sensor: SensorModel,
    pub association: AssociationSettings,
}

#[derive(Debug, Error)]
pub enum RunError {
    #[error("none of the {stations} stations in {} could be read", directory.display())]
    NothingReadable { stations: usize, directory: PathBuf },
}

/// Every station of a survey decoded and detected, in survey order.
pub struct Detected {
    pub stations: Vec<FrontEndResult>,
    /// Wall time of the stage, seconds.
    pub wall_seconds: f64,
}

/// Decodes and detects every station of `survey` on all cores. A station whose primary image
/// cannot be read is kept as a warning (reported when it is mapped); when no station can be
/// read at all, every warning is reported and the run fails.
pub fn detect_survey(
    survey: &Survey,
    calib: &Calibration,
    settings: &DetectorSettings,
    progress: &dyn Progress,
) -> Result<Detected, RunError> {
    let started = Instant::now();
    progress.begin(Stage::Detect, survey.stations.len());
    let stations: Vec<FrontEndResult> = survey
        .stations
        .par_iter()
        .map(|station| {
            let result = detect_station(station, &survey.directory, calib, settings);
            progress.advance();
            result
        })
        .collect();
    progress.end();
    if stations.iter().all(|r| r.station.is_err()) {
        for warning in stations.iter().filter_map(|r| r.station.as_ref().err()) {
            progress.warn(warning);
        }
        return Err(RunError::NothingReadable {
            stations: survey.stations.len(),
            directory: survey.directory.clone(),
        });
    }
    Ok(Detected {
        stations,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}

/// A mapped survey: the mapper (map, gallery, sightings), one record per mapped station, and
/// the warnings of the stations that were skipped.
pub struct Traverse<C: Calculus> {
    pub mapper: Mapper<C>,
    pub records: Vec<StationRecord>,
    pub skipped: Vec<String>,
    /// Wall time of the mapping stage, seconds.
    pub wall_seconds: f64,
}

impl<C: Calculus> Traverse<C> {
    /// The figures of `summary.json`, given the detection stage's wall time.
    pub fn summary(&self, detect_wall_seconds: f64) -> RunSummary {
        RunSummary::of(
            &self.records,
            &self.mapper,
            self.skipped.len(),
            detect_wall_seconds,
            self.wall_seconds,
        )
    }
}

/// Maps the detected stations in order with `mapper`; `on_station` sees every station's record
/// with the map after it, and its error stops the run.
pub fn map_stations<C: Calculus, E>(
    detected: &Detected,
    mut mapper: Mapper<C>,
    progress: &dyn Progress,
    mut on_station: impl FnMut(&StationRecord, &Mapper<C>) -> Result<(), E>,
) -> Result<Traverse<C>, E> {
    let started = Instant::now();
    let mut records: Vec<StationRecord> = Vec::new();
    let mut skipped = Vec::new();
    progress.begin(Stage::Map, detected.stations.len());
    for result in &detected.stations {
        let station = match &result.station {
            Ok(station) => station,
            Err(warning) => {
                progress.warn(warning);
                skipped.push(warning.clone());
                progress.advance();
                continue;
            }
        };
        let mut record = mapper.process(records.len(), station);
        record.seconds.decode = result.decode_seconds;
        record.seconds.detect = result.detect_seconds;
        for warning in &record.warnings {
            progress.warn(warning);
        }
        let recording = Instant::now();
        on_station(&record, &mapper)?;
        record.seconds.recording = recording.elapsed().as_secs_f64();
        records.push(record);
        progress.advance();
    }
    progress.end();
    Ok(Traverse {
        mapper,
        records,
        skipped,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}
