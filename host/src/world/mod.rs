//! Stage 1, the world: what is out there before any camera looks at it.
//!
//! - [`constants`]: the Earth's radius and the reference orbit, in metres;
//! - [`geom`]: vectors and rotations;
//! - [`scene`]: scene and dataset descriptions (TOML files and the built-in presets);
//! - [`earth`]: the Earth's outgoing long-wave radiation (OLR) and its temperature map;
//! - [`moon`]: the Moon as a background disc (size, distance, surface temperature);
//! - [`spacecraft`]: target meshes (the cube-cylinder, Tango) and their thermal solution.
//!
//! Imports only `tirroi_core` and the crate's foundation modules, never a later stage.

pub mod constants;
pub mod earth;
pub mod geom;
pub mod moon;
pub mod scene;
pub mod spacecraft;
