//! The communication grid of a run: how many macro steps of `h` lie
//! between a start and a stop time, and where communication point `j` is
//! (`start + j·h`, counted from the start, never summed). The one place
//! that says so: [`crate::system::Experiment::stepped`] tells the FMUs the
//! stop time the masters ([`crate::master`]) will reach. Uses nothing of
//! the crate.

/// Number of macro steps of `h` from `start` to `stop`: the nearest whole
/// number, so that a stop time that is a multiple of the step up to rounding
/// (20 / 1e-4) is reached exactly.
pub fn step_count(start: f64, h: f64, stop: f64) -> usize {
    ((stop - start) / h).round().max(0.0) as usize
}

/// The time of communication point `j` of a run from `start` in steps of
/// `h`: `start + j·h`, counted from the start (never summed), as
/// [`crate::master::simulate_with`] steps; point 0 is `start` itself.
pub fn communication_time(start: f64, h: f64, j: usize) -> f64 {
    if j == 0 {
        start
    } else {
        counted(start, h, j)
    }
}

/// `start + j·h`: where step `j` of [`crate::master::simulate_with`]
/// starts (and step `j - 1` ends).
#[inline(always)]
pub(crate) fn counted(start: f64, h: f64, j: usize) -> f64 {
    // `j` converted as a signed integer (one instruction; without the
    // sign, several): the same number, a count being far below 2⁶³
    start + j as i64 as f64 * h
}
