//! Time: values keyed at frames and read back at any time ([`keys`]), and the transforms of
//! keyed objects built from them ([`transform`]). Everything here is f64 and a pure function
//! of its arguments, so a frame's values never depend on which frames were computed before.
//!
//! Motion blur traces what moves at each ray's own time: keyed objects and instances through
//! their tracks (boxes over the shutter from [`bounds`]), the camera when its tracks change in
//! the shutter, and time-sampled data (`series:`) blended linearly between the data frames the
//! shutter spans ([`crate::geometry::sweep`], one BVH per stretch between two data frames).

pub mod bounds;
pub mod keys;
pub mod transform;

pub use transform::Placement;
