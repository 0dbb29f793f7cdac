//! Any bytes as a system file (`.ssd`) next to the examples' `.ssv` files,
//! read by the host's system-file reader: a result or an error, never a
//! panic or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::LazyLock;

static DIR: LazyLock<(tempfile::TempDir, PathBuf)> = LazyLock::new(|| {
    let dir = tempfile::tempdir().unwrap();
    let examples = fricsim_fuzz::fmi::repository().join("examples");
    for entry in std::fs::read_dir(&examples).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ssv") {
            std::fs::copy(&path, dir.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    let ssd = dir.path().join("fuzz.ssd");
    (dir, ssd)
});

fuzz_target!(|data: &[u8]| {
    let ssd = &DIR.1;
    std::fs::write(ssd, data).unwrap();
    if let Err(e) = fricsim_core::ssp::SystemFile::open(ssd) {
        assert!(!e.to_string().is_empty());
    }
});
