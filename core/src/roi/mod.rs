//! Region-of-interest (ROI) detection on DN frames (paper Section 4.2).
//!
//! Every detector splits the frame into foreground and background row by row and
//! turns that foreground mask into one box with a [`BoxRule`]:
//!
//! - [`otsu`]: global threshold maximising the between-class variance, exact on the
//!   full bit depth;
//! - [`adaptive`]: local-mean threshold over a square block, streaming column sums;
//! - [`wge`]: weak gradient elimination (Prewitt gradients, drop the weakest fraction);
//! - [`dog`]: difference-of-Gaussians blob detection over space and scale;
//! - [`auto`]: ours, scene-aware: picks the target's outline among coarse edge
//!   components and refines it at full resolution, optionally in a tracking window;
//!   `auto-v2` ([`auto::learned`]) is its development successor (a learned region
//!   stage and a confidence), registered beside it.
//!
//! A detector is a small `Copy` parameter struct implementing [`Detector`]; its
//! working memory is a [`Scratch`] the caller owns, of a size known at compile time.
//! No detector allocates, and none panics on any frame a [`Frame`] can hold.

mod bbox;
mod components;
mod mask;
pub(crate) mod plane;
pub mod registry;
pub mod track;

pub mod adaptive;
pub mod auto;
pub mod dog;
pub mod otsu;
pub mod wge;

use core::fmt;

pub use bbox::Roi;
pub use mask::RoiBuilder;

use crate::capacity::{ConstInit, FrameCapacity, Reference};
use crate::frame::Frame;

/// How a foreground mask becomes one box.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BoxRule {
    /// The box of all foreground pixels: what the paper's numbers imply.
    ///
    /// The default until the renderer's scenes exist to compare both rules on (the
    /// evaluation issue decides and updates this).
    #[default]
    AllForeground,
    /// The box of the largest 8-connected foreground component (most pixels; ties go
    /// to the component whose first pixel comes first in raster order), found by a
    /// streaming run-length labelling in bounded memory.
    LargestComponent,
}

impl BoxRule {
    /// Both rules, in the order tuning tries them.
    pub const ALL: [BoxRule; 2] = [BoxRule::LargestComponent, BoxRule::AllForeground];

    /// The rule's name on the command line and in parameter descriptions:
    /// `all-foreground` or `largest-component`.
    pub const fn name(self) -> &'static str {
        match self {
            BoxRule::AllForeground => "all-foreground",
            BoxRule::LargestComponent => "largest-component",
        }
    }

    /// The rule of a name ([`BoxRule::name`]), `None` for any other string.
    pub fn from_name(name: &str) -> Option<BoxRule> {
        BoxRule::ALL.into_iter().find(|r| r.name() == name)
    }
}

impl fmt::Display for BoxRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What a detector found in one frame, with cheap diagnostics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Detection {
    /// The region of interest, or `None` when no pixel is foreground.
    pub roi: Option<Roi>,
    /// The threshold the detector used; its unit depends on the detector (DN for Otsu,
    /// DN offset for adaptive, Prewitt L1 gradient for WGE, scale-normalised DoG
    /// response in DN for DoG, the coarse edge threshold `coarse_sigma · σ` in DN of
    /// a step over two pixels for auto). See each detector's `detect` documentation.
    pub threshold: u32,
    /// Number of foreground pixels in the mask (before the [`BoxRule`]).
    pub foreground_px: u32,
    /// Confidence that `roi` is the target (a hit: IoU ≥ 0.5 with the truth), in
    /// thousandths: 0–[`SCORE_FULL_PERMILLE`]. `0` whenever `roi` is `None`. The paper's
    /// four detectors have no model of confidence: they report
    /// [`SCORE_FULL_PERMILLE`] for any box. Integer, so the host and flight builds agree
    /// bit for bit.
    pub score_permille: u16,
}

/// The largest [`Detection::score_permille`]: full confidence (1.000).
pub const SCORE_FULL_PERMILLE: u16 = 1000;

impl Detection {
    /// The confidence as a fraction in 0–1 (`score_permille / 1000`).
    pub fn score(&self) -> f32 {
        f32::from(self.score_permille) / f32::from(SCORE_FULL_PERMILLE)
    }

    /// The score the paper's four report: full confidence for a box, zero without.
    pub const fn certain_if_found(roi: &Option<Roi>) -> u16 {
        if roi.is_some() {
            SCORE_FULL_PERMILLE
        } else {
            0
        }
    }
}

/// Why a detector refused to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DetectError {
    /// A parameter is outside its documented bounds.
    InvalidParameter {
        /// The parameter's field name.
        name: &'static str,
        /// What the bounds are.
        expected: &'static str,
    },
    /// The frame is larger than the capacity of the detector's scratch
    /// ([`FrameCapacity`]): use a scratch of a larger capacity.
    FrameTooLarge {
        /// Frame width, pixels.
        width: usize,
        /// Frame height, pixels.
        height: usize,
        /// Largest width the scratch holds.
        capacity_width: usize,
        /// Largest height the scratch holds.
        capacity_height: usize,
    },
}

impl DetectError {
    /// `Ok` when `frame` fits capacity `C`, else [`DetectError::FrameTooLarge`].
    ///
    /// # Errors
    /// [`DetectError::FrameTooLarge`] when the frame is wider or taller than `C`.
    #[inline]
    pub fn check_capacity<C: FrameCapacity>(frame: &Frame<'_>) -> Result<(), DetectError> {
        if frame.width() > C::WIDTH || frame.height() > C::HEIGHT {
            return Err(DetectError::FrameTooLarge {
                width: frame.width(),
                height: frame.height(),
                capacity_width: C::WIDTH,
                capacity_height: C::HEIGHT,
            });
        }
        Ok(())
    }
}

impl fmt::Display for DetectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DetectError::InvalidParameter { name, expected } => {
                write!(f, "invalid parameter `{name}`: expected {expected}")
            }
            DetectError::FrameTooLarge {
                width,
                height,
                capacity_width,
                capacity_height,
            } => write!(
                f,
                "frame is {width}x{height} px, larger than the {capacity_width}x{capacity_height} px capacity of the detector's scratch"
            ),
        }
    }
}

/// A detector's whole working memory at capacity `C`: its own buffers `W` (its
/// [`Detector::Work`]) and the mask-to-box state.
///
/// Its size is `core::mem::size_of::<Scratch<W, C>>()`, fixed at compile time; each
/// detector module exports the reference capacity's as `SCRATCH_BYTES` and names its
/// scratch (`OtsuScratch<C = Reference>`, ...). Build it once (`Scratch::new()` for the
/// reference 328×248, `Scratch::for_capacity()` for another, e.g.
/// `OtsuScratch::<Cap640x512>::for_capacity()`; both `const fn`, so it can live in a
/// `static`) and reuse it for every frame up to `C`'s size.
#[derive(Clone)]
pub struct Scratch<W, C: FrameCapacity = Reference> {
    pub(crate) work: W,
    pub(crate) roi: RoiBuilder<C>,
}

impl<W, C: FrameCapacity> Scratch<W, C> {
    /// The detector's own buffers (read-only: what a detector exposes of its last
    /// frame, e.g. `auto-v2`'s [`auto::learned::AutoV2Work::winner`]).
    pub fn work(&self) -> &W {
        &self.work
    }
}

impl<W: ConstInit> Scratch<W> {
    /// Fresh scratch of the reference capacity, 328×248.
    pub const fn new() -> Self {
        Self::for_capacity()
    }
}

impl<W: ConstInit, C: FrameCapacity> Scratch<W, C> {
    /// Fresh scratch of capacity `C`.
    pub const fn for_capacity() -> Self {
        Scratch {
            work: W::INIT,
            roi: RoiBuilder::for_capacity(),
        }
    }
}

impl<W: ConstInit, C: FrameCapacity> Default for Scratch<W, C> {
    fn default() -> Self {
        Self::for_capacity()
    }
}

/// The common interface of all ROI detectors.
///
/// A detector's parameter struct implements it together with `Default` (its default
/// parameters), `Copy` and `Display` (its parameters as `name=value` pairs), and is
/// registered with one line in the [`registry`].
pub trait Detector: Sized {
    /// The detector's own buffers (without the mask-to-box state) at capacity `C`;
    /// fresh ones are [`ConstInit::INIT`] (a constant, so a [`Scratch`] can be built
    /// in a `const` context).
    type Work<C: FrameCapacity>: ConstInit + Clone;

    /// Short lower-case name, as on the command line (`otsu`, `adaptive`, ...).
    const NAME: &'static str;

    /// Checks the parameters against their documented bounds.
    ///
    /// # Errors
    /// [`DetectError::InvalidParameter`] naming the first field out of bounds.
    fn validate(&self) -> Result<(), DetectError>;

    /// The rule turning the mask into a box.
    fn box_rule(&self) -> BoxRule;

    /// Sets the rule turning the mask into a box; a detector that makes its box
    /// without a mask (`auto`) ignores it.
    fn set_box_rule(&mut self, rule: BoxRule) {
        let _ = rule;
    }

    /// Computes the foreground mask of `frame` and hands it to `sink` one row at a
    /// time, top to bottom, every row exactly once (`sink(y, mask)` with
    /// `mask.len() == frame.width()`). Returns the threshold used (see
    /// [`Detection::threshold`]). Parameters must have been validated and the frame
    /// must fit `C` ([`DetectError::check_capacity`]).
    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut Self::Work<C>,
        sink: F,
    ) -> u32;

    /// Runs the detector on `frame` in `scratch`.
    ///
    /// # Errors
    /// [`DetectError::InvalidParameter`] when [`Detector::validate`] fails,
    /// [`DetectError::FrameTooLarge`] when the frame exceeds the scratch's capacity.
    fn detect<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<Self::Work<C>, C>,
    ) -> Result<Detection, DetectError> {
        self.validate()?;
        DetectError::check_capacity::<C>(frame)?;
        let Scratch { work, roi } = scratch;
        roi.start(self.box_rule(), frame.width());
        let threshold = self.foreground(frame, work, |y, mask| roi.push_row(y, mask));
        let (found, foreground_px) = roi.finish();
        Ok(Detection {
            score_permille: Detection::certain_if_found(&found),
            roi: found,
            threshold,
            foreground_px,
        })
    }
}

crate::detector_registry! {
    /// The detectors by name, for command lines, configuration and telemetry: the
    /// paper's four in its order, then `auto` and its development successor `auto-v2`.
    pub enum Method;
    /// The parameters of one detector (which one says [`Params::method`]).
    pub enum Params;
    /// Every detector's scratch memory in one place: [`Detectors::detect`] runs the
    /// detector of a [`Params`] in its own scratch. 190 KB on x86-64 (the sum of the
    /// scratch sizes); a `static` on flight hardware, boxed on the host.
    pub struct Detectors;
    /// [`otsu::Otsu`].
    Otsu(otsu) => otsu::Otsu,
    /// [`adaptive::Adaptive`].
    Adaptive(adaptive) => adaptive::Adaptive,
    /// [`wge::Wge`].
    Wge(wge) => wge::Wge,
    /// [`dog::Dog`].
    Dog(dog) => dog::Dog,
    /// [`auto::Auto`] (ours, not the paper's).
    Auto(auto) => auto::Auto,
    /// [`auto::learned::AutoV2`]: `auto`'s development successor (issue 16: a learned
    /// region stage and a confidence; `null` below its threshold). Registered beside
    /// `auto` for the comparison; `auto` stays v1 until v2 meets the goals.
    AutoV2(auto_v2) => auto::learned::AutoV2,
}

impl Method {
    /// The paper's four methods, in its order (its tables, figures and tuning).
    pub const PAPER: [Method; 4] = [Method::Otsu, Method::Adaptive, Method::Wge, Method::Dog];
}
