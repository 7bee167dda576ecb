//! Target spacecraft: triangle meshes with per-part materials (cube + cylinder of
//! Section 4.1, Tango of Section 5) and their lumped-parameter thermal network.
