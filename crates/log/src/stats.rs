//! Time per robot — moving, waiting, idle, motions, cycle time — as one fold over the
//! typed events ([`crate::trace::Kind`]). The engine folds its events as it records them
//! ([`crate::result::RunResult::robots`]); the report folds a log's events the same way,
//! so `vworks run`, `run --json`, Python and the report give the same numbers.
//!
//! The definitions (docs/engine.md, "Results"):
//! - **moving**: from each `motion_start` to its `motion_end`;
//! - **waiting**: from each `wait_until` or `join` to its `wait_end`;
//! - **idle**: the rest of the run, from 0 to the run's end: delays, zero-time work, and
//!   the time after the robot's program ended while others still ran;
//! - an `end`, `error` or `remote_end` closes what is open (`stop` in a handler ends a
//!   motion or a wait where it is); what is still open at the run's end closes there;
//! - the **cycle time** (`end_time_ns`): when the program ended (its last `end`,
//!   `remote_end` or `error`) if it did, else the run's end.
//!
//! Handlers take no simulated time (they run between events, in zero time), so there is
//! no "in handler" time to count.

use crate::trace::Kind;

/// What a robot does over an interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Activity {
    /// A motion (`motion_start` to `motion_end`).
    Moving,
    /// A `wait_until` or `join` (to its `wait_end`).
    Waiting,
}

impl Activity {
    /// `moving`, `waiting`.
    pub fn name(self) -> &'static str {
        match self {
            Activity::Moving => "moving",
            Activity::Waiting => "waiting",
        }
    }
}

/// How a robot stood when the run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// Its program ended (and it serves no remote work).
    Ended,
    /// A runtime error stopped it.
    Error,
    /// It waits with no timeout (for a condition, a signal or a join).
    Waiting,
    /// It was still running (a motion, a delay, a timed wait).
    Running,
}

impl Ending {
    /// `ended`, `error`, `waiting`, `running`.
    pub fn name(self) -> &'static str {
        match self {
            Ending::Ended => "ended",
            Ending::Error => "error",
            Ending::Waiting => "waiting",
            Ending::Running => "running",
        }
    }

    /// The ending named `name`.
    pub fn from_name(name: &str) -> Option<Ending> {
        [
            Ending::Ended,
            Ending::Error,
            Ending::Waiting,
            Ending::Running,
        ]
        .into_iter()
        .find(|e| e.name() == name)
    }
}

/// Time spent per robot.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotStats {
    /// Name.
    pub name: String,
    /// In motion (ns).
    pub moving_ns: i64,
    /// Waiting: conditions, signals, joins (ns).
    pub waiting_ns: i64,
    /// Neither, from 0 to the run's end (ns): delays, and after the program ended.
    pub idle_ns: i64,
    /// Motions started.
    pub motions: u32,
    /// The cycle time: when its program ended, or the run's end if it did not (ns).
    pub end_time_ns: i64,
    /// How it stood at the run's end.
    pub ended: Ending,
}

/// One robot's closed intervals: (activity, start ns, end ns).
pub type Intervals = Vec<(Activity, i64, i64)>;

/// The fold: feed every event in order ([`Fold::event`]), then [`Fold::finish`].
/// Allocates nothing per event unless intervals are kept.
#[derive(Clone, Debug)]
pub struct Fold {
    names: Vec<String>,
    /// Per robot, in one place (one bounds check per event).
    robots: Vec<Robot>,
    /// Per robot, if kept: (activity, start, end) in the order they closed.
    intervals: Option<Vec<Intervals>>,
}

/// One robot's running totals.
#[derive(Clone, Copy, Debug)]
struct Robot {
    /// Open motion and wait: their start times.
    open: [Option<i64>; 2],
    /// Time moving and waiting so far.
    total: [i64; 2],
    motions: u32,
    /// Its last `end`, `remote_end` or `error`.
    ended_at: Option<i64>,
    /// How it stands by its events alone (a log has nothing else).
    state: Ending,
}

impl Fold {
    /// A fold over the robots `names` (indices in events refer to this order); with
    /// `keep_intervals`, every closed interval is kept for a timeline.
    pub fn new(names: Vec<String>, keep_intervals: bool) -> Fold {
        let n = names.len();
        let robot = Robot {
            open: [None; 2],
            total: [0; 2],
            motions: 0,
            ended_at: None,
            state: Ending::Running,
        };
        Fold {
            names,
            robots: vec![robot; n],
            intervals: keep_intervals.then(|| vec![Vec::new(); n]),
        }
    }

    #[inline]
    fn close(&mut self, r: usize, a: Activity, t: i64) {
        let robot = &mut self.robots[r];
        if let Some(s) = robot.open[a as usize].take() {
            robot.total[a as usize] += t - s;
            if let Some(iv) = &mut self.intervals {
                iv[r].push((a, s, t));
            }
        }
    }

    /// Folds in robot `robot`'s event of `kind` at `t` (events without a robot, and robots
    /// out of range, change nothing).
    ///
    /// A zoned motion's `motion_end` (its data is `Data::MotionEnd`) is not folded: the
    /// TCP entered the zone and the robot moves on — through the next motion's corner, or
    /// to the point, which the next statement that does not move waits for. Moving time
    /// goes on until a motion stops (`motion_end` without a zone) or a statement that does
    /// not move begins (`delay`, `wait_until`, a join, the end), which closes it.
    #[inline]
    pub fn event(&mut self, t: i64, robot: Option<usize>, kind: Kind) {
        let Some(r) = robot else { return };
        let Some(st) = self.robots.get_mut(r) else {
            return;
        };
        match kind {
            Kind::MotionStart => {
                st.motions += 1;
                st.open[Activity::Moving as usize].get_or_insert(t);
            }
            Kind::MotionEnd => self.close(r, Activity::Moving, t),
            // A zoned point ahead became a stop point: the robot moved until now.
            Kind::Delay => self.close(r, Activity::Moving, t),
            Kind::WaitUntil | Kind::Join => {
                self.close(r, Activity::Moving, t);
                let st = &mut self.robots[r];
                st.state = Ending::Waiting;
                st.open[Activity::Waiting as usize].get_or_insert(t);
            }
            Kind::WaitEnd => {
                st.state = Ending::Running;
                self.close(r, Activity::Waiting, t);
            }
            Kind::End | Kind::RemoteEnd | Kind::Error => {
                st.state = if kind == Kind::Error {
                    Ending::Error
                } else {
                    Ending::Ended
                };
                st.ended_at = Some(t);
                self.close(r, Activity::Moving, t);
                self.close(r, Activity::Waiting, t);
            }
            Kind::RemoteStart => st.state = Ending::Running,
            _ => {}
        }
    }

    /// Whether robot `r` has an open wait (its events say it waits).
    pub fn waiting(&self, r: usize) -> bool {
        self.robots
            .get(r)
            .is_some_and(|o| o.open[Activity::Waiting as usize].is_some())
    }

    /// The statistics at the run's end `end_ns`; `ended` gives each robot's ending where
    /// the caller knows it better than the events do (the engine asks the VMs; a log
    /// records it), else the events decide.
    pub fn finish(
        mut self,
        end_ns: i64,
        ended: &dyn Fn(usize) -> Option<Ending>,
    ) -> (Vec<RobotStats>, Vec<Intervals>) {
        let mut out = Vec::with_capacity(self.names.len());
        for r in 0..self.names.len() {
            self.close(r, Activity::Moving, end_ns);
            self.close(r, Activity::Waiting, end_ns);
            let st = self.robots[r];
            let ending = ended(r).unwrap_or(st.state);
            let [moving_ns, waiting_ns] = st.total;
            out.push(RobotStats {
                name: std::mem::take(&mut self.names[r]),
                moving_ns,
                waiting_ns,
                idle_ns: (end_ns - moving_ns - waiting_ns).max(0),
                motions: st.motions,
                end_time_ns: match (ending, st.ended_at) {
                    (Ending::Ended, Some(t)) => t,
                    _ => end_ns,
                },
                ended: ending,
            });
        }
        let mut intervals = self.intervals.unwrap_or_default();
        for iv in &mut intervals {
            iv.sort_by_key(|(a, s, _)| (*s, *a as u8));
        }
        (out, intervals)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Times from docs/engine.md's definitions, computed by hand: r0 moves 0–2 s, waits
    /// 2–5 s, delays 5–6 s and ends at 6 s; r1 waits from 1 s and is still waiting when the
    /// run ends at 10 s.
    #[test]
    fn moving_waiting_and_idle_cover_the_run() {
        let s = 1_000_000_000;
        let mut f = Fold::new(vec!["r0".into(), "r1".into()], true);
        for (t, r, k) in [
            (0, 0, Kind::MotionStart),
            (s, 1, Kind::WaitUntil),
            (2 * s, 0, Kind::MotionEnd),
            (2 * s, 0, Kind::WaitUntil),
            (5 * s, 0, Kind::WaitEnd),
            (5 * s, 0, Kind::Delay),
            (6 * s, 0, Kind::DelayEnd),
            (6 * s, 0, Kind::End),
        ] {
            f.event(t, Some(r), k);
        }
        f.event(7 * s, None, Kind::CollisionStart);
        assert!(f.waiting(1) && !f.waiting(0));
        let (stats, iv) = f.finish(10 * s, &|_| None);
        assert_eq!(
            (stats[0].moving_ns, stats[0].waiting_ns, stats[0].idle_ns),
            (2 * s, 3 * s, 5 * s)
        );
        assert_eq!(
            (stats[0].end_time_ns, stats[0].ended),
            (6 * s, Ending::Ended)
        );
        assert_eq!(
            (stats[1].moving_ns, stats[1].waiting_ns, stats[1].idle_ns),
            (0, 9 * s, s)
        );
        assert_eq!(
            (stats[1].end_time_ns, stats[1].ended),
            (10 * s, Ending::Waiting)
        );
        assert_eq!(
            iv[0],
            vec![
                (Activity::Moving, 0, 2 * s),
                (Activity::Waiting, 2 * s, 5 * s)
            ]
        );
        assert_eq!(iv[1], vec![(Activity::Waiting, s, 10 * s)]);
    }

    #[test]
    fn an_end_closes_what_is_open_and_the_caller_knows_endings_best() {
        let mut f = Fold::new(vec!["r".into()], false);
        f.event(0, Some(0), Kind::MotionStart);
        f.event(3, Some(0), Kind::End);
        f.event(4, Some(0), Kind::RemoteStart);
        let (stats, iv) = f.finish(9, &|_| Some(Ending::Running));
        assert_eq!((stats[0].moving_ns, stats[0].idle_ns), (3, 6));
        assert_eq!((stats[0].end_time_ns, stats[0].ended), (9, Ending::Running));
        assert!(iv.is_empty());
    }
}
