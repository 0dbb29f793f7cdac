//! BeltOscillator (`tests/c/belt_oscillator`): an FMI 2.0 Co-Simulation FMU
//! written by hand in C, with its own model description, compiled and zipped
//! into a `.fmu` at test time, and the counters it exports for the tests.
#![allow(dead_code)]

use crate::common::c_fmu;
use fricsim::fmu::Fmu;
use std::path::{Path, PathBuf};

/// The folder with `belt_oscillator.c` and `modelDescription.xml`.
pub const SOURCE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/c/belt_oscillator");

/// Value references of the model description.
pub const F: u32 = 0;
pub const X: u32 = 1;
pub const V: u32 = 2;

/// The `fault` parameter's values.
pub const NAN_STATE: i32 = 1;
pub const DISCARD: i32 = 2;
pub const ERROR: i32 = 3;
pub const FATAL: i32 = 4;
pub const SLOW: i32 = 5;
/// Faults that end or block the process (for isolated runs).
pub const SEGFAULT: i32 = 6;
pub const ABORT: i32 = 7;
pub const EXIT_0: i32 = 8;
pub const HANG: i32 = 9;

/// Compile the C source and zip it with its model description into
/// `dir/BeltOscillator.fmu` (binaries/linux64/BeltOscillator.so).
pub fn build_fmu(dir: &Path) -> PathBuf {
    c_fmu(
        Path::new(SOURCE_DIR),
        "belt_oscillator.c",
        "BeltOscillator",
        dir,
    )
}

/// The FMU's own bookkeeping, read from its loaded binary. Holding this
/// keeps the binary loaded (dlopen of the same path shares the library),
/// so the counters can be read after the host has dropped the FMU.
pub struct Counters {
    library: libloading::Library,
}

impl Counters {
    pub fn of(fmu: &Fmu) -> Counters {
        // SAFETY: loading the binary the host has already loaded.
        let library = unsafe { libloading::Library::new(fmu.library().path()) }.unwrap();
        Counters { library }
    }

    fn read(&self, symbol: &str) -> i32 {
        // SAFETY: belt_oscillator.c exports both counters as `int f(void)`.
        unsafe {
            let f: libloading::Symbol<unsafe extern "C" fn() -> i32> =
                self.library.get(symbol.as_bytes()).unwrap();
            f()
        }
    }

    /// Instances not yet freed with fmi2FreeInstance.
    pub fn live_instances(&self) -> i32 {
        self.read("belt_live_instances")
    }

    /// Calls made on an instance after it returned fmi2Fatal.
    pub fn calls_after_fatal(&self) -> i32 {
        self.read("belt_calls_after_fatal")
    }
}
