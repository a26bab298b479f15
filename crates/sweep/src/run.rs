//! Running variants: each loaded from the shared [`Loader`] (its overrides applied, its
//! programs and models from the cache), simulated, and reduced to a [`Row`]. Threads take
//! the next variant from a shared counter and hand each row over in variant order as soon
//! as every row before it is done ([`run_streamed`]), so the table is the same whatever
//! the number of threads, and only the rows that finished early are held: a thread does
//! not start a variant more than [`WINDOW`] after the first one not yet done.
//!
//! A watchdog stops a variant that runs longer than its wall-time limit (its row's
//! outcome is `timeout`) and, when the sweep is stopped (Ctrl-C), every running variant
//! at once (their rows are left out).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use vworks_app::{CellSource, LogRequest, RunError, RunRequest};
use vworks_cell::{Loader, Override};
use vworks_log::result::{Outcome, RunResult};

/// How a variant ended: its run's [`Outcome`], or what only a sweep says of a variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowOutcome {
    /// The run ended so (`error` also when its log could not be written).
    Run(Outcome),
    /// Stopped at its wall-time limit.
    Timeout,
    /// The variant did not load: the row's `error` says why.
    Invalid,
}

impl RowOutcome {
    /// Every outcome a row may have, in the order the sweep's summary counts them.
    pub const ALL: [RowOutcome; 8] = [
        RowOutcome::Run(Outcome::Completed),
        RowOutcome::Run(Outcome::Collision),
        RowOutcome::Run(Outcome::Deadlock),
        RowOutcome::Run(Outcome::Error),
        RowOutcome::Run(Outcome::Until),
        RowOutcome::Run(Outcome::Interrupted),
        RowOutcome::Timeout,
        RowOutcome::Invalid,
    ];

    /// As the table writes it: the run's outcome as in `run --json`, `timeout`, `invalid`.
    pub fn name(self) -> &'static str {
        match self {
            RowOutcome::Run(o) => o.name(),
            RowOutcome::Timeout => "timeout",
            RowOutcome::Invalid => "invalid",
        }
    }

    /// The outcome a table names (`name`'s inverse), if it is one.
    pub fn from_name(name: &str) -> Option<RowOutcome> {
        RowOutcome::ALL.into_iter().find(|o| o.name() == name)
    }

    /// Its place in [`RowOutcome::ALL`]: an index for counting rows by outcome.
    pub fn index(self) -> usize {
        match self {
            RowOutcome::Run(Outcome::Completed) => 0,
            RowOutcome::Run(Outcome::Collision) => 1,
            RowOutcome::Run(Outcome::Deadlock) => 2,
            RowOutcome::Run(Outcome::Error) => 3,
            RowOutcome::Run(Outcome::Until) => 4,
            RowOutcome::Run(Outcome::Interrupted) => 5,
            RowOutcome::Timeout => 6,
            RowOutcome::Invalid => 7,
        }
    }
}

/// One variant's result: what the sweep table holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The variant's index (0-based, in sweep order).
    pub index: usize,
    /// Its values (path, value as the workcell would write it).
    pub values: Vec<(String, toml::Value)>,
    /// How it ended: the run's outcome (`error` also when its log could not be
    /// written), `timeout` (stopped at its wall-time limit), or `invalid` (the variant did
    /// not load: see `error`).
    pub outcome: RowOutcome,
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
    /// The variant's log (`keep_logs`) could not be written: `error` says why.
    pub log_failed: bool,
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
            outcome: RowOutcome::Run(r.outcome),
            end_time: r.end_time_ns as f64 / 1e9,
            cycle_times: r
                .robots
                .iter()
                .map(|s| {
                    let ended = s.ended == vworks_log::stats::Ending::Ended;
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
            log_failed: false,
        }
    }

    fn invalid(index: usize, overrides: &[Override], why: String) -> Row {
        Row {
            index,
            values: values(overrides),
            outcome: RowOutcome::Invalid,
            end_time: 0.0,
            cycle_times: Vec::new(),
            collisions: 0,
            min_clearance: None,
            error: why.lines().next().unwrap_or_default().to_string(),
            log_failed: false,
        }
    }

    /// The variant's log could not be written: the row is an `error` saying why.
    fn log_failed(mut self, why: &str) -> Row {
        self.outcome = RowOutcome::Run(Outcome::Error);
        self.error = why.lines().next().unwrap_or_default().to_string();
        self.log_failed = true;
        self
    }

    /// Completed without a collision: a candidate for the summary's best.
    pub fn feasible(&self) -> bool {
        self.outcome == RowOutcome::Run(Outcome::Completed) && self.collisions == 0
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
    /// With `keep_logs`: only these variants' logs (`None`: every variant's).
    pub keep_logs_of: Option<VariantSet>,
    /// Stop a variant that runs longer than this (wall time): its row is a `timeout`.
    pub variant_timeout: Option<Duration>,
}

/// Variant numbers, as `--keep-logs-variants 3,7,10-12` lists them: single numbers and
/// ranges (both ends included), in any order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VariantSet {
    /// Sorted, disjoint ranges (both ends included).
    ranges: Vec<(usize, usize)>,
}

impl VariantSet {
    /// Reads `3,7,10-12`; `Err` says which part is wrong and what to write.
    pub fn parse(text: &str) -> Result<VariantSet, String> {
        let mut ranges = Vec::new();
        for part in text.split(',') {
            let part = part.trim();
            let number = |s: &str| s.trim().parse::<usize>().ok();
            let range = match part.split_once('-') {
                None => number(part).map(|n| (n, n)),
                Some((a, b)) => number(a).zip(number(b)),
            };
            match range {
                Some((a, b)) if a <= b => ranges.push((a, b)),
                Some((a, b)) => {
                    return Err(format!(
                        "`{part}` is a range from {a} down to {b}; write it from the smaller: {b}-{a}"
                    ));
                }
                None => {
                    return Err(format!(
                        "`{part}` is not a variant number or a range of them; write e.g. 3,7,10-12"
                    ));
                }
            }
        }
        ranges.sort_unstable();
        let mut merged: Vec<(usize, usize)> = Vec::new();
        for (a, b) in ranges {
            match merged.last_mut() {
                Some(last) if a <= last.1.saturating_add(1) => last.1 = last.1.max(b),
                _ => merged.push((a, b)),
            }
        }
        Ok(VariantSet { ranges: merged })
    }

    /// Whether variant `i` is one of them.
    pub fn contains(&self, i: usize) -> bool {
        let at = self.ranges.partition_point(|(_, b)| *b < i);
        self.ranges.get(at).is_some_and(|(a, _)| *a <= i)
    }

    /// The largest number listed.
    pub fn last(&self) -> Option<usize> {
        self.ranges.last().map(|(_, b)| *b)
    }
}

/// Rows started at most this far past the first one not yet done: the rows held
/// (finished before an earlier one) are fewer.
pub const WINDOW: usize = 1024;

/// Runs `variants` of the loader's workcell; `progress` is called with the number done
/// after each one; `stop` ends the sweep early (the rows not run are missing). The rows
/// are in variant order. (For many variants, [`run_streamed`] holds none of them.)
pub fn run_variants(
    loader: &Loader,
    variants: &[Vec<Override>],
    options: &RunOptions,
    progress: &(dyn Fn(usize) + Sync),
    stop: Option<&Arc<AtomicBool>>,
) -> Vec<Row> {
    let mut rows = Vec::new();
    run_streamed(
        loader,
        variants.len(),
        &|i| variants.get(i).cloned().unwrap_or_default(),
        options,
        progress,
        stop,
        &mut |row| rows.push(row),
    );
    rows
}

/// Runs variants `0..count` (`variant(i)` makes the i-th) and hands each row to `sink` in
/// variant order as soon as it and every row before it are done. `progress` is called
/// with the number done after each; `stop` stops every running variant at once and starts
/// no more (their rows are left out; the rows done are all handed over). Returns the
/// most rows held at once waiting for an earlier one (fewer than [`WINDOW`]).
pub fn run_streamed(
    loader: &Loader,
    count: usize,
    variant: &(dyn Fn(usize) -> Vec<Override> + Sync),
    options: &RunOptions,
    progress: &(dyn Fn(usize) + Sync),
    stop: Option<&Arc<AtomicBool>>,
    sink: &mut (dyn FnMut(Row) + Send),
) -> usize {
    let jobs = match options.jobs {
        0 => std::thread::available_parallelism().map_or(1, usize::from),
        n => n,
    };
    let watch = Watchdog::default();
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let work = |i: usize| {
        let overrides = variant(i);
        let running = watch.start(options.variant_timeout);
        let row = run_watched(loader, i, &overrides, options, &running);
        watch.end(&running);
        row
    };
    std::thread::scope(|s| {
        let watching = s.spawn(|| watch.run(stop));
        let held = schedule(count, jobs, WINDOW, &stopped, &work, progress, sink);
        watch.finish();
        let _ = watching.join();
        held
    })
}

/// Runs `work(i)` for `i` in `0..count` on `jobs` threads, each taking the next `i`, but
/// never one `window` or more past the first not yet done; hands the results to `sink` in
/// order (`None`: no result, skipped). Stops taking work once `stopped()`. Returns the most
/// results held at once.
fn schedule<T: Send>(
    count: usize,
    jobs: usize,
    window: usize,
    stopped: &(dyn Fn() -> bool + Sync),
    work: &(dyn Fn(usize) -> Option<T> + Sync),
    progress: &(dyn Fn(usize) + Sync),
    sink: &mut (dyn FnMut(T) + Send),
) -> usize {
    let state = Mutex::new(Order {
        taken: 0,
        next: 0,
        held: BTreeMap::new(),
        max_held: 0,
        waiting: 0,
        sink,
    });
    let moved = Condvar::new();
    let done = AtomicUsize::new(0);
    let lock = || state.lock().unwrap_or_else(PoisonError::into_inner);
    let thread = || {
        loop {
            let i = {
                let mut o = lock();
                while o.taken >= o.next + window && !stopped() {
                    // Woken when a row is handed over, or to look at `stopped` again.
                    o.waiting += 1;
                    o = moved
                        .wait_timeout(o, Duration::from_millis(50))
                        .unwrap_or_else(PoisonError::into_inner)
                        .0;
                    o.waiting -= 1;
                }
                if stopped() || o.taken >= count {
                    return;
                }
                o.taken += 1;
                o.taken - 1
            };
            let result = work(i);
            let mut o = lock();
            o.put(i, result);
            if o.waiting > 0 {
                moved.notify_all();
            }
            drop(o);
            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
        }
    };
    let jobs = jobs.clamp(1, count.max(1));
    if jobs == 1 {
        thread();
    } else {
        std::thread::scope(|s| {
            for _ in 0..jobs {
                s.spawn(thread);
            }
        });
    }
    let mut o = state.into_inner().unwrap_or_else(PoisonError::into_inner);
    // Stopped: the rows done after one that was not are handed over too, in order.
    for (_, r) in std::mem::take(&mut o.held) {
        if let Some(r) = r {
            (o.sink)(r);
        }
    }
    o.max_held
}

/// Results in order: those that finished before an earlier one wait in `held`.
struct Order<'s, T> {
    /// Indices handed out.
    taken: usize,
    /// The first index not yet handed to the sink.
    next: usize,
    held: BTreeMap<usize, Option<T>>,
    max_held: usize,
    /// Threads waiting for the window to move (woken only if there are some).
    waiting: usize,
    sink: &'s mut (dyn FnMut(T) + Send),
}

impl<T> Order<'_, T> {
    fn put(&mut self, i: usize, result: Option<T>) {
        self.held.insert(i, result);
        self.max_held = self.max_held.max(self.held.len() - 1);
        while let Some(r) = self.held.remove(&self.next) {
            if let Some(r) = r {
                (self.sink)(r);
            }
            self.next += 1;
        }
    }
}

/// A variant being run: its own stop flag, its deadline, and whether it passed it.
struct Running {
    stop: Arc<AtomicBool>,
    deadline: Option<Instant>,
    timed_out: AtomicBool,
}

/// Stops variants past their deadline, and every variant when the sweep is stopped.
#[derive(Default)]
struct Watchdog {
    running: Mutex<Vec<Arc<Running>>>,
    finished: Mutex<bool>,
    wake: Condvar,
}

impl Watchdog {
    fn list(&self) -> MutexGuard<'_, Vec<Arc<Running>>> {
        self.running.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn start(&self, limit: Option<Duration>) -> Arc<Running> {
        let r = Arc::new(Running {
            stop: Arc::new(AtomicBool::new(false)),
            deadline: limit.map(|l| Instant::now() + l),
            timed_out: AtomicBool::new(false),
        });
        self.list().push(Arc::clone(&r));
        r
    }

    fn end(&self, r: &Arc<Running>) {
        self.list().retain(|x| !Arc::ptr_eq(x, r));
    }

    fn finish(&self) {
        *self.finished.lock().unwrap_or_else(PoisonError::into_inner) = true;
        self.wake.notify_all();
    }

    /// Until `finish`: every 10 ms, stops the variants past their deadline, or all of
    /// them once `stop` is set.
    fn run(&self, stop: Option<&Arc<AtomicBool>>) {
        let mut finished = self.finished.lock().unwrap_or_else(PoisonError::into_inner);
        while !*finished {
            let all = stop.is_some_and(|s| s.load(Ordering::Relaxed));
            let now = Instant::now();
            for r in self.list().iter() {
                if r.deadline.is_some_and(|d| now >= d) && !r.stop.load(Ordering::Relaxed) {
                    r.timed_out.store(true, Ordering::Relaxed);
                    r.stop.store(true, Ordering::Relaxed);
                } else if all {
                    r.stop.store(true, Ordering::Relaxed);
                }
            }
            finished = self
                .wake
                .wait_timeout(finished, Duration::from_millis(10))
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
    }
}

/// One variant under the watchdog: `None` if the sweep was stopped while it ran.
fn run_watched(
    loader: &Loader,
    index: usize,
    overrides: &[Override],
    options: &RunOptions,
    running: &Running,
) -> Option<Row> {
    let row = run_with(loader, index, overrides, options, Some(&running.stop));
    if row.outcome != RowOutcome::Run(Outcome::Interrupted) {
        return Some(row);
    }
    if !running.timed_out.load(Ordering::Relaxed) {
        return None;
    }
    let limit = options.variant_timeout.unwrap_or_default().as_secs_f64();
    Some(Row {
        outcome: RowOutcome::Timeout,
        error: format!(
            "ran longer than the variant timeout of {limit} s (wall time), stopped at {} s of simulated time",
            row.end_time
        ),
        ..row
    })
}

/// One variant: load, simulate (with its log if asked), reduce.
pub fn run_one(loader: &Loader, index: usize, overrides: &[Override], options: &RunOptions) -> Row {
    run_with(loader, index, overrides, options, None)
}

fn run_with(
    loader: &Loader,
    index: usize,
    overrides: &[Override],
    options: &RunOptions,
    stop: Option<&Arc<AtomicBool>>,
) -> Row {
    let log = options
        .keep_logs
        .as_ref()
        .filter(|_| {
            options
                .keep_logs_of
                .as_ref()
                .is_none_or(|of| of.contains(index))
        })
        .map(|dir| dir.join(format!("variant-{index:05}.mcap")));
    let request = RunRequest {
        cell: CellSource::Variant { loader, overrides },
        until_ns: options.until_ns,
        log: log.as_deref().map(|path| LogRequest { path, every: 1 }),
        stop: stop.cloned(),
    };
    match vworks_app::run(request) {
        Ok(out) => {
            let row = Row::of(index, overrides, &out.result);
            match &out.result.log_error {
                Some(e) => row.log_failed(e),
                None => row,
            }
        }
        Err(RunError::Load(e)) => Row::invalid(index, overrides, e.to_string()),
        Err(RunError::Log { message, .. }) => {
            Row::invalid(index, overrides, String::new()).log_failed(&message)
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// Rows come out in order whatever the threads, and the rows held while an early
    /// variant is slow stay within the window, however many variants there are.
    #[test]
    fn rows_are_handed_over_in_order_holding_at_most_the_window() {
        let (count, window) = (5_000, 16);
        let others = AtomicUsize::new(0);
        let work = |i: usize| {
            if i == 0 {
                // Slow: the other thread finishes the window behind it, then would go on
                // (without the window) while this one is still running.
                while others.load(Ordering::Relaxed) < window - 1 {
                    std::thread::yield_now();
                }
                for _ in 0..100_000 {
                    std::thread::yield_now();
                    if others.load(Ordering::Relaxed) >= 2 * window {
                        break;
                    }
                }
            } else {
                others.fetch_add(1, Ordering::Relaxed);
            }
            (i % 7 != 3).then_some(i)
        };
        let mut got = Vec::new();
        let held = schedule(count, 2, window, &|| false, &work, &|_| {}, &mut |i| {
            got.push(i)
        });
        let want: Vec<usize> = (0..count).filter(|i| i % 7 != 3).collect();
        assert_eq!(got, want);
        assert!(held < window, "{held} rows held, the window is {window}");
    }

    #[test]
    fn variant_sets_read_numbers_and_ranges() {
        let s = VariantSet::parse("10-12, 3,7,11-13").unwrap();
        let got: Vec<usize> = (0..20).filter(|i| s.contains(*i)).collect();
        assert_eq!(got, [3, 7, 10, 11, 12, 13]);
        assert_eq!(s.last(), Some(13));
        for (bad, says) in [
            ("3,x", "`x` is not a variant number"),
            ("", "`` is not a variant number"),
            ("5-2", "write it from the smaller: 2-5"),
            ("-1", "`-1` is not a variant number"),
        ] {
            let e = VariantSet::parse(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn a_stopped_schedule_hands_over_what_was_done() {
        let stop = AtomicBool::new(false);
        let work = |i: usize| {
            if i == 9 {
                stop.store(true, Ordering::Relaxed);
            }
            Some(i)
        };
        let mut got = Vec::new();
        schedule(
            100,
            1,
            4,
            &|| stop.load(Ordering::Relaxed),
            &work,
            &|_| {},
            &mut |i| got.push(i),
        );
        assert_eq!(got, (0..10).collect::<Vec<_>>());
    }
}
