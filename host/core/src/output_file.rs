//! Result files written safely: whatever writes a result (the CSV writer
//! of [`crate::results`], any other format) writes its bytes to an
//! [`OutputFile`], which
//!
//! * refuses a path that is one of the run's inputs (the system file, an
//!   FMU, an `.ssv`, the `--input` table, the plot): same device and inode
//!   when both exist, the same absolute path (its directory canonicalized)
//!   when neither does;
//! * locks the path for the run: an advisory lock (`flock`, through
//!   [`File::try_lock`]) on the lock file `.<name>.fricsim-lock` beside
//!   it; a second writer is refused at once, naming the writer's pid
//!   (Linux: from `/proc/locks`, the lock file left empty; elsewhere the
//!   lock file holds it). The lock dies with its process, so a run killed with
//!   SIGKILL blocks no one; the lock file is removed at the end of a run
//!   that runs its code to the end (one left by a killed run is reused);
//! * writes to the temporary file `.<name>.fricsim-partial-<pid>` in the
//!   same directory (starting the disk writing every MiB as it goes,
//!   `Writeback`) and, once complete, flushes it to the disk
//!   (`fsync`), renames it over the path (atomic on POSIX: a reader sees
//!   the previous file or the new one, never a mix) and flushes the
//!   directory, so that the rename itself survives a power loss;
//! * removes the temporary file when it is not put in place: a write
//!   error (a full disk) leaves the previous result untouched. Temporary
//!   files of runs killed before their end (SIGKILL, power loss) are
//!   removed by the next run that locks the same path.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// Why a result file cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("the result file {out} is {what} {input}, an input of the run: choose another result file (--out)")]
    IsInput {
        out: PathBuf,
        what: String,
        input: PathBuf,
    },
    #[error("{path} is being written by another fricsim run (pid {pid}): wait for it to end or choose another result file (--out)")]
    Locked { path: PathBuf, pid: String },
    #[error("{path}: {source}; the file at that path was left as it was")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// A result file being written: locked, written to a temporary file
/// beside it, put in place by [`OutputFile::commit`] (see the module).
pub struct OutputFile {
    path: PathBuf,
    partial: PathBuf,
    /// Opened at the first write, so that a run that writes nothing
    /// leaves nothing.
    out: Option<BufWriter<Writeback>>,
    /// The first write error: the file is then never put in place.
    failed: Option<(std::io::ErrorKind, String)>,
    _lock: Lock,
}

impl OutputFile {
    /// Claim `path` for a result: not one of `inputs` (each with what it
    /// is: `the system file`, `the FMU`), not being written by another
    /// run. Creates its directory and the lock file; the file itself is
    /// written at the first bytes.
    pub fn create(path: &Path, inputs: &[(&str, &Path)]) -> Result<OutputFile, OutputError> {
        refuse_inputs(path, inputs)?;
        let io = |source| OutputError::Io {
            path: path.to_path_buf(),
            source,
        };
        let name = path
            .file_name()
            .ok_or_else(|| io(std::io::Error::other("not a file name")))?
            .to_string_lossy()
            .into_owned();
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&dir).map_err(io)?;
        let lock = Lock::take(path, &dir.join(format!(".{name}.fricsim-lock")))?;
        let partial_prefix = format!(".{name}.fricsim-partial-");
        remove_stale_partials(&dir, &partial_prefix);
        Ok(OutputFile {
            path: path.to_path_buf(),
            partial: dir.join(format!("{partial_prefix}{}", std::process::id())),
            out: None,
            failed: None,
            _lock: lock,
        })
    }

    /// The result file's path (not the temporary file's).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file, created at the first call.
    fn out(&mut self) -> std::io::Result<&mut BufWriter<Writeback>> {
        if self.out.is_none() {
            let file = OpenOptions::new()
                .write(true)
                .read(true)
                .create(true)
                .truncate(true)
                .open(&self.partial)?;
            self.out = Some(BufWriter::with_capacity(1 << 16, Writeback::new(file)));
        }
        Ok(self.out.as_mut().expect("opened above"))
    }

    /// Put the file in place: flush, `fsync`, rename over the path,
    /// `fsync` the directory. After a write error, nothing is put in
    /// place: the error is returned and the temporary file removed.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let path = self.path.clone();
        let io = |source| OutputError::Io {
            path: path.clone(),
            source,
        };
        if let Some((kind, message)) = self.failed.take() {
            return Err(io(std::io::Error::new(kind, message)));
        }
        let out = self.out().map_err(io)?;
        out.flush().map_err(io)?;
        out.get_ref().file.sync_all().map_err(io)?;
        std::fs::rename(&self.partial, &self.path).map_err(io)?;
        self.out = None;
        // the rename is durable once the directory is (fsync(2))
        // (the temporary file's directory: `.` for a bare file name)
        let dir = self.partial.parent().unwrap_or(Path::new("."));
        File::open(dir).and_then(|d| d.sync_all()).map_err(io)?;
        Ok(())
    }

    fn note<T>(&mut self, result: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &result {
            self.failed.get_or_insert((e.kind(), e.to_string()));
        }
        result
    }
}

impl Write for OutputFile {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let result = self.out().and_then(|o| o.write(bytes));
        self.note(result)
    }

    fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let result = self.out().and_then(|o| o.write_all(bytes));
        self.note(result)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let result = self.out().and_then(|o| o.flush());
        self.note(result)
    }
}

/// For writers that go back to fill in a header (counts known at the end).
impl Seek for OutputFile {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let result = self.out().and_then(|o| o.seek(to));
        self.note(result)
    }
}

impl Drop for OutputFile {
    /// A file not put in place is removed (a write error, an error of the
    /// writer, a panic).
    fn drop(&mut self) {
        if let Some(out) = self.out.take() {
            // not flushed: its bytes go nowhere
            let (writeback, _) = out.into_parts();
            drop(writeback);
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}

/// The temporary file, which starts the disk writing each
/// [`Writeback::EVERY`] bytes as they are written (Linux's
/// `sync_file_range(2)` with `SYNC_FILE_RANGE_WRITE`, which does not
/// wait), so that the `fsync` that puts the result in place finds most of
/// it on the disk already instead of writing it all then. Elsewhere a
/// plain file.
struct Writeback {
    file: File,
    /// Where the next byte goes, and where the bytes not yet sent to the
    /// disk start.
    position: u64,
    unsent: u64,
}

impl Writeback {
    /// 1 MiB: the final `fsync` of the 22 MB MAT file of the stick-slip
    /// benchmark waits about 0.5 ms for the tail, against 3 ms with 4 MiB
    /// (`strace -T`); a call per MiB costs nothing measurable.
    const EVERY: u64 = 1 << 20;

    fn new(file: File) -> Writeback {
        Writeback {
            file,
            position: 0,
            unsent: 0,
        }
    }

    fn start_writing(&mut self) {
        if self.position < self.unsent + Self::EVERY {
            return;
        }
        #[cfg(target_os = "linux")]
        {
            use std::os::fd::AsRawFd;
            // SAFETY: a valid descriptor and range; the call only starts
            // the writing of pages already written, and a failure here
            // is found again by the fsync at the end
            unsafe {
                libc::sync_file_range(
                    self.file.as_raw_fd(),
                    self.unsent as libc::off64_t,
                    (self.position - self.unsent) as libc::off64_t,
                    libc::SYNC_FILE_RANGE_WRITE,
                );
            }
        }
        self.unsent = self.position;
    }
}

impl Write for Writeback {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(bytes)?;
        self.position += n as u64;
        self.start_writing();
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Seek for Writeback {
    /// A writer going back to fill in a header: the bytes from there on
    /// are sent again with the next ones.
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.position = self.file.seek(to)?;
        self.unsent = self.unsent.min(self.position);
        Ok(self.position)
    }
}

/// Temporary files `<prefix><pid>` of processes that no longer run. Called
/// with the lock held, so that no live run of this path owns one.
fn remove_stale_partials(dir: &Path, prefix: &str) {
    crate::stale::remove_left_by_gone_processes(dir, prefix, |p| std::fs::remove_file(p));
}

/// The advisory lock of a result path, held by a locked lock file.
struct Lock {
    path: PathBuf,
    _file: File,
}

impl Lock {
    /// Lock `lock_path` (created if need be) for the result `out`, or
    /// say which pid holds it.
    fn take(out: &Path, lock_path: &Path) -> Result<Lock, OutputError> {
        let io = |source| OutputError::Io {
            path: lock_path.to_path_buf(),
            source,
        };
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(lock_path)
                .map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(OutputError::Locked {
                        path: out.to_path_buf(),
                        pid: lock_holder(&mut file).unwrap_or_else(|| "unknown".to_string()),
                    });
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
            }
            // The run that held the lock removes the file before it lets
            // go: a lock on the file it removed guards nothing, so lock
            // the file that is at the path now.
            let locked = file.metadata().map_err(io)?;
            match std::fs::metadata(lock_path) {
                Ok(now) if now.dev() == locked.dev() && now.ino() == locked.ino() => {
                    // Linux tells the holder's pid (/proc/locks): the file
                    // stays empty, without a data block, which the file
                    // system would write out with the result's `fsync`
                    // and then wait on, and free, when the file is
                    // removed (1.3 to 1.7 ms on an ext4 mounted with
                    // `discard`). Elsewhere the file holds the pid.
                    #[cfg(not(target_os = "linux"))]
                    {
                        file.set_len(0).map_err(io)?;
                        write!(file, "{}", std::process::id()).map_err(io)?;
                    }
                    return Ok(Lock {
                        path: lock_path.to_path_buf(),
                        _file: file,
                    });
                }
                _ => continue,
            }
        }
    }
}

/// The pid of the process that holds the lock on the lock file `file`, if
/// it can be told: on Linux the `FLOCK` entry of its device and inode in
/// `/proc/locks` (`1: FLOCK  ADVISORY  WRITE 6964 fe:00:11338430 0 EOF`,
/// the device as hexadecimal major and minor numbers); elsewhere what the
/// holder wrote into the file.
#[cold]
fn lock_holder(file: &mut File) -> Option<String> {
    #[cfg(target_os = "linux")]
    {
        let m = file.metadata().ok()?;
        let id = format!(
            "{:02x}:{:02x}:{}",
            libc::major(m.dev()),
            libc::minor(m.dev()),
            m.ino()
        );
        let locks = std::fs::read_to_string("/proc/locks").ok()?;
        locks.lines().find_map(|line| {
            // (a waiting lock's line has `->` after the number)
            let fields: Vec<&str> = line.split_whitespace().filter(|f| *f != "->").collect();
            match fields[..] {
                [_, "FLOCK", _, _, pid, device_inode, ..] if device_inode == id => {
                    Some(pid.to_string())
                }
                _ => None,
            }
        })
    }
    #[cfg(not(target_os = "linux"))]
    {
        use std::io::Read;
        let mut pid = String::new();
        file.read_to_string(&mut pid).ok()?;
        let pid = pid.trim();
        (!pid.is_empty()).then(|| pid.to_string())
    }
}

impl Drop for Lock {
    /// Remove the lock file, then let go of the lock (closing the file).
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Refuse `out` if it is the same file as one of `inputs`.
fn refuse_inputs(out: &Path, inputs: &[(&str, &Path)]) -> Result<(), OutputError> {
    match inputs.iter().find(|(_, input)| same_file(out, input)) {
        Some((what, input)) => Err(OutputError::IsInput {
            out: out.to_path_buf(),
            what: what.to_string(),
            input: input.to_path_buf(),
        }),
        None => Ok(()),
    }
}

/// Whether `a` and `b` name the same file: the same device and inode when
/// both exist (through symbolic and hard links), the same absolute path
/// when neither does.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        (Err(_), Err(_)) => absolute(a) == absolute(b),
        _ => false,
    }
}

/// `path` made absolute, its directory canonicalized where it exists.
fn absolute(path: &Path) -> PathBuf {
    let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    match (path.parent(), path.file_name()) {
        (Some(dir), Some(name)) => dir
            .canonicalize()
            .map(|d| d.join(name))
            .unwrap_or_else(|_| path.clone()),
        _ => path,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_committed_file_replaces_the_previous_one_and_leaves_nothing_beside_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        std::fs::write(&path, "old\n").unwrap();
        let mut f = OutputFile::create(&path, &[]).unwrap();
        f.write_all(b"new\n").unwrap();
        // while it is written, the previous file is whole
        f.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old\n");
        f.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new\n");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["r.csv"]);
    }

    #[test]
    fn a_file_dropped_before_its_commit_leaves_the_previous_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        std::fs::write(&path, "old\n").unwrap();
        let mut f = OutputFile::create(&path, &[]).unwrap();
        f.write_all(&[b'x'; 100_000]).unwrap();
        drop(f);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_second_writer_of_the_same_path_is_refused_with_the_first_ones_pid() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        let first = OutputFile::create(&path, &[]).unwrap();
        // flock locks belong to the open file, so a second open in the
        // same process is refused as another process would be
        let e = OutputFile::create(&path, &[]).err().unwrap().to_string();
        assert!(
            e.contains(&format!(
                "is being written by another fricsim run (pid {})",
                std::process::id()
            )),
            "{e}"
        );
        drop(first);
        assert!(OutputFile::create(&path, &[]).is_ok());
    }

    #[test]
    fn partial_files_of_dead_processes_are_removed_by_the_next_writer() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        // a pid that cannot exist (above Linux's largest, 2^22)
        let dead = dir.path().join(".r.csv.fricsim-partial-99999999");
        let live = dir
            .path()
            .join(format!(".r.csv.fricsim-partial-{}", std::process::id()));
        std::fs::write(&dead, "cut mid-r").unwrap();
        std::fs::write(&live, "x").unwrap();
        let _f = OutputFile::create(&path, &[]).unwrap();
        assert!(!dead.exists());
        assert!(live.exists());
    }

    #[test]
    fn the_same_file_through_a_link_or_another_spelling_is_an_input() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("system.ssd");
        std::fs::write(&input, "<ssd/>").unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let spelled = dir.path().join("sub/../system.ssd");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let inputs = [("the system file", input.as_path())];
        for out in [&link, &spelled] {
            let e = OutputFile::create(out, &inputs).err().unwrap().to_string();
            assert!(e.contains("is the system file"), "{e}");
            assert!(e.contains(&input.display().to_string()), "{e}");
        }
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "<ssd/>");
        // two paths not yet written: the same when they name one place
        let plot = dir.path().join("p.png");
        assert!(same_file(&plot, &dir.path().join("sub/../p.png")));
        assert!(!same_file(&plot, &dir.path().join("q.png")));
    }
}
