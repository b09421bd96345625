//! Checks that serde cannot express, each reported at the value: `Checker` (one file's
//! positions and errors; finite numbers, ranges, colours, plugin names; the conversion modules
//! add their parts to it) and `references` (names used but never defined, after merging).

use crate::desc::{
    parse_memory_size, MemorySize, Origin, SceneDesc, Spanned, MEMORY_SIZE_EXAMPLES,
};
use crate::error::{shown, unknown_name, SceneError};
use crate::spans::{Node, SourceMap};

/// Reads positions and builds errors for one file.
pub(crate) struct Checker<'a> {
    pub src: &'a SourceMap,
}

impl Checker<'_> {
    pub fn origin(&self, node: &Node) -> Origin {
        self.src.origin(node.start)
    }

    pub fn error(&self, node: &Node, message: impl Into<String>) -> SceneError {
        SceneError::at(self.origin(node), message)
    }

    /// A value as written in the file (not as parsed: `18446744073709551615` stays that, not
    /// `18446744073709552000`), safe to echo (see `shown`).
    pub fn literal(&self, node: &Node) -> String {
        shown(self.src.slice(node).trim()).into_owned()
    }

    pub fn spanned<T>(&self, value: T, node: &Node) -> Spanned<T> {
        Spanned {
            value,
            at: self.origin(node),
        }
    }

    /// NaN and infinities anywhere, `params` included: nothing downstream wants them.
    pub fn finite_numbers(&self, root: &Node) -> Result<(), SceneError> {
        root.each_number(&mut |node| {
            let text = self.src.slice(node);
            if literal_is_finite(text) {
                Ok(())
            } else if text.contains("inf") || text.contains("NaN") {
                Err(self.error(
                    node,
                    format!("{text} is not allowed here; expected a finite number"),
                ))
            } else {
                Err(self.error(
                    node,
                    format!(
                        "{text} is too large (it overflows to infinity); expected a finite number"
                    ),
                ))
            }
        })
    }

    /// `value` in `[min, max]`, named `name` in the message.
    pub fn range(
        &self,
        node: &Node,
        name: &str,
        value: f64,
        min: f64,
        max: f64,
    ) -> Result<f64, SceneError> {
        if (min..=max).contains(&value) {
            return Ok(value);
        }
        let expected = if max == f64::INFINITY {
            format!("expected {min} or more")
        } else {
            format!("expected a value from {min} to {max}")
        };
        let written = self.literal(node);
        Err(self.error(node, format!("`{name}` is {written}; {expected}")))
    }

    /// `value > 0`.
    pub fn positive(&self, node: &Node, name: &str, value: f64) -> Result<f64, SceneError> {
        if value > 0.0 {
            Ok(value)
        } else {
            let written = self.literal(node);
            Err(self.error(
                node,
                format!("`{name}` is {written}; expected a number greater than 0"),
            ))
        }
    }

    /// A memory size written as a string (`"6 GiB"`, `"50%"`; see `parse_memory_size`).
    pub fn memory_size(
        &self,
        node: &Node,
        name: &str,
        text: &str,
    ) -> Result<MemorySize, SceneError> {
        parse_memory_size(text).map_err(|why| {
            self.error(
                node,
                format!(
                    "`{name}` is {}: {why}; expected {MEMORY_SIZE_EXAMPLES}",
                    self.literal(node)
                ),
            )
        })
    }

    /// A whole number in `[min, max]`.
    pub fn whole(
        &self,
        node: &Node,
        name: &str,
        value: f64,
        min: u32,
        max: u32,
    ) -> Result<u32, SceneError> {
        if value.fract() == 0.0 && value >= f64::from(min) && value <= f64::from(max) {
            return Ok(value as u32);
        }
        let written = self.literal(node);
        Err(self.error(
            node,
            format!("`{name}` is {written}; expected a whole number from {min} to {max}"),
        ))
    }

    /// Every component of a colour `>= 0`, reported at the component.
    pub fn colour(&self, node: &Node, name: &str, rgb: [f64; 3]) -> Result<[f64; 3], SceneError> {
        for (i, &c) in rgb.iter().enumerate() {
            if c < 0.0 {
                let at = node.item(i).unwrap_or(node);
                let written = self.literal(at);
                return Err(self.error(
                    at,
                    format!(
                        "`{name}` has a negative component {written}; expected components of 0 \
                         or more"
                    ),
                ));
            }
        }
        Ok(rgb)
    }

    /// A plugin name string: not empty.
    pub fn plugin_name(
        &self,
        node: &Node,
        name: String,
        example: &str,
    ) -> Result<Spanned<String>, SceneError> {
        if name.trim().is_empty() {
            return Err(self.error(
                node,
                format!("the plugin name is empty; expected a plugin name such as \"{example}\""),
            ));
        }
        Ok(self.spanned(name, node))
    }
}

/// Whether a RON number literal denotes a finite value (integers always do).
fn literal_is_finite(text: &str) -> bool {
    let digits = text.trim_start_matches(['+', '-']);
    if ["0x", "0X", "0b", "0B", "0o", "0O"]
        .iter()
        .any(|p| digits.starts_with(p))
    {
        return true;
    }
    let text: String = text.chars().filter(|&c| c != '_').collect();
    let text = text
        .strip_suffix("f32")
        .or_else(|| text.strip_suffix("f64"))
        .unwrap_or(&text);
    // Integer suffixes (`5u8`) and other forms ron accepted: integers, so finite.
    text.parse::<f64>().map_or(true, f64::is_finite)
}

/// Names used before they are known (material textures, object materials) and volume names
/// given twice, after merging.
pub(crate) fn references(scene: &SceneDesc) -> Result<(), SceneError> {
    let textures: Vec<&str> = scene.textures.iter().map(|(n, _)| n.as_str()).collect();
    for (_, material) in &scene.materials {
        let m = &material.value;
        for texture in [&m.texture, &m.reflect_texture, &m.transmit_texture]
            .into_iter()
            .flatten()
        {
            if !textures.contains(&texture.value.as_str()) {
                let message = unknown_name("texture", &texture.value, "", textures.iter().copied());
                return Err(SceneError::at(texture.at.clone(), message));
            }
        }
    }
    let materials: Vec<&str> = scene.materials.iter().map(|(n, _)| n.as_str()).collect();
    for object in &scene.objects {
        if let Some(material) = &object.value.material {
            if !materials.contains(&material.value.as_str()) {
                let message =
                    unknown_name("material", &material.value, "", materials.iter().copied());
                return Err(SceneError::at(material.at.clone(), message));
            }
        }
    }
    let groups: Vec<&str> = scene.clip_groups.iter().map(|(n, _)| n.as_str()).collect();
    for object in &scene.objects {
        if let Some(clip) = &object.value.clip {
            if !groups.contains(&clip.value.as_str()) {
                let message = unknown_name("clip group", &clip.value, "", groups.iter().copied());
                return Err(SceneError::at(clip.at.clone(), message));
            }
        }
    }
    for volume in &scene.volumes {
        let clip = volume
            .value
            .render
            .as_ref()
            .and_then(|r| r.value.clip.as_ref());
        if let Some(clip) = clip {
            if !groups.contains(&clip.value.as_str()) {
                let message = unknown_name("clip group", &clip.value, "", groups.iter().copied());
                return Err(SceneError::at(clip.at.clone(), message));
            }
        }
    }
    let names: Vec<&Spanned<String>> = scene
        .volumes
        .iter()
        .filter_map(|v| v.value.name.as_ref())
        .collect();
    for (i, name) in names.iter().enumerate() {
        if let Some(first) = names[..i].iter().find(|n| n.value == name.value) {
            return Err(SceneError::at(
                name.at.clone(),
                format!(
                    "the volume name `{}` is already used at {}; expected each volume name once",
                    name.value, first.at
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::literal_is_finite;

    #[test]
    fn finite_literals() {
        for ok in ["1", "-2.5", "1e-3", "0xFF", "1_000.5", "3f32", "7u8", ".5"] {
            assert!(literal_is_finite(ok), "{ok}");
        }
        for bad in ["NaN", "-inf", "+inf", "inff64", "1e999", "-1e400"] {
            assert!(!literal_is_finite(bad), "{bad}");
        }
    }
}
