//! Grid generators.
//!
//! * [`cartesian`]: squares (2D) or cubes (3D).
//! * [`simplices`]: each square split into 2 triangles by the diagonal (i, j)–(i+1, j+1),
//!   each cube into 6 tetrahedra sharing the diagonal (i, j, k)–(i+1, j+1, k+1) (the Kuhn
//!   or Freudenthal split). Both are the same construction: one simplex per permutation of
//!   the axes, walking from the cube's lowest to its highest corner.

mod structured;

pub use structured::{cartesian, simplices};
