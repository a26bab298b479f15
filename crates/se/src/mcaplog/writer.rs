//! The log's writer thread: the simulation encodes messages into batches; this thread
//! frames them as MCAP records, compresses the chunks (zstd) and writes the file, so
//! compression runs beside the simulation instead of inside it.
//!
//! Batches are byte buffers holding whole messages, each as a fixed header (channel,
//! sequence, time, length, little-endian) followed by the encoded message. A bounded
//! channel carries full batches to the thread (back-pressure: the simulation waits when the
//! writer is [`QUEUED_BATCHES`] behind) and a second channel brings emptied batches back,
//! so in steady state no buffer is allocated. The file's bytes do not depend on thread
//! timing: messages reach the MCAP writer in the order they were encoded.

use std::fs::File;
use std::io::BufWriter;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::thread::JoinHandle;

/// The MCAP writer the thread owns.
pub(crate) type Mcap = mcap::Writer<BufWriter<File>>;

/// A batch is shipped to the writer thread once it holds this many bytes.
pub(crate) const BATCH_BYTES: usize = 64 * 1024;

/// Full batches that may wait for the writer thread before the simulation waits.
pub(crate) const QUEUED_BATCHES: usize = 2;

/// Bytes of a message's header in a batch: channel u16, sequence u32, time u64, length u32.
const HEADER: usize = 2 + 4 + 8 + 4;

/// The simulation's end of the writer thread.
pub(crate) struct Sink {
    /// The batch being filled.
    batch: Vec<u8>,
    /// Full batches to the thread; `None` once closed.
    full: Option<SyncSender<Vec<u8>>>,
    /// Emptied batches back from the thread.
    empty: Receiver<Vec<u8>>,
    thread: Option<JoinHandle<Result<(), String>>>,
}

/// Where a message being encoded starts in the batch (from [`Sink::begin`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Started(usize);

impl Sink {
    /// Starts the thread that writes `mcap` (already holding schemas, channels, metadata
    /// and attachments) and finishes it when the sink is finished or dropped.
    pub(crate) fn spawn(mcap: Mcap) -> std::io::Result<Sink> {
        let (full_tx, full_rx) = sync_channel::<Vec<u8>>(QUEUED_BATCHES);
        let (empty_tx, empty_rx) = sync_channel::<Vec<u8>>(QUEUED_BATCHES + 2);
        let thread = std::thread::Builder::new()
            .name("vworks-log".into())
            .spawn(move || write_batches(mcap, &full_rx, &empty_tx))?;
        Ok(Sink {
            batch: Vec::with_capacity(BATCH_BYTES + BATCH_BYTES / 4),
            full: Some(full_tx),
            empty: empty_rx,
            thread: Some(thread),
        })
    }

    /// Starts a message on `channel`: returns where it starts and the buffer to append
    /// its encoding to; [`Sink::end`] completes it, [`Sink::cancel`] drops it.
    pub(crate) fn begin(
        &mut self,
        channel: u16,
        sequence: u32,
        time: u64,
    ) -> (Started, &mut Vec<u8>) {
        let start = self.batch.len();
        self.batch.extend_from_slice(&channel.to_le_bytes());
        self.batch.extend_from_slice(&sequence.to_le_bytes());
        self.batch.extend_from_slice(&time.to_le_bytes());
        self.batch.extend_from_slice(&0u32.to_le_bytes());
        (Started(start), &mut self.batch)
    }

    /// The length of the message begun at `start` so far.
    pub(crate) fn len_since(&self, start: Started) -> usize {
        self.batch.len() - start.0 - HEADER
    }

    /// Drops the message begun at `start`.
    pub(crate) fn cancel(&mut self, start: Started) {
        self.batch.truncate(start.0);
    }

    /// Completes the message begun at `start`; ships the batch when it is full. An error
    /// means the writer thread stopped (its reason comes from [`Sink::finish`]).
    pub(crate) fn end(&mut self, start: Started) -> Result<(), String> {
        let len = self.len_since(start);
        let Ok(len32) = u32::try_from(len) else {
            self.cancel(start);
            return Err(format!("a message of {len} bytes is too large to log"));
        };
        let at = start.0 + HEADER - 4;
        self.batch[at..at + 4].copy_from_slice(&len32.to_le_bytes());
        if self.batch.len() >= BATCH_BYTES {
            self.ship()?;
        }
        Ok(())
    }

    /// Sends the batch to the thread and takes an emptied one (or a new one) to fill.
    fn ship(&mut self) -> Result<(), String> {
        let Some(full) = &self.full else {
            return Err("the log is closed".into());
        };
        let next = match self.empty.try_recv() {
            Ok(b) => b,
            Err(TryRecvError::Empty | TryRecvError::Disconnected) => {
                Vec::with_capacity(BATCH_BYTES + BATCH_BYTES / 4)
            }
        };
        let batch = std::mem::replace(&mut self.batch, next);
        if full.send(batch).is_err() {
            // The thread stopped on an error; `finish` reports it.
            self.full = None;
            return Err("the log writer stopped".into());
        }
        Ok(())
    }

    /// Writes what is left, closes the file (summary, footer, CRCs) and waits for the
    /// thread; returns the first error the thread met.
    pub(crate) fn finish(&mut self) -> Result<(), String> {
        let shipped = if self.batch.is_empty() || self.full.is_none() {
            Ok(())
        } else {
            self.ship()
        };
        self.full = None; // closing the channel ends the thread's loop
        let joined = match self.thread.take() {
            Some(t) => match t.join() {
                Ok(r) => r,
                Err(_) => Err("the log writer thread stopped unexpectedly".into()),
            },
            None => Ok(()),
        };
        joined.and(shipped)
    }
}

impl Drop for Sink {
    /// A log dropped without [`Sink::finish`] (an error elsewhere, an unwinding panic) is
    /// still finished, so the file stays readable.
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

/// The thread: writes every message of every batch, returns the batches, finishes the
/// file when the channel closes. Stops at the first error (the simulation learns of it at
/// its next send).
fn write_batches(
    mut mcap: Mcap,
    full: &Receiver<Vec<u8>>,
    empty: &SyncSender<Vec<u8>>,
) -> Result<(), String> {
    while let Ok(mut batch) = full.recv() {
        let mut rest = batch.as_slice();
        while let Some((header, tail)) = rest.split_first_chunk::<HEADER>() {
            let h = header;
            let channel_id = u16::from_le_bytes([h[0], h[1]]);
            let sequence = u32::from_le_bytes([h[2], h[3], h[4], h[5]]);
            let time = u64::from_le_bytes([h[6], h[7], h[8], h[9], h[10], h[11], h[12], h[13]]);
            let len = u32::from_le_bytes([h[14], h[15], h[16], h[17]]) as usize;
            let Some((data, after)) = tail.split_at_checked(len) else {
                return Err("internal error: a truncated message in a log batch".into());
            };
            let header = mcap::records::MessageHeader {
                channel_id,
                sequence,
                log_time: time,
                publish_time: time,
            };
            mcap.write_to_known_channel(&header, data)
                .map_err(|e| e.to_string())?;
            rest = after;
        }
        batch.clear();
        // The simulation may have finished meanwhile; a batch nobody takes is just freed.
        let _ = empty.try_send(batch);
    }
    mcap.finish().map_err(|e| e.to_string())?;
    Ok(())
}
