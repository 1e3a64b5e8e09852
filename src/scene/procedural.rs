//! Procedural objects for the paper's experiments, held as themselves (`geometry::Implicit`) so
//! that lattices of millions of primitives never pass through the scene file object by object.

pub use crate::geometry::{BarArray, Lattice};
