//! What every model of a scene shares: the loaded scene and its errors ([`loaded`]), the
//! sections every model reads ([`sections`]), the [`model::Model`] trait and the loop that
//! drives it ([`driver`]), the outputs ([`output`], [`sample`], [`plots`]), the bounds
//! on what a scene may ask for ([`limits`], [`bounds`]), the heap policy of a process
//! that runs scenes ([`heap`]), expressions ([`expr`]) and cell laws
//! ([`laws`]); and what two models genuinely share: the particle packing and particle
//! outputs of `nscd` and `lsm` ([`particles`], [`particle_output`],
//! [`particle_plots`]), the lattice of `lbm` and of `lsm`'s fluid ([`lattice`]), the grid
//! builder of `continuum` and `cosserat` ([`grid`]) and the Cosserat keys of the shared
//! sections ([`rotation_keys`]); with the `mpi` feature, what every distributed run
//! shares (`distributed`).
//!
//! Nothing here imports a model folder.

pub mod bounds;
pub mod checkpoint;
#[cfg(feature = "mpi")]
pub mod distributed;
pub mod driver;
pub mod expr;
pub mod grid;
pub mod heap;
pub mod keys;
pub mod lattice;
pub mod laws;
pub mod limits;
pub mod loaded;
pub mod model;
pub mod output;
pub mod overrides;
pub mod particle_output;
pub mod particle_plots;
pub mod particle_velocity;
pub mod particles;
pub mod plan;
pub mod plots;
pub mod rotation_keys;
pub mod sample;
pub mod scene_errors;
pub mod sections;
pub mod snapshot;
pub mod trig;
