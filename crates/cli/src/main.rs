//! The `porofrac` command.
fn main() {}
