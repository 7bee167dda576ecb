//! Stage 2, imaging: from a world to digital-number (DN) frames.
//!
//! - [`render`]: the physical renderer (target and Earth radiance → DN, noise);
//! - [`fits`]: reading FITS images (BSCALE/BZERO applied, size checked first);
//! - [`fixture`]: procedural test frames with known boxes (no physics);
//! - [`signature`]: the real camera's own signature (fit on a real frame, realisations);
//! - [`image_io`]: reading and writing 8/16-bit PNG/TIFF frames;
//! - [`psf`]: the optics' point-spread function (Airy at the aperture × pixel footprint);
//! - [`overlay`]: frames drawn with boxes on them (previews, demo and paper figures).
//!
//! Imports the [`world`](crate::world) stage, never a later one.

pub mod fits;
pub mod fixture;
pub mod image_io;
pub mod overlay;
pub mod psf;
pub mod render;
pub mod signature;
