//! Runs that hand their rows on as they go ([`simulate_streaming`]): the
//! same rows and times, bit for bit, as a run that keeps every row
//! ([`simulate_with`]), for the Jacobi, Gauss-Seidel and Newton masters,
//! around the chunk boundaries, and for a run that fails past the first
//! chunk; no chunk holds more than [`CHUNK_STEPS`] rows; a sink that fails
//! or asks to stop stops the run; the CSV written as the rows come is the
//! one written from the whole run, byte for byte.

use crate::belt;
use crate::common;

use fricsim::master::{
    by_name, simulate_streaming, simulate_with, NoObserver, RowSink, Rows, Run, Streamed,
    CHUNK_STEPS,
};
use fricsim::output_file::OutputFile;
use fricsim::results::{write_run, ResultWriter};
use fricsim::system::System;
use std::path::{Path, PathBuf};

fn dist(name: &str) -> PathBuf {
    let p = common::repository().join("dist").join(name);
    assert!(p.exists(), "{} is missing: run ./build-fmu.sh", p.display());
    p
}

fn stick_slip() -> System {
    let (rig, lugre) = (dist("Rig1D.fmu"), dist("LuGre.fmu"));
    let components = [
        ("rig".to_string(), rig.as_path()),
        ("friction".to_string(), lugre.as_path()),
    ];
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("friction.F".to_string(), "rig.F".to_string()),
    ];
    System::build(&components, &[], &connections).unwrap()
}

/// Every row handed on, and how many each chunk held.
#[derive(Default)]
struct Collect {
    time: Vec<f64>,
    rows: Vec<Vec<f64>>,
    chunks: Vec<usize>,
    /// Stop after this many chunks ([`RowSink::stop_requested`]).
    stop_after: Option<usize>,
    /// Fail at this chunk.
    fail_at: Option<usize>,
}

impl RowSink for Collect {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        if self.fail_at == Some(self.chunks.len()) {
            return Err("the disk is full".to_string());
        }
        assert!(rows.len() >= times.len());
        self.chunks.push(times.len());
        self.time.extend_from_slice(times);
        self.rows
            .extend(rows.iter().take(times.len()).map(<[f64]>::to_vec));
        Ok(())
    }

    fn stop_requested(&self) -> Option<String> {
        (self.stop_after == Some(self.chunks.len())).then(|| "asked to stop".to_string())
    }
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|x| x.to_bits()).collect()
}

fn assert_same_rows(whole: &Run, streamed: &Streamed, sink: &Collect, what: &str) {
    assert_eq!(whole.columns, streamed.columns, "{what}");
    assert_eq!(whole.rows.len(), streamed.rows, "{what}");
    assert_eq!(sink.rows.len(), streamed.rows, "{what}");
    assert_eq!(bits(&whole.time), bits(&sink.time), "{what}: times");
    for (i, (a, b)) in whole.rows.iter().zip(&sink.rows).enumerate() {
        assert_eq!(bits(a), bits(b), "{what}: row {i}");
    }
    assert_eq!(whole.error, streamed.error, "{what}");
    assert!(
        sink.chunks.iter().all(|&n| n <= CHUNK_STEPS + 1),
        "{what}: chunks of {:?} rows",
        sink.chunks
    );
}

#[test]
fn streamed_rows_are_the_whole_runs_bit_for_bit_around_chunk_boundaries() {
    let h = 1e-4;
    for master in ["jacobi", "gauss-seidel", "newton"] {
        for steps in [
            0,
            1,
            CHUNK_STEPS - 1,
            CHUNK_STEPS,
            CHUNK_STEPS + 1,
            2 * CHUNK_STEPS + 3,
        ] {
            let stop = steps as f64 * h;
            let what = format!("{master}, {steps} steps");
            let mut system = stick_slip();
            let mut m = by_name(master).unwrap();
            let whole =
                simulate_with(&mut system, m.as_mut(), 0.0, h, stop, &mut NoObserver).unwrap();
            let mut system = stick_slip();
            let mut m = by_name(master).unwrap();
            let mut sink = Collect::default();
            let streamed = simulate_streaming(
                &mut system,
                m.as_mut(),
                0.0,
                h,
                stop,
                &mut NoObserver,
                &mut sink,
            )
            .unwrap();
            assert_eq!(streamed.rows, steps + 1, "{what}");
            assert!(streamed.error.is_none(), "{what}");
            assert_same_rows(&whole, &streamed, &sink, &what);
            // a chunk of rows at a time: the memory of a run does not grow
            // with its length
            assert_eq!(
                sink.chunks.len(),
                steps.div_ceil(CHUNK_STEPS).max(1),
                "{what}"
            );
        }
    }
}

#[test]
fn a_run_failing_past_the_first_chunk_hands_on_the_rows_before_the_failure() {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    let lugre = common::lugre_fmu();
    let fault_step = CHUNK_STEPS + 10;
    let coupled = || {
        let components = [
            ("rig".to_string(), belt.as_path()),
            ("friction".to_string(), lugre.as_path()),
        ];
        let parameters = [
            ("rig.fault".to_string(), belt::DISCARD as f64),
            ("rig.fault_step".to_string(), fault_step as f64),
            ("rig.v0".to_string(), 0.0),
        ];
        let connections = [
            ("rig.v".to_string(), "friction.v".to_string()),
            ("friction.F".to_string(), "rig.F".to_string()),
        ];
        System::build(&components, &parameters, &connections).unwrap()
    };
    let h = 1.0 / 1024.0;
    let stop = 3.0 * CHUNK_STEPS as f64 * h;
    let whole = simulate_with(
        &mut coupled(),
        by_name("jacobi").unwrap().as_mut(),
        0.0,
        h,
        stop,
        &mut NoObserver,
    )
    .unwrap();
    let mut sink = Collect::default();
    let streamed = simulate_streaming(
        &mut coupled(),
        by_name("jacobi").unwrap().as_mut(),
        0.0,
        h,
        stop,
        &mut NoObserver,
        &mut sink,
    )
    .unwrap();
    assert_eq!(streamed.rows, fault_step, "{:?}", streamed.error);
    assert!(streamed.error.as_deref().unwrap().contains("fmi2Discard"));
    assert_same_rows(&whole, &streamed, &sink, "failing run");
}

#[test]
fn a_sink_that_fails_or_asks_to_stop_stops_the_run_between_chunks() {
    let h = 1e-4;
    let stop = 5.0 * CHUNK_STEPS as f64 * h;
    let mut sink = Collect {
        stop_after: Some(2),
        ..Collect::default()
    };
    let run = simulate_streaming(
        &mut stick_slip(),
        by_name("jacobi").unwrap().as_mut(),
        0.0,
        h,
        stop,
        &mut NoObserver,
        &mut sink,
    )
    .unwrap();
    assert_eq!(run.error.as_deref(), Some("asked to stop"));
    // two chunks of steps, every row so far handed on (the last with the
    // stop)
    assert_eq!(run.rows, 2 * CHUNK_STEPS + 1);
    assert_eq!(sink.chunks, [CHUNK_STEPS, CHUNK_STEPS, 1]);
    assert_eq!(*sink.time.last().unwrap(), 2.0 * CHUNK_STEPS as f64 * h);

    let mut sink = Collect {
        fail_at: Some(1),
        ..Collect::default()
    };
    let run = simulate_streaming(
        &mut stick_slip(),
        by_name("jacobi").unwrap().as_mut(),
        0.0,
        h,
        stop,
        &mut NoObserver,
        &mut sink,
    )
    .unwrap();
    assert_eq!(run.error.as_deref(), Some("the disk is full"));
    assert_eq!(run.rows, CHUNK_STEPS);
    assert_eq!(sink.chunks, [CHUNK_STEPS]);
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

#[test]
fn the_csv_written_as_the_rows_come_is_the_whole_runs_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let h = 1e-4;
    let stop = 2.0 * CHUNK_STEPS as f64 * h + 0.05;
    let whole = simulate_with(
        &mut stick_slip(),
        by_name("jacobi").unwrap().as_mut(),
        0.0,
        h,
        stop,
        &mut NoObserver,
    )
    .unwrap();
    let kept_file = dir.path().join("whole.csv");
    write_run(&whole, OutputFile::create(&kept_file, &[]).unwrap()).unwrap();

    let streamed_file = dir.path().join("sub/streamed.csv");
    let mut system = stick_slip();
    let columns = system.columns();
    let mut writer = ResultWriter::new(OutputFile::create(&streamed_file, &[]).unwrap(), &columns);
    let plotted = vec!["friction.F".to_string(), "rig.x".to_string()];
    writer.keep_columns(&columns, &plotted).unwrap();
    let run = simulate_streaming(
        &mut system,
        by_name("jacobi").unwrap().as_mut(),
        0.0,
        h,
        stop,
        &mut NoObserver,
        &mut writer,
    )
    .unwrap();
    // the summary and the plotted columns, from the rows as they came
    let stats = writer.stats.clone();
    let kept = writer.kept().unwrap();
    writer.finish(run.error.as_deref()).unwrap();
    assert!(read(&kept_file) == read(&streamed_file), "the files differ");
    assert_eq!(stats.rows, whole.rows.len());
    assert_eq!(stats.first_time, Some(0.0));
    assert_eq!(stats.last_time, whole.time.last().copied());
    for (k, name) in columns.iter().enumerate() {
        let column: Vec<f64> = whole.rows.column(k).collect();
        let lo = column.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        let hi = column.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        assert_eq!((stats.min[k], stats.max[k]), (lo, hi), "{name}");
        assert_eq!(stats.last[k], *column.last().unwrap());
    }
    assert_eq!(kept.columns, plotted);
    assert_eq!(bits(&kept.time), bits(&whole.time));
    for (name, k) in plotted.iter().zip(0..) {
        let i = columns.iter().position(|c| c == name).unwrap();
        let a: Vec<f64> = whole.rows.column(i).collect();
        let b: Vec<f64> = kept.rows.column(k).collect();
        assert_eq!(bits(&a), bits(&b), "{name}");
    }
    assert!(writer_for_unknown_column_is_refused(
        &dir.path().join("unused.csv"),
        &columns
    ));
}

fn writer_for_unknown_column_is_refused(path: &Path, columns: &[String]) -> bool {
    let mut w = ResultWriter::new(OutputFile::create(path, &[]).unwrap(), columns);
    let e = w
        .keep_columns(columns, &["rig.nothing".to_string()])
        .unwrap_err();
    e.contains("cannot plot `rig.nothing`")
}
