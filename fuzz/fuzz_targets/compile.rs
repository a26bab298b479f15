//! Source text → compiler → bytecode: must never panic, never emit bytecode that fails
//! verification (E0900), and every module that compiles must round-trip through `.wslb`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    match vworks_wslc::compile("fuzz.wsl", src) {
        Ok(out) => {
            let back = vworks_vm::Module::decode(&out.module.encode()).expect("a compiled module round-trips");
            assert_eq!(back, out.module);
            let _ = vworks_vm::bytecode::disassemble(&out.module, &[src]);
        }
        Err(e) => {
            assert!(!e.diagnostics.is_empty());
            assert!(e.diagnostics.iter().all(|d| d.code != vworks_wslc::Code::E0900), "{:?}", e.diagnostics);
            let mut s = vworks_wslc::Sources::new();
            s.add("fuzz.wsl", src);
            let _ = vworks_wslc::render(&e.diagnostics, &s, false);
        }
    }
});
