//! Safe unpacking of a `.fmu` (a zip archive, FMI 2.0.4 §2.4 "FMU
//! Distribution") into a fresh temporary directory.
//!
//! Every entry is checked before anything is written: names must be
//! relative paths without `..` components or drive prefixes, symbolic links
//! and duplicated names are refused, the entry count and the declared sizes
//! must stay within [`UnpackOptions`], and `modelDescription.xml` must be at
//! the root. While inflating, the bytes actually written are counted, so an
//! entry whose header understates its size is cut off at the limit. Files are
//! created with `create_new` below the temporary directory only; no symbolic
//! link is ever created, so no write can leave it.

use crate::error::{ArchiveProblem, FmuError};
use crate::library::{PLATFORM, PLATFORM_FMI3};
use std::collections::HashSet;
use std::fs::{self, File};
use std::io::{self, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use tempfile::TempDir;
use zip::ZipArchive;

/// Default limit on the unpacked size, per entry and in total.
pub const DEFAULT_MAX_BYTES: u64 = 512 * 1024 * 1024;
/// Default limit on the number of entries.
pub const DEFAULT_MAX_ENTRIES: usize = 10_000;
/// Unix file-type bits (`S_IFMT`) and the symbolic-link type (`S_IFLNK`).
const S_IFMT: u32 = 0o170_000;
const S_IFLNK: u32 = 0o120_000;

/// Limits and location for [`unpack`].
#[derive(Clone, Debug)]
pub struct UnpackOptions {
    /// Largest unpacked size of one entry and of all entries together.
    pub max_bytes: u64,
    /// Largest number of entries.
    pub max_entries: usize,
    /// Directory in which the temporary directory is created (default: the
    /// system's temporary directory).
    pub temp_parent: Option<PathBuf>,
    /// Write only what an FMU running here can read: the model
    /// description, `binaries/linux64/` (FMI 3.0: `binaries/x86_64-linux/`), `resources/` and the other files
    /// outside `binaries/`, `documentation/` and `sources/`. The binaries
    /// of other platforms, the documentation and the sources are checked
    /// like every entry but not inflated (their folders are made, so the
    /// platforms an FMU has can still be listed). [`Fmu::open`] sets it:
    /// our FMUs carry a Windows DLL beside the Linux library, and inflating
    /// it was half the time spent opening one.
    ///
    /// [`Fmu::open`]: crate::Fmu::open
    pub skip_unused: bool,
    /// Write the model description only, every other entry checked but
    /// not written (their folders are made, as with `skip_unused`):
    /// `fricsim info`, which loads no binary.
    pub description_only: bool,
}

impl Default for UnpackOptions {
    fn default() -> Self {
        UnpackOptions {
            max_bytes: DEFAULT_MAX_BYTES,
            max_entries: DEFAULT_MAX_ENTRIES,
            temp_parent: None,
            skip_unused: false,
            description_only: false,
        }
    }
}

/// The start of the unpack folders' names: `fricsim-fmu-<pid>-XXXXXX`, the
/// pid telling a later run whether the process that made the folder still
/// runs ([`crate::stale`]).
pub const FOLDER_PREFIX: &str = "fricsim-fmu-";

/// Remove, once per process and parent folder, the unpack folders in
/// `parent` of processes that no longer run: a run killed with SIGKILL or
/// crashed runs no destructor, and its folders would stay for good. The
/// first FMU opened pays for one listing of `parent`.
fn remove_folders_of_killed_runs(parent: &Path) {
    static SWEPT: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());
    {
        let mut swept = SWEPT.lock().unwrap_or_else(|p| p.into_inner());
        if swept.iter().any(|p| p == parent) {
            return;
        }
        swept.push(parent.to_path_buf());
    }
    crate::stale::remove_left_by_gone_processes(parent, FOLDER_PREFIX, |p| {
        std::fs::remove_dir_all(p)
    });
}

/// Unpack the FMU at `path` into a new temporary directory, which is removed
/// when the returned [`TempDir`] is dropped (or at once if unpacking fails).
pub fn unpack(path: &Path, options: &UnpackOptions) -> Result<TempDir, FmuError> {
    unpack_requiring(path, options, "modelDescription.xml")
}

/// [`unpack`] for any zip-based package (an FMU, an SSP): the same checks,
/// with `required` the file that must be at the archive's root
/// (`modelDescription.xml`, `SystemStructure.ssd`).
pub fn unpack_requiring(
    path: &Path,
    options: &UnpackOptions,
    required: &str,
) -> Result<TempDir, FmuError> {
    let refuse = |entry: Option<&str>, problem: ArchiveProblem| FmuError::Archive {
        path: path.to_path_buf(),
        entry: entry.map(str::to_string),
        problem,
    };
    let file = File::open(path).map_err(|source| FmuError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut archive = ZipArchive::new(BufReader::new(file))
        .map_err(|e| refuse(None, ArchiveProblem::NotAZip(e.to_string())))?;

    if archive.has_duplicate_names() {
        let start = archive.central_directory_start();
        let name = File::open(path)
            .ok()
            .and_then(|f| first_duplicate_name(&mut BufReader::new(f), start));
        return Err(refuse(name.as_deref(), ArchiveProblem::Duplicate));
    }
    if archive.len() > options.max_entries {
        return Err(refuse(
            None,
            ArchiveProblem::TooManyEntries {
                count: archive.len(),
                limit: options.max_entries,
            },
        ));
    }

    // Check every entry before writing anything.
    let metadata = archive.metadata();
    let mut plan = Vec::with_capacity(archive.len());
    let mut seen = HashSet::with_capacity(archive.len());
    let mut declared_total: u64 = 0;
    for index in 0..archive.len() {
        let entry = metadata
            .entry(index)
            .map_err(|e| refuse(None, ArchiveProblem::NotAZip(e.to_string())))?;
        let name = String::from_utf8_lossy(entry.name_raw()).into_owned();
        let relative = checked_relative_path(&name).map_err(|p| refuse(Some(&name), p))?;
        if entry.is_symlink()
            || entry
                .unix_mode()
                .is_some_and(|mode| mode & S_IFMT == S_IFLNK)
        {
            return Err(refuse(Some(&name), ArchiveProblem::Symlink));
        }
        if !seen.insert(relative.clone()) {
            return Err(refuse(Some(&name), ArchiveProblem::Duplicate));
        }
        if entry.size() > options.max_bytes {
            return Err(refuse(
                Some(&name),
                ArchiveProblem::EntryTooLarge {
                    limit: options.max_bytes,
                },
            ));
        }
        declared_total = declared_total.saturating_add(entry.size());
        if declared_total > options.max_bytes {
            return Err(refuse(
                Some(&name),
                ArchiveProblem::TotalTooLarge {
                    limit: options.max_bytes,
                },
            ));
        }
        plan.push((index, name, relative, entry.is_dir()));
    }
    if !seen.contains(Path::new(required)) {
        return Err(refuse(
            None,
            if required == "modelDescription.xml" {
                ArchiveProblem::MissingModelDescription
            } else {
                ArchiveProblem::MissingRootEntry {
                    name: required.to_string(),
                }
            },
        ));
    }

    let parent = options
        .temp_parent
        .clone()
        .unwrap_or_else(std::env::temp_dir);
    remove_folders_of_killed_runs(&parent);
    let mut builder = tempfile::Builder::new();
    let prefix = format!("{FOLDER_PREFIX}{}-", std::process::id());
    builder.prefix(&prefix);
    let dir = builder.tempdir_in(&parent).map_err(|source| FmuError::Io {
        path: parent.clone(),
        source,
    })?;

    let mut budget = options.max_bytes;
    for (index, name, relative, is_dir) in plan {
        let target = dir.path().join(&relative);
        let write_err = |e: io::Error| refuse(Some(&name), ArchiveProblem::Write(e));
        if is_dir {
            fs::create_dir_all(&target).map_err(write_err)?;
            continue;
        }
        if let Some(parent) = target.parent() {
            fs::create_dir_all(parent).map_err(write_err)?;
        }
        if options.skip_unused && !used_when_running(&relative)
            || options.description_only && relative != Path::new("modelDescription.xml")
        {
            continue;
        }
        let mut entry = archive
            .by_index(index)
            .map_err(|e| refuse(Some(&name), ArchiveProblem::Corrupt(e.to_string())))?;
        let mut out = File::create_new(&target).map_err(write_err)?;
        let written = copy_limited(&mut entry, &mut out, budget).map_err(|e| match e {
            CopyError::Read(e) => refuse(Some(&name), ArchiveProblem::Corrupt(e.to_string())),
            CopyError::Write(e) => write_err(e),
            CopyError::Limit if budget == options.max_bytes => refuse(
                Some(&name),
                ArchiveProblem::EntryTooLarge {
                    limit: options.max_bytes,
                },
            ),
            CopyError::Limit => refuse(
                Some(&name),
                ArchiveProblem::TotalTooLarge {
                    limit: options.max_bytes,
                },
            ),
        })?;
        budget -= written;
    }
    Ok(dir)
}

/// Whether a running FMU may read the file at `relative` (see
/// [`UnpackOptions::skip_unused`]): anything but the binaries of other
/// platforms, the documentation and the sources (FMI 2.0.4 §2.4).
fn used_when_running(relative: &Path) -> bool {
    let mut parts = relative.components().map(|c| c.as_os_str());
    match parts.next().and_then(|first| first.to_str()) {
        Some("documentation" | "sources") => false,
        // the platform as FMI 2.0 and as FMI 3.0 name it (the model
        // description, which says which, is not read yet)
        Some("binaries") => parts
            .next()
            .is_some_and(|p| p == PLATFORM || p == PLATFORM_FMI3),
        _ => true,
    }
}

/// The entry name as a relative path, or why it is refused. Both `/` and
/// `\` count as separators, so a Windows-made name cannot hide a `..`.
fn checked_relative_path(name: &str) -> Result<PathBuf, ArchiveProblem> {
    if name.contains('\0') {
        return Err(ArchiveProblem::NulInName);
    }
    if name.starts_with('/') || name.starts_with('\\') {
        return Err(ArchiveProblem::AbsolutePath);
    }
    let bytes = name.as_bytes();
    if bytes.len() >= 2 && bytes[0].is_ascii_alphabetic() && bytes[1] == b':' {
        return Err(ArchiveProblem::DrivePrefix);
    }
    let mut relative = PathBuf::new();
    for component in name.split(['/', '\\']) {
        match component {
            ".." => return Err(ArchiveProblem::ParentComponent),
            "" | "." => {}
            c => relative.push(c),
        }
    }
    if relative.as_os_str().is_empty() {
        // "/" alone was refused above; "./" or "" names nothing.
        return Err(ArchiveProblem::AbsolutePath);
    }
    Ok(relative)
}

enum CopyError {
    Read(io::Error),
    Write(io::Error),
    Limit,
}

/// Copy `from` into `to`, failing as soon as more than `limit` bytes have
/// come out of `from` (whatever the archive declared). Returns the count.
fn copy_limited(from: &mut impl Read, to: &mut impl Write, limit: u64) -> Result<u64, CopyError> {
    let mut buffer = [0u8; 64 * 1024];
    let mut written: u64 = 0;
    loop {
        let n = match from.read(&mut buffer) {
            Ok(0) => return Ok(written),
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(CopyError::Read(e)),
        };
        written += n as u64;
        if written > limit {
            return Err(CopyError::Limit);
        }
        to.write_all(&buffer[..n]).map_err(CopyError::Write)?;
    }
}

/// The first name that occurs twice in the central directory (the zip crate
/// keeps only one entry per name, so the duplicate is found here). `None` if
/// the directory cannot be read this way.
fn first_duplicate_name(reader: &mut (impl Read + Seek), directory_start: u64) -> Option<String> {
    const CENTRAL_HEADER: u32 = 0x0201_4b50;
    const MAX_SCANNED: usize = 1_000_000;
    reader.seek(SeekFrom::Start(directory_start)).ok()?;
    let mut seen = HashSet::new();
    for _ in 0..MAX_SCANNED {
        let mut header = [0u8; 46];
        reader.read_exact(&mut header).ok()?;
        if u32::from_le_bytes(header[0..4].try_into().ok()?) != CENTRAL_HEADER {
            return None;
        }
        let field = |at: usize| u16::from_le_bytes([header[at], header[at + 1]]) as usize;
        let (name_len, extra_len, comment_len) = (field(28), field(30), field(32));
        let mut name = vec![0u8; name_len];
        reader.read_exact(&mut name).ok()?;
        reader
            .seek(SeekFrom::Current((extra_len + comment_len) as i64))
            .ok()?;
        let name = String::from_utf8_lossy(&name).into_owned();
        if !seen.insert(name.clone()) {
            return Some(name);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked() {
        assert_eq!(
            checked_relative_path("a/b.txt").unwrap(),
            PathBuf::from("a/b.txt")
        );
        assert_eq!(
            checked_relative_path("./a\\b").unwrap(),
            PathBuf::from("a/b")
        );
        assert!(matches!(
            checked_relative_path("../evil"),
            Err(ArchiveProblem::ParentComponent)
        ));
        assert!(matches!(
            checked_relative_path("a/../../evil"),
            Err(ArchiveProblem::ParentComponent)
        ));
        assert!(matches!(
            checked_relative_path("a\\..\\evil"),
            Err(ArchiveProblem::ParentComponent)
        ));
        assert!(matches!(
            checked_relative_path("/tmp/evil"),
            Err(ArchiveProblem::AbsolutePath)
        ));
        assert!(matches!(
            checked_relative_path("\\evil"),
            Err(ArchiveProblem::AbsolutePath)
        ));
        assert!(matches!(
            checked_relative_path("C:/evil"),
            Err(ArchiveProblem::DrivePrefix)
        ));
        assert!(matches!(
            checked_relative_path("c:evil"),
            Err(ArchiveProblem::DrivePrefix)
        ));
    }

    /// The limit applies to the bytes that come out, whatever was declared.
    #[test]
    fn copy_stops_at_the_limit_of_an_endless_stream() {
        let mut sink = io::sink();
        let mut endless = io::repeat(0);
        assert!(matches!(
            copy_limited(&mut endless, &mut sink, 1_000_000),
            Err(CopyError::Limit)
        ));
        let mut short = io::repeat(7).take(1000);
        assert!(matches!(
            copy_limited(&mut short, &mut sink, 1000),
            Ok(1000)
        ));
    }
}
