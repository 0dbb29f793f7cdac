//! Any text to the host's `modelDescription.xml` parser: a result or an
//! error, never a panic or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Err(e) = fricsim_fmi::ModelDescription::parse(text) {
            assert!(!e.to_string().is_empty());
        }
    }
});
