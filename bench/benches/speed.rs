//! Criterion benchmarks of the Rust parts behind BENCHMARKS.md's speed
//! tables (`cargo bench -p fricsim-bench --bench speed`), with criterion's
//! statistics for a closer look at one figure; the tables themselves come
//! from `speed-table` (scripts/bench.sh), which measures everything in one
//! run, FMPy included.
//!
//! - `fmu_step/<model>`: one communication step of each friction FMU of
//!   dist/ through the C ABI (set inputs, `fmi2DoStep`, get outputs) at
//!   h = 1e-3 s ([`FmuStepper`]).
//! - `bristle_curve/<count>`: the bristle law over the 1000-increment
//!   curve with one reversal ([`bristle_curve`]), 10 to 100 000 bristles.

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use fricsim_bench::{bristle_curve, FmuStepper, FRICTION_FMUS};
use fricsim_fmi::Fmu;
use friction_laws::bristle::{Bristle, BristleParams};
use std::path::Path;

fn fmu_step(c: &mut Criterion) {
    let dist = Path::new(env!("CARGO_MANIFEST_DIR")).join("../dist");
    let mut group = c.benchmark_group("fmu_step");
    for (index, driven) in FRICTION_FMUS.iter().enumerate() {
        let model = driven.model;
        let fmu = Fmu::open(dist.join(format!("{model}.fmu")))
            .unwrap_or_else(|e| panic!("{model}.fmu: {e} (run ./build-fmu.sh)"));
        let mut stepper = FmuStepper::new(&fmu, index).unwrap();
        let h = 1e-3;
        let mut k = 0u64;
        group.bench_function(driven.label, |b| {
            b.iter(|| {
                stepper.step(k as f64 * h, h).unwrap();
                k += 1;
            })
        });
    }
    group.finish();
}

fn bristle_count(c: &mut Criterion) {
    let mut group = c.benchmark_group("bristle_curve");
    group.sample_size(20);
    for count in [10, 100, 1_000, 10_000, 100_000] {
        let fresh = Bristle::new(BristleParams {
            n_bristles: count,
            ..Default::default()
        })
        .unwrap();
        group.bench_with_input(BenchmarkId::from_parameter(count), &fresh, |b, fresh| {
            b.iter_batched(
                || fresh.clone(),
                |mut b| bristle_curve(&mut b),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, fmu_step, bristle_count);
criterion_main!(benches);
