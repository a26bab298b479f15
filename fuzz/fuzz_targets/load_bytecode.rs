//! Untrusted bytes → bytecode loader: must never panic. The checksum is fixed up first so
//! the fuzzer reaches the structural checks and the verifier instead of stopping at CRC.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut b = data.to_vec();
    if b.len() >= 16 && b.starts_with(b"WSLB") {
        let n = (b.len() - 16) as u32;
        b[8..12].copy_from_slice(&n.to_le_bytes());
        let crc = crc32fast_hash(&b[16..]);
        b[12..16].copy_from_slice(&crc.to_le_bytes());
    }
    if let Ok(m) = vworks_vm::Module::decode(&b) {
        let _ = vworks_vm::bytecode::disassemble(&m, &[]);
        // A module that loads re-encodes to bytes that load to the same module.
        let again = vworks_vm::Module::decode(&m.encode()).expect("re-encoded module loads");
        assert_eq!(again, m);
    }
});

fn crc32fast_hash(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in data {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}
