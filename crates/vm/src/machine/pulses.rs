//! Pulses (`PulseGlobal`, WSL's `pulse g for T`): a global set to 1 now and back to 0
//! later by the robot's I/O, as a controller ends a `PulseDO` — whatever the program does
//! meanwhile, and after it has ended too. A pulse's end is a `set` event of the robot,
//! which comes before the robot's other events of its instant.

use crate::bytecode::SrcPos;

/// A pulse under way: global `global` goes back to 0 at `end`.
#[derive(Clone, Copy, Debug)]
pub(super) struct PulseEnd {
    pub(super) end: i64,
    pub(super) global: u32,
    /// The statement that started it.
    pub(super) pos: SrcPos,
}

/// The pulses under way, in the order they started.
#[derive(Debug, Default)]
pub(super) struct Pulses {
    under_way: Vec<PulseEnd>,
}

impl Pulses {
    /// A pulse of global `g` that ends at `end`, started by the statement at `pos`; a new
    /// pulse of the same global replaces the one under way.
    pub(super) fn start(&mut self, g: u32, end: i64, pos: SrcPos) {
        self.under_way.retain(|p| p.global != g);
        self.under_way.push(PulseEnd {
            end,
            global: g,
            pos,
        });
    }

    /// The earliest pulse end (the first started, on a tie) and its index.
    pub(super) fn earliest(&self) -> Option<(PulseEnd, usize)> {
        let (_, i) = self
            .under_way
            .iter()
            .enumerate()
            .map(|(i, p)| (p.end, i))
            .min()?;
        Some((self.under_way[i], i))
    }

    /// Takes pulse `i` (it has ended), if there is one.
    pub(super) fn take(&mut self, i: usize) -> Option<PulseEnd> {
        (i < self.under_way.len()).then(|| self.under_way.remove(i))
    }
}
