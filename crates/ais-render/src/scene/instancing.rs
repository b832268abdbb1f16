//! Mitsuba's `shapegroup` and `instance`: the shapes of a group are read once, where the
//! group is declared (it renders nothing itself), and each `instance` places the group in
//! the scene under its own `to_world`, composed after theirs. The group's geometry is built
//! once and shared by its instances (see the geometry's instancing).

use super::description::{read_shape, SceneDescription, ShapeDescription};
use super::{FileResolver, Plugin};
use glam::DMat4;
use std::path::Path;

/// A `shapegroup`: its id and shapes.
#[derive(Clone, Debug)]
pub struct ShapeGroup {
    /// The id instances reference.
    pub id: String,
    /// Its shapes, in the group's frame.
    pub shapes: Vec<ShapeDescription>,
}

/// An `instance`: a shape group placed in the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct InstanceDescription {
    /// The group (its index in [`SceneDescription::shape_groups`]).
    pub group: usize,
    /// Group frame → world.
    pub to_world: DMat4,
    /// Line of the `<shape type="instance">` element.
    pub line: u32,
}

/// Reads a `shapegroup` (its nested shapes; emitters are refused, as instanced emitters are
/// in Mitsuba) into `scene.shape_groups`.
pub(super) fn read_shape_group(
    path: &Path,
    files: &FileResolver,
    group: &Plugin,
    scene: &mut SceneDescription,
) -> Result<(), (u32, String)> {
    let id = group
        .id
        .clone()
        .ok_or((group.line, "a shapegroup needs an id".to_string()))?;
    let mut shapes = Vec::new();
    for child in &group.children {
        if child.tag != "shape" || matches!(child.kind.as_str(), "shapegroup" | "instance") {
            let message = format!(
                "a shapegroup holds shapes only, not <{} type=\"{}\">",
                child.tag, child.kind
            );
            return Err((child.line, message));
        }
        let shape = read_shape(path, files, child, scene)?;
        if shape.emitter.is_some() {
            return Err((
                child.line,
                "a shape in a shapegroup cannot emit (Mitsuba does not instance emitters)".into(),
            ));
        }
        shapes.push(shape);
    }
    if !group.references.is_empty() || !group.properties.is_empty() {
        let message = "a shapegroup takes only nested shapes (no properties or references)";
        return Err((group.line, message.into()));
    }
    scene.shape_groups.push(ShapeGroup { id, shapes });
    Ok(())
}

/// An `instance`: the group it references (declared before it) and its `to_world`.
pub(super) fn read_instance(
    path: &Path,
    instance: &Plugin,
    scene: &mut SceneDescription,
) -> Result<InstanceDescription, (u32, String)> {
    let [(_, id, line)] = instance.references.as_slice() else {
        return Err((
            instance.line,
            "an instance references exactly one shapegroup".into(),
        ));
    };
    let group = (scene.shape_groups.iter())
        .position(|g| &g.id == id)
        .ok_or((
            *line,
            format!("no shapegroup with id \"{id}\" (declare it before its instances)"),
        ))?;
    if let Some(child) = instance.children.first() {
        return Err((
            child.line,
            format!("<{}> is not allowed in an instance", child.tag),
        ));
    }
    let to_world = instance.transform("to_world")?;
    super::description::warn_unknown(path, instance, &["to_world"], &mut scene.warnings);
    Ok(InstanceDescription {
        group,
        to_world,
        line: instance.line,
    })
}
