//! Random FMI call sequences: the first byte picks one of the seven models,
//! the rest is a program for `host/tests/fmi/sequence.rs`, which panics
//! (a finding) when an invariant breaks.
#![no_main]
use fricsim_fuzz::{api, fmi, MODELS};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((first, program)) = data.split_first() {
        let model = &MODELS[*first as usize % MODELS.len()];
        fmi::sequence::run(api(), model, program);
    }
});
