//! Grid generators.
//!
//! * [`cartesian`]: squares (2D) or cubes (3D).
//! * [`simplices`]: each square split into 2 triangles by the diagonal (i, j)–(i+1, j+1),
//!   each cube into 6 tetrahedra sharing the diagonal (i, j, k)–(i+1, j+1, k+1) (the Kuhn
//!   or Freudenthal split). Both are the same construction: one simplex per permutation of
//!   the axes, walking from the cube's lowest to its highest corner.
//! * [`perturb`]: seeded random jitter of the interior nodes of any grid (2D or 3D).
//! * [`voronoi`]: a 2D Voronoi (PEBI) grid of `n` cells clipped to a box, with Lloyd
//!   iterations.
//! * [`composite`]: a 2D Cartesian far field with a refined triangle zone around a point,
//!   joined by hanging nodes, with `refined` and well cell tags.
//! * [`round_well`]: a 2D Cartesian far field with a zone of graded triangles (constrained
//!   Delaunay with refinement) around a circular well, joined by hanging nodes.
//! * [`tetrahedralize`]: some cells of any 3D grid replaced by tetrahedra (refined by
//!   edge splits) that conform with the cells around them: an MDEM zone in a VEM far
//!   field, e.g. around a well in a corner-point grid.

mod composite;
mod extrude;
mod perturb;
mod round_well;
mod structured;
mod tetrahedralize;
mod voronoi;

pub use composite::{CompositeSpec, Diagonals, REFINED_TAG, composite};
pub use extrude::extrude;
pub use perturb::{MAX_PERTURB, perturb};
pub use round_well::{MIN_ANGLE_DEG, MIN_WELL_NODES, RoundWellSpec, ZoneCells, round_well};
pub use structured::{cartesian, simplices};
pub use tetrahedralize::{Tetrahedralized, tetrahedralize};
pub use voronoi::{DEFAULT_LLOYD, voronoi};
