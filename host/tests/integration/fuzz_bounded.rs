//! The fuzz targets of `fuzz/` in a bounded, reproducible form that runs
//! with the ordinary tests: a seeded generator, a fixed number of
//! iterations, a few seconds per target. Any failure prints the seed and
//! iteration, so it can be replayed. The long runs (libFuzzer, coverage
//! guided) are `scripts/fuzz.sh`; see docs/development.md, "Robustness checks".
//!
//! - random FMI call sequences against every shipped FMU
//!   (`fmi/sequence.rs` says what must hold);
//! - random and mutated bytes to `fmi2DeSerializeFMUstate`: anything but
//!   the genuine bytes is refused, and no refused state is handed out;
//! - mutated `modelDescription.xml` files to the host's parser and mutated
//!   `.ssd`/`.ssv` files to the system-file reader: an error or a result,
//!   never a panic.

use crate::fmi;
use fmi::*;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Fixed seed: the same programs on every run.
const SEED: u64 = 0x5eed_0007;

/// A mutation of `input`: bit flips, byte changes, deletions, duplicated or
/// moved slices, inserted markup and numbers, truncation (one to four of
/// them).
fn mutate(rng: &mut Rng, input: &[u8]) -> Vec<u8> {
    const TOKENS: &[&str] = &[
        "<",
        ">",
        "&",
        "&amp;",
        "\"",
        "'",
        "/>",
        "<!--",
        "<![CDATA[",
        "\u{0}",
        "\u{feff}",
        "é",
        "-1",
        "4294967296",
        "1e999",
        "nan",
        "-0",
        "valueReference=\"0\"",
        "causality=\"output\"",
        "<ScalarVariable name=\"x\" valueReference=\"0\"><Real/></ScalarVariable>",
        "<!DOCTYPE x [<!ENTITY a \"aaaaaaaaaa\">]>",
        "xmlns=\"urn:x\"",
    ];
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let n = out.len().max(1);
        let at = rng.below(n).min(out.len());
        match rng.below(7) {
            0 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] ^= 1 << rng.below(8)
            }
            1 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] = rng.next_u64() as u8
            }
            2 => {
                let end = (at + 1 + rng.below(64)).min(out.len());
                out.drain(at..end);
            }
            3 => {
                let end = (at + 1 + rng.below(256)).min(out.len());
                let slice = out[at..end].to_vec();
                let to = rng.below(out.len() + 1);
                out.splice(to..to, slice);
            }
            4 => {
                let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                out.splice(at..at, token.iter().copied());
            }
            5 => out.truncate(at),
            _ => {
                let n = 1 + rng.below(8);
                let bytes = rng.bytes(n);
                out.splice(at..at, bytes);
            }
        }
    }
    out
}

/// Accepted and refused inputs of a parser.
#[derive(Default)]
struct Tally {
    accepted: usize,
    refused: usize,
}

impl Tally {
    /// Count `parse()`'s outcome; a panic is a finding, shown with `input`.
    fn count<T, E: std::fmt::Display>(
        &mut self,
        parse: impl FnOnce() -> Result<T, E>,
        input: impl FnOnce() -> String,
    ) {
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)) {
            Ok(Ok(_)) => self.accepted += 1,
            Ok(Err(e)) => {
                assert!(!e.to_string().is_empty(), "an empty message");
                self.refused += 1
            }
            Err(_) => panic!("the parser panicked on {}", input()),
        }
    }
}

/// A hang detector: if no program finishes for `STALL` (a program takes
/// milliseconds), the test process stops with the FMU and program it was
/// running, instead of a CI job that times out without saying where. It
/// watches until dropped, at the end of the test.
struct Watchdog {
    current: Arc<Mutex<(String, Instant)>>,
    done: Arc<AtomicBool>,
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        self.done.store(true, Ordering::Relaxed);
    }
}

const STALL: Duration = Duration::from_secs(120);

impl Watchdog {
    fn start() -> Watchdog {
        let current = Arc::new(Mutex::new((String::new(), Instant::now())));
        let done = Arc::new(AtomicBool::new(false));
        let (watched, finished) = (Arc::clone(&current), Arc::clone(&done));
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_secs(1));
            if finished.load(Ordering::Relaxed) {
                return;
            }
            let Some(watched) = watched.lock().ok().map(|c| c.clone()) else {
                return;
            };
            if watched.1.elapsed() > STALL {
                // straight to the process's stderr: the test harness's
                // capture of eprintln! would be lost with the process
                let _ = writeln!(
                    std::io::stderr(),
                    "fuzz_bounded: {} has not returned in {STALL:?}: a hang (seed {SEED:#x})",
                    watched.0
                );
                std::process::abort();
            }
        });
        Watchdog { current, done }
    }

    fn running(&self, what: String) {
        if let Ok(mut c) = self.current.lock() {
            *c = (what, Instant::now());
        }
    }
}

#[test]
fn random_call_sequences_against_every_shipped_fmu() {
    let mut rng = Rng(SEED);
    let start = Instant::now();
    let mut calls = 0;
    let watchdog = Watchdog::start();
    for &name in SHIPPED.iter() {
        let loaded = load_shipped(name);
        for iteration in 0..1000 {
            let len = 16 + rng.below(600);
            let program = rng.bytes(len);
            watchdog.running(format!("{name}: program {iteration}"));
            let outcome =
                std::panic::catch_unwind(|| sequence::run(loaded.api, &loaded.model, &program));
            match outcome {
                Ok(n) => calls += n,
                Err(_) => panic!(
                    "{name}: program {iteration} (seed {SEED:#x}) broke an invariant: {program:?}"
                ),
            }
        }
    }
    eprintln!("{calls} FMI calls in {:.1?}", start.elapsed());
    assert!(calls > 7 * 1000 * 20);
}

#[test]
fn mutated_serialized_states_are_refused() {
    let mut rng = Rng(SEED + 1);
    for &name in SHIPPED.iter() {
        let loaded = load_shipped(name);
        let i = loaded.instance("states");
        assert_eq!(i.initialize(), OK);
        for k in 0..3 {
            assert_eq!(i.do_step(k as f64 * 1e-3, 1e-3), OK);
        }
        let genuine = i.serialize();
        let mut refused = 0;
        for iteration in 0..3000 {
            let bytes = if iteration % 4 == 0 {
                let n = rng.below(2 * genuine.len());
                rng.bytes(n)
            } else {
                mutate(&mut rng, &genuine)
            };
            if bytes == genuine {
                continue;
            }
            assert_eq!(
                i.restore(&bytes),
                ERROR,
                "{name}: mutated state {iteration} (seed {SEED:#x}) accepted"
            );
            let errors = i.log.take_errors();
            assert!(
                errors.len() == 1 && errors[0].starts_with("fmi2DeSerializeFMUstate"),
                "{errors:?}"
            );
            refused += 1;
        }
        assert!(refused > 2900);
        // The instance is untouched: it still steps from t = 3 ms.
        assert_eq!(i.do_step(3e-3, 1e-3), OK);
    }
}

#[test]
fn mutated_model_descriptions_never_panic_the_parser() {
    let mut rng = Rng(SEED + 2);
    let dir = repository().join("modelDescription");
    let mut seeds: Vec<Vec<u8>> = SHIPPED
        .iter()
        .map(|n| std::fs::read(dir.join(format!("{n}.xml"))).unwrap())
        .collect();
    seeds.push(
        std::fs::read(repository().join("host/tests/c/belt_oscillator/modelDescription.xml"))
            .unwrap(),
    );
    let start = Instant::now();
    let mut tally = Tally::default();
    for iteration in 0..15000 {
        let base = &seeds[iteration % seeds.len()];
        let bytes = mutate(&mut rng, base);
        let text = String::from_utf8_lossy(&bytes);
        tally.count(
            || fricsim::fmu::ModelDescription::parse(&text),
            || format!("iteration {iteration} (seed {:#x}):\n{text}", SEED + 2),
        );
    }
    let Tally { accepted, refused } = tally;
    eprintln!(
        "{accepted} accepted, {refused} refused in {:.1?}",
        start.elapsed()
    );
    assert!(refused > 5000, "{refused}");
}

#[test]
fn mutated_system_files_never_panic_the_reader() {
    let mut rng = Rng(SEED + 3);
    let examples = repository().join("examples");
    let work = tempfile::tempdir().unwrap();
    // The .ssv files the examples reference, next to the mutated .ssd.
    for entry in std::fs::read_dir(&examples).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "ssv") {
            std::fs::copy(&path, work.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    let ssds: Vec<(String, Vec<u8>)> = std::fs::read_dir(&examples)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ssd"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    let ssvs: Vec<(String, Vec<u8>)> = std::fs::read_dir(work.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    let start = Instant::now();
    let mut tally = Tally::default();
    for iteration in 0..4000 {
        let (name, ssd) = &ssds[iteration % ssds.len()];
        // Mostly the .ssd, every fourth time one .ssv instead.
        let mutated_ssv = (iteration % 4 == 3).then(|| rng.below(ssvs.len()));
        let ssd_bytes = if mutated_ssv.is_some() {
            ssd.clone()
        } else {
            mutate(&mut rng, ssd)
        };
        let path = work.path().join(name);
        std::fs::write(&path, &ssd_bytes).unwrap();
        if let Some(k) = mutated_ssv {
            let bytes = mutate(&mut rng, &ssvs[k].1);
            std::fs::write(work.path().join(&ssvs[k].0), bytes).unwrap();
        }
        tally.count(
            || fricsim::ssp::SystemFile::open(&path),
            || {
                format!(
                    "iteration {iteration} (seed {:#x}), {name}:\n{}",
                    SEED + 3,
                    String::from_utf8_lossy(&ssd_bytes)
                )
            },
        );
        if let Some(k) = mutated_ssv {
            std::fs::write(work.path().join(&ssvs[k].0), &ssvs[k].1).unwrap();
        }
        std::fs::remove_file(&path).unwrap();
    }
    let Tally { accepted, refused } = tally;
    eprintln!(
        "{accepted} accepted, {refused} refused in {:.1?}",
        start.elapsed()
    );
    assert!(refused > 1000, "{refused}");
}
