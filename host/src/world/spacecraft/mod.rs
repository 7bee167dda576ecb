//! Target spacecraft: triangle meshes with per-part materials (cube + cylinder of
//! Section 4.1, Tango of Section 5, a winged small satellite) and their lumped-parameter
//! thermal network.

pub mod mesh;
pub mod models;
pub mod thermal;

pub use mesh::{Material, Mesh, Part};
pub use models::{MaterialCase, cube_cylinder, tango, winged_sat};
pub use thermal::{
    ThermalEnvironment, ThermalError, ThermalNetwork, ThermalSolution, solve_steady_state,
};
