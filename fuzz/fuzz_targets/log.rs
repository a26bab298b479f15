//! MCAP bytes → `read_log_bytes_with` (poses and shapes too) → the report with its 3D
//! view's data: never a
//! panic, whatever the bytes (a log cut short, a damaged chunk or `/tf` message, another
//! program's MCAP file).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let options = vworks_log::mcaplog::ReadOptions { poses: true };
    if let Ok(contents) = vworks_log::mcaplog::read_log_bytes_with("fuzz.mcap", data, options) {
        let _ = vworks_report::page(&contents, "fuzz.mcap");
    }
});
