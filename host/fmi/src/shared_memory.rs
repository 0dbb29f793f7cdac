//! Memory shared by the isolated child and its parent: a file in the run's
//! temporary directory mapped by both (`mmap(MAP_SHARED)`), so that what
//! the child stored is still there for the parent after the child died,
//! whatever killed it. Only atomics are read and written through it.

use std::fs::OpenOptions;
use std::os::fd::AsRawFd;
use std::path::Path;
use std::sync::atomic::AtomicU64;

/// A file of `words` 64-bit words mapped into this process.
pub struct Mapping {
    pointer: *mut AtomicU64,
    words: usize,
}

// SAFETY: the mapping is only accessed through atomics, and unmapped only
// when the last owner drops it.
unsafe impl Send for Mapping {}
unsafe impl Sync for Mapping {}

impl Mapping {
    /// Map the file `path`, creating it and setting its length to
    /// `words` × 8 bytes if `create` (new pages read as zeros).
    pub fn open(path: &Path, words: usize, create: bool) -> std::io::Result<Mapping> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(create)
            .truncate(create)
            .open(path)?;
        let bytes = words
            .checked_mul(8)
            .filter(|&b| b > 0)
            .ok_or_else(|| std::io::Error::other(format!("cannot map {words} words")))?;
        if create {
            file.set_len(bytes as u64)?;
        } else if file.metadata()?.len() < bytes as u64 {
            return Err(std::io::Error::other(format!(
                "{} is shorter than {bytes} bytes",
                path.display()
            )));
        }
        // SAFETY: a fresh shared mapping of a file we opened read-write and
        // sized; the pointer is checked below and unmapped on drop.
        let pointer = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                bytes,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_SHARED,
                file.as_raw_fd(),
                0,
            )
        };
        if pointer == libc::MAP_FAILED {
            return Err(std::io::Error::last_os_error());
        }
        Ok(Mapping {
            pointer: pointer.cast(),
            words,
        })
    }

    /// Word `i` (panics past the end: a bug of this module, never input).
    #[inline(always)]
    pub fn word(&self, i: usize) -> &AtomicU64 {
        assert!(i < self.words, "word {i} of {}", self.words);
        // SAFETY: in bounds (checked), page-aligned base, live mapping.
        unsafe { &*self.pointer.add(i) }
    }
}

impl Drop for Mapping {
    fn drop(&mut self) {
        // SAFETY: the mapping made in `open`, not used after this.
        unsafe { libc::munmap(self.pointer.cast(), self.words * 8) };
    }
}
