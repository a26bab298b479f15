//! Mutation fuzzing in the normal test suite: thousands of damaged programs and modules.
//!
//! Programs from `test_data/ok` and the contract's examples are mutated (bytes deleted,
//! duplicated, replaced, tokens spliced in, lines shuffled) with a fixed-seed generator,
//! so a failure reproduces. For every mutant the compiler must return — a module or
//! diagnostics, never a panic — and must never report an internal error (E0900, its own
//! bytecode failing verification). Modules that compile must survive an encode/decode
//! round trip. Encoded modules are then damaged byte by byte (with the checksum fixed
//! up, so the structural checks and the verifier are reached) and the loader must
//! return an error or a module that verifies, never panic. The long-running versions of
//! both are the cargo-fuzz targets in `fuzz/`.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // tests fail by panicking

use std::path::PathBuf;

use vworks_vm::Module;
use vworks_vm::bytecode::disassemble;
use vworks_wslc::{Code, compile};

/// xorshift64*: small, deterministic, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

const SPLICE: &[&str] = &[
    "(",
    ")",
    "{",
    "}",
    ";",
    ",",
    ".",
    "..",
    "[",
    "]",
    "=",
    "+=",
    "==",
    "<",
    "-",
    "*",
    "/",
    "!",
    "x",
    "parts",
    "main",
    "proc ",
    "func ",
    "global ",
    "var ",
    "const ",
    "if ",
    "else ",
    "while ",
    "for ",
    "in ",
    "return ",
    "move_j ",
    "move_l ",
    "move_c ",
    "delay ",
    "wait_until ",
    "when ",
    "every ",
    "after ",
    "do ",
    "parallel ",
    "remote ",
    "signal ",
    "grip ",
    "disable ",
    "log ",
    "stop;",
    "fail ",
    " speed ",
    " accel ",
    " timeout ",
    " cycles ",
    "0",
    "1",
    "2s",
    "10mm",
    "90deg",
    "50%",
    "250mm/s",
    "1e400",
    "99999999999999999999",
    "\"",
    "\"text\"",
    "/*",
    "*/",
    "//",
    "joints(",
    "pose(",
    "now()",
    "cycle()",
    "and ",
    "or ",
    "not ",
    "mod ",
    "\u{2026}",
    "é",
    "\0",
    "\n",
];

fn corpus() -> Vec<String> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("test_data");
    let mut out = Vec::new();
    for sub in ["ok", "spec"] {
        let mut paths: Vec<PathBuf> = std::fs::read_dir(root.join(sub))
            .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        paths.sort();
        for p in paths
            .into_iter()
            .filter(|p| p.extension().is_some_and(|x| x == "wsl"))
        {
            if let Ok(s) = std::fs::read_to_string(&p) {
                out.push(s);
            }
        }
    }
    assert!(out.len() >= 8, "corpus too small");
    out
}

fn char_boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn mutate(src: &str, rng: &mut Rng) -> String {
    let mut s = src.to_string();
    for _ in 0..1 + rng.below(4) {
        let a = char_boundary(&s, rng.below(s.len() + 1));
        let b = char_boundary(&s, a + rng.below(24));
        match rng.below(6) {
            0 => s.replace_range(a..b, ""),
            1 => {
                let piece = s[a..b].to_string();
                s.insert_str(a, &piece);
            }
            2 => s.insert_str(a, SPLICE[rng.below(SPLICE.len())]),
            3 => s.replace_range(a..b, SPLICE[rng.below(SPLICE.len())]),
            4 => {
                let mut lines: Vec<&str> = s.lines().collect();
                if lines.len() > 1 {
                    let i = rng.below(lines.len());
                    let j = rng.below(lines.len());
                    lines.swap(i, j);
                }
                s = lines.join("\n");
            }
            _ => {
                // Deep nesting now and then.
                let n = rng.below(300);
                s.insert_str(a, &format!("{}1{}", "(".repeat(n), ")".repeat(n)));
            }
        }
    }
    s
}

#[test]
fn mutated_programs_never_crash_the_compiler() {
    let corpus = corpus();
    let mut rng = Rng(0x5eed_1234_abcd_0001);
    let (mut ok, mut failed) = (0, 0);
    for i in 0..4000 {
        let src = mutate(&corpus[i % corpus.len()], &mut rng);
        match compile("mutant.wsl", &src) {
            Ok(out) => {
                ok += 1;
                let back = Module::decode(&out.module.encode())
                    .unwrap_or_else(|e| panic!("round trip of mutant {i}: {e}\n{src}"));
                assert_eq!(back, out.module, "mutant {i}");
            }
            Err(e) => {
                failed += 1;
                assert!(!e.diagnostics.is_empty());
                assert!(
                    e.diagnostics.iter().all(|d| d.code != Code::E0900),
                    "internal error on mutant {i}: {:?}\n{src}",
                    e.diagnostics
                );
                for d in &e.diagnostics {
                    assert!(
                        d.at.line >= 1 && d.at.col >= 1,
                        "mutant {i}: diagnostic without position: {d:?}"
                    );
                }
            }
        }
    }
    eprintln!("4000 mutants: {ok} compiled, {failed} rejected with diagnostics");
    // The mutations must exercise both outcomes, or the test proves little.
    assert!(ok > 100 && failed > 1000, "ok {ok}, failed {failed}");
}

#[test]
fn damaged_bytecode_never_crashes_the_loader() {
    let corpus = corpus();
    let modules: Vec<Vec<u8>> = corpus
        .iter()
        .filter_map(|s| compile("m.wsl", s).ok())
        .map(|o| o.module.encode())
        .collect();
    assert!(modules.len() >= 8);
    let mut rng = Rng(0xb17e_c0de_0000_0002);
    let (mut loaded, mut rejected) = (0, 0);
    for i in 0..6000 {
        let mut b = modules[i % modules.len()].clone();
        for _ in 0..1 + rng.below(3) {
            let at = 16 + rng.below(b.len().saturating_sub(16));
            let last = b.len() - 1;
            match rng.below(4) {
                0 => b[at.min(last)] ^= 1 << rng.below(8),
                1 => b[at.min(last)] = rng.next() as u8,
                2 => b.truncate(at.max(17)),
                _ => {
                    let v = rng.next().to_le_bytes();
                    let at = at.min(b.len().saturating_sub(4));
                    b[at..at + 4].copy_from_slice(&v[..4]);
                }
            }
        }
        // Fix the header so the structure and the verifier are reached.
        let payload = b.len() - 16;
        b[8..12].copy_from_slice(&(payload as u32).to_le_bytes());
        let crc = crc32(&b[16..]);
        b[12..16].copy_from_slice(&crc.to_le_bytes());
        match Module::decode(&b) {
            Ok(m) => {
                loaded += 1;
                let _ = disassemble(&m, &[]);
            }
            Err(_) => rejected += 1,
        }
    }
    eprintln!("6000 damaged modules: {loaded} loaded and verified, {rejected} rejected");
    assert!(rejected > 1000, "loaded {loaded}, rejected {rejected}");
    // Without the fix-up, the checksum rejects damage outright.
    let mut b = modules[0].clone();
    let last = b.len() - 1;
    b[last] ^= 0x40;
    assert_eq!(Module::decode(&b), Err(vworks_vm::LoadError::Checksum));
    assert_eq!(
        Module::decode(b"not bytecode"),
        Err(vworks_vm::LoadError::BadMagic)
    );
}

/// CRC-32 (IEEE), bitwise; independent of the implementation the loader uses.
fn crc32(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in data {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}
