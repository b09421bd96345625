//! Parameter helpers every primitive family uses.

use luxon_plugin::{finite, invalid_at, Error};
use serde::Deserialize;

/// Lets an optional parameter be written as a plain value (`radius: 1`): without RON's
/// `implicit_some` extension an `Option` field would demand `Some(1)`.
pub(crate) fn plain_some<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(d).map(Some)
}

/// `x` if it is a number > 0; else an error reported at parameter `name` in the scene.
pub(crate) fn positive(name: &str, x: f64) -> Result<f64, Error> {
    let [x] = finite(name, [x])?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(invalid_at(
            name,
            format!("expected a number > 0, found {x}"),
        ))
    }
}
