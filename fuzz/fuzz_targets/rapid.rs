//! RAPID text → the RAPID front-end → bytecode: must never panic, never emit bytecode that
//! fails verification (E0900), and every module that compiles must round-trip through
//! `.wslb`. An input with U+0001 characters is a task of several files (split there), so
//! the joining of files and the mapping of spans back to them are exercised. Each input
//! is compiled twice: with any signal allowed, and with a fixed wiring (a `[[io]]` of
//! three signals), so the E0302 paths are exercised too.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vworks_wslc::rapid::{IoSignal, SignalKind};

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    let io = [
        IoSignal { name: "doReady".into(), kind: SignalKind::Do, global: "doready".into(), init: 0 },
        IoSignal { name: "diReady".into(), kind: SignalKind::Di, global: "doready".into(), init: 0 },
        IoSignal { name: "goCode".into(), kind: SignalKind::Go, global: "gocode".into(), init: 3 },
    ];
    let names: Vec<String> = (0..src.split('\u{1}').count()).map(|k| format!("f{k}.mod")).collect();
    let files: Vec<(&str, &str)> = names.iter().map(String::as_str).zip(src.split('\u{1}')).collect();
    let texts: Vec<&str> = files.iter().map(|(_, t)| *t).collect();
    for wiring in [None, Some(&io[..])] {
        match vworks_wslc::rapid::compile_files(&files, wiring) {
            Ok(out) => {
                let back = vworks_vm::Module::decode(&out.module.encode()).expect("a compiled module round-trips");
                assert_eq!(back, out.module);
                assert_eq!(out.module.files, names);
                let _ = vworks_vm::bytecode::disassemble(&out.module, &texts);
            }
            Err(e) => {
                assert!(!e.diagnostics.is_empty());
                assert!(e.diagnostics.iter().all(|d| d.code != vworks_wslc::Code::E0900), "{:?}", e.diagnostics);
                let mut s = vworks_wslc::Sources::new();
                for (name, text) in &files {
                    s.add(name, text);
                }
                // Every place is in one of the files, its span inside that file's text.
                for d in &e.diagnostics {
                    let (_, text) = files.iter().find(|(n, _)| *n == d.at.file).expect("a diagnostic names one of the files");
                    if let Some(sp) = d.at.span {
                        assert!(sp.start <= sp.end && sp.end as usize <= text.len(), "{d:?}");
                    }
                }
                let _ = vworks_wslc::render(&e.diagnostics, &s, false);
            }
        }
    }
});
