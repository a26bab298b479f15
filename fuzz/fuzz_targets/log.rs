//! MCAP bytes → `read_log_bytes` → the report: never a panic, whatever the bytes (a log
//! cut short, a damaged chunk, another program's MCAP file).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(contents) = vworks_se::mcaplog::read_log_bytes("fuzz.mcap", data) {
        let report = vworks_report::Report::from_log(&contents);
        let _ = vworks_report::html(&report, &contents.events, "fuzz.mcap");
    }
});
