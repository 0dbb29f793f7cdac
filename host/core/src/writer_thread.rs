//! Writing a run's rows on a thread of its own, while the run steps on.
//!
//! A run hands its rows over in chunks of a few thousand
//! ([`crate::master::simulate_streaming`]); writing a chunk (formatting
//! CSV numbers, copying a MAT file's columns, the `write` calls, the
//! summary of each column) takes about as long as computing it. With
//! [`on_writer_thread`] the run's thread gives each chunk away by value
//! ([`RowSink::write_chunk`]: the table changes hands, nothing is copied)
//! and goes on stepping into a second table, while the writer thread
//! writes the first to the sink and hands it back emptied. At most
//! [`TABLES`] tables exist, so memory stays bounded whatever the run's
//! length, and a writer that falls behind holds the run back rather than
//! letting chunks pile up.
//!
//! The sink sees the same rows in the same order as it would on the run's
//! thread, so the file is the same byte for byte. What changes is when the
//! run learns of the sink's error or its request to stop (a signal): at
//! the next chunk after the writer thread has seen it, not at once.

use crate::master::RowSink;
use crate::rows::Rows;
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};
use std::sync::Mutex;

/// Tables of rows in use at once: the one the run records into, the one
/// being written, and one queued between them.
pub const TABLES: usize = 3;

/// Run `body` with a [`RowSink`] that passes every chunk to `sink` on a
/// thread of its own; returns what `body` returned and `sink`, once every
/// chunk handed over has been written.
///
/// A panic on the writer thread is resumed on the caller's once `body`
/// has returned.
pub fn on_writer_thread<S, R>(sink: S, body: impl FnOnce(&mut dyn RowSink) -> R) -> (R, S)
where
    S: RowSink + Send,
{
    let shared = Shared::default();
    std::thread::scope(|scope| {
        // one chunk queued while another is being written
        let (to_writer, chunks) = sync_channel::<(Vec<f64>, Rows)>(1);
        let (to_run, emptied) = channel::<Rows>();
        let shared = &shared;
        let writer = std::thread::Builder::new()
            .name("fricsim-writer".into())
            .spawn_scoped(scope, move || write_chunks(sink, chunks, to_run, shared))
            .expect("cannot start the writer thread");
        let mut front = Front {
            to_writer: Some(to_writer),
            emptied,
            made: 1,
            shared,
        };
        let result = body(&mut front);
        // no more chunks: the writer ends once it has written the last
        front.to_writer = None;
        let sink = writer
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (result, sink)
    })
}

/// What the writer thread tells the run besides the emptied tables.
#[derive(Default)]
struct Shared {
    /// The sink's first error: the chunks after it are not written.
    error: Mutex<Option<String>>,
    /// The sink's [`RowSink::stop_requested`], asked after each chunk.
    stop: Mutex<Option<String>>,
}

/// The writer thread: each chunk to `sink`, then back emptied.
fn write_chunks<S: RowSink>(
    mut sink: S,
    chunks: Receiver<(Vec<f64>, Rows)>,
    to_run: Sender<Rows>,
    shared: &Shared,
) -> S {
    for (times, mut rows) in chunks {
        let failed = shared.error.lock().map(|e| e.is_some()).unwrap_or(true);
        if !failed {
            if let Err(e) = sink.write(&times, &rows) {
                *lock(&shared.error) = Some(e);
            }
        }
        *lock(&shared.stop) = sink.stop_requested();
        rows.clear();
        // the run has ended: the table is not needed
        let _ = to_run.send(rows);
    }
    sink
}

/// A lock that a panic on the other thread did not spoil (the values are
/// plain options, whole at any time).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The run's side: the sink it writes to.
struct Front<'a> {
    /// `None` once the run has ended.
    to_writer: Option<SyncSender<(Vec<f64>, Rows)>>,
    emptied: Receiver<Rows>,
    /// Tables made so far (the run's first one counts).
    made: usize,
    shared: &'a Shared,
}

impl Front<'_> {
    fn error(&self) -> Option<String> {
        lock(&self.shared.error).clone()
    }

    fn send(&mut self, times: Vec<f64>, rows: Rows) -> Result<(), String> {
        let sent = match &self.to_writer {
            Some(to_writer) => to_writer.send((times, rows)).is_ok(),
            None => false,
        };
        if sent {
            Ok(())
        } else {
            Err(self
                .error()
                .unwrap_or_else(|| "the writer thread has stopped".to_string()))
        }
    }
}

impl RowSink for Front<'_> {
    /// A chunk the run keeps (its last): copied, then handed over.
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        if let Some(e) = self.error() {
            return Err(e);
        }
        let copy = Rows::from_rows(rows.width(), rows.iter().take(times.len()));
        self.send(times.to_vec(), copy)
    }

    fn stop_requested(&self) -> Option<String> {
        lock(&self.shared.stop).clone()
    }

    fn write_chunk(&mut self, times: Vec<f64>, rows: Rows) -> Result<Rows, String> {
        if let Some(e) = self.error() {
            return Err(e);
        }
        let (width, capacity) = (rows.width(), rows.capacity());
        self.send(times, rows)?;
        // an emptied table if one is back, else a new one while fewer
        // than TABLES exist, else wait for the writer to empty one
        if let Ok(table) = self.emptied.try_recv() {
            return Ok(table);
        }
        if self.made < TABLES {
            self.made += 1;
            return Ok(Rows::with_capacity(width, capacity));
        }
        self.emptied.recv().map_err(|_| {
            self.error()
                .unwrap_or_else(|| "the writer thread has stopped".to_string())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records what it is given, fails at a chosen chunk.
    #[derive(Default)]
    struct Collect {
        times: Vec<f64>,
        rows: Vec<Vec<f64>>,
        fail_at: Option<usize>,
        chunks: usize,
    }

    impl RowSink for Collect {
        fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
            self.chunks += 1;
            if self.fail_at == Some(self.chunks) {
                return Err(format!("chunk {} refused", self.chunks));
            }
            self.times.extend_from_slice(times);
            self.rows
                .extend(rows.iter().take(times.len()).map(|r| r.to_vec()));
            Ok(())
        }
        fn stop_requested(&self) -> Option<String> {
            (self.chunks >= 3).then(|| "three chunks are enough".to_string())
        }
    }

    /// A table of `n` rows of width 2 from `start`, with room for 8.
    fn table(start: usize, n: usize) -> Rows {
        let mut rows = Rows::with_capacity(2, 8);
        for i in start..start + n {
            rows.push_row(&[i as f64, -(i as f64)]);
        }
        rows
    }

    #[test]
    fn chunks_arrive_whole_and_in_order_and_tables_are_reused() {
        let (made, sink) = on_writer_thread(Collect::default(), |front| {
            let mut made = Vec::new();
            for c in 0..10 {
                let back = front
                    .write_chunk(vec![c as f64; 4], table(4 * c, 5))
                    .unwrap();
                assert!(back.is_empty());
                assert_eq!((back.width(), back.capacity()), (2, 8));
                made.push(back);
            }
            front.write(&[10.0], &table(40, 2)).unwrap();
            made.len()
        });
        assert_eq!(made, 10);
        // four rows of each chunk (its fifth is the run's), then the last
        assert_eq!(sink.rows.len(), 41);
        for (i, row) in sink.rows.iter().enumerate() {
            assert_eq!(row, &[i as f64, -(i as f64)]);
        }
        assert_eq!(sink.times.len(), 41);
        assert_eq!(sink.chunks, 11);
    }

    #[test]
    fn an_error_of_the_sink_reaches_the_run_and_stops_the_writing() {
        let sink = Collect {
            fail_at: Some(2),
            ..Collect::default()
        };
        let (outcome, sink) = on_writer_thread(sink, |front| {
            for c in 0..100 {
                front.write_chunk(vec![0.0; 4], table(4 * c, 5))?;
            }
            Ok(())
        });
        assert_eq!(outcome, Err("chunk 2 refused".to_string()));
        // the first chunk only; those after the error are not written
        assert_eq!(sink.rows.len(), 4);
        assert_eq!(sink.chunks, 2);
    }

    #[test]
    fn a_stop_the_sink_asks_for_reaches_the_run() {
        let (chunks_sent, sink) = on_writer_thread(Collect::default(), |front| {
            let mut sent = 0;
            while front.stop_requested().is_none() {
                front
                    .write_chunk(vec![0.0; 4], table(0, 5))
                    .expect("no error");
                sent += 1;
                assert!(sent < 10_000, "the stop never arrived");
            }
            sent
        });
        assert!(chunks_sent >= 3);
        assert_eq!(sink.chunks, chunks_sent);
    }
}
