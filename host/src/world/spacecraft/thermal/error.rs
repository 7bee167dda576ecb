//! [`ThermalError`]: why the thermal network could not be built or solved.

use std::fmt;

/// Why the thermal network could not be built or solved.
#[derive(Debug, Clone, PartialEq)]
pub enum ThermalError {
    /// The mesh has no facets.
    EmptyMesh,
    /// Facet `facet` names a vertex or part that does not exist, or `part_of` and
    /// `triangles` differ in length (`facet` = the shorter length).
    BadIndex {
        /// The facet.
        facet: usize,
    },
    /// A vertex coordinate is not finite.
    BadVertex {
        /// The vertex.
        vertex: usize,
    },
    /// Facet `facet` has zero (or non-finite) area.
    DegenerateFacet {
        /// The facet.
        facet: usize,
        /// Its area, m².
        area_m2: f64,
    },
    /// A part's material or dissipation is out of bounds.
    BadMaterial {
        /// The part's name.
        part: &'static str,
        /// What is wrong.
        reason: &'static str,
    },
    /// An environment field is out of bounds.
    BadEnvironment {
        /// What is wrong.
        reason: &'static str,
    },
    /// A conductively connected group of enclosed facets (no radiating facet) carries
    /// dissipation: it has no steady state.
    NoSteadyState {
        /// One facet of the group.
        facet: usize,
    },
    /// A transient input (heat capacities, step, orbit, start temperatures) is out of
    /// bounds.
    BadTransient {
        /// What is wrong.
        reason: String,
    },
    /// The orbit integration did not become periodic within the orbit limit.
    NotPeriodic {
        /// Orbits integrated.
        orbits: usize,
        /// Largest |T(t + P) − T(t)| over the facets after the last orbit, K.
        change_k: f64,
    },
    /// Newton's method did not reach the tolerance.
    NoConvergence {
        /// Newton steps taken.
        iterations: usize,
        /// Largest nodal residual reached, W.
        residual_w: f64,
        /// The residual asked for, W.
        tolerance_w: f64,
    },
}

impl fmt::Display for ThermalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ThermalError::EmptyMesh => write!(f, "thermal network: the mesh has no facets"),
            ThermalError::BadIndex { facet } => write!(
                f,
                "thermal network: facet {facet} refers to a missing vertex or part (or part_of is shorter than triangles)"
            ),
            ThermalError::BadVertex { vertex } => {
                write!(f, "thermal network: vertex {vertex} is not finite")
            }
            ThermalError::DegenerateFacet { facet, area_m2 } => write!(
                f,
                "thermal network: facet {facet} is degenerate (area {area_m2:e} m²)"
            ),
            ThermalError::BadMaterial { part, reason } => {
                write!(f, "thermal network: part {part:?}: {reason}")
            }
            ThermalError::BadEnvironment { reason } => {
                write!(f, "thermal environment: {reason}")
            }
            ThermalError::NoSteadyState { facet } => write!(
                f,
                "thermal network: facet {facet} belongs to an enclosed group with dissipation and no radiating surface: no steady state"
            ),
            ThermalError::BadTransient { reason } => {
                write!(f, "transient thermal: {reason}")
            }
            ThermalError::NotPeriodic { orbits, change_k } => write!(
                f,
                "transient thermal: not periodic after {orbits} orbits (largest change over the last orbit {change_k:.3} K)"
            ),
            ThermalError::NoConvergence {
                iterations,
                residual_w,
                tolerance_w,
            } => write!(
                f,
                "thermal network: no convergence after {iterations} Newton steps (max residual {residual_w:e} W, asked {tolerance_w:e} W)"
            ),
        }
    }
}

impl std::error::Error for ThermalError {}
