//! porofrac: fracturing of porous rock on polyhedral grids, and the particle, lattice and
//! Cosserat models beside it.
//!
//! This facade re-exports every crate of the workspace under a short name, for a program
//! that wants all of porofrac behind one dependency. Each crate is also usable on its own
//! (a user who wants the VEM law or the TPFA solver depends on that crate alone):
//!
//! * [`grid`]: polyhedral grids (topology, geometry, generators, Gmsh/VTK/GRDECL input);
//! * [`vtk`]: VTK XML writers and atomic file writes;
//! * [`law`]: the `CellLaw` trait, Kelvin notation, stiffness tensors, the law test kit;
//! * [`vem`]: the first-order virtual element law;
//! * [`mdem`]: MDEM and central-force DEM laws;
//! * [`sparse`]: sparse direct solvers (Cholesky, LDLᵀ, low-rank updates, orderings);
//! * [`amg`]: smoothed-aggregation multigrid and conjugate gradients;
//! * [`dist`]: the partitioner and, with MPI (its `mpi` feature), the distributed matrix,
//!   multigrid and conjugate gradients;
//! * [`flow`]: TPFA single-phase flow;
//! * [`frac`]: failure criteria, failure state, stress recovery;
//! * [`sim`]: the continuum model: assembly, solvers, Biot coupling, fracturing;
//! * [`cosserat`]: the variational DEM for Cosserat media;
//! * [`particles`]: disk particles, packings, neighbour search;
//! * [`nscd`]: non-smooth contact dynamics of rigid disks;
//! * [`lsm`]: the lattice solid model of bonded disks;
//! * [`lbm`]: the lattice Boltzmann fluid with heat;
//! * [`particle_fluid`]: particles carried by the lattice Boltzmann fluid;
//! * [`scene`]: scene files → runs and outputs (what the `porofrac` command uses).
//!
//! The workspace-level validation tests (closed-form solutions, patch tests,
//! convergence) live in `tests/` beside this file.

pub use porofrac_amg as amg;
pub use porofrac_cosserat as cosserat;
pub use porofrac_dist as dist;
pub use porofrac_flow as flow;
pub use porofrac_frac as frac;
pub use porofrac_grid as grid;
pub use porofrac_law as law;
pub use porofrac_lbm as lbm;
pub use porofrac_lsm as lsm;
pub use porofrac_mdem as mdem;
pub use porofrac_nscd as nscd;
pub use porofrac_particle_fluid as particle_fluid;
pub use porofrac_particles as particles;
pub use porofrac_scene as scene;
pub use porofrac_sim as sim;
pub use porofrac_sparse as sparse;
pub use porofrac_vem as vem;
pub use porofrac_vtk as vtk;
