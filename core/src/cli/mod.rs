//! The subcommands of `luxon`, one module each.

pub mod check;
pub mod job;
pub mod plugins;
pub mod progress;
pub mod render;
pub mod shading;
pub mod spd;
pub mod sweep;
