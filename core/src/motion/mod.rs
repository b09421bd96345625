//! Time: values keyed at frames and read back at any time ([`keys`]), and the transforms of
//! keyed objects built from them ([`transform`]). Everything here is f64 and a pure function
//! of its arguments, so a frame's values never depend on which frames were computed before.

pub mod bounds;
pub mod keys;
pub mod transform;

pub use transform::Placement;
