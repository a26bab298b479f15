//! Pulses (`PulseGlobal`, WSL's `pulse g for T`): a global set to 1 now and back to 0
//! later by the robot's I/O, as a controller ends a `PulseDO` — whatever the program does
//! meanwhile, and after it has ended too. A pulse's end is a `set` event of the robot,
//! which comes before the robot's other events of its instant.

use super::*;

/// A pulse under way: global `global` goes back to 0 at `end`.
#[derive(Clone, Copy, Debug)]
pub(super) struct PulseEnd {
    end: i64,
    global: u32,
    /// The statement that started it.
    pos: SrcPos,
}

impl Vm {
    /// A pulse of global `g` started at `t` by the statement at `pos`, lasting `secs`
    /// (checked when the event was described); a new pulse of the same global replaces the
    /// one under way.
    pub(super) fn start_pulse(&mut self, g: u32, secs: f64, t: i64, pos: SrcPos) {
        let end = t.saturating_add(span_ns(secs, t, "the pulse").unwrap_or(0));
        self.pulses.retain(|p| p.global != g);
        self.pulses.push(PulseEnd {
            end,
            global: g,
            pos,
        });
    }

    /// The end of the earliest pulse (the first started, on a tie), if it comes before
    /// `main` (the main program's next event) and `fire` (the next handler firing): the
    /// I/O acts first at an instant. A failed robot (`Next::Done`) ends no pulse.
    pub(super) fn pulse_event(&mut self, main: &Next, fire: Option<(i64, usize)>) -> Option<Next> {
        let (t, i) = self
            .pulses
            .iter()
            .enumerate()
            .map(|(i, p)| (p.end, i))
            .min()?;
        if matches!(main, Next::Done)
            || fire.is_some_and(|(tf, _)| tf < t)
            || matches!(main, Next::Event(e) if e.time < t)
        {
            return None;
        }
        let p = self.pulses[i];
        self.source = Source::Pulse(i);
        Some(Next::Event(Event {
            robot: self.cfg.robot,
            time: t,
            kind: EventKind::Set {
                global: p.global,
                value: 0,
                ty: self.m.globals[p.global as usize].ty,
            },
            pos: p.pos,
        }))
    }

    /// Performs the end of pulse `i`: its global back to 0.
    pub(super) fn perform_pulse_end(&mut self, i: usize) {
        if i < self.pulses.len() {
            let p = self.pulses.remove(i);
            self.time = self.time.max(p.end);
            self.set_global(p.global, 0);
        }
    }
}
