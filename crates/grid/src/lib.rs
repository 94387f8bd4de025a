//! Polyhedral grids in 2D and 3D for porofrac: topology, geometry, generators, and
//! Gmsh/VTK import and VTK export.
//!
//! # Data model
//!
//! A [`Grid<D>`] (D = 2 or 3, a const parameter: one code path for both) stores flat
//! arrays with offsets, like reservoir simulators do:
//!
//! ```text
//!   nodes ── coordinates x_n
//!   faces ── face → nodes   (an oriented loop; 2 nodes in 2D, a polygon in 3D)
//!         ── face → cells   [c0, c1]: the normal points from c0 to c1; c1 = none on
//!                           the boundary
//!         ── area A_f, unit normal n_f, centroid c_f
//!   cells ── cell → faces   with a flag "normal points out of this cell"
//!         ── cell → nodes   (counter-clockwise in 2D)
//!         ── volume |K|, centroid x_K
//!   tags  ── named cell sets and face sets; bounding-box sides xmin … zmax
//! ```
//!
//! Non-planar 3D faces are split into triangles about the vertex average `x̄` of the face
//! ([`point::for_each_facet`]); area vectors, volumes, centroids and the nodal boundary
//! normals [`Grid::cell_node_normals`] (the VEM face integrals) all use this one
//! triangulation, so `Σ_f A_f n_f = 0` and the discrete divergence theorem hold exactly.
//!
//! A grid is validated when it is built ([`Grid::from_cell_faces`]): a bad grid is an
//! error naming the cell, face or node, never a panic.

pub mod builder;
pub mod error;
pub mod field;
pub mod generate;
pub mod grid;
/// Mesh files: Gmsh `.msh` import, VTK `.vtu` import/export, `.pvd` time series.
pub mod io;
pub mod point;

pub use builder::CellFaceLoops;
pub use error::{GridError, Result};
pub use field::ScalarField;
pub use grid::{Grid, NO_CELL, SIDE_NAMES};
pub use point::Point;
