//! Mitsuba's `shapegroup` and `instance`: the shapes of a group are read once, where the
//! group is declared (it renders nothing itself), and each `instance` adds them to the scene
//! under its own `to_world`, composed with theirs.
//!
//! The instances are copies: each one's shapes enter the BVH (and their mesh files are read)
//! again, so memory and build time grow with the number of instances. A two-level BVH that
//! shares a group's geometry is not built yet; the scene warns once.

use super::description::{read_shape, SceneDescription, ShapeDescription};
use super::{FileResolver, Plugin};
use std::path::Path;

/// A `shapegroup`: its id and shapes.
#[derive(Clone, Debug)]
pub struct ShapeGroup {
    /// The id instances reference.
    pub id: String,
    /// Its shapes, in the group's frame.
    pub shapes: Vec<ShapeDescription>,
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

/// The shapes an `instance` adds: those of the group it references, under its `to_world`.
pub(super) fn instance_shapes(
    path: &Path,
    instance: &Plugin,
    scene: &mut SceneDescription,
) -> Result<Vec<ShapeDescription>, (u32, String)> {
    let [(_, id, line)] = instance.references.as_slice() else {
        return Err((
            instance.line,
            "an instance references exactly one shapegroup".into(),
        ));
    };
    let group = (scene.shape_groups.iter()).find(|g| &g.id == id).ok_or((
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
    let shapes = (group.shapes.iter())
        .map(|shape| ShapeDescription {
            to_world: to_world * shape.to_world,
            ..shape.clone()
        })
        .collect();
    if !scene
        .warnings
        .iter()
        .any(|w| w.contains("instances are copied"))
    {
        scene.warnings.push(format!(
            "{}:{}: instances are copied into the scene (ais has no two-level BVH yet): memory \
             and build time grow with their number",
            path.display(),
            instance.line
        ));
    }
    super::description::warn_unknown(path, instance, &["to_world"], &mut scene.warnings);
    Ok(shapes)
}
