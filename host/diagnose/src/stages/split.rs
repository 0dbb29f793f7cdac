//! Stage 3, the split: which samples and friction intervals fit the
//! models and which score them.
//!
//! Takes the data records, their friction data and whether held-out
//! records were given; gives a [`Split`]: the folds (each a set of
//! intervals and samples to fit on and the samples it scores), the
//! intervals every fold scores together, and the [`Blocks`] the data are
//! cut into. The words used throughout: a model is *fitted* on one part
//! of the data and *scored* on another it did not see; the *held-out
//! records* are the files given to score on (`--heldout`), and without
//! them the scored part is cut out of the data records.

use crate::problem::{FrictionData, Measured};
use crate::sim::ChannelResiduals;
use crate::{CrossValidate, Options, CROSS_VALIDATE_MAX_SAMPLES};

/// Blocks of phase `b mod 3` = this are held out by a single split.
pub(crate) const HELD_OUT_PHASE: usize = 1;

/// Phases of the blocks: the folds of the cross-validation.
const PHASES: usize = 3;

/// A file's time span cut into equal blocks (at least 3), every third held
/// out ([`crate::held_out_block`]); or, with several records each held out
/// in turn, one phase per record.
#[derive(Clone, Debug)]
pub struct Blocks {
    t0: f64,
    t1: f64,
    pub count: usize,
    /// Leave one record out: the joined start time of every record after
    /// the first (the phase of a time is its record).
    record_starts: Option<Vec<f64>>,
}

impl Blocks {
    pub fn new(time: &[f64], count: usize) -> Blocks {
        Blocks {
            t0: time.first().copied().unwrap_or(0.0),
            t1: time.last().copied().unwrap_or(0.0),
            count: count.max(3),
            record_starts: None,
        }
    }

    /// The blocks of `data` whose phases are its records
    /// ([`CrossValidate::Records`]).
    pub fn by_records(data: &Measured, count: usize) -> Blocks {
        Blocks {
            record_starts: Some(
                data.records[1..]
                    .iter()
                    .map(|r| data.time[r.rows.start])
                    .collect(),
            ),
            ..Blocks::new(&data.time, count)
        }
    }

    /// How many phases (folds of a cross-validation) there are.
    fn phases(&self) -> usize {
        self.record_starts.as_ref().map_or(PHASES, |s| s.len() + 1)
    }

    /// The block (0-based) holding time `t`.
    pub fn block(&self, t: f64) -> usize {
        let b = ((t - self.t0) / (self.t1 - self.t0) * self.count as f64) as usize;
        b.min(self.count - 1)
    }

    /// The phase (`b mod 3`) of the block holding time `t` (its record,
    /// when the records are the phases).
    pub fn phase(&self, t: f64) -> usize {
        match &self.record_starts {
            Some(starts) => starts.iter().filter(|&&s| s <= t).count(),
            None => self.block(t) % PHASES,
        }
    }

    /// Whether the block holding time `t` is held out by a single split.
    pub fn held_out(&self, t: f64) -> bool {
        self.phase(t) == HELD_OUT_PHASE
    }

    /// The positions of a co-simulation's samples (of the file with
    /// `time`) in blocks of `phase` (`in_phase`) or of the other phases.
    pub(crate) fn picker(&self, time: &[f64], phase: usize, in_phase: bool) -> Picker {
        let time = time.to_vec();
        let blocks = self.clone();
        Picker {
            pick: Box::new(move |r: &ChannelResiduals| {
                (0..r.samples.len())
                    .filter(|&s| (blocks.phase(time[r.samples[s]]) == phase) == in_phase)
                    .collect()
            }),
            records: None,
        }
    }
}

/// The positions (into `ChannelResiduals::samples`) a [`Picker`] takes.
type PickFn = Box<dyn Fn(&ChannelResiduals) -> Vec<usize> + Sync>;

/// Which samples of a co-simulation a score or a fit uses (positions into
/// `ChannelResiduals::samples`), and which records must be co-simulated
/// for them (`None`: all).
pub(crate) struct Picker {
    pub(crate) pick: PickFn,
    pub(crate) records: Option<Vec<usize>>,
}

impl Picker {
    /// Every sample of every record.
    pub(crate) fn all() -> Picker {
        Picker {
            pick: Box::new(all_samples),
            records: None,
        }
    }

    /// Every sample of the records `records`.
    fn records(records: Vec<usize>) -> Picker {
        Picker {
            pick: Box::new(all_samples),
            records: Some(records),
        }
    }
}

/// Every compared sample of a co-simulation.
fn all_samples(r: &ChannelResiduals) -> Vec<usize> {
    (0..r.samples.len()).collect()
}

/// One way of cutting the data into a part that fits and a part that is
/// scored: the held-out records, one third of the blocks, or one of the
/// folds of a cross-validation.
pub(crate) struct Fold {
    /// Intervals of the data records' friction data the force fits use.
    pub(crate) fit_intervals: Vec<usize>,
    /// Positions (into `ChannelResiduals::samples`) of a co-simulation of
    /// the scored data that this fold scores.
    pub(crate) scores: Picker,
    /// Positions of a co-simulation of the data records that this fold's
    /// output-error fits use.
    pub(crate) fits: Picker,
}

/// The split of the data into what fits and what scores.
pub(crate) struct Split {
    pub(crate) blocks: Blocks,
    /// Each data record held out in turn ([`CrossValidate::Records`]).
    pub(crate) by_records: bool,
    /// Every block scored, each by the fold that did not fit on it.
    pub(crate) cross: bool,
    pub(crate) folds: Vec<Fold>,
    /// The trusted intervals of the data records' friction data: what a
    /// model fitted on all of them uses.
    pub(crate) fit_intervals: Vec<usize>,
    /// Intervals of the scored friction data that some fold scores.
    pub(crate) scored_intervals: Vec<usize>,
}

/// The trusted intervals of `d`.
fn trusted(d: &FrictionData) -> Vec<usize> {
    (0..d.t.len()).filter(|&j| d.trusted[j]).collect()
}

impl Split {
    /// Cut `data` (the data records, with their friction data
    /// `data_friction`) into folds; `heldout_friction`: the friction data
    /// of the held-out records, when given (they are then scored whole by
    /// one fold fitted on all of `data`). An error when the records cannot
    /// be held out in turn as asked, or when too few samples are left to
    /// fit or to score.
    pub(crate) fn new(
        data: &Measured,
        data_friction: &FrictionData,
        heldout_friction: Option<&FrictionData>,
        options: &Options,
    ) -> Result<Split, String> {
        let given = heldout_friction.is_some();
        let by_records = !given
            && data.records.len() > 1
            && matches!(
                options.cross_validate,
                CrossValidate::Auto | CrossValidate::Records
            );
        if !given && !by_records && options.cross_validate == CrossValidate::Records {
            return Err(format!(
                "{}: cross-validation by records needs at least two records (give several data files)",
                data.label
            ));
        }
        let blocks = if by_records {
            Blocks::by_records(data, options.blocks)
        } else {
            Blocks::new(&data.time, options.blocks)
        };
        let fit_intervals = trusted(data_friction);
        let cross = !given
            && match options.cross_validate {
                CrossValidate::Always | CrossValidate::Records => true,
                CrossValidate::Never => false,
                CrossValidate::Auto => by_records || data.time.len() <= CROSS_VALIDATE_MAX_SAMPLES,
            };
        let (scored_intervals, folds) = match heldout_friction {
            Some(h) => (
                trusted(h),
                vec![Fold {
                    fit_intervals: fit_intervals.clone(),
                    scores: Picker::all(),
                    fits: Picker::all(),
                }],
            ),
            None => {
                let phases: Vec<usize> = if cross {
                    (0..blocks.phases()).collect()
                } else {
                    vec![HELD_OUT_PHASE]
                };
                let folds = phases
                    .iter()
                    .map(|&phase| Fold {
                        fit_intervals: fit_intervals
                            .iter()
                            .copied()
                            .filter(|&j| blocks.phase(data_friction.t[j]) != phase)
                            .collect(),
                        // by records: only the records a fold scores or fits
                        // are co-simulated for it
                        scores: if by_records {
                            Picker::records(vec![phase])
                        } else {
                            blocks.picker(&data.time, phase, true)
                        },
                        fits: if by_records {
                            Picker::records(
                                (0..data.records.len()).filter(|&r| r != phase).collect(),
                            )
                        } else {
                            blocks.picker(&data.time, phase, false)
                        },
                    })
                    .collect();
                let scored = fit_intervals
                    .iter()
                    .copied()
                    .filter(|&j| phases.contains(&blocks.phase(data_friction.t[j])))
                    .collect();
                (scored, folds)
            }
        };
        let fewest_fit = folds
            .iter()
            .map(|f| f.fit_intervals.len())
            .min()
            .unwrap_or(0);
        if fewest_fit < crate::problem::MIN_SAMPLES / 2 || scored_intervals.len() < options.groups {
            return Err(format!(
                "{}: too few samples to fit ({}) and hold out ({})",
                data.label,
                fewest_fit,
                scored_intervals.len()
            ));
        }
        Ok(Split {
            blocks,
            by_records,
            cross,
            folds,
            fit_intervals,
            scored_intervals,
        })
    }

    /// What is scored, in words, for the report's `heldout`: `heldout_label`
    /// (the held-out records' label) when they were given, else which part
    /// of `data` is.
    pub(crate) fn describe(&self, data: &Measured, heldout_label: Option<&str>) -> String {
        match heldout_label {
            Some(h) => h.to_string(),
            None if self.by_records => format!(
                "each of the {} records ({}) in turn, scored by the model fitted on the others",
                data.records.len(),
                data.label
            ),
            None if self.cross => format!(
                "every one of {} equal time blocks of {}, by three-fold cross-validation (blocks 1, 4, 7, ..., then 2, 5, 8, ..., then 3, 6, 9, ... held out, each scored by the model fitted on the others)",
                self.blocks.count, data.label
            ),
            None => format!(
                "every third of {} equal time blocks of {} (blocks 2, 5, 8, ...)",
                self.blocks.count, data.label
            ),
        }
    }
}
