//! `prototypes:` and `instances:`: named groups of objects and their copies, each placed by a
//! `world_from_object` transform. One file's are checked at their positions (`Checker::prototype`,
//! `Checker::instance`); once every file is merged, `resolve_instances` checks what they name
//! (prototypes, materials) and that instance names are not taken.

use crate::desc::*;
use crate::error::{shown, unknown_name, SceneError};
use crate::raw;
use crate::spans::Node;
use crate::validate::Checker;

type Result<T> = std::result::Result<T, SceneError>;

impl Checker<'_> {
    /// The prototype at `node` (its name at `key`): its objects, which take no clip group and
    /// no name.
    pub(crate) fn prototype(
        &self,
        p: raw::Prototype,
        key: &Node,
        node: &Node,
    ) -> Result<Spanned<PrototypeDesc>> {
        let list = node.field("objects").unwrap_or(node);
        let mut objects = Vec::with_capacity(p.objects.len());
        for (i, o) in p.objects.into_iter().enumerate() {
            let at = list.item(i).unwrap_or(list);
            if o.clip.is_some() {
                return Err(self.error(
                    at.field("clip").unwrap_or(at),
                    "objects of a prototype cannot use clip groups (clip planes are in world \
                     space, the prototype's objects in its own); expected no `clip` here",
                ));
            }
            if o.name.is_some() {
                return Err(self.error(
                    at.field("name").unwrap_or(at),
                    "objects of a prototype cannot be named (the animation moves whole \
                     instances); expected no `name` here, and a `name` on the instance",
                ));
            }
            objects.push(self.object(o, at)?);
        }
        let list = node.field("meshes").unwrap_or(node);
        let mut mesh_files = Vec::with_capacity(p.meshes.len());
        for (i, m) in p.meshes.into_iter().enumerate() {
            mesh_files.push(self.mesh(m, list.item(i).unwrap_or(list))?);
        }
        let p = PrototypeDesc {
            objects,
            inline: Vec::new(),
            mesh_files,
        };
        Ok(self.spanned(p, key))
    }

    /// The instance at `node`.
    pub(crate) fn instance(&self, i: raw::Instance, node: &Node) -> Result<Spanned<InstanceDesc>> {
        let field = |name: &str| node.field(name).unwrap_or(node);
        let world_from_object = match i.world_from_object {
            Some(t) => {
                let at = field("world_from_object");
                self.spanned(self.transform(t, at)?, at)
            }
            None => self.spanned(TransformDesc::IDENTITY, node),
        };
        Ok(self.spanned(
            InstanceDesc {
                prototype: self.spanned(i.prototype, field("prototype")),
                name: i.name.map(|n| self.spanned(n, field("name"))),
                world_from_object,
                material: i.material.map(|m| self.spanned(m, field("material"))),
            },
            node,
        ))
    }

    /// A transform: `translate`/`rotate`/`scale` or `matrix`, invertible.
    pub(crate) fn transform(&self, t: raw::Transform, node: &Node) -> Result<TransformDesc> {
        let field = |name: &str| node.field(name).unwrap_or(node);
        if let Some(m) = t.matrix {
            if t.translate.is_some() || t.rotate.is_some() || t.scale.is_some() {
                return Err(self.error(
                    field("matrix"),
                    "give either `matrix` or `translate`/`rotate`/`scale`, not both",
                ));
            }
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            if det == 0.0 || !det.is_finite() {
                return Err(self.error(
                    field("matrix"),
                    format!(
                        "the `matrix` is singular (its 3x3 part has determinant {det}); \
                         expected an invertible transform"
                    ),
                ));
            }
            return Ok(TransformDesc::Matrix(m));
        }
        let scale = t.scale.unwrap_or([1.0; 3]);
        if let Some(k) = scale.iter().position(|&s| s == 0.0) {
            let at = field("scale");
            return Err(self.error(
                at.item(k).unwrap_or(at),
                "`scale` has a zero component; expected non-zero scales (an object scaled to \
                 nothing cannot be turned back)",
            ));
        }
        let rotate = match t.rotate {
            Some(r) => {
                let n =
                    (r.axis[0] * r.axis[0] + r.axis[1] * r.axis[1] + r.axis[2] * r.axis[2]).sqrt();
                if n == 0.0 {
                    let at = field("rotate");
                    return Err(self.error(
                        at.field("axis").unwrap_or(at),
                        "the rotation's `axis` has zero length; expected a non-zero vector",
                    ));
                }
                // An axis of length 1 to rounding stays as written, so that an axis written
                // out after normalising (by `luxon convert`) reads back to the same bits.
                let unit = (n - 1.0).abs() <= 4.0 * f64::EPSILON;
                Some(RotationDesc {
                    axis: if unit { r.axis } else { r.axis.map(|c| c / n) },
                    degrees: r.degrees,
                })
            }
            None => None,
        };
        Ok(TransformDesc::Trs {
            translate: t.translate.unwrap_or([0.0; 3]),
            rotate,
            scale,
        })
    }
}

/// After merging: every instance names a prototype that exists and holds objects, and
/// materials that exist; an instance's name is used once among instances and objects
/// (`objects`: the objects' names).
pub(crate) fn resolve_instances(
    scene: &SceneDesc,
    objects: &[(usize, Spanned<String>)],
    instances: &[(usize, Spanned<String>)],
) -> Result<()> {
    let materials: Vec<&str> = scene.materials.iter().map(|(n, _)| n.as_str()).collect();
    let material = |m: &Option<Spanned<String>>| match m {
        Some(m) if !materials.contains(&m.value.as_str()) => {
            let message = unknown_name("material", &m.value, "", materials.iter().copied());
            Err(SceneError::at(m.at.clone(), message))
        }
        _ => Ok(()),
    };
    for (_, p) in &scene.prototypes {
        for o in &p.value.objects {
            material(&o.value.material)?;
        }
        for m in &p.value.mesh_files {
            material(&m.material)?;
        }
    }
    let names: Vec<&str> = scene.prototypes.iter().map(|(n, _)| n.as_str()).collect();
    for instance in &scene.instances {
        let i = &instance.value;
        let wanted = &i.prototype;
        let Some((_, p)) = scene.prototypes.iter().find(|(n, _)| *n == wanted.value) else {
            let message = unknown_name("prototype", &wanted.value, "", names.iter().copied());
            return Err(SceneError::at(wanted.at.clone(), message));
        };
        if p.value.objects.is_empty() && p.value.mesh_files.is_empty() {
            return Err(SceneError::at(
                wanted.at.clone(),
                format!(
                    "prototype `{}` (at {}) has no objects, so this instance would place \
                     nothing; expected objects in the prototype, or no instance of it",
                    shown(&wanted.value),
                    p.at
                ),
            ));
        }
        material(&i.material)?;
    }
    for (k, (_, name)) in instances.iter().enumerate() {
        let before = instances[..k].iter().chain(objects);
        if let Some((_, first)) = before.into_iter().find(|(_, n)| n.value == name.value) {
            return Err(SceneError::at(
                name.at.clone(),
                format!(
                    "the instance name `{}` is already used at {}; expected each instance \
                     (and object) name once",
                    shown(&name.value),
                    first.at
                ),
            ));
        }
    }
    Ok(())
}
