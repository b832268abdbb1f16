//! Named per-vertex and per-face attributes of a mesh (Mitsuba's `vertex_*` and `face_*`),
//! which the `mesh_attribute` texture reads.
//!
//! A PLY file's properties beyond positions, normals, texture coordinates and indices become
//! attributes as Mitsuba groups them: consecutive properties `{prefix}_{x|y|z|w}`,
//! `{prefix}_{r|g|b|a}`, `{prefix}_{0|1|2|3}` or `{prefix}_{1|2|3|4}` form one attribute
//! `{vertex|face}_{prefix}`; `r g b [a]` and `red green blue [alpha]` form
//! `{vertex|face}_color`; any other property is an attribute of its own name.

use glam::{Vec2, Vec3};

/// One attribute: `dimension` values per vertex or per face.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttribute {
    /// Its name, with its `vertex_` or `face_` prefix.
    pub name: String,
    /// Values per element (1 to 4).
    pub dimension: usize,
    /// The values, element after element.
    pub values: Vec<f32>,
}

impl MeshAttribute {
    /// Whether it has a value per face (else per vertex).
    pub fn per_face(&self) -> bool {
        self.name.starts_with("face_")
    }

    /// The value of element `index`, its first three components (a single one replicated).
    fn element(&self, index: usize) -> Vec3 {
        let start = index * self.dimension;
        let values = &self.values[start..start + self.dimension];
        match values {
            [single] => Vec3::splat(*single),
            [x, y] => Vec3::new(*x, *y, 0.0),
            [x, y, z, ..] => Vec3::new(*x, *y, *z),
            [] => Vec3::ZERO,
        }
    }
}

/// Where on a mesh an attribute is looked up.
#[derive(Clone, Copy, Debug)]
pub struct AttributeSite<'a> {
    /// The mesh's attributes.
    pub attributes: &'a [MeshAttribute],
    /// The triangle's index in its mesh.
    pub triangle: usize,
    /// Its vertices.
    pub vertices: [u32; 3],
    /// The point's barycentric coordinates (of the second and third vertex).
    pub barycentrics: Vec2,
}

impl AttributeSite<'_> {
    /// The attribute `name` here: a face's value, or the vertices' values interpolated.
    pub fn value(&self, name: &str) -> Option<(Vec3, usize)> {
        let attribute = self.attributes.iter().find(|a| a.name == name)?;
        let value = if attribute.per_face() {
            attribute.element(self.triangle)
        } else {
            let [a, b, c] = self.vertices.map(|v| attribute.element(v as usize));
            let (u, v) = (self.barycentrics.x, self.barycentrics.y);
            a * (1.0 - u - v) + b * u + c * v
        };
        Some((value, attribute.dimension))
    }
}

/// The suffix groups that join consecutive properties into one attribute.
const GROUPS: [[&str; 4]; 4] = [
    ["x", "y", "z", "w"],
    ["r", "g", "b", "a"],
    ["0", "1", "2", "3"],
    ["1", "2", "3", "4"],
];

/// Groups the property names `names` (in the file's order) into attributes named with
/// `prefix` (`vertex_` or `face_`): each group's name and the indices of its properties.
pub fn group_properties(prefix: &str, names: &[String]) -> Vec<(String, Vec<usize>)> {
    let mut groups = Vec::new();
    let mut i = 0;
    while i < names.len() {
        let (name, length) = grouped_at(names, i);
        groups.push((format!("{prefix}{name}"), (i..i + length).collect()));
        i += length;
    }
    groups
}

/// The attribute name of the properties starting at `start`, and how many it takes.
fn grouped_at(names: &[String], start: usize) -> (String, usize) {
    for colour in [
        ["r", "g", "b", "a"].as_slice(),
        ["red", "green", "blue", "alpha"].as_slice(),
    ] {
        let length = run_length(names, start, |k, name| name == colour[k]);
        if length >= 3 {
            return ("color".into(), length);
        }
    }
    if let Some((prefix, _)) = names[start].rsplit_once('_') {
        for suffixes in GROUPS {
            let length = run_length(names, start, |k, name| {
                name.rsplit_once('_') == Some((prefix, suffixes[k]))
            });
            if length >= 1 && names[start].ends_with(&format!("_{}", suffixes[0])) {
                return (prefix.to_string(), length);
            }
        }
    }
    (names[start].clone(), 1)
}

/// How many of the (at most 4) names from `start` satisfy `matches(k, name)` in a row.
fn run_length(names: &[String], start: usize, matches: impl Fn(usize, &str) -> bool) -> usize {
    (0..4)
        .take_while(|&k| names.get(start + k).is_some_and(|name| matches(k, name)))
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn properties_group_as_mitsuba_groups_them() {
        let groups = group_properties(
            "vertex_",
            &names(&[
                "color_0", "color_1", "color_2", "weight_0", "r", "g", "b", "temp",
            ]),
        );
        let summary: Vec<(&str, usize)> = groups
            .iter()
            .map(|(name, indices)| (name.as_str(), indices.len()))
            .collect();
        assert_eq!(
            summary,
            [
                ("vertex_color", 3),
                ("vertex_weight", 1),
                ("vertex_color", 3),
                ("vertex_temp", 1)
            ]
        );
    }

    #[test]
    fn vertex_attributes_interpolate_and_face_attributes_do_not() {
        let attributes = [
            MeshAttribute {
                name: "vertex_w".into(),
                dimension: 1,
                values: vec![0.0, 1.0, 2.0],
            },
            MeshAttribute {
                name: "face_color".into(),
                dimension: 3,
                values: vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
            },
        ];
        let site = AttributeSite {
            attributes: &attributes,
            triangle: 1,
            vertices: [0, 1, 2],
            barycentrics: Vec2::new(0.25, 0.5),
        };
        let (w, dimension) = site.value("vertex_w").unwrap();
        assert_eq!((w, dimension), (Vec3::splat(1.25), 1));
        assert_eq!(
            site.value("face_color").unwrap().0,
            Vec3::new(0.4, 0.5, 0.6)
        );
        assert!(site.value("vertex_missing").is_none());
    }
}
