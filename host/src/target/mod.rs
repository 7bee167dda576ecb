//! Target spacecraft: triangle meshes with per-part materials (cube + cylinder of
//! Section 4.1, Tango of Section 5) and their lumped-parameter thermal network.

pub mod mesh;
pub mod models;

pub use mesh::{Material, Mesh, Part};
pub use models::{MaterialCase, cube_cylinder, tango};
