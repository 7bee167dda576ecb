//! The Earth seen from orbit: TOA longwave flux grids (built-in and CERES SYN1deg),
//! Eq. 10 temperatures, mesh refinement and eclipse scaling (paper Section 3.2).
