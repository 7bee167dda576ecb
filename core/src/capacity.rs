//! The frame capacity of the detectors, in the type: the heapless habit.
//!
//! Every buffer a detector keeps (a mask row, column sums, the 4×4 cell planes of
//! `dog` and `auto`, the mask-to-box runs, ...) is sized by the largest frame it must
//! hold, fixed at compile time. That size is a type parameter `C: FrameCapacity`; the
//! marker [`Capacity<W, H>`] names it, and [`Reference`] (= [`Cap328x248`], the
//! Hayabusa2 TIR's 328×248) is the default everywhere, so `OtsuScratch`, the registry's
//! `Detectors` and `Method::scratch_bytes` mean what they meant before.
//!
//! Stable Rust cannot write `[T; W.div_ceil(4) * H.div_ceil(4)]` with `W` and `H`
//! generic (that needs `generic_const_exprs`), so the capacity is not a pair of const
//! parameters on every struct. Instead [`FrameCapacity`] names one array type per
//! buffer shape (generic over the element: `Row<T>` is `[T; W]`, `Cells<T>` is
//! `[T; ⌈W/4⌉·⌈H/4⌉]`, ...), and the private `capacity!` macro implements it for each
//! supported `Capacity<W, H>` where the lengths are concrete constants. Each array
//! type is [`ConstInit`] (so every `Scratch` is still built by a `const fn` and can be
//! a `static`) and derefs to a slice through `AsRef`/`AsMut`.
//!
//! The trait is sealed: its lengths are what the detectors' bounds arguments rely
//! on, so only the capacities below exist. Each must satisfy the bounds stated where
//! they are used (and checked at compile time below): sides at most 1024 pixels
//! (`auto` stores inclusive cell coordinates in `u8`, 256 cells of 4 pixels), pixel
//! count small enough for `otsu`'s packed 32-bit sums (< 2^32 / 511).
//!
//! | capacity | alias | use |
//! |---|---|---|
//! | 160×120 | [`Cap160x120`] | small uncooled microbolometers (Lepton-class) |
//! | 320×256 | [`Cap320x256`] | QVGA-class TIR cameras |
//! | 328×248 | [`Cap328x248`] = [`Reference`] | Hayabusa2 TIR (the paper's reference; flight) |
//! | 640×480 | [`Cap640x480`] | VGA microbolometers |
//! | 640×512 | [`Cap640x512`] | 640×512 TIR cores |
//! | 1024×768 | [`Cap1024x768`] | Hera TIRI-class arrays |

use core::fmt::Debug;

/// A value every buffer of a fresh scratch starts from, usable in `const` contexts.
pub trait ConstInit: Sized {
    /// The initial value (zero, `false`, or a type's own "empty").
    const INIT: Self;
}

macro_rules! zero_init {
    ($($t:ty = $v:expr),+ $(,)?) => {
        $(impl ConstInit for $t {
            const INIT: Self = $v;
        })+
    };
}
zero_init!(
    u8 = 0,
    u16 = 0,
    u32 = 0,
    u64 = 0,
    i16 = 0,
    i32 = 0,
    f32 = 0.0,
    bool = false
);

impl<T: ConstInit + Copy, const N: usize> ConstInit for [T; N] {
    const INIT: Self = [T::INIT; N];
}

impl<A: ConstInit, B: ConstInit> ConstInit for (A, B) {
    const INIT: Self = (A::INIT, B::INIT);
}

/// A fixed-size buffer of `T` (an array whose length the capacity fixes).
pub trait Buffer<T>: ConstInit + AsRef<[T]> + AsMut<[T]> + Clone + Copy + Debug {}

impl<T: ConstInit + Copy + Debug, const N: usize> Buffer<T> for [T; N] {}

/// The element types the capacity's buffers hold.
pub trait Element: ConstInit + Copy + Debug {}

impl<T: ConstInit + Copy + Debug> Element for T {}

/// Counters of `otsu`'s full-resolution refinement histogram (two lanes of half the
/// pixels each): `u16` while half a frame fits (≤ 131 070 pixels, so 328×248's 40 672
/// per lane), `u32` above.
pub trait Counter: Element {
    /// Adds one.
    fn increment(&mut self);
    /// The count.
    fn get(self) -> u32;
}

impl Counter for u16 {
    #[inline(always)]
    fn increment(&mut self) {
        *self += 1;
    }
    #[inline(always)]
    fn get(self) -> u32 {
        u32::from(self)
    }
}

impl Counter for u32 {
    #[inline(always)]
    fn increment(&mut self) {
        *self += 1;
    }
    #[inline(always)]
    fn get(self) -> u32 {
        self
    }
}

mod sealed {
    pub trait Sealed {}
}

/// The marker of a capacity of `W × H` pixels (see [`FrameCapacity`] for the
/// supported ones).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Capacity<const W: usize, const H: usize>;

/// A detector capacity: the largest frame a scratch holds, and its buffers' types.
///
/// Implemented for the supported [`Capacity`] markers only (sealed). Lengths with
/// `PW = ⌈W/4⌉`, `PH = ⌈H/4⌉` (the 4×4 cell planes of `dog` and `auto`).
pub trait FrameCapacity: sealed::Sealed + Copy + Debug + 'static {
    /// Largest frame width, pixels.
    const WIDTH: usize;
    /// Largest frame height, pixels.
    const HEIGHT: usize;
    /// `[T; W]`: a pixel row.
    type Row<T: Element>: Buffer<T>;
    /// `[T; W + 1]`: a row of prefix sums.
    type RowPlus1<T: Element>: Buffer<T>;
    /// `[T; H]`: a pixel column.
    type Column<T: Element>: Buffer<T>;
    /// `[T; ⌈W/2⌉]`: the runs of one row of pixels (foreground, gap, ...).
    type Runs<T: Element>: Buffer<T>;
    /// `[T; 2·⌈W/2⌉]`: components open at once in the mask-to-box labelling.
    type OpenComponents<T: Element>: Buffer<T>;
    /// `[T; PW·PH]`: a plane of 4×4 cells.
    type Cells<T: Element>: Buffer<T>;
    /// `[T; PW]`: a row of cells.
    type CellRow<T: Element>: Buffer<T>;
    /// `[T; PW/2 + 1]`: the runs of one row of cells.
    type CellRuns<T: Element>: Buffer<T>;
    /// `[T; ⌈PW/2⌉·⌈PH/2⌉]`: `dog`'s half plane.
    type HalfCells<T: Element>: Buffer<T>;
    /// `[T; max(PW, PH) + 136]`: `dog`'s padded row (a row or column of cells plus the
    /// widest kernel's padding).
    type PaddedCellRow<T: Element>: Buffer<T>;
    /// `otsu`'s refinement counter ([`Counter`]).
    type FineCount: Counter;
}

/// Implements [`FrameCapacity`] for `Capacity<W, H>` and names it.
macro_rules! capacity {
    ($($(#[$meta:meta])* $alias:ident = $w:literal x $h:literal, $count:ty;)+) => {
        $(
            $(#[$meta])*
            pub type $alias = Capacity<$w, $h>;

            impl sealed::Sealed for Capacity<$w, $h> {}

            impl FrameCapacity for Capacity<$w, $h> {
                const WIDTH: usize = $w;
                const HEIGHT: usize = $h;
                type Row<T: Element> = [T; $w];
                type RowPlus1<T: Element> = [T; $w + 1];
                type Column<T: Element> = [T; $h];
                type Runs<T: Element> = [T; runs($w)];
                type OpenComponents<T: Element> = [T; 2 * runs($w)];
                type Cells<T: Element> = [T; cells($w) * cells($h)];
                type CellRow<T: Element> = [T; cells($w)];
                type CellRuns<T: Element> = [T; cells($w) / 2 + 1];
                type HalfCells<T: Element> = [T; cells($w).div_ceil(2) * cells($h).div_ceil(2)];
                type PaddedCellRow<T: Element> = [T; padded_cells($w, $h)];
                type FineCount = $count;
            }

            const _: () = check_bounds($w, $h, core::mem::size_of::<$count>());
        )+
    };
}

/// Cells of 4 pixels along a side of `px` pixels.
const fn cells(px: usize) -> usize {
    px.div_ceil(crate::roi::plane::BLOCK)
}

/// Runs a row of `px` pixels can hold.
const fn runs(px: usize) -> usize {
    px.div_ceil(2)
}

/// `dog`'s padded row: the longer side in cells plus the widest kernel.
const fn padded_cells(w: usize, h: usize) -> usize {
    let (pw, ph) = (cells(w), cells(h));
    (if pw > ph { pw } else { ph }) + crate::roi::dog::KERNEL_CAPACITY
}

/// The bounds every capacity must meet (see the module documentation).
const fn check_bounds(w: usize, h: usize, count_bytes: usize) {
    assert!(w >= 1 && h >= 1);
    // `auto`: inclusive cell coordinates in `u8`.
    assert!(cells(w) <= 256 && cells(h) <= 256);
    // (u64: `usize` is 32 bits on the flight targets.)
    let px = w as u64 * h as u64;
    // `otsu`: packed sums of `v − bin start` (< 2^9) over the frame in 32 bits.
    assert!(511 * px < 1 << 32);
    // `otsu`: refinement counters hold half the frame.
    assert!(px.div_ceil(2) < 1u64 << (8 * count_bytes));
    // The mask-to-box labelling: `u16` run ends, labels and row stamps.
    assert!(w < u16::MAX as usize && h < u16::MAX as usize);
}

capacity! {
    /// 160×120 pixels.
    Cap160x120 = 160 x 120, u16;
    /// 320×256 pixels.
    Cap320x256 = 320 x 256, u16;
    /// 328×248 pixels: the Hayabusa2 TIR, the reference ([`Reference`]).
    Cap328x248 = 328 x 248, u16;
    /// 640×480 pixels.
    Cap640x480 = 640 x 480, u32;
    /// 640×512 pixels.
    Cap640x512 = 640 x 512, u32;
    /// 1024×768 pixels (Hera TIRI-class).
    Cap1024x768 = 1024 x 768, u32;
}

/// The reference capacity, 328×248 (Hayabusa2 TIR): the default of every scratch.
pub type Reference = Cap328x248;

/// Width and height of every supported capacity, smallest area first.
pub const SUPPORTED: [(usize, usize); 6] = [
    (160, 120),
    (328, 248),
    (320, 256),
    (640, 480),
    (640, 512),
    (1024, 768),
];
