//! Every decision number of `auto` that is not a parameter, with the reason for its
//! value. (The numbers worth tuning are fields of [`super::Auto`], with these
//! reasons on the fields: `side_shift`, `relabel_codes`, `near_sat_sigma`,
//! `sat_ratio`, `margin_divisor`.)

/// Rows sampled by the noise estimate, evenly spaced over the window: with every other
/// pixel of each row that is about 2 600 samples on a full frame, plenty for a median,
/// at a few percent of a pass over the frame.
pub const NOISE_ROWS: usize = 16;
/// Fewest samples a noise median is taken from; fewer (a tiny window, or a frame
/// clipped nearly everywhere) give no estimate and σ falls back to 1 DN.
pub const MIN_NOISE_SAMPLES: u32 = 16;
/// σ from the median `m` of first differences `|b − a|` of pixels with noise σ: the
/// difference has σ√2 and a Gaussian's median absolute value is 0.6745 of its σ, so
/// `m = 0.954 σ` and `σ = m · 21/20` (1.050 for 1/0.954 = 1.048; integers only).
pub const FIRST_DIFF_SIGMA: (u32, u32) = (21, 20);
/// σ from the median of second differences `|a − 2b + c|`: σ√6 · 0.6745 = 1.652 σ,
/// so `σ = m · 20/33` (0.606 for 1/1.652 = 0.605).
pub const SECOND_DIFF_SIGMA: (u32, u32) = (20, 33);
/// Deep space fills the window when more than 1/`SPACE_ZERO_SHARE` of the sampled
/// pairs are both at 0 DN (2: most of them): the only texture left is the target's own
/// shading, and the second-difference σ (blind to it) is used.
pub const SPACE_ZERO_SHARE: u32 = 2;
/// Deep space is clean (sunlit frames: 0 DN nearly everywhere) when the pairs both at
/// 0 DN are at least this many times the pairs with one pixel at 0 and one above:
/// noise clipped at 0 around a level *at* 0 makes two such mixed pairs for every
/// pair at 0, so a sparse sprinkle of clipped noise is well below 1 : 4.
pub const CLEAN_ZERO_PER_MIXED: u32 = 4;
/// The step plane's unit is σ / `STEP_UNITS_PER_SIGMA` (σ/4): fine enough that the
/// thresholds (multiples of σ) fall between codes a quarter of σ apart at worst.
pub const STEP_UNITS_PER_SIGMA: u32 = 4;
/// Fraction bits of a step code: 2^4 = 16 codes per octave (a code is within 1/16 of
/// an octave, 4.4 %, of its step; 8 bits then span steps up to 2^15.9 units).
pub const STEP_CODE_FRACTION_BITS: u32 = 4;
/// Step codes per octave, from [`STEP_CODE_FRACTION_BITS`].
pub const STEP_CODES_PER_OCTAVE: u32 = 1 << STEP_CODE_FRACTION_BITS;
/// Most labelling passes of a frame: the first at `coarse_sigma`, then each with the
/// threshold raised by `Auto::relabel_codes`; four reach 1.5^3 = 3.4 times the first
/// threshold (a frame that still has more components than labels is boxed from the
/// components labelled).
pub const RELABEL_ATTEMPTS: usize = 4;
/// The refinement window and the gate reach this many cells beyond the winner: a
/// boundary at the edge of a cell shows its step in the next cell too.
pub const GATE_CELLS: u8 = 1;
/// Beside a saturated target the frame is nearly noise-free and the boundaries that
/// matter are of cold, unsaturated faces: the full-resolution threshold is this many
/// times `fine_sigma · σ`.
pub const SATURATED_TAU_FACTOR: u16 = 2;
/// Fewest saturated pixels that make a saturated target (fewer: hot pixels).
pub const MIN_SATURATED_PX: u32 = 4;
/// A saturated target's outermost lines of at most this many saturated pixels are
/// trimmed: pixels less than half covered saturate too, and stick out of the truth box
/// one or two at a time.
pub const TRIM_LINE_PX: u16 = 2;
/// Lines trimmed per side at most (a partly covered pixel row or column, and the
/// corner pixel beyond it).
pub const TRIM_PASSES: usize = 2;
