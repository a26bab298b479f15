//! The `.wslb` binary encoding of a [`Module`] and its bounds-checked reader.
//!
//! Layout (all integers little-endian):
//!
//! ```text
//! "WSLB" | version: u16 | reserved: u16 = 0 | payload length: u32 | CRC-32 of payload: u32
//! payload = sections in this fixed order, each: tag [u8; 4] | length: u32 | bytes
//!   SRC_ STRS CNST GLOB VARS PROC CODE COND WHEN RMTE SIGS PART JNTS LOGF LINE
//! ```
//!
//! The reader never trusts a length or count: every read is bounds-checked and a count
//! can claim no more items than the bytes left could hold, so corrupt input is an error,
//! never a panic or a huge allocation.

use super::instr::Instr;
use super::*;
use crate::types::{ConstValue, Dim, MAX_AXES, Type};

/// The first four bytes of every `.wslb` file.
pub const MAGIC: [u8; 4] = *b"WSLB";
/// The format version this build writes and reads.
pub const FORMAT_VERSION: u16 = 5;

const SECTIONS: [&[u8; 4]; 15] = [
    b"SRC_", b"STRS", b"CNST", b"GLOB", b"VARS", b"PROC", b"CODE", b"COND", b"WHEN", b"RMTE",
    b"SIGS", b"PART", b"JNTS", b"LOGF", b"LINE",
];

const NO_NAME: u32 = u32::MAX;

struct Writer {
    out: Vec<u8>,
}

impl Writer {
    fn u8(&mut self, v: u8) {
        self.out.push(v);
    }
    fn u16(&mut self, v: u16) {
        self.out.extend_from_slice(&v.to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.out.extend_from_slice(&v.to_le_bytes());
    }
    fn len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }
    fn f64(&mut self, v: f64) {
        self.out.extend_from_slice(&v.to_le_bytes());
    }
    fn str(&mut self, s: &str) {
        self.len(s.len());
        self.out.extend_from_slice(s.as_bytes());
    }
    fn pos(&mut self, p: SrcPos) {
        self.u32(p.file);
        self.u32(p.line);
        self.u32(p.col);
    }
    fn ty(&mut self, t: Type) {
        match t {
            Type::Bool => self.u8(0),
            Type::Int => self.u8(1),
            Type::Num(d) => {
                self.u8(2);
                for e in [d.length, d.angle, d.time] {
                    self.u8(e as u8);
                }
            }
            Type::Joints => self.u8(3),
            Type::Pose => self.u8(4),
            Type::Text => self.u8(5),
        }
    }
    fn value(&mut self, v: &ConstValue) {
        match v {
            ConstValue::Bool(b) => {
                self.u8(0);
                self.u8(u8::from(*b));
            }
            ConstValue::Int(i) => {
                self.u8(1);
                self.out.extend_from_slice(&i.to_le_bytes());
            }
            ConstValue::Num(x) => {
                self.u8(2);
                self.f64(*x);
            }
            ConstValue::Joints(v) => {
                self.u8(3);
                self.u8(v.len().min(255) as u8);
                v.iter().for_each(|x| self.f64(*x));
            }
            ConstValue::Pose(p) => {
                self.u8(4);
                p.iter().for_each(|x| self.f64(*x));
            }
            ConstValue::Text(k) => {
                self.u8(5);
                self.u32(*k);
            }
        }
    }
    fn captures(&mut self, c: &[Capture]) {
        self.len(c.len());
        for c in c {
            self.u32(c.slot);
            self.u8(c.width);
        }
    }
    fn section(&mut self, tag: &[u8; 4], body: impl FnOnce(&mut Writer)) {
        self.out.extend_from_slice(tag);
        let at = self.out.len();
        self.u32(0);
        body(self);
        let n = (self.out.len() - at - 4) as u32;
        self.out[at..at + 4].copy_from_slice(&n.to_le_bytes());
    }
}

impl Module {
    /// Encodes the module as `.wslb` bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer { out: Vec::new() };
        w.section(SECTIONS[0], |w| {
            w.len(self.files.len());
            for f in &self.files {
                w.str(f);
            }
        });
        w.section(SECTIONS[1], |w| {
            w.len(self.strings.len());
            self.strings.iter().for_each(|s| w.str(s));
        });
        w.section(SECTIONS[2], |w| {
            w.len(self.consts.len());
            for c in &self.consts {
                w.u32(c.name.unwrap_or(NO_NAME));
                w.ty(c.ty);
                w.value(&c.value);
                w.pos(c.pos);
            }
        });
        w.section(SECTIONS[3], |w| {
            w.len(self.globals.len());
            for g in &self.globals {
                w.u32(g.name);
                w.ty(g.ty);
                w.value(&g.init);
                w.pos(g.pos);
            }
        });
        w.section(SECTIONS[4], |w| {
            w.u32(self.var_slots);
            w.len(self.vars.len());
            for v in &self.vars {
                w.u32(v.name);
                w.ty(v.ty);
                w.u32(v.slot);
                w.value(&v.init);
                w.pos(v.pos);
                w.u8(u8::from(v.param));
            }
        });
        w.section(SECTIONS[5], |w| {
            w.len(self.procs.len());
            for p in &self.procs {
                w.u32(p.name);
                w.u8(p.kind.code());
                w.len(p.params.len());
                for a in &p.params {
                    w.u32(a.name);
                    w.ty(a.ty);
                }
                match p.ret {
                    None => w.u8(0),
                    Some(t) => {
                        w.u8(1);
                        w.ty(t);
                    }
                }
                w.u32(p.frame_slots);
                w.u32(p.code_start);
                w.u32(p.code_len);
                w.pos(p.pos);
                match &p.handler {
                    None => w.u8(0),
                    Some(h) => {
                        w.u8(1);
                        w.u32(h.pc);
                        w.len(h.stmts.len());
                        for (s, e) in &h.stmts {
                            w.u32(*s);
                            w.u32(*e);
                        }
                    }
                }
            }
        });
        w.section(SECTIONS[6], |w| {
            w.len(self.code.len());
            self.code.iter().for_each(|i| i.encode(&mut w.out));
        });
        w.section(SECTIONS[7], |w| {
            w.len(self.conds.len());
            for c in &self.conds {
                w.u32(c.func);
                w.captures(&c.captures);
                w.len(c.globals.len());
                c.globals.iter().for_each(|g| w.u32(*g));
                w.pos(c.pos);
            }
        });
        w.section(SECTIONS[8], |w| {
            w.len(self.handlers.len());
            for h in &self.handlers {
                match h.trigger {
                    Trigger::EveryCycles => w.u8(0),
                    Trigger::Every => w.u8(1),
                    Trigger::After => w.u8(2),
                    Trigger::Condition(c) => {
                        w.u8(3);
                        w.u32(c);
                    }
                }
                w.u32(h.action);
                w.u32(h.target);
                w.captures(&h.captures);
                w.pos(h.pos);
            }
        });
        w.section(SECTIONS[9], |w| {
            w.len(self.remotes.len());
            for r in &self.remotes {
                w.u32(r.robot);
                w.u32(r.proc);
                w.len(r.args.len());
                r.args.iter().for_each(|t| w.ty(*t));
                w.pos(r.pos);
            }
        });
        w.section(SECTIONS[10], |w| {
            w.len(self.signals_sent.len());
            for s in &self.signals_sent {
                w.u32(s.robot);
                w.u32(s.name);
                w.pos(s.pos);
            }
            w.len(self.signals_awaited.len());
            self.signals_awaited.iter().for_each(|s| w.u32(*s));
            w.len(self.syncs.len());
            for x in &self.syncs {
                w.u32(x.name);
                w.len(x.tasks.len());
                x.tasks.iter().for_each(|t| w.u32(*t));
                w.pos(x.pos);
            }
        });
        w.section(SECTIONS[11], |w| {
            w.len(self.parts.len());
            for p in &self.parts {
                w.u32(p.part);
                w.pos(p.pos);
            }
        });
        w.section(SECTIONS[12], |w| {
            w.len(self.joints_sites.len());
            for j in &self.joints_sites {
                w.u8(j.count);
                w.u16(j.linear_mask);
                w.pos(j.pos);
            }
        });
        w.section(SECTIONS[13], |w| {
            w.len(self.log_formats.len());
            for f in &self.log_formats {
                w.len(f.parts.len());
                for p in &f.parts {
                    match p {
                        LogPart::Text(s) => {
                            w.u8(0);
                            w.u32(*s);
                        }
                        LogPart::Value(t) => {
                            w.u8(1);
                            w.ty(*t);
                        }
                    }
                }
            }
        });
        w.section(SECTIONS[14], |w| {
            w.len(self.lines.len());
            for l in &self.lines {
                w.u32(l.pc);
                w.pos(l.pos);
            }
        });
        let payload = w.out;
        let mut out = Vec::with_capacity(payload.len() + 16);
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u32).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// Reads and verifies `.wslb` bytes. Any corruption is an error, never a panic.
    pub fn decode(bytes: &[u8]) -> Result<Module, LoadError> {
        if bytes.len() < 4 || bytes[..4] != MAGIC {
            return Err(LoadError::BadMagic);
        }
        let mut r = Reader { bytes, pos: 4 };
        let version = u16::from_le_bytes(r.array()?);
        if version != FORMAT_VERSION {
            return Err(LoadError::Version {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        if u16::from_le_bytes(r.array()?) != 0 {
            return Err(r.error("reserved header field is not zero".into()));
        }
        let len = r.u32()? as usize;
        let crc = r.u32()?;
        if bytes.len() - r.pos != len {
            return Err(LoadError::Malformed {
                offset: r.pos,
                message: format!(
                    "the header says the payload has {len} bytes, but {} follow (truncated or padded file)",
                    bytes.len() - r.pos
                ),
            });
        }
        if crc32fast::hash(&bytes[r.pos..]) != crc {
            return Err(LoadError::Checksum);
        }
        let mut m = Module::default();
        for (i, tag) in SECTIONS.iter().enumerate() {
            let mut s = r.section(tag)?;
            let s = &mut s;
            match i {
                0 => m.files = s.list(4, Reader::string)?,
                1 => m.strings = s.list(4, Reader::string)?,
                2 => {
                    m.consts = s.list(15, |s| {
                        let name = s.u32()?;
                        Ok(ConstInfo {
                            name: (name != NO_NAME).then_some(name),
                            ty: s.ty()?,
                            value: s.value()?,
                            pos: s.pos()?,
                        })
                    })?
                }
                3 => {
                    m.globals = s.list(15, |s| {
                        Ok(GlobalInfo {
                            name: s.u32()?,
                            ty: s.ty()?,
                            init: s.value()?,
                            pos: s.pos()?,
                        })
                    })?
                }
                4 => {
                    m.var_slots = s.u32()?;
                    m.vars = s.list(20, |s| {
                        Ok(VarInfo {
                            name: s.u32()?,
                            ty: s.ty()?,
                            slot: s.u32()?,
                            init: s.value()?,
                            pos: s.pos()?,
                            param: match s.u8()? {
                                0 => false,
                                1 => true,
                                other => {
                                    return Err(s.error(format!(
                                        "a variable's param flag is {other}, not 0 or 1"
                                    )));
                                }
                            },
                        })
                    })?
                }
                5 => {
                    m.procs = s.list(30, |s| {
                        let name = s.u32()?;
                        let kind_code = s.u8()?;
                        let kind = ProcKind::from_code(kind_code).ok_or_else(|| {
                            s.error(format!("unknown procedure kind {kind_code}"))
                        })?;
                        let params = s.list(5, |s| {
                            Ok(ParamInfo {
                                name: s.u32()?,
                                ty: s.ty()?,
                            })
                        })?;
                        let ret = match s.u8()? {
                            0 => None,
                            1 => Some(s.ty()?),
                            b => return Err(s.error(format!("bad return-type flag {b}"))),
                        };
                        Ok(ProcInfo {
                            name,
                            kind,
                            params,
                            ret,
                            frame_slots: s.u32()?,
                            code_start: s.u32()?,
                            code_len: s.u32()?,
                            pos: s.pos()?,
                            max_stack: 0,
                            handler: match s.u8()? {
                                0 => None,
                                1 => Some(ErrorHandler {
                                    pc: s.u32()?,
                                    stmts: s.list(8, |s| Ok((s.u32()?, s.u32()?)))?,
                                }),
                                b => return Err(s.error(format!("bad error-handler flag {b}"))),
                            },
                        })
                    })?
                }
                6 => m.code = s.list(1, Instr::decode)?,
                7 => {
                    m.conds = s.list(20, |s| {
                        Ok(CondInfo {
                            func: s.u32()?,
                            captures: s.captures()?,
                            globals: s.list(4, Reader::u32)?,
                            pos: s.pos()?,
                        })
                    })?
                }
                8 => {
                    m.handlers = s.list(21, |s| {
                        let trigger = match s.u8()? {
                            0 => Trigger::EveryCycles,
                            1 => Trigger::Every,
                            2 => Trigger::After,
                            3 => Trigger::Condition(s.u32()?),
                            b => return Err(s.error(format!("unknown trigger kind {b}"))),
                        };
                        Ok(HandlerInfo {
                            trigger,
                            action: s.u32()?,
                            target: s.u32()?,
                            captures: s.captures()?,
                            pos: s.pos()?,
                        })
                    })?
                }
                9 => {
                    m.remotes = s.list(20, |s| {
                        Ok(RemoteSite {
                            robot: s.u32()?,
                            proc: s.u32()?,
                            args: s.list(1, Reader::ty)?,
                            pos: s.pos()?,
                        })
                    })?
                }
                10 => {
                    m.signals_sent = s.list(16, |s| {
                        Ok(SignalSite {
                            robot: s.u32()?,
                            name: s.u32()?,
                            pos: s.pos()?,
                        })
                    })?;
                    m.signals_awaited = s.list(4, Reader::u32)?;
                    m.syncs = s.list(16, |s| {
                        Ok(SyncSite {
                            name: s.u32()?,
                            tasks: s.list(4, Reader::u32)?,
                            pos: s.pos()?,
                        })
                    })?;
                }
                11 => {
                    m.parts = s.list(12, |s| {
                        Ok(PartSite {
                            part: s.u32()?,
                            pos: s.pos()?,
                        })
                    })?
                }
                12 => {
                    m.joints_sites = s.list(11, |s| {
                        Ok(JointsSite {
                            count: s.u8()?,
                            linear_mask: u16::from_le_bytes(s.array()?),
                            pos: s.pos()?,
                        })
                    })?
                }
                13 => {
                    m.log_formats = s.list(4, |s| {
                        Ok(LogFormat {
                            parts: s.list(2, |s| match s.u8()? {
                                0 => Ok(LogPart::Text(s.u32()?)),
                                1 => Ok(LogPart::Value(s.ty()?)),
                                b => Err(s.error(format!("unknown log part kind {b}"))),
                            })?,
                        })
                    })?
                }
                _ => {
                    m.lines = s.list(16, |s| {
                        Ok(LineEntry {
                            pc: s.u32()?,
                            pos: s.pos()?,
                        })
                    })?
                }
            }
            s.finish(tag)?;
        }
        if r.pos != bytes.len() {
            return Err(r.error("bytes after the last section".into()));
        }
        m.verify()?;
        Ok(m)
    }
}

/// A bounds-checked cursor over untrusted bytes.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn error(&self, message: String) -> LoadError {
        LoadError::Malformed {
            offset: self.pos,
            message,
        }
    }

    pub(crate) fn array<const N: usize>(&mut self) -> Result<[u8; N], LoadError> {
        let end = self.pos.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(self.error(format!("unexpected end of data (needed {N} more bytes)")));
        };
        let mut a = [0u8; N];
        a.copy_from_slice(&self.bytes[self.pos..end]);
        self.pos = end;
        Ok(a)
    }

    pub(crate) fn u8(&mut self) -> Result<u8, LoadError> {
        Ok(self.array::<1>()?[0])
    }

    pub(crate) fn u16(&mut self) -> Result<u16, LoadError> {
        Ok(u16::from_le_bytes(self.array()?))
    }

    fn u32(&mut self) -> Result<u32, LoadError> {
        Ok(u32::from_le_bytes(self.array()?))
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn section(&mut self, tag: &[u8; 4]) -> Result<Reader<'a>, LoadError> {
        let found: [u8; 4] = self.array()?;
        if &found != tag {
            return Err(self.error(format!(
                "expected section {:?}, found {:?}",
                String::from_utf8_lossy(tag),
                String::from_utf8_lossy(&found)
            )));
        }
        let len = self.u32()? as usize;
        if len > self.remaining() {
            return Err(self.error(format!(
                "section {:?} claims {len} bytes but only {} remain",
                String::from_utf8_lossy(tag),
                self.remaining()
            )));
        }
        let sub = Reader {
            bytes: &self.bytes[..self.pos + len],
            pos: self.pos,
        };
        self.pos += len;
        Ok(sub)
    }

    fn finish(&self, tag: &[u8; 4]) -> Result<(), LoadError> {
        if self.remaining() != 0 {
            return Err(self.error(format!(
                "{} unread bytes at the end of section {:?}",
                self.remaining(),
                String::from_utf8_lossy(tag)
            )));
        }
        Ok(())
    }

    /// Reads a count of items that take at least `min_size` bytes each, then the items.
    fn list<T>(
        &mut self,
        min_size: usize,
        mut item: impl FnMut(&mut Self) -> Result<T, LoadError>,
    ) -> Result<Vec<T>, LoadError> {
        let n = self.u32()? as usize;
        if n.saturating_mul(min_size.max(1)) > self.remaining() {
            return Err(self.error(format!(
                "a count of {n} items does not fit in the {} bytes left",
                self.remaining()
            )));
        }
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(item(self)?);
        }
        Ok(v)
    }

    fn string(&mut self) -> Result<String, LoadError> {
        let n = self.u32()? as usize;
        if n > self.remaining() {
            return Err(self.error(format!("a string of {n} bytes runs past the end")));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        let s = std::str::from_utf8(s)
            .map_err(|e| self.error(format!("a string is not UTF-8: {e}")))?
            .to_string();
        self.pos += n;
        Ok(s)
    }

    fn pos(&mut self) -> Result<SrcPos, LoadError> {
        Ok(SrcPos {
            file: self.u32()?,
            line: self.u32()?,
            col: self.u32()?,
        })
    }

    fn f64(&mut self) -> Result<f64, LoadError> {
        Ok(f64::from_le_bytes(self.array()?))
    }

    fn ty(&mut self) -> Result<Type, LoadError> {
        Ok(match self.u8()? {
            0 => Type::Bool,
            1 => Type::Int,
            2 => {
                let [l, a, t]: [u8; 3] = self.array()?;
                Type::Num(Dim::new(l as i8, a as i8, t as i8))
            }
            3 => Type::Joints,
            4 => Type::Pose,
            5 => Type::Text,
            b => return Err(self.error(format!("unknown type tag {b}"))),
        })
    }

    fn value(&mut self) -> Result<ConstValue, LoadError> {
        Ok(match self.u8()? {
            0 => match self.u8()? {
                0 => ConstValue::Bool(false),
                1 => ConstValue::Bool(true),
                b => return Err(self.error(format!("a bool constant must be 0 or 1, found {b}"))),
            },
            1 => ConstValue::Int(i64::from_le_bytes(self.array()?)),
            2 => ConstValue::Num(self.f64()?),
            3 => {
                let n = self.u8()? as usize;
                if n > MAX_AXES {
                    return Err(self.error(format!(
                        "a joints constant has {n} values; at most {MAX_AXES} are allowed"
                    )));
                }
                let mut v = Vec::with_capacity(n);
                for _ in 0..n {
                    v.push(self.f64()?);
                }
                ConstValue::Joints(v)
            }
            4 => {
                let mut p = [0.0; 6];
                for x in &mut p {
                    *x = self.f64()?;
                }
                ConstValue::Pose(p)
            }
            5 => ConstValue::Text(self.u32()?),
            b => return Err(self.error(format!("unknown constant tag {b}"))),
        })
    }

    fn captures(&mut self) -> Result<Vec<Capture>, LoadError> {
        self.list(5, |s| {
            Ok(Capture {
                slot: s.u32()?,
                width: s.u8()?,
            })
        })
    }
}
