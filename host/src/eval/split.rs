//! The tune/test split of a labelled dataset: which frames parameters are tuned on and
//! which they are tested on, plus the `--where` filters on group labels.
//!
//! [`split`] puts a frame in the [`Split::Tune`] part when the 64-bit FNV-1a hash of its
//! file name (the `file` column of `truth.csv`, as written, bytes of the UTF-8 text),
//! passed through the SplitMix64 finaliser so that file names differing in one digit
//! land far apart, is below [`TUNE_PERCENT`] % of the hash range: `mix(fnv1a(file)) %
//! 100 < 30`. About 30 % of the frames are tuned on, the rest are the test part. The
//! rule depends on nothing but the file name: the same frame is in the same part in
//! every dataset, run, platform and thread count, and the two parts are disjoint and
//! cover every row.
//!
//! The parts are disjoint within one rendered dataset only. Two renders of a preset
//! with the same seed and different `--count` share scenes under other file names
//! (the j-th frame of each scene kind has the same pose and range, with other noise),
//! so parameters tuned on one must not be tested on the other: tune on a render with
//! another seed, or on the same render's tune part.

use crate::eval::scoring::{GROUP_COLUMNS, TruthRow};
use crate::seed::{fnv1a64, splitmix64_finalise};

/// Percentage of frames (by file-name hash) in the [`Split::Tune`] part.
pub const TUNE_PERCENT: u64 = 30;

/// A part of a labelled dataset (see the module documentation for the rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Split {
    /// About [`TUNE_PERCENT`] % of the frames: the parameters are chosen on these.
    Tune,
    /// The rest: scored once with the chosen parameters.
    Test,
}

/// The part a frame belongs to: [`Split::Tune`] when `splitmix64_finalise(fnv1a64(file)) % 100 <`
/// [`TUNE_PERCENT`].
pub fn split_of(file: &str) -> Split {
    if splitmix64_finalise(fnv1a64(file.as_bytes())) % 100 < TUNE_PERCENT {
        Split::Tune
    } else {
        Split::Test
    }
}

/// The rows of `rows` in `part`, in their order (see [`split_of`]).
pub fn split(rows: &[TruthRow], part: Split) -> Vec<TruthRow> {
    rows.iter()
        .filter(|r| split_of(&r.file) == part)
        .cloned()
        .collect()
}

/// A filter on a group label, `key=value` (`tirroi tune --where`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Where {
    /// Group column: one of [`GROUP_COLUMNS`] or `range`.
    pub key: String,
    /// Value the column must have (for `range`: `close`, `mid` or `far`, see
    /// [`crate::eval::scoring::range_band`]).
    pub value: String,
}

/// Parses `key=value` with a known group column.
///
/// # Errors
/// One line naming the bad text and what is accepted.
pub fn parse_where(s: &str) -> Result<Where, String> {
    let Some((key, value)) = s.split_once('=') else {
        return Err(format!(
            "`{s}`: expected key=value, e.g. mode=radiometry or range=close"
        ));
    };
    let (key, value) = (key.trim(), value.trim());
    if !(GROUP_COLUMNS.contains(&key) || key == "range") {
        return Err(format!(
            "`{s}`: unknown group `{key}`; expected one of {}, range",
            GROUP_COLUMNS.join(", ")
        ));
    }
    if value.is_empty() {
        return Err(format!("`{s}`: empty value"));
    }
    if key == "range" && !["close", "mid", "far"].contains(&value) {
        return Err(format!(
            "`{s}`: unknown range band `{value}`; expected close, mid or far"
        ));
    }
    Ok(Where {
        key: key.into(),
        value: value.into(),
    })
}

/// The rows whose labels pass every filter: for each key named, the row's value of that
/// group is one of the values given for it (filters on different keys combine with
/// "and", filters on the same key with "or"). No filters keep every row.
pub fn filter(rows: &[TruthRow], wheres: &[Where]) -> Vec<TruthRow> {
    rows.iter()
        .filter(|row| {
            let mut keys: Vec<&str> = wheres.iter().map(|w| w.key.as_str()).collect();
            keys.sort_unstable();
            keys.dedup();
            keys.iter().all(|&key| {
                let value = row
                    .groups
                    .iter()
                    .find(|(k, _)| k == key)
                    .map(|(_, v)| v.as_str());
                wheres
                    .iter()
                    .any(|w| w.key == key && Some(w.value.as_str()) == value)
            })
        })
        .cloned()
        .collect()
}
