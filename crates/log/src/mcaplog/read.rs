//! Reading a log back: its topics, message counts and simulated span, its metadata and
//! its events, decoded into the run's typed events ([`crate::trace::Event`]). A log cut short (the run was killed) is read up to the damage, and the
//! damage is reported beside what was read.

use std::collections::BTreeMap;
use std::path::Path;

use vworks_model::files::read_regular;

use super::poses::{self, FrameTransform};
use super::{LogError, LoggedEvent, RESULT_METADATA};

/// What to decode besides the counts, span, events and metadata.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReadOptions {
    /// Also the poses and shapes: every `/tf` message's transforms and every `/scene`
    /// message (what plays the run back in 3D). Off, they are only counted.
    pub poses: bool,
}

/// What a log holds.
#[derive(Clone, Debug, Default)]
pub struct LogContents {
    /// Messages per topic (topics with at least one message).
    pub counts: BTreeMap<String, u64>,
    /// The first and last message time (ns), if there are messages.
    pub span: Option<(u64, u64)>,
    /// The `/events` messages, in order.
    pub events: Vec<LoggedEvent>,
    /// If the file is unfinished or damaged: how many messages were read before the
    /// damage, and what the damage is. Everything before it is above.
    pub damage: Option<(u64, String)>,
    /// The `vworks` metadata record: the version, the cell's name, its robots (comma
    /// separated), the cycle, the workcell file (empty if the record was not found).
    pub metadata: BTreeMap<String, String>,
    /// The `vworks_result` metadata record ([`RESULT_METADATA`]): the outcome, the end
    /// time and each robot's ending (empty if the run did not finish the log, or for
    /// logs of version 1).
    pub result: BTreeMap<String, String>,
    /// With [`ReadOptions::poses`]: the frame names `transforms` refer to, in the order
    /// first seen.
    pub frames: Vec<String>,
    /// With [`ReadOptions::poses`]: every `/tf` message, its time (ns) and transforms.
    pub transforms: Vec<(u64, Vec<FrameTransform>)>,
    /// With [`ReadOptions::poses`]: every `/scene` message (`foxglove.SceneUpdate` as
    /// JSON), with its time (ns).
    pub scene: Vec<(u64, serde_json::Value)>,
}

/// Reads the log at `path` (counts, span, events, metadata).
pub fn read_log(path: &Path) -> Result<LogContents, LogError> {
    read_log_with(path, ReadOptions::default())
}

/// The largest log read (4 GiB): a log is read whole into memory.
pub const MAX_LOG_BYTES: u64 = 4 << 30;

/// Reads the log at `path`, decoding what `options` asks for besides. Only a regular file
/// (or a link to one) of at most [`MAX_LOG_BYTES`] is read.
pub fn read_log_with(path: &Path, options: ReadOptions) -> Result<LogContents, LogError> {
    let file = path.display().to_string();
    let bytes = read_regular(path, MAX_LOG_BYTES).map_err(|e| LogError::Read {
        file: file.clone(),
        reason: match e.kind() {
            std::io::ErrorKind::NotFound => format!(
                "{e}; check the path, or write the log first: `vworks run CELL --log {file}`"
            ),
            std::io::ErrorKind::FileTooLarge => {
                format!("{e}; or log fewer cycles: `vworks run CELL --log {file} --log-every 10`")
            }
            _ => e.to_string(),
        },
    })?;
    read_log_bytes_with(&file, &bytes, options)
}

/// Reads a log from its bytes; `file` names it in errors.
pub fn read_log_bytes(file: &str, bytes: &[u8]) -> Result<LogContents, LogError> {
    read_log_bytes_with(file, bytes, ReadOptions::default())
}

/// Reads a log from its bytes, decoding what `options` asks for; `file` names it in
/// errors.
pub fn read_log_bytes_with(
    file: &str,
    bytes: &[u8],
    options: ReadOptions,
) -> Result<LogContents, LogError> {
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(LogError::NotMcap { file: file.into() });
    }
    let invalid = |reason: String| LogError::Invalid {
        file: file.into(),
        reason,
    };
    // A damaged chunk header or record can claim any size, which the mcap crate's message
    // stream would allocate at once (2^56 bytes; a 4 GB string: found by fuzzing). So the
    // log is read with its sans-io reader and a record size limit, every length checked
    // before a record is parsed, and messages taken from their records here.
    let mut out = LogContents::default();
    // The reader trusts the records inside an uncompressed chunk to fit in it (a longer one
    // underflows its count: found by fuzzing). Such a chunk is the damage: everything
    // before it is read (the reader then finds the file cut short there).
    let damage = match uncompressed_chunks_fit(bytes) {
        Ok(()) => scan(bytes, &mut out, &invalid, options)?,
        Err((at, why)) => {
            scan(&bytes[..at], &mut out, &invalid, options)?;
            Some(why)
        }
    };
    if let Some(why) = damage {
        let read = out.counts.values().sum();
        out.damage = Some((read, why));
    }
    Ok(out)
}

/// Reads every record of `bytes` into `out` (counts per topic, time span, events,
/// metadata); returns what is damaged, if something is, where the reading stopped.
fn scan(
    bytes: &[u8],
    out: &mut LogContents,
    invalid: &dyn Fn(String) -> LogError,
    options: ReadOptions,
) -> Result<Option<String>, LogError> {
    use mcap::records::op;
    use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(MAX_RECORD),
    );
    let mut rest = bytes;
    let mut messages = 0u64;
    // Channel id → topic, and whether its messages are JSON.
    let mut topics: BTreeMap<u16, String> = BTreeMap::new();
    let mut json_channels: BTreeMap<u16, bool> = BTreeMap::new();
    let mut frame_index: BTreeMap<String, u32> = BTreeMap::new();
    let u16_at = |d: &[u8], at: usize| d.get(at..at + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    let u64_at = |d: &[u8], at: usize| {
        d.get(at..at + 8)
            .and_then(|b| b.try_into().ok())
            .map(u64::from_le_bytes)
    };
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event {
            Ok(LinearReadEvent::ReadRequest(need)) => {
                let len = need.min(rest.len());
                reader.insert(len).copy_from_slice(&rest[..len]);
                reader.notify_read(len);
                rest = &rest[len..];
                continue;
            }
            Ok(LinearReadEvent::Record { opcode, data }) => (opcode, data),
            Err(mcap::McapError::RecordTooLarge { opcode, len }) => {
                return Ok(Some(format!(
                    "after {messages} messages a record (opcode {opcode:#04x}) claims {len} bytes: the file is damaged there"
                )));
            }
            Err(e) => return Ok(Some(e.to_string())),
        };
        if !lengths_fit(opcode, data) {
            return Ok(Some(format!(
                "after {messages} messages a record (opcode {opcode:#04x}) has a field longer than the record: the file is damaged there"
            )));
        }
        match opcode {
            // Channel: id u16, schema id u16, topic (u32 length, bytes), …
            op::CHANNEL => {
                let (Some(id), Some(len)) = (u16_at(data, 0), data.get(4..8)) else {
                    continue;
                };
                let len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
                if let Some(topic) = data.get(8..8 + len) {
                    topics.insert(id, String::from_utf8_lossy(topic).into_owned());
                }
                // … message encoding (u32 length, bytes).
                let enc = data.get(8 + len..12 + len).and_then(|l| {
                    let n = u32::from_le_bytes([l[0], l[1], l[2], l[3]]) as usize;
                    data.get(12 + len..12 + len + n)
                });
                json_channels.insert(id, enc == Some(b"json".as_slice()));
            }
            // The run's metadata (its lengths fit: safe to parse).
            op::METADATA => {
                if let Ok(mcap::records::Record::Metadata(m)) = mcap::parse_record(opcode, data) {
                    if m.name == "vworks" {
                        out.metadata = m.metadata;
                    } else if m.name == RESULT_METADATA {
                        out.result = m.metadata;
                    }
                }
            }
            // Message: channel id u16, sequence u32, log time u64, publish time u64, data.
            op::MESSAGE => {
                let (Some(channel), Some(log_time)) = (u16_at(data, 0), u64_at(data, 6)) else {
                    return Ok(Some(format!("message {messages} is cut short")));
                };
                let Some(topic) = topics.get(&channel) else {
                    return Ok(Some(format!(
                        "message {messages} is on channel {channel}, which the log never declared"
                    )));
                };
                messages += 1;
                *out.counts.entry(topic.clone()).or_default() += 1;
                let (first, last) = out.span.unwrap_or((log_time, log_time));
                out.span = Some((first.min(log_time), last.max(log_time)));
                if topic == "/events" {
                    let payload = data.get(22..).unwrap_or_default();
                    let v: serde_json::Value = serde_json::from_slice(payload)
                        .map_err(|e| invalid(format!("an event is not JSON: {e}")))?;
                    let event = LoggedEvent::from_json(&v).map_err(|why| {
                        invalid(format!(
                            "event {}: {why}; was it written by a newer vworks?",
                            out.events.len()
                        ))
                    })?;
                    out.events.push(event);
                } else if options.poses && topic == "/tf" {
                    let payload = data.get(22..).unwrap_or_default();
                    let named = if json_channels.get(&channel).copied().unwrap_or(false) {
                        serde_json::from_slice(payload)
                            .ok()
                            .and_then(|v| poses::decode_json(&v))
                    } else {
                        poses::decode_protobuf(payload)
                    };
                    let Some(named) = named else {
                        return Ok(Some(format!(
                            "/tf message {} cannot be decoded: the file is damaged there",
                            out.transforms.len()
                        )));
                    };
                    let mut index = |name: String| {
                        let next = frame_index.len() as u32;
                        *frame_index.entry(name.clone()).or_insert_with(|| {
                            out.frames.push(name);
                            next
                        })
                    };
                    let ts = named
                        .into_iter()
                        .map(|(parent, child, translation, rotation)| FrameTransform {
                            parent: index(parent),
                            child: index(child),
                            translation,
                            rotation,
                        })
                        .collect();
                    out.transforms.push((log_time, ts));
                } else if options.poses && topic == "/scene" {
                    let payload = data.get(22..).unwrap_or_default();
                    let Ok(v) = serde_json::from_slice(payload) else {
                        return Ok(Some(format!(
                            "/scene message {} is not JSON: the file is damaged there",
                            out.scene.len()
                        )));
                    };
                    out.scene.push((log_time, v));
                }
            }
            _ => {}
        }
    }
    Ok(None)
}

/// Checks every uncompressed chunk of the file: each record inside it must fit in the
/// chunk's records. Returns where the first chunk that breaks this starts, and why.
/// Records are walked as the file lays them out (opcode u8, length u64); what cannot be
/// walked further is left to the reader, which reports it.
fn uncompressed_chunks_fit(bytes: &[u8]) -> Result<(), (usize, String)> {
    const CHUNK: u8 = 0x06;
    let u64_at = |at: usize| {
        bytes
            .get(at..at.checked_add(8)?)
            .and_then(|b| b.try_into().ok())
            .map(u64::from_le_bytes)
    };
    let mut at = mcap::MAGIC.len();
    while let (Some(&opcode), Some(len)) = (bytes.get(at), u64_at(at + 1)) {
        let body = at + 9;
        // A record may claim more than the file holds (a file cut short): the reader
        // streams what there is, so a chunk is checked up to the file's end.
        let claimed = usize::try_from(len).ok().and_then(|l| body.checked_add(l));
        let end = claimed.map_or(bytes.len(), |e| e.min(bytes.len()));
        if opcode == CHUNK {
            // start u64, end u64, uncompressed size u64, crc u32, compression (u32 length
            // and text), records length u64, records.
            let comp_len = bytes
                .get(body + 28..body + 32)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
            if let Some(comp_len) = comp_len
                && comp_len == 0
                && let Some(records_len) = u64_at(body + 32)
            {
                let start = body + 40;
                let records_end = usize::try_from(records_len)
                    .ok()
                    .and_then(|l| start.checked_add(l))
                    .filter(|e| *e <= end)
                    .unwrap_or(end);
                let mut r = start;
                while r < records_end {
                    let inner = u64_at(r + 1)
                        .and_then(|l| usize::try_from(l).ok())
                        .and_then(|l| (r + 9).checked_add(l));
                    match inner {
                        Some(next) if next <= records_end => r = next,
                        _ => {
                            return Err((
                                at,
                                format!(
                                    "the chunk at byte {at} holds a record longer than the chunk: the file is damaged there"
                                ),
                            ));
                        }
                    }
                }
            }
        }
        match claimed {
            Some(e) if e <= bytes.len() => at = e,
            _ => return Ok(()),
        }
    }
    Ok(())
}

/// Whether every length-prefixed field of a record fits in the record: the mcap crate
/// reserves a string or map's declared length before reading it (3.5 GB for a damaged
/// metadata map: found by fuzzing). Checks the records with such fields that a data
/// section holds: header, schema, channel, metadata, attachment.
fn lengths_fit(opcode: u8, data: &[u8]) -> bool {
    use mcap::records::op;
    // Skips `fixed` bytes, then a field with a u32 (or u64) length prefix.
    struct Fields<'a>(&'a [u8]);
    impl Fields<'_> {
        fn skip(&mut self, n: usize) -> bool {
            match self.0.get(n..) {
                Some(rest) => {
                    self.0 = rest;
                    true
                }
                None => false,
            }
        }
        fn prefixed(&mut self, wide: bool) -> bool {
            let w = if wide { 8 } else { 4 };
            let Some(b) = self.0.get(..w) else {
                return false;
            };
            let mut len = [0u8; 8];
            len[..w].copy_from_slice(b);
            let len = u64::from_le_bytes(len);
            self.skip(w) && usize::try_from(len).is_ok_and(|l| self.skip(l))
        }
        /// A string map: a u32 byte length, then (key, value) strings filling it exactly.
        fn map(&mut self) -> bool {
            let Some(b) = self.0.get(..4) else {
                return false;
            };
            let len = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
            let Some(entries) = self.0.get(4..).and_then(|r| r.get(..len)) else {
                return false;
            };
            let mut inner = Fields(entries);
            while !inner.0.is_empty() {
                if !(inner.prefixed(false) && inner.prefixed(false)) {
                    return false;
                }
            }
            self.skip(4 + len)
        }
    }
    let mut f = Fields(data);
    match opcode {
        op::HEADER => f.prefixed(false) && f.prefixed(false),
        op::SCHEMA => f.skip(2) && f.prefixed(false) && f.prefixed(false) && f.prefixed(false),
        op::CHANNEL => f.skip(4) && f.prefixed(false) && f.prefixed(false) && f.map(),
        op::METADATA => f.prefixed(false) && f.map(),
        op::ATTACHMENT => f.skip(16) && f.prefixed(false) && f.prefixed(false) && f.prefixed(true),
        _ => true,
    }
}

/// The largest record a log may hold (vworks writes chunks of about 10 kB).
const MAX_RECORD: usize = 256 << 20;
