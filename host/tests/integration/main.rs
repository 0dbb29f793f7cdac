//! fricsim's integration tests, one test binary: each file here is a
//! module of it (they were one binary each; one binary links once instead
//! of 35 times, which takes minutes off a build of the tests). The test
//! harness runs the tests of every module side by side, two at a time on
//! two cores; a file's tests are chosen by its module name, e.g.
//! `cargo test --profile release-test -p fricsim --test integration stick_slip::`.
//!
//! `allocation.rs` stays a binary of its own: it counts the process's
//! allocations through its own global allocator.

// shared helpers, beside this folder (bench/tests includes common/ too)
#[path = "../belt/mod.rs"]
mod belt;
#[path = "../common/mod.rs"]
mod common;
#[path = "../fmi/mod.rs"]
mod fmi;
#[path = "../paper_examples/mod.rs"]
mod paper_examples;
#[path = "../stair/mod.rs"]
mod stair;

mod appels_herder;
mod archive;
mod classical;
mod cli_errors;
mod connection_units;
mod crash_safe_output;
mod diagnose;
mod diagnose_any_plant;
mod diagnose_hidden_effects;
mod diagnose_records;
mod diagnose_reexamine;
mod diagnose_time_limit;
mod docs;
mod emps;
mod fmi3_import;
mod fmu_logging;
mod fuzz_bounded;
mod instance;
mod isolated_runs;
mod jacobi_plan;
mod leak_check;
mod library;
mod lugre;
mod lying_description;
mod mat_results;
mod mid_run_failures;
mod misuse;
mod model_description;
mod model_exchange;
mod output_sensitivities;
mod parallel_instances;
mod parameter_sensitivities;
mod reference;
mod run_options;
mod ssp;
mod stick_slip;
mod streaming;
mod strong_coupling;
mod strong_coupling_fallbacks;
mod sun2016;
mod sweep;
mod thimmalapura2004;
mod wijata2016;
