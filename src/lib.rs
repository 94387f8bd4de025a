//! porofrac: fracturing of porous rock on polyhedral grids.
//!
//! This facade re-exports the workspace crates, each usable on its own:
//!
//! * [`grid`]: polyhedral grids (topology, geometry, generators, import/export);
//! * [`law`]: the `CellLaw` trait, Kelvin notation, stiffness tensors, the law test kit;
//! * [`vem`]: the first-order virtual element law;
//! * [`mdem`]: MDEM and central-force DEM laws;
//! * [`flow`]: TPFA single-phase flow;
//! * [`sim`]: assembly, boundary conditions and solvers.
//!
//! The workspace-level validation tests (closed-form solutions, patch tests,
//! convergence) live in `tests/` beside this file.

pub use porofrac_flow as flow;
pub use porofrac_grid as grid;
pub use porofrac_law as law;
pub use porofrac_mdem as mdem;
pub use porofrac_sim as sim;
pub use porofrac_vem as vem;
