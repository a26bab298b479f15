//! Running variants: each loaded from the shared [`Loader`] (its overrides applied, its
//! programs and models from the cache), simulated, and reduced to a [`Row`]. Threads take
//! the next variant from a shared counter; rows are kept by index, so the table is the
//! same whatever the number of threads.

use std::path::Path;
use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use vworks_cell::{Loader, Override};
use vworks_se::engine::{RunResult, Simulation};
use vworks_se::mcaplog::McapLog;
use vworks_se::result::Outcome;

/// One variant's result: what the sweep table holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The variant's index (0-based, in sweep order).
    pub index: usize,
    /// Its values (path, value as the workcell would write it).
    pub values: Vec<(String, toml::Value)>,
    /// `completed`, `collision`, `deadlock`, `error`, `until`, `interrupted` (stopped by
    /// [`RunOptions::stop`]), or `invalid` (the variant did not load: see `error`).
    pub outcome: String,
    /// The run's end (s).
    pub end_time: f64,
    /// Each robot's cycle time (s): when its program ended (`None` if it did not).
    pub cycle_times: Vec<(String, Option<f64>)>,
    /// Collisions (contacts that started).
    pub collisions: usize,
    /// The closest two bodies came (m), if closer than the cell's `clearance` (a near
    /// miss) or touching (0); `None` if they never came within it.
    pub min_clearance: Option<f64>,
    /// The deadlock, error or load error, in one line (empty if none).
    pub error: String,
}

impl Row {
    fn of(index: usize, overrides: &[Override], r: &RunResult) -> Row {
        let near = r
            .warnings
            .iter()
            .filter_map(|w| w.distance_m)
            .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.min(d))));
        Row {
            index,
            values: values(overrides),
            outcome: r.outcome.name().to_string(),
            end_time: r.end_time_ns as f64 / 1e9,
            cycle_times: r
                .robots
                .iter()
                .map(|s| {
                    let ended = s.ended == vworks_se::stats::Ending::Ended;
                    (s.name.clone(), ended.then_some(s.end_time_ns as f64 / 1e9))
                })
                .collect(),
            collisions: r.collisions.len(),
            min_clearance: if r.collisions.is_empty() {
                near
            } else {
                Some(0.0)
            },
            error: r
                .errors
                .first()
                .map(|e| e.message.lines().next().unwrap_or_default().to_string())
                .unwrap_or_default(),
        }
    }

    fn invalid(index: usize, overrides: &[Override], why: String) -> Row {
        Row {
            index,
            values: values(overrides),
            outcome: "invalid".into(),
            end_time: 0.0,
            cycle_times: Vec::new(),
            collisions: 0,
            min_clearance: None,
            error: why.lines().next().unwrap_or_default().to_string(),
        }
    }

    /// Completed without a collision: a candidate for the summary's best.
    pub fn feasible(&self) -> bool {
        self.outcome == Outcome::Completed.name() && self.collisions == 0
    }
}

fn values(overrides: &[Override]) -> Vec<(String, toml::Value)> {
    overrides
        .iter()
        .map(|o| (o.path.clone(), o.value.clone()))
        .collect()
}

/// How to run the variants.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Threads (0: one per core).
    pub jobs: usize,
    /// Stop each run at this time (ns).
    pub until_ns: Option<i64>,
    /// Write each variant's MCAP log into this folder (`variant-00042.mcap`).
    pub keep_logs: Option<std::path::PathBuf>,
    /// When this becomes true, the runs under way end between two events (outcome
    /// `interrupted`): with `run_variants`' `stop`, a sweep of endless programs can be
    /// stopped.
    pub stop: Option<Arc<AtomicBool>>,
}

/// Runs `variants` of the loader's workcell; `progress` is called with the number done
/// after each one; `stop` ends the sweep early (the rows not run are missing). The rows
/// are in variant order.
pub fn run_variants(
    loader: &Loader,
    variants: &[Vec<Override>],
    options: &RunOptions,
    progress: &(dyn Fn(usize) + Sync),
    stop: Option<&AtomicBool>,
) -> Vec<Row> {
    let jobs = match options.jobs {
        0 => std::thread::available_parallelism().map_or(1, usize::from),
        n => n,
    }
    .min(variants.len().max(1));
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let rows: Mutex<Vec<Option<Row>>> = Mutex::new(vec![None; variants.len()]);
    let work = || {
        loop {
            if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                return;
            }
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(overrides) = variants.get(i) else {
                return;
            };
            let row = run_one(loader, i, overrides, options);
            if let Ok(mut r) = rows.lock() {
                r[i] = Some(row);
            }
            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
        }
    };
    if jobs <= 1 {
        work();
    } else {
        std::thread::scope(|s| {
            for _ in 0..jobs {
                s.spawn(work);
            }
        });
    }
    rows.into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .into_iter()
        .flatten()
        .collect()
}

/// One variant: load, simulate (with its log if asked), reduce.
pub fn run_one(loader: &Loader, index: usize, overrides: &[Override], options: &RunOptions) -> Row {
    let cell = match loader.load(overrides) {
        Ok(c) => Arc::new(c),
        Err(e) => return Row::invalid(index, overrides, e.to_string()),
    };
    let mut sim = Simulation::new(Arc::clone(&cell));
    if let Some(stop) = &options.stop {
        sim = sim.with_stop(Arc::clone(stop));
    }
    if let Some(dir) = &options.keep_logs {
        let path = dir.join(format!("variant-{index:05}.mcap"));
        match McapLog::create(Path::new(&path), &cell, 1) {
            Ok(log) => sim = sim.with_log(log),
            Err(e) => return Row::invalid(index, overrides, e.to_string()),
        }
    }
    let r = sim.run(options.until_ns);
    Row::of(index, overrides, &r)
}
