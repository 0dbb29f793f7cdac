//! One call at a time per instance, at almost no cost to the importer
//! that calls from one thread.
//!
//! FMI 2.0 leaves calls into one instance from two threads at once
//! undefined (FMI 2.0.4 §2.1.5); a friction block must not take its
//! importer down for them, so the second call is refused (`fmi2Error`
//! and a message) instead of running on a state the first is changing.
//!
//! The plain way, one atomic exchange to enter and a store to leave,
//! costs a locked instruction on every call: about a tenth of a
//! co-simulation step of two FMUs here (BENCHMARKS.md, "The instance
//! guard"). Almost every importer calls an instance from one thread, so
//! the guard is *biased* towards the thread that calls it, as the Java
//! virtual machine biased its locks:
//!
//! - **The owner's calls** (the thread the bias is given to): enter by a
//!   plain store (`inside` = true) and a load of `owner`, leave by a
//!   plain store. No locked instruction, no fence.
//! - **Every other call** takes the locked exchange on `busy`, as before.
//!   If the instance is biased to another thread, it first takes the bias
//!   away (`owner` = 0) and then makes every thread of the process pass a
//!   full memory barrier (Linux `membarrier(2)`, Windows
//!   `FlushProcessWriteBuffers`): after that, either it sees the owner's
//!   `inside` (the owner is in a call: refused) or the owner sees that
//!   its bias is gone and takes the locked path too (where `busy` refuses
//!   it). This is the asymmetric form of Dekker's algorithm that
//!   userspace RCU (liburcu) builds on: the frequent side's fence is only
//!   a compiler fence because the rare side's barrier runs on every CPU.
//! - **The bias** goes to a thread after [`BIAS_AFTER`] locked calls in a
//!   row from it, so an instance handed from thread to thread on every
//!   call (a thread pool) stays on the locked path and never pays the
//!   barrier, which costs microseconds.
//!
//! Where the thread cannot be told by one register load
//! ([`thread_token`]) or the barrier is missing (an old kernel, a
//! sandbox that forbids the system call), no bias is ever given: every
//! call takes the locked path, as the guard always did.

use std::cell::UnsafeCell;
use std::sync::atomic::{compiler_fence, AtomicBool, AtomicU8, AtomicUsize, Ordering};

/// Locked calls in a row from one thread before the bias goes to it.
pub const BIAS_AFTER: u32 = 16;

/// The guard of one instance (see the module's text).
pub struct Guard {
    /// Set while a call admitted by the locked path runs.
    busy: AtomicBool,
    /// The thread the guard is biased to ([`thread_token`]), 0 if none.
    owner: AtomicUsize,
    /// Set by the owner while its call runs (plain stores).
    inside: AtomicBool,
    /// The thread of the last locked calls and how many in a row; read
    /// and written only with `busy` held.
    streak: UnsafeCell<(usize, u32)>,
}

// SAFETY: `streak` is reached only with `busy` held (one thread at a
// time); the rest are atomics.
unsafe impl Sync for Guard {}

/// How a call was admitted: how it leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Admission {
    /// The owner's call: clears `inside`.
    Owner,
    /// A locked call: may give the bias to its thread, then clears `busy`.
    Locked,
}

impl Default for Guard {
    fn default() -> Guard {
        Guard {
            busy: AtomicBool::new(false),
            owner: AtomicUsize::new(0),
            inside: AtomicBool::new(false),
            streak: UnsafeCell::new((0, 0)),
        }
    }
}

impl Guard {
    /// Admit a call from this thread, or `None` if another thread is
    /// inside a call (or, rarely, was just leaving one).
    #[inline(always)]
    pub fn admit(&self) -> Option<Admission> {
        let me = thread_token();
        if me != 0 && self.owner.load(Ordering::Relaxed) == me {
            self.inside.store(true, Ordering::Relaxed);
            // The light half of the asymmetric barrier: the store above
            // and the load below stay in this order in the code; the CPU
            // may still swap them, which the heavy half
            // ([`Guard::revoke`]) makes harmless.
            compiler_fence(Ordering::SeqCst);
            if self.owner.load(Ordering::Relaxed) == me {
                return Some(Admission::Owner);
            }
            // the bias was taken away meanwhile: the locked path
            self.inside.store(false, Ordering::Release);
        }
        self.admit_locked(me)
    }

    /// The locked path of [`Guard::admit`].
    #[cold]
    #[inline(never)]
    fn admit_locked(&self, me: usize) -> Option<Admission> {
        if self.busy.swap(true, Ordering::Acquire) {
            return None;
        }
        let owner = self.owner.load(Ordering::Relaxed);
        if owner != 0 && owner != me && !self.revoke() {
            // The owner is inside a call: it keeps the bias, so that the
            // next call from another thread takes it away again, with the
            // barrier, and looks again (with `owner` left at 0, the next
            // one would come in beside the owner's call).
            self.owner.store(owner, Ordering::Relaxed);
            self.busy.store(false, Ordering::Release);
            return None;
        }
        Some(Admission::Locked)
    }

    /// Take the bias away from its owner (`busy` held): true if the owner
    /// is not inside a call, which it cannot enter again without `busy`;
    /// false if it is (or cannot be known to be out), the bias then given
    /// back by the caller.
    fn revoke(&self) -> bool {
        #[cfg(test)]
        tests::REVOCATIONS.fetch_add(1, Ordering::Relaxed);
        self.owner.store(0, Ordering::Relaxed);
        if !heavy_barrier() {
            // No barrier after all (it worked when the bias was given):
            // whether the owner is inside cannot be known, so the call is
            // refused, and no bias is given again in this process.
            BARRIER.store(UNAVAILABLE, Ordering::Relaxed);
            return false;
        }
        // Every thread has passed a full barrier since `owner` = 0: the
        // owner's `inside` = true is seen here if it was set before, and
        // if it is set after, the owner reads `owner` = 0 and leaves.
        // (Acquire: the owner's last call, ended by its Release store of
        // `inside` = false, happens before this one.)
        !self.inside.load(Ordering::Acquire)
    }

    /// End the call `admission` admitted (on the thread it admitted).
    #[inline(always)]
    pub fn release(&self, admission: Admission) {
        match admission {
            Admission::Owner => self.inside.store(false, Ordering::Release),
            Admission::Locked => self.release_locked(),
        }
    }

    /// [`Guard::release`] of a locked call: counts the thread's calls in a
    /// row and gives it the bias after [`BIAS_AFTER`].
    #[cold]
    #[inline(never)]
    fn release_locked(&self) {
        let me = thread_token();
        // SAFETY: `busy` is held by this call (see the field).
        let streak = unsafe { &mut *self.streak.get() };
        if streak.0 == me {
            streak.1 = streak.1.saturating_add(1);
        } else {
            *streak = (me, 1);
        }
        if me != 0 && streak.1 >= BIAS_AFTER && barrier_available() {
            self.owner.store(me, Ordering::Relaxed);
        }
        self.busy.store(false, Ordering::Release);
    }

    /// The thread the guard is biased to, 0 if none (for tests).
    pub fn owner(&self) -> usize {
        self.owner.load(Ordering::Relaxed)
    }
}

/// This thread's identity, from one register load: the thread pointer
/// the platform's ABI keeps for thread-local storage, distinct for every
/// live thread (x86-64 Linux: the self-pointer at `%fs:0`; Windows x64:
/// the TEB's self-pointer at `gs:[0x30]`; AArch64 Linux: `TPIDR_EL0`).
/// 0 where none is known: no bias is given.
#[inline(always)]
pub fn thread_token() -> usize {
    #[cfg(all(target_arch = "x86_64", target_os = "linux"))]
    {
        let t: usize;
        // SAFETY: the x86-64 TLS ABI keeps the thread pointer's own value
        // at %fs:0 for every thread (glibc and musl alike).
        unsafe {
            std::arch::asm!(
                "mov {}, qword ptr fs:[0]",
                out(reg) t,
                options(nostack, readonly, preserves_flags)
            );
        }
        t
    }
    #[cfg(all(target_arch = "x86_64", windows))]
    {
        let t: usize;
        // SAFETY: gs:[0x30] is the TEB's NT_TIB.Self on Windows x64 (and
        // under Wine).
        unsafe {
            std::arch::asm!(
                "mov {}, qword ptr gs:[0x30]",
                out(reg) t,
                options(nostack, readonly, preserves_flags)
            );
        }
        t
    }
    #[cfg(all(target_arch = "aarch64", target_os = "linux"))]
    {
        let t: usize;
        // SAFETY: reading the thread-pointer register has no effect.
        unsafe {
            std::arch::asm!(
                "mrs {}, tpidr_el0",
                out(reg) t,
                options(nomem, nostack, preserves_flags)
            );
        }
        t
    }
    #[cfg(not(any(
        all(target_arch = "x86_64", any(target_os = "linux", windows)),
        all(target_arch = "aarch64", target_os = "linux")
    )))]
    {
        0
    }
}

const UNKNOWN: u8 = 0;
const AVAILABLE: u8 = 1;
const UNAVAILABLE: u8 = 2;
/// Whether the process-wide barrier works here: [`prepare_barrier`]
/// decides, [`barrier_available`] reads.
static BARRIER: AtomicU8 = AtomicU8::new(UNKNOWN);
/// Instantiations that found the process already running several threads
/// ([`prepare_barrier`]).
static BUSY_PROCESS: AtomicU8 = AtomicU8::new(0);
/// After this many, the bias is given up for the process.
const BUSY_PROCESS_TRIES: u8 = 4;

/// Whether [`heavy_barrier`] is ready in this process (no system call:
/// the guard asks it with `busy` held).
fn barrier_available() -> bool {
    BARRIER.load(Ordering::Relaxed) == AVAILABLE
}

/// Make the barrier ready if that is cheap, at `fmi2Instantiate` (once it
/// is decided, nothing). Linux: the process registers for
/// `membarrier(2)`'s private expedited command (Linux 4.14 and later),
/// which takes microseconds in a process of one thread but waits for an
/// RCU grace period, 5 to 20 ms measured here, once a second thread
/// exists. So it is done only while the process has one thread; after
/// [`BUSY_PROCESS_TRIES`] instantiations in a busier process the bias is
/// given up (every call takes the locked path, as the guard always did).
pub fn prepare_barrier() {
    if BARRIER.load(Ordering::Relaxed) != UNKNOWN {
        return;
    }
    if !one_thread() {
        if BUSY_PROCESS.fetch_add(1, Ordering::Relaxed) + 1 >= BUSY_PROCESS_TRIES {
            BARRIER.store(UNAVAILABLE, Ordering::Relaxed);
        }
        return;
    }
    force_barrier();
}

/// Make the barrier ready whatever it costs (tests); whether it is.
pub fn force_barrier() -> bool {
    if BARRIER.load(Ordering::Relaxed) == UNKNOWN {
        let ok = register_barrier();
        BARRIER.store(if ok { AVAILABLE } else { UNAVAILABLE }, Ordering::Relaxed);
    }
    barrier_available()
}

/// Whether the process has one thread (Linux: `Threads:` of
/// /proc/self/status; elsewhere registering costs nothing: true).
#[cfg(target_os = "linux")]
fn one_thread() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            let line = status.lines().find(|l| l.starts_with("Threads:"))?;
            line["Threads:".len()..].trim().parse::<u32>().ok()
        })
        == Some(1)
}

#[cfg(not(target_os = "linux"))]
fn one_thread() -> bool {
    true
}

#[cfg(target_os = "linux")]
mod membarrier {
    /// `membarrier(2)` commands (linux/membarrier.h).
    pub const QUERY: libc::c_long = 0;
    pub const PRIVATE_EXPEDITED: libc::c_long = 1 << 3;
    pub const REGISTER_PRIVATE_EXPEDITED: libc::c_long = 1 << 4;

    pub fn call(command: libc::c_long) -> libc::c_long {
        // SAFETY: membarrier takes two integers and touches no memory of
        // ours.
        unsafe { libc::syscall(libc::SYS_membarrier, command, 0 as libc::c_long) }
    }
}

#[cfg(target_os = "linux")]
fn register_barrier() -> bool {
    use membarrier::*;
    let supported = call(QUERY);
    let needed = PRIVATE_EXPEDITED | REGISTER_PRIVATE_EXPEDITED;
    supported >= 0 && supported & needed == needed && call(REGISTER_PRIVATE_EXPEDITED) == 0
}

#[cfg(target_os = "linux")]
fn heavy_barrier() -> bool {
    use membarrier::*;
    // Refused if the process is not registered: a child made by fork()
    // keeps the registration on the kernels tried here, but should one
    // not, the child (whose BARRIER was copied from the parent) registers
    // then, slowly but once.
    call(PRIVATE_EXPEDITED) == 0
        || (call(REGISTER_PRIVATE_EXPEDITED) == 0 && call(PRIVATE_EXPEDITED) == 0)
}

#[cfg(windows)]
#[link(name = "kernel32")]
extern "system" {
    /// Makes every thread of the process pass a full memory barrier (an
    /// interprocessor interrupt to each processor running one).
    fn FlushProcessWriteBuffers();
}

#[cfg(windows)]
fn register_barrier() -> bool {
    true
}

#[cfg(windows)]
fn heavy_barrier() -> bool {
    // SAFETY: no arguments, no failure.
    unsafe { FlushProcessWriteBuffers() };
    true
}

#[cfg(not(any(target_os = "linux", windows)))]
fn register_barrier() -> bool {
    false
}

#[cfg(not(any(target_os = "linux", windows)))]
fn heavy_barrier() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU64;
    use std::sync::Arc;

    /// Biases taken away, by every test of this module.
    pub static REVOCATIONS: AtomicU64 = AtomicU64::new(0);

    #[test]
    fn threads_have_distinct_tokens() {
        let here = thread_token();
        let there = std::thread::spawn(thread_token).join().unwrap();
        if cfg!(any(
            all(target_arch = "x86_64", any(target_os = "linux", windows)),
            all(target_arch = "aarch64", target_os = "linux")
        )) {
            assert_ne!(here, 0);
            assert_ne!(there, 0);
            assert_ne!(here, there);
            assert_eq!(here, thread_token(), "the same thread, the same token");
        }
    }

    /// The bias goes to a thread after BIAS_AFTER locked calls in a row,
    /// its calls then enter as the owner's, and one call from another
    /// thread takes the bias away.
    #[test]
    fn the_bias_comes_after_a_streak_and_goes_with_another_thread() {
        let guard = Arc::new(Guard::default());
        if thread_token() == 0 || !force_barrier() {
            return; // no bias on this platform: every call is locked
        }
        for k in 0..BIAS_AFTER {
            assert_eq!(guard.owner(), 0, "call {k}");
            let a = guard.admit().unwrap();
            assert_eq!(a, Admission::Locked);
            guard.release(a);
        }
        assert_eq!(guard.owner(), thread_token());
        let a = guard.admit().unwrap();
        assert_eq!(a, Admission::Owner);
        guard.release(a);
        let other = Arc::clone(&guard);
        let there = std::thread::spawn(move || {
            let a = other.admit().unwrap();
            other.release(a);
            a
        })
        .join()
        .unwrap();
        assert_eq!(there, Admission::Locked);
        assert_eq!(guard.owner(), 0, "the bias was taken away");
        assert_eq!(guard.admit(), Some(Admission::Locked));
    }

    /// While the owner is inside a call, another thread is refused, and
    /// the owner is refused while the other is inside.
    #[test]
    fn a_call_while_the_owner_is_inside_is_refused() {
        force_barrier();
        let guard = Arc::new(Guard::default());
        for _ in 0..BIAS_AFTER {
            let a = guard.admit().unwrap();
            guard.release(a);
        }
        let held = guard.admit().unwrap();
        let other = Arc::clone(&guard);
        let refused = std::thread::spawn(move || other.admit().is_none())
            .join()
            .unwrap();
        assert!(refused, "a second thread entered during the owner's call");
        guard.release(held);
        // and the other way round
        let other = Arc::clone(&guard);
        let (entered_tx, entered_rx) = std::sync::mpsc::channel();
        let (leave_tx, leave_rx) = std::sync::mpsc::channel::<()>();
        let inside = std::thread::spawn(move || {
            let a = other.admit().unwrap();
            entered_tx.send(()).unwrap();
            leave_rx.recv().unwrap();
            other.release(a);
        });
        entered_rx.recv().unwrap();
        assert!(
            guard.admit().is_none(),
            "the owner entered during another thread's call"
        );
        leave_tx.send(()).unwrap();
        inside.join().unwrap();
        assert!(guard.admit().is_some());
    }

    /// Threads hammering one guard: never two inside at once. Each call
    /// checks a counter of threads inside (it must find 0, make it 1 and
    /// find 1 again before leaving), with pauses that let the bias move
    /// between threads.
    #[test]
    fn never_two_inside_at_once() {
        force_barrier();
        let guard = Arc::new(Guard::default());
        let inside = Arc::new(AtomicU64::new(0));
        let as_owner = Arc::new(AtomicU64::new(0));
        let locked = Arc::new(AtomicU64::new(0));
        let threads: Vec<_> = (0..4u64)
            .map(|k| {
                let (guard, inside) = (Arc::clone(&guard), Arc::clone(&inside));
                let (as_owner, locked) = (Arc::clone(&as_owner), Arc::clone(&locked));
                std::thread::spawn(move || {
                    for i in 0..200_000u64 {
                        if let Some(a) = guard.admit() {
                            assert_eq!(inside.fetch_add(1, Ordering::SeqCst), 0);
                            match a {
                                Admission::Owner => as_owner.fetch_add(1, Ordering::Relaxed),
                                Admission::Locked => locked.fetch_add(1, Ordering::Relaxed),
                            };
                            for _ in 0..(i % 7) {
                                std::hint::spin_loop();
                            }
                            assert_eq!(inside.fetch_sub(1, Ordering::SeqCst), 1);
                            guard.release(a);
                        }
                        // bursts: a thread alone for a while earns the bias,
                        // the next to come takes it away
                        if (i + 37 * k) % 1_000 == 0 {
                            std::thread::yield_now();
                        }
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
        assert!(locked.load(Ordering::Relaxed) > 0);
        if thread_token() != 0 && barrier_available() {
            // both paths and the hand-over between them were exercised
            let (owner, revoked) = (
                as_owner.load(Ordering::Relaxed),
                REVOCATIONS.load(Ordering::Relaxed),
            );
            eprintln!(
                "{owner} calls as the owner, {} locked, {revoked} biases taken away",
                locked.load(Ordering::Relaxed)
            );
            assert!(owner > 0, "no call entered as the owner");
            assert!(revoked > 0, "no bias was taken away");
        }
    }
}
