//! RAPID text → the RAPID front-end → bytecode: must never panic, never emit bytecode that
//! fails verification (E0900), and every module that compiles must round-trip through
//! `.wslb`. Each input is compiled twice: with any signal allowed, and with a fixed wiring
//! (a `[[io]]` of three signals), so the E0302 paths are exercised too.
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
    for wiring in [None, Some(&io[..])] {
        match vworks_wslc::rapid::compile_with_io("fuzz.mod", src, wiring) {
            Ok(out) => {
                let back = vworks_vm::Module::decode(&out.module.encode()).expect("a compiled module round-trips");
                assert_eq!(back, out.module);
                let _ = vworks_vm::bytecode::disassemble(&out.module, Some(src));
            }
            Err(e) => {
                assert!(!e.diagnostics.is_empty());
                assert!(e.diagnostics.iter().all(|d| d.code != vworks_wslc::Code::E0900), "{:?}", e.diagnostics);
                let mut s = vworks_wslc::Sources::new();
                s.add("fuzz.mod", src);
                let _ = vworks_wslc::render(&e.diagnostics, &s, false);
            }
        }
    }
});
