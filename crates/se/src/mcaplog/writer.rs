//! The log's writer thread: the simulation appends records to batches; this thread turns
//! them into MCAP messages, compresses the chunks (zstd) and writes the file, so the
//! per-cycle encoding and the compression run beside the simulation instead of inside it.
//!
//! A batch is a byte buffer of records, each a tag byte and the time (u64), then:
//! - [`MESSAGE`]: the channel (u16), the length (u32) and a message encoded by the
//!   simulation (events, scene updates, log lines: rare);
//! - [`CYCLE`]: the boundary's index (u64) and its cycle payload
//!   ([`super::cycles::append_cycle`]), from which the thread's
//!   [`CycleEncoder`] builds `/state` and `/tf`.
//!
//! All integers little-endian. A bounded channel carries full batches to the thread
//! (back-pressure: the simulation waits when the writer is [`QUEUED_BATCHES`] behind) and a
//! second channel brings emptied batches back, so in steady state no buffer is allocated.
//! The file's bytes do not depend on thread timing: records are written in the order the
//! simulation appended them, with sequence numbers counted here.

use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use super::cycles::CycleEncoder;
use super::{STATE, TF, TOPICS};

/// The MCAP writer the thread owns.
pub(crate) type Mcap = mcap::Writer<BufWriter<File>>;

/// A batch is shipped to the writer thread once it holds this many bytes.
pub(crate) const BATCH_BYTES: usize = 64 * 1024;

/// Full batches that may wait for the writer thread before the simulation waits.
pub(crate) const QUEUED_BATCHES: usize = 4;

/// Record tag: a message encoded by the simulation.
const MESSAGE: u8 = 0;
/// Record tag: a cycle boundary's joints and part poses.
const CYCLE: u8 = 1;

/// Messages written per topic, indexed like [`TOPICS`].
pub(crate) type Counts = [u64; TOPICS.len()];

/// What the writer thread needs besides the records (`W`: the file; tests use others).
pub(crate) struct WriterSetup<W: Write + Seek> {
    pub(crate) mcap: mcap::Writer<W>,
    pub(crate) cycles: CycleEncoder,
    /// The channel id of each topic, indexed like [`TOPICS`].
    pub(crate) channels: [u16; TOPICS.len()],
}

/// The simulation's end of the writer thread.
pub(crate) struct Sink {
    /// The batch being filled.
    batch: Vec<u8>,
    /// Full batches to the thread; `None` once closed.
    full: Option<SyncSender<Vec<u8>>>,
    /// Emptied batches back from the thread.
    empty: Receiver<Vec<u8>>,
    thread: Option<JoinHandle<Result<Counts, String>>>,
    /// What `finish` returned, for a second call.
    finished: Option<Result<Counts, String>>,
}

/// Where a message being encoded starts in the batch (from [`Sink::begin`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Started(usize);

/// Bytes of a message record's header: tag, time, channel, length.
const MESSAGE_HEADER: usize = 1 + 8 + 2 + 4;

impl Sink {
    /// Starts the thread; it writes the records into `setup.mcap` (which already holds
    /// schemas, channels, metadata and attachments) and finishes the file when the sink is
    /// finished or dropped.
    pub(crate) fn spawn<W>(setup: WriterSetup<W>) -> std::io::Result<Sink>
    where
        W: Write + Seek + Send + 'static,
    {
        let (full_tx, full_rx) = sync_channel::<Vec<u8>>(QUEUED_BATCHES);
        let (empty_tx, empty_rx) = sync_channel::<Vec<u8>>(QUEUED_BATCHES + 2);
        let thread = std::thread::Builder::new()
            .name("vworks-log".into())
            .spawn(move || write_batches(setup, &full_rx, &empty_tx))?;
        Ok(Sink {
            batch: Vec::with_capacity(BATCH_BYTES + BATCH_BYTES / 4),
            full: Some(full_tx),
            empty: empty_rx,
            thread: Some(thread),
            finished: None,
        })
    }

    /// Starts a message on `channel` at `time`: returns where it starts and the buffer to
    /// append its encoding to; [`Sink::end`] completes it, [`Sink::cancel`] drops it.
    pub(crate) fn begin(&mut self, channel: u16, time: u64) -> (Started, &mut Vec<u8>) {
        let start = self.batch.len();
        self.batch.push(MESSAGE);
        self.batch.extend_from_slice(&time.to_le_bytes());
        self.batch.extend_from_slice(&channel.to_le_bytes());
        self.batch.extend_from_slice(&0u32.to_le_bytes());
        (Started(start), &mut self.batch)
    }

    /// Drops the message begun at `start`.
    pub(crate) fn cancel(&mut self, start: Started) {
        self.batch.truncate(start.0);
    }

    /// Completes the message begun at `start`; ships the batch when it is full. An error
    /// means the writer thread stopped (its reason comes from [`Sink::finish`]).
    pub(crate) fn end(&mut self, start: Started) -> Result<(), String> {
        let len = self.batch.len() - start.0 - MESSAGE_HEADER;
        let Ok(len32) = u32::try_from(len) else {
            self.cancel(start);
            return Err(format!("a message of {len} bytes is too large to log"));
        };
        let at = start.0 + MESSAGE_HEADER - 4;
        self.batch[at..at + 4].copy_from_slice(&len32.to_le_bytes());
        self.ship_if_full()
    }

    /// Appends a cycle record: the boundary at `time`, the `cycle`-th, and its payload
    /// written by `payload` (exactly the encoder's `payload_len` bytes).
    pub(crate) fn cycle(
        &mut self,
        time: u64,
        cycle: u64,
        payload: impl FnOnce(&mut Vec<u8>),
    ) -> Result<(), String> {
        self.batch.push(CYCLE);
        self.batch.extend_from_slice(&time.to_le_bytes());
        self.batch.extend_from_slice(&cycle.to_le_bytes());
        payload(&mut self.batch);
        self.ship_if_full()
    }

    fn ship_if_full(&mut self) -> Result<(), String> {
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
        let next = self
            .empty
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH_BYTES + BATCH_BYTES / 4));
        let batch = std::mem::replace(&mut self.batch, next);
        if full.send(batch).is_err() {
            // The thread stopped on an error; `finish` reports it.
            self.full = None;
            return Err("the log writer stopped".into());
        }
        Ok(())
    }

    /// Writes what is left, closes the file (summary, footer, CRCs) and waits for the
    /// thread; returns the messages written per topic, or the first error the thread met.
    pub(crate) fn finish(&mut self) -> Result<Counts, String> {
        if let Some(done) = &self.finished {
            return done.clone();
        }
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
            None => Err("the log writer never started".into()),
        };
        let done = joined.and_then(|counts| shipped.map(|()| counts));
        self.finished = Some(done.clone());
        done
    }
}

impl Drop for Sink {
    /// A log dropped without [`Sink::finish`] (an error elsewhere, an unwinding panic) is
    /// still finished, so the file stays readable.
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

/// Splits `n` bytes off the front of `rest`.
fn take<'a>(rest: &mut &'a [u8], n: usize) -> Result<&'a [u8], String> {
    let Some((head, tail)) = rest.split_at_checked(n) else {
        return Err("internal error: a truncated record in a log batch".into());
    };
    *rest = tail;
    Ok(head)
}

fn take_u64(rest: &mut &[u8]) -> Result<u64, String> {
    let b = take(rest, 8)?;
    Ok(u64::from_le_bytes([
        b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7],
    ]))
}

/// The thread: writes every record of every batch, returns the batches, finishes the
/// file when the channel closes. Stops at the first error (the simulation learns of it at
/// its next send).
fn write_batches<W: Write + Seek>(
    setup: WriterSetup<W>,
    full: &Receiver<Vec<u8>>,
    empty: &SyncSender<Vec<u8>>,
) -> Result<Counts, String> {
    let WriterSetup {
        mut mcap,
        mut cycles,
        channels,
    } = setup;
    let payload_len = cycles.payload_len();
    let mut counts: Counts = [0; TOPICS.len()];
    let mut sequence = 0u32;
    let (mut state, mut tf) = (Vec::with_capacity(1024), Vec::with_capacity(4096));
    let mut write =
        |mcap: &mut mcap::Writer<W>, counts: &mut Counts, channel: u16, time: u64, data: &[u8]| {
            sequence = sequence.wrapping_add(1);
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence,
                log_time: time,
                publish_time: time,
            };
            mcap.write_to_known_channel(&header, data)
                .map_err(|e| super::error_chain(&e))?;
            if let Some(topic) = channels.iter().position(|c| *c == channel) {
                counts[topic] += 1;
            }
            Ok::<(), String>(())
        };
    while let Ok(mut batch) = full.recv() {
        let mut rest = batch.as_slice();
        while let Some((&tag, tail)) = rest.split_first() {
            rest = tail;
            let time = take_u64(&mut rest)?;
            if tag == CYCLE {
                let cycle = take_u64(&mut rest)?;
                let payload = take(&mut rest, payload_len)?;
                cycles.encode(time, cycle, payload, &mut state, &mut tf);
                write(&mut mcap, &mut counts, channels[STATE], time, &state)?;
                if !tf.is_empty() {
                    write(&mut mcap, &mut counts, channels[TF], time, &tf)?;
                }
            } else {
                let head = take(&mut rest, 6)?;
                let channel = u16::from_le_bytes([head[0], head[1]]);
                let len = u32::from_le_bytes([head[2], head[3], head[4], head[5]]) as usize;
                let data = take(&mut rest, len)?;
                write(&mut mcap, &mut counts, channel, time, data)?;
            }
        }
        batch.clear();
        // The simulation may have finished meanwhile; a batch nobody takes is just freed.
        let _ = empty.try_send(batch);
    }
    mcap.finish().map_err(|e| super::error_chain(&e))?;
    Ok(counts)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use std::collections::BTreeMap;

    use super::*;
    use crate::mcaplog::Encoding;

    /// A file that takes `room` bytes, then fails every write as a full disk does.
    struct FillsUp {
        data: std::io::Cursor<Vec<u8>>,
        room: u64,
    }

    impl Write for FillsUp {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if self.data.position() + buf.len() as u64 > self.room {
                return Err(std::io::Error::from(std::io::ErrorKind::StorageFull));
            }
            self.data.write(buf)
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    impl Seek for FillsUp {
        fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
            self.data.seek(to)
        }
    }

    #[test]
    fn a_write_error_in_the_thread_reaches_the_simulation() {
        let cell = crate::workcell::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../workcells/handoff/cell.toml"),
        )
        .unwrap();
        let file = FillsUp {
            data: std::io::Cursor::new(Vec::new()),
            room: 200_000,
        };
        let mut mcap = mcap::WriteOptions::new()
            .chunk_size(Some(10_000))
            .create(file)
            .unwrap();
        let schema = mcap.add_schema("raw", "", &[]).unwrap();
        let channel = mcap
            .add_channel(schema, "/raw", "", &BTreeMap::new())
            .unwrap();
        let setup = WriterSetup {
            mcap,
            cycles: CycleEncoder::new(&cell, Encoding::Protobuf),
            channels: [channel; TOPICS.len()],
        };
        let mut sink = Sink::spawn(setup).unwrap();
        let mut failed = None;
        for i in 0..100_000u64 {
            let (start, b) = sink.begin(channel, i);
            // Incompressible enough that the room runs out.
            b.extend((0..200u64).map(|k| ((i * 7919 + k * 104_729) % 251) as u8));
            if let Err(e) = sink.end(start) {
                failed = Some((i, e));
                break;
            }
        }
        let (at, _) = failed.expect("the simulation learns that the writer stopped");
        assert!(at < 20_000, "only after {at} messages");
        let err = sink.finish().unwrap_err();
        assert!(err.contains("no storage space"), "{err}");
        // Asking again gives the same answer; dropping does not hang or panic.
        assert_eq!(sink.finish().unwrap_err(), err);
        drop(sink);
    }

    #[test]
    fn records_come_out_in_order_with_their_counts() {
        let cell = crate::workcell::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../workcells/track/cell.toml"),
        )
        .unwrap();
        let path = std::env::temp_dir().join(format!("vworks-writer-{}.mcap", std::process::id()));
        let mut mcap = mcap::WriteOptions::new()
            .create(BufWriter::new(File::create(&path).unwrap()))
            .unwrap();
        let schema = mcap.add_schema("raw", "", &[]).unwrap();
        let ids: Vec<u16> = TOPICS
            .iter()
            .map(|t| mcap.add_channel(schema, t, "", &BTreeMap::new()).unwrap())
            .collect();
        let channels = [ids[0], ids[1], ids[2], ids[3], ids[4]];
        let cycles = CycleEncoder::new(&cell, Encoding::Protobuf);
        let payload = vec![0u8; cycles.payload_len()];
        let mut sink = Sink::spawn(WriterSetup {
            mcap,
            cycles,
            channels,
        })
        .unwrap();
        // Enough records for several batches: events and cycles interleaved.
        for i in 0..5_000u64 {
            let (start, b) = sink.begin(channels[0], i * 10);
            b.extend_from_slice(&i.to_le_bytes());
            sink.end(start).unwrap();
            sink.cycle(i * 10 + 5, i, |b| b.extend_from_slice(&payload))
                .unwrap();
        }
        let counts = sink.finish().unwrap();
        // Every cycle gives a state; only the first (a keyframe) has transforms, since the
        // joints never change (and the next keyframe is a second away, past the end).
        assert_eq!(counts, [5_000, 5_000, 1, 0, 0]);
        let bytes = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        let mut last = (0, 0);
        let mut events = 0u64;
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            assert!((m.log_time, m.sequence) > last, "in order");
            last = (m.log_time, m.sequence);
            if m.channel.topic == "/events" {
                assert_eq!(m.data[..], events.to_le_bytes());
                events += 1;
            }
        }
        assert_eq!(events, 5_000);
    }
}
