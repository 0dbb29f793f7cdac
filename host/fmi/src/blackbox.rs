//! The black box: which FMI call the isolated child is in.
//!
//! Before each FMI call the child's [`Instance`](crate::Instance)
//! stores the instance's index, the function's name and a call count, and
//! after it clears the index; `fmi2DoStep` also stores its communication
//! point. These are a few stores into shared memory, no system call. When
//! the child dies, the parent reads what it was doing; while it lives, the
//! parent reads how long the current call has lasted (the call count
//! unchanged since it first saw it) to stop a call that hangs.

use crate::shared_memory::Mapping;
use std::path::Path;
use std::sync::atomic::Ordering::{Acquire, Relaxed, Release};
use std::sync::Arc;

/// Word indices in the black box file.
const CALLS: usize = 0;
const IN_CALL: usize = 1;
const TIME: usize = 2;
const TIME_KNOWN: usize = 3;
const NAME_LEN: usize = 4;
const NAME: usize = 5;
/// Bytes of a function name kept (the longest FMI 2.0 name has 30).
const NAME_BYTES: usize = 48;
const WORDS: usize = NAME + NAME_BYTES / 8;

/// The black box as the child writes it, shared by its instances.
#[derive(Clone)]
pub struct BlackBox {
    map: Arc<Mapping>,
}

/// What the child was doing, as the parent reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct CallRecord {
    /// FMI calls begun so far.
    pub calls: u64,
    /// The index of the instance in an FMI call (in the order of the
    /// system's components), `None` between calls.
    pub instance: Option<usize>,
    /// The function of the last call begun.
    pub function: String,
    /// The communication point of the last `fmi2DoStep` begun.
    pub time: Option<f64>,
}

impl BlackBox {
    /// Create the (zeroed) black box file at `path` (the parent).
    pub fn create(path: &Path) -> std::io::Result<BlackBox> {
        Ok(BlackBox {
            map: Arc::new(Mapping::open(path, WORDS, true)?),
        })
    }

    /// Map the black box file the parent created (the child).
    pub fn open(path: &Path) -> std::io::Result<BlackBox> {
        Ok(BlackBox {
            map: Arc::new(Mapping::open(path, WORDS, false)?),
        })
    }

    /// The recorder of the instance with index `instance`.
    pub fn recorder(&self, instance: usize) -> CallRecorder {
        CallRecorder {
            map: self.map.clone(),
            instance: instance as u64 + 1,
        }
    }

    /// What the child was doing when last written.
    pub fn read(&self) -> CallRecord {
        let m = &self.map;
        let mut name = [0u8; NAME_BYTES];
        for (k, chunk) in name.chunks_exact_mut(8).enumerate() {
            chunk.copy_from_slice(&m.word(NAME + k).load(Relaxed).to_le_bytes());
        }
        let len = (m.word(NAME_LEN).load(Relaxed) as usize).min(NAME_BYTES);
        let instance = m.word(IN_CALL).load(Relaxed);
        CallRecord {
            calls: m.word(CALLS).load(Acquire),
            instance: instance.checked_sub(1).map(|i| i as usize),
            function: String::from_utf8_lossy(&name[..len]).into_owned(),
            time: (m.word(TIME_KNOWN).load(Relaxed) == 1)
                .then(|| f64::from_bits(m.word(TIME).load(Relaxed))),
        }
    }
}

/// One instance's view of the black box (see [`crate::Instance::set_black_box`]).
pub struct CallRecorder {
    map: Arc<Mapping>,
    /// The instance's index + 1 (0 means "in no call").
    instance: u64,
}

impl CallRecorder {
    /// A call of `function` begins.
    #[inline]
    pub fn enter(&self, function: &'static str) {
        let m = &self.map;
        let bytes = function.as_bytes();
        let len = bytes.len().min(NAME_BYTES);
        let mut name = [0u8; NAME_BYTES];
        name[..len].copy_from_slice(&bytes[..len]);
        for (k, chunk) in name.chunks_exact(8).enumerate() {
            let word = u64::from_le_bytes(chunk.try_into().expect("8 bytes"));
            m.word(NAME + k).store(word, Relaxed);
        }
        m.word(NAME_LEN).store(len as u64, Relaxed);
        m.word(IN_CALL).store(self.instance, Relaxed);
        m.word(CALLS).fetch_add(1, Release);
    }

    /// `fmi2DoStep` from the communication point `t` begins.
    #[inline]
    pub fn at_time(&self, t: f64) {
        self.map.word(TIME).store(t.to_bits(), Relaxed);
        self.map.word(TIME_KNOWN).store(1, Relaxed);
    }

    /// The call returned.
    #[inline]
    pub fn leave(&self) {
        self.map.word(IN_CALL).store(0, Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parent_reads_what_the_child_recorded() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("blackbox");
        let parent = BlackBox::create(&path).unwrap();
        let empty = parent.read();
        assert_eq!(
            empty,
            CallRecord {
                calls: 0,
                instance: None,
                function: String::new(),
                time: None
            }
        );
        let child = BlackBox::open(&path).unwrap();
        let belt = child.recorder(1);
        belt.at_time(0.25);
        belt.enter("fmi2DeSerializeFMUstate_and_a_name_longer_than_48_bytes");
        let r = parent.read();
        assert_eq!((r.calls, r.instance, r.time), (1, Some(1), Some(0.25)));
        assert_eq!(
            r.function,
            "fmi2DeSerializeFMUstate_and_a_name_longer_than_4"
        );
        belt.leave();
        belt.enter("fmi2DoStep");
        assert_eq!(parent.read().function, "fmi2DoStep");
        belt.leave();
        assert_eq!(parent.read().instance, None);
        assert_eq!(parent.read().calls, 2);
    }
}
