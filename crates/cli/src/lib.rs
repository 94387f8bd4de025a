//! The library behind the `porofrac` command: scene files (parsing and checks),
//! expressions, running a scene and writing its outputs.
//!
//! The scene-file keys and the outputs are the contract of `SCENE.md`; see the README.

pub mod check;
pub mod expr;
pub mod flowsetup;
pub mod output;
pub mod plots;
pub mod run;
pub mod sample;
pub mod scene;
