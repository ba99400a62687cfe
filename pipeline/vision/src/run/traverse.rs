//! `pipeline run` as library calls: [`traverse_survey`] decodes and detects the stations of a
//! survey on a pool of threads of their own while it maps them, in survey order, as each is
//! detected (000 §IV–§VI). Mapping is sequential by nature and uses one core for most of a
//! station, so detection keeps the others busy meanwhile instead of waiting for it. Progress and
//! warnings go through [`Progress`], so that the CLI can draw bars and a library user can ignore
//! them; each mapped station is handed to a callback (the CLI's recorders).

use super::front_end::{detect_station, FrontEndResult};
use super::mapper::Mapper;
use super::record::{MetricsRecord, StationRecord};
use super::summary::RunSummary;
use crate::association::AssociationSettings;
use crate::calib::Calibration;
use crate::detection::DetectorSettings;
use crate::ranging::SensorModel;
use crate::survey::Survey;
use qrm_core::calculus::Calculus;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver};
use std::sync::Mutex;
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

/// What a run reports as it goes. Detection calls it from worker threads, mapping from the
/// calling thread.
pub trait Progress: Sync {
    /// `stage` begins with `stations` stations to do.
    fn begin(&self, _stage: Stage, _stations: usize) {}
    /// One more station of `stage` is done. The two stages run at once, so calls of both
    /// interleave; each stage's own calls come one at a time.
    fn advance(&self, _stage: Stage) {}
    /// `stage` is over.
    fn end(&self, _stage: Stage) {}
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
pub enum RunError<E> {
    #[error("none of the {stations} stations in {} could be read", directory.display())]
    NothingReadable { stations: usize, directory: PathBuf },
    #[error("cannot start the detection threads: {0}")]
    Threads(String),
    /// The caller's start or per-station callback failed.
    #[error(transparent)]
    Caller(E),
}

/// A mapped survey: the mapper (map, gallery, sightings), one record per mapped station, and
/// the warnings of the stations that were skipped.
pub struct Traverse<C: Calculus> {
    /// The map as published ([`Mapper::finish`]).
    pub mapper: Mapper<C>,
    /// Its metrics: the last station's record has those of the map before uncorroborated
    /// landmarks were left out.
    pub published: MetricsRecord,
    pub records: Vec<StationRecord>,
    pub skipped: Vec<String>,
    /// Wall time of detection, from the start to the last station detected, seconds.
    pub wall_front_end: f64,
    /// Wall time of mapping, from the first station mapped to the last, seconds: it overlaps
    /// detection's.
    pub wall_mapping: f64,
}

impl<C: Calculus> Traverse<C> {
    /// The figures of `summary.json`.
    pub fn summary(&self) -> RunSummary {
        RunSummary::of(
            &self.records,
            &self.mapper,
            &self.published,
            self.skipped.len(),
            self.wall_front_end,
            self.wall_mapping,
        )
    }
}

/// Detects every station of `survey` and maps it with `mapper`, in survey order, each as soon
/// as it and those before it are detected. `start` runs once, when the first station that can
/// be read is detected (the CLI creates its output directory and recorders there), and its
/// result goes to `on_station` with every station's record and the map after it; an error of
/// either stops the run. A station whose primary image cannot be read is skipped with a
/// warning; when none can be read, every warning is reported and the run fails before `start`.
pub fn traverse_survey<C: Calculus, S, E>(
    survey: &Survey,
    calib: &Calibration,
    detector: &DetectorSettings,
    mut mapper: Mapper<C>,
    progress: &dyn Progress,
    start: impl FnOnce() -> Result<S, E>,
    mut on_station: impl FnMut(&mut S, &StationRecord, &Mapper<C>) -> Result<(), E>,
) -> Result<(Traverse<C>, S), RunError<E>> {
    let started = Instant::now();
    // A pool of its own: on the global pool, mapping's parallel measurements would queue behind
    // every station's detection.
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .map_err(|e| RunError::Threads(e.to_string()))?;
    let stop = AtomicBool::new(false);
    let detected_at = Mutex::new(0.0);
    let (sender, receiver) = channel();
    progress.begin(Stage::Detect, survey.stations.len());
    std::thread::scope(|scope| {
        scope.spawn(|| {
            // First in, first out: stations are detected in survey order, as mapping needs them.
            pool.scope_fifo(|fifo| {
                for (index, station) in survey.stations.iter().enumerate() {
                    let (sender, stop) = (sender.clone(), &stop);
                    fifo.spawn_fifo(move |_| {
                        if stop.load(Ordering::Relaxed) {
                            return;
                        }
                        let result = detect_station(station, &survey.directory, calib, detector);
                        progress.advance(Stage::Detect);
                        // Mapping may have stopped on an error and dropped its end.
                        let _ = sender.send((index, result));
                    });
                }
            });
            drop(sender);
            *detected_at.lock().expect("no panics hold it") = started.elapsed().as_secs_f64();
            progress.end(Stage::Detect);
        });
        let mut stations = InOrder {
            receiver,
            waiting: BTreeMap::new(),
            next: 0,
        };
        let outcome = map_in_order(
            &mut stations,
            survey,
            &mut mapper,
            progress,
            start,
            &mut on_station,
        );
        // Detection left to do is of no use once mapping has stopped.
        stop.store(true, Ordering::Relaxed);
        drop(stations);
        outcome
    })
    .map(|(records, skipped, wall_mapping, state)| {
        let published = mapper.finish();
        let traverse = Traverse {
            mapper,
            published,
            records,
            skipped,
            wall_front_end: *detected_at.lock().expect("no panics hold it"),
            wall_mapping,
        };
        (traverse, state)
    })
}

/// A mapped sequence: its records, the skipped stations' warnings, the mapping's wall time and
/// the caller's state.
type Mapped<S> = (Vec<StationRecord>, Vec<String>, f64, S);

/// The mapping half of [`traverse_survey`].
fn map_in_order<C: Calculus, S, E>(
    stations: &mut InOrder,
    survey: &Survey,
    mapper: &mut Mapper<C>,
    progress: &dyn Progress,
    start: impl FnOnce() -> Result<S, E>,
    on_station: &mut impl FnMut(&mut S, &StationRecord, &Mapper<C>) -> Result<(), E>,
) -> Result<Mapped<S>, RunError<E>> {
    // The unreadable stations before the first readable one wait for it: with none at all,
    // the run fails before anything is started.
    let mut unreadable = Vec::new();
    let first = loop {
        match stations.next() {
            Some(result) if result.station.is_err() => unreadable.push(result),
            Some(result) => break result,
            None => {
                for warning in unreadable.iter().filter_map(|r| r.station.as_ref().err()) {
                    progress.warn(warning);
                }
                return Err(RunError::NothingReadable {
                    stations: survey.stations.len(),
                    directory: survey.directory.clone(),
                });
            }
        }
    };
    let mut state = start().map_err(RunError::Caller)?;
    let started = Instant::now();
    let mut records: Vec<StationRecord> = Vec::new();
    let mut skipped = Vec::new();
    progress.begin(Stage::Map, survey.stations.len());
    for result in unreadable.into_iter().chain([first]).chain(stations) {
        let station = match &result.station {
            Ok(station) => station,
            Err(warning) => {
                progress.warn(warning);
                skipped.push(warning.clone());
                progress.advance(Stage::Map);
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
        on_station(&mut state, &record, mapper).map_err(RunError::Caller)?;
        record.seconds.recording = recording.elapsed().as_secs_f64();
        records.push(record);
        progress.advance(Stage::Map);
    }
    progress.end(Stage::Map);
    Ok((records, skipped, started.elapsed().as_secs_f64(), state))
}

/// Detected stations in survey order, from the detection threads' results in the order they
/// were done.
struct InOrder {
    receiver: Receiver<(usize, FrontEndResult)>,
    waiting: BTreeMap<usize, FrontEndResult>,
    next: usize,
}

impl Iterator for InOrder {
    type Item = FrontEndResult;

    fn next(&mut self) -> Option<FrontEndResult> {
        loop {
            if let Some(result) = self.waiting.remove(&self.next) {
                self.next += 1;
                return Some(result);
            }
            // Every sender gone: detection is over (or one of its threads panicked, which the
            // scope raises when it joins).
            let (index, result) = self.receiver.recv().ok()?;
            self.waiting.insert(index, result);
        }
    }
}
