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
//!   components and refines it at full resolution, optionally in a tracking window.
//!
//! A detector is a small `Copy` parameter struct implementing [`Detector`]; its
//! working memory is a [`Scratch`] the caller owns, of a size known at compile time.
//! No detector allocates, and none panics on any frame a [`Frame`] can hold.

mod bbox;
mod components;
mod mask;
mod plane;

pub mod adaptive;
pub mod auto;
pub mod dog;
pub mod otsu;
pub mod wge;

use core::fmt;

pub use bbox::Roi;
pub use mask::RoiBuilder;

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
}

impl fmt::Display for DetectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DetectError::InvalidParameter { name, expected } => {
                write!(f, "invalid parameter `{name}`: expected {expected}")
            }
        }
    }
}

/// A detector's whole working memory: its own buffers `W` and the mask-to-box state.
///
/// Its size is `core::mem::size_of::<Scratch<W>>()`, fixed at compile time; each
/// detector module exports it as `SCRATCH_BYTES`. Build it once (`Scratch::new()` is a
/// `const fn`, so it can live in a `static`) and reuse it for every frame.
#[derive(Clone)]
pub struct Scratch<W> {
    pub(crate) work: W,
    pub(crate) roi: RoiBuilder,
}

/// The common interface of all ROI detectors.
pub trait Detector {
    /// The detector's own buffers (without the mask-to-box state).
    type Work;

    /// Short lower-case name, as on the command line (`otsu`, `adaptive`, ...).
    const NAME: &'static str;

    /// Checks the parameters against their documented bounds.
    ///
    /// # Errors
    /// [`DetectError::InvalidParameter`] naming the first field out of bounds.
    fn validate(&self) -> Result<(), DetectError>;

    /// The rule turning the mask into a box.
    fn box_rule(&self) -> BoxRule;

    /// Computes the foreground mask of `frame` and hands it to `sink` one row at a
    /// time, top to bottom, every row exactly once (`sink(y, mask)` with
    /// `mask.len() == frame.width()`). Returns the threshold used (see
    /// [`Detection::threshold`]). Parameters must have been validated.
    fn foreground<F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut Self::Work,
        sink: F,
    ) -> u32;

    /// Runs the detector on `frame` in `scratch`.
    ///
    /// # Errors
    /// [`DetectError::InvalidParameter`] when [`Detector::validate`] fails.
    fn detect(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<Self::Work>,
    ) -> Result<Detection, DetectError> {
        self.validate()?;
        let Scratch { work, roi } = scratch;
        roi.start(self.box_rule(), frame.width());
        let threshold = self.foreground(frame, work, |y, mask| roi.push_row(y, mask));
        let (found, foreground_px) = roi.finish();
        Ok(Detection {
            roi: found,
            threshold,
            foreground_px,
        })
    }
}

/// The detectors by name, for command lines, configuration and telemetry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// [`otsu::Otsu`].
    Otsu,
    /// [`adaptive::Adaptive`].
    Adaptive,
    /// [`wge::Wge`].
    Wge,
    /// [`dog::Dog`].
    Dog,
    /// [`auto::Auto`] (ours, not the paper's).
    Auto,
}

impl Method {
    /// All methods: the paper's four in its order, then `auto`.
    pub const ALL: [Method; 5] = [
        Method::Otsu,
        Method::Adaptive,
        Method::Wge,
        Method::Dog,
        Method::Auto,
    ];

    /// The paper's four methods, in its order (its tables, figures and tuning).
    pub const PAPER: [Method; 4] = [Method::Otsu, Method::Adaptive, Method::Wge, Method::Dog];

    /// The lower-case name used on the command line.
    pub const fn name(self) -> &'static str {
        match self {
            Method::Otsu => otsu::Otsu::NAME,
            Method::Adaptive => adaptive::Adaptive::NAME,
            Method::Wge => wge::Wge::NAME,
            Method::Dog => dog::Dog::NAME,
            Method::Auto => auto::Auto::NAME,
        }
    }

    /// Parses a lower-case name (`otsu`, `adaptive`, `wge`, `dog`, `auto`).
    pub fn from_name(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Bytes of scratch memory the method needs beyond the input frame.
    pub const fn scratch_bytes(self) -> usize {
        match self {
            Method::Otsu => otsu::SCRATCH_BYTES,
            Method::Adaptive => adaptive::SCRATCH_BYTES,
            Method::Wge => wge::SCRATCH_BYTES,
            Method::Dog => dog::SCRATCH_BYTES,
            Method::Auto => auto::SCRATCH_BYTES,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
