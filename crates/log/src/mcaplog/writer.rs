//! The log's writer thread: the simulation appends records to batches; this thread turns
//! them into MCAP messages, compresses the chunks (zstd) and writes the file, so the
//! per-cycle encoding and the compression run beside the simulation instead of inside it.
//!
//! The thread opens the file's MCAP structure itself (schemas, channels, metadata,
//! attachments, the first scene), so creating a log costs the simulation only the file's
//! creation. A batch is a byte buffer of records, each a tag byte and the time (u64), then:
//! - [`MESSAGE`]: the topic (u8, index in [`TOPICS`]), the length (u32) and a message
//!   encoded by the simulation (events and log lines: rare);
//! - [`CYCLE`]: the boundary's index (u64) and its cycle payload
//!   ([`super::cycles::append_cycle`]), from which the thread's [`CycleEncoder`] builds
//!   `/state` and `/tf`;
//! - [`COLOUR`]: on (u8), the lengths (u16) of two frame names and the names: a collision
//!   started or ended, and the thread publishes the two bodies' new colour on `/scene`;
//! - [`METADATA`]: the length (u32) and a JSON object `{"name": …, "metadata": {…}}`,
//!   written as an MCAP metadata record (the run's result, at its end).
//!
//! All integers little-endian. A bounded channel carries full batches to the thread
//! (back-pressure: the simulation waits when the writer is [`QUEUED_BATCHES`] behind) and a
//! second channel brings emptied batches back, so in steady state no buffer is allocated.
//! The file's bytes do not depend on thread timing: records are written in the order the
//! simulation appended them, with sequence numbers counted here.

use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::sync::Mutex;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use super::cycles::CycleEncoder;
use super::scene::Scene;
use super::{SCENE, STATE, TF, TOPICS};

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
/// Record tag: two bodies change colour.
const COLOUR: u8 = 2;
/// Record tag: a metadata record.
const METADATA: u8 = 3;

/// Messages written per topic, indexed like [`TOPICS`].
pub(crate) type Counts = [u64; TOPICS.len()];

/// What the writer thread needs besides the records (`W`: the file; tests use others).
pub(crate) struct WriterSetup<W: Write + Seek> {
    /// The MCAP writer, schemas and channels registered, metadata and attachments written.
    pub(crate) mcap: mcap::Writer<W>,
    pub(crate) cycles: CycleEncoder,
    /// The channel id of each topic, indexed like [`TOPICS`].
    pub(crate) channels: [u16; TOPICS.len()],
    /// The bodies; published whole at t = 0.
    pub(crate) scene: Scene,
}

/// The simulation's end of the writer thread.
pub(crate) struct Sink {
    /// The batch being filled.
    batch: Vec<u8>,
    /// Full batches to the thread; `None` once closed.
    full: Option<SyncSender<Vec<u8>>>,
    /// Emptied batches back from the thread (in a mutex only so that a simulation is
    /// `Sync`: the simulation's thread is its only user).
    empty: Mutex<Receiver<Vec<u8>>>,
    thread: Option<JoinHandle<Result<Counts, String>>>,
    /// What `finish` returned, for a second call.
    finished: Option<Result<Counts, String>>,
}

/// Where a message being encoded starts in the batch (from [`Sink::begin`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Started(usize);

/// Bytes of a message record's header: tag, time, topic, length.
const MESSAGE_HEADER: usize = 1 + 8 + 1 + 4;

impl Sink {
    /// Starts the thread: it runs `open` (which registers the schemas and channels and
    /// writes metadata and attachments), publishes the scene, writes the records, and
    /// finishes the file when the sink is finished or dropped. An error from `open` is the
    /// log's error (see [`Sink::finish`]).
    pub(crate) fn spawn<W, F>(open: F) -> std::io::Result<Sink>
    where
        W: Write + Seek + 'static,
        F: FnOnce() -> Result<WriterSetup<W>, String> + Send + 'static,
    {
        let (full_tx, full_rx) = sync_channel::<Vec<u8>>(QUEUED_BATCHES);
        let (empty_tx, empty_rx) = sync_channel::<Vec<u8>>(QUEUED_BATCHES + 2);
        let thread = std::thread::Builder::new()
            .name("vworks-log".into())
            .spawn(move || write_batches(open()?, &full_rx, &empty_tx))?;
        Ok(Sink {
            batch: Vec::with_capacity(BATCH_BYTES + BATCH_BYTES / 4),
            full: Some(full_tx),
            empty: Mutex::new(empty_rx),
            thread: Some(thread),
            finished: None,
        })
    }

    /// Starts a message on topic `topic` (index in [`TOPICS`]) at `time`: returns where it
    /// starts and the buffer to append its encoding to; [`Sink::end`] completes it,
    /// [`Sink::cancel`] drops it.
    pub(crate) fn begin(&mut self, topic: usize, time: u64) -> (Started, &mut Vec<u8>) {
        let start = self.batch.len();
        self.batch.push(MESSAGE);
        self.batch.extend_from_slice(&time.to_le_bytes());
        self.batch.push(topic as u8);
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

    /// Appends a colour record: the bodies of frames `a` and `b` turn red (`on`) or grey.
    pub(crate) fn colour(&mut self, time: u64, on: bool, a: &str, b: &str) -> Result<(), String> {
        // Frame names longer than 64 KiB do not exist (they come from URDFs and the cell).
        let (a, b) = (clip(a), clip(b));
        self.batch.push(COLOUR);
        self.batch.extend_from_slice(&time.to_le_bytes());
        self.batch.push(u8::from(on));
        self.batch
            .extend_from_slice(&(a.len() as u16).to_le_bytes());
        self.batch
            .extend_from_slice(&(b.len() as u16).to_le_bytes());
        self.batch.extend_from_slice(a);
        self.batch.extend_from_slice(b);
        self.ship_if_full()
    }

    /// Appends a metadata record `name` holding `map`.
    pub(crate) fn metadata(
        &mut self,
        name: &str,
        map: &std::collections::BTreeMap<String, String>,
    ) -> Result<(), String> {
        let json = serde_json::json!({"name": name, "metadata": map}).to_string();
        let len = u32::try_from(json.len()).map_err(|_| "the run's metadata is too large")?;
        self.batch.push(METADATA);
        self.batch.extend_from_slice(&0u64.to_le_bytes());
        self.batch.extend_from_slice(&len.to_le_bytes());
        self.batch.extend_from_slice(json.as_bytes());
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
        let recycled = match self.empty.get_mut() {
            Ok(empty) => empty.try_recv().ok(),
            Err(_) => None,
        };
        let next = recycled.unwrap_or_else(|| Vec::with_capacity(BATCH_BYTES + BATCH_BYTES / 4));
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

/// At most `u16::MAX` bytes of `s`.
fn clip(s: &str) -> &[u8] {
    let b = s.as_bytes();
    &b[..b.len().min(usize::from(u16::MAX))]
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

/// The thread: publishes the scene, writes every record of every batch, returns the
/// batches, finishes the file when the channel closes. Stops at the first error (the
/// simulation learns of it at its next send).
fn write_batches<W: Write + Seek>(
    setup: WriterSetup<W>,
    full: &Receiver<Vec<u8>>,
    empty: &SyncSender<Vec<u8>>,
) -> Result<Counts, String> {
    let WriterSetup {
        mcap,
        mut cycles,
        channels,
        mut scene,
    } = setup;
    let mut out = Out {
        mcap,
        channels,
        counts: [0; TOPICS.len()],
        sequence: 0,
        json: Vec::with_capacity(4096),
    };
    out.scene(&scene, 0, None)?;
    let payload_len = cycles.payload_len();
    let (mut state, mut tf) = (Vec::with_capacity(1024), Vec::with_capacity(4096));
    while let Ok(mut batch) = full.recv() {
        let mut rest = batch.as_slice();
        while let Some((&tag, tail)) = rest.split_first() {
            rest = tail;
            let time = take_u64(&mut rest)?;
            match tag {
                CYCLE => {
                    let cycle = take_u64(&mut rest)?;
                    let payload = take(&mut rest, payload_len)?;
                    cycles.encode(time, cycle, payload, &mut state, &mut tf);
                    out.write(STATE, time, &state)?;
                    if !tf.is_empty() {
                        out.write(TF, time, &tf)?;
                    }
                }
                COLOUR => {
                    let head = take(&mut rest, 5)?;
                    let on = head[0] != 0;
                    let a_len = usize::from(u16::from_le_bytes([head[1], head[2]]));
                    let b_len = usize::from(u16::from_le_bytes([head[3], head[4]]));
                    let a = String::from_utf8_lossy(take(&mut rest, a_len)?).into_owned();
                    let b = String::from_utf8_lossy(take(&mut rest, b_len)?).into_owned();
                    scene.colour(&a, &b, on);
                    out.scene(&scene, time, Some(&[a.as_str(), b.as_str()]))?;
                }
                METADATA => {
                    let head = take(&mut rest, 4)?;
                    let len = u32::from_le_bytes([head[0], head[1], head[2], head[3]]) as usize;
                    let v: serde_json::Value = serde_json::from_slice(take(&mut rest, len)?)
                        .map_err(|e| format!("internal error: metadata: {e}"))?;
                    let metadata = v["metadata"]
                        .as_object()
                        .map(|m| {
                            m.iter()
                                .map(|(k, v)| (k.clone(), v.as_str().unwrap_or("").to_string()))
                                .collect()
                        })
                        .unwrap_or_default();
                    let name = v["name"].as_str().unwrap_or("vworks_result").to_string();
                    out.mcap
                        .write_metadata(&mcap::records::Metadata { name, metadata })
                        .map_err(|e| super::error_chain(&e))?;
                }
                _ => {
                    let head = take(&mut rest, 5)?;
                    let topic = usize::from(head[0]);
                    let len = u32::from_le_bytes([head[1], head[2], head[3], head[4]]) as usize;
                    let data = take(&mut rest, len)?;
                    out.write(topic, time, data)?;
                }
            }
        }
        batch.clear();
        // The simulation may have finished meanwhile; a batch nobody takes is just freed.
        let _ = empty.try_send(batch);
    }
    out.mcap.finish().map_err(|e| super::error_chain(&e))?;
    Ok(out.counts)
}

/// The thread's output: the MCAP writer, with sequence numbers and counts per topic.
struct Out<W: Write + Seek> {
    mcap: mcap::Writer<W>,
    channels: [u16; TOPICS.len()],
    counts: Counts,
    sequence: u32,
    /// A reused buffer for scene updates.
    json: Vec<u8>,
}

impl<W: Write + Seek> Out<W> {
    /// Writes one message on topic `topic` (index in [`TOPICS`]) and counts it.
    fn write(&mut self, topic: usize, time: u64, data: &[u8]) -> Result<(), String> {
        let (Some(channel), Some(count)) = (self.channels.get(topic), self.counts.get_mut(topic))
        else {
            return Err(format!("internal error: no topic {topic}"));
        };
        self.sequence = self.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id: *channel,
            sequence: self.sequence,
            log_time: time,
            publish_time: time,
        };
        self.mcap
            .write_to_known_channel(&header, data)
            .map_err(|e| super::error_chain(&e))?;
        *count += 1;
        Ok(())
    }

    /// Publishes the scene (or the bodies of the frames `only`) at `time`.
    fn scene(&mut self, scene: &Scene, time: u64, only: Option<&[&str]>) -> Result<(), String> {
        let mut json = std::mem::take(&mut self.json);
        json.clear();
        let t = i64::try_from(time).unwrap_or(i64::MAX);
        let r = serde_json::to_writer(&mut json, &scene.update(t, only))
            .map_err(|e| e.to_string())
            .and_then(|()| self.write(SCENE, time, &json));
        self.json = json;
        r
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use std::collections::BTreeMap;

    use super::*;
    use crate::cell::{BodyInfo, CellInfo, RobotInfo};
    use crate::mcaplog::Encoding;
    use vworks_model::math::Iso;
    use vworks_model::model::Geometry;

    /// A cell of two built-in robots, a device and a part.
    fn cell() -> CellInfo {
        let robot = |name: &str, model: &str, x: f64| RobotInfo {
            name: name.into(),
            model: std::sync::Arc::new(vworks_model::builtin::load(model).unwrap()),
            base: Iso::from_xyz_rpy([x, 0.0, 0.0], [0.0; 3]),
            tool: Iso::IDENTITY,
            module: Default::default(),
        };
        let body = |name: &str| BodyInfo {
            name: name.into(),
            geometry: Geometry::Box {
                half: [0.1, 0.1, 0.1],
            },
            pose: Iso::IDENTITY,
        };
        CellInfo {
            name: "test".into(),
            file: "cell.toml".into(),
            cycle_ns: 10_000_000,
            clearance: 0.01,
            robots: vec![robot("r1", "ur5", 0.0), robot("t", "track", 1.0)],
            devices: vec![body("table")],
            parts: vec![body("part1")],
            globals: Vec::new(),
            sources: Vec::new(),
            files: Vec::new(),
            overrides: Vec::new(),
        }
    }

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
        let cell = cell();
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
            scene: Scene::new(&cell),
        };
        let mut sink = Sink::spawn(move || Ok(setup)).unwrap();
        let mut failed = None;
        for i in 0..100_000u64 {
            let (start, b) = sink.begin(0, i);
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
        let cell = cell();
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
        let scene = Scene::new(&cell);
        let setup = WriterSetup {
            mcap,
            cycles,
            channels,
            scene,
        };
        let mut sink = Sink::spawn(move || Ok(setup)).unwrap();
        // Enough records for several batches: events and cycles interleaved.
        for i in 0..5_000u64 {
            let (start, b) = sink.begin(0, i * 10);
            b.extend_from_slice(&i.to_le_bytes());
            sink.end(start).unwrap();
            sink.cycle(i * 10 + 5, i, |b| b.extend_from_slice(&payload))
                .unwrap();
        }
        let counts = sink.finish().unwrap();
        // Every cycle gives a state; only the first (a keyframe) has transforms, since the
        // joints never change (and the next keyframe is a second away, past the end); the
        // scene is published once at the start.
        assert_eq!(counts, [5_000, 5_000, 1, 1, 0]);
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
