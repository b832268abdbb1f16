//! Reading Mitsuba 3 XML into [`Plugin`] trees: `$param` substitution, property tags and
//! transforms. Interpretation of the plugins happens in [`super::description`].

use super::properties::{LocatedProperty, Plugin, Property};
use super::spectrum::{SampledSpectrum, Spectrum};
use crate::error::InputError;
use glam::{DMat4, DVec3};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// Tags that introduce a nested plugin.
const PLUGIN_TAGS: &[&str] = &[
    "shape",
    "bsdf",
    "emitter",
    "sensor",
    "film",
    "sampler",
    "texture",
    "integrator",
    "rfilter",
];

/// Tags of Mitsuba that this reader refuses with a clear error rather than ignore.
const UNSUPPORTED_TAGS: &[&str] = &["medium", "phase", "volume", "alias"];

/// How deeply files may include one another (deeper is taken for a cycle).
const DEEPEST_INCLUDE: usize = 16;

/// The deepest nesting of plugins a scene may use (Mitsuba's scenes nest a handful).
pub const DEEPEST_NESTING: usize = 64;

/// The children of the root `<scene>`, after substitution.
pub struct ParsedScene {
    /// Top-level plugins, in file order.
    pub plugins: Vec<Plugin>,
    /// Non-fatal problems, each naming the file and line.
    pub warnings: Vec<String>,
    /// The values of `<path>` elements, in file order.
    pub paths: Vec<String>,
}

struct Reader<'a> {
    file: &'a Path,
    /// The scene file the reading started from (an included file's names may be relative to
    /// its folder, as Mitsuba's file resolver makes them).
    top: &'a Path,
    text: &'a str,
    parameters: HashMap<String, String>,
    /// The parameters a `$name` has used.
    used: std::cell::RefCell<std::collections::HashSet<String>>,
    warnings: Vec<String>,
}

/// The attributes each kind of element may carry.
fn known_attributes(tag: &str) -> &'static [&'static str] {
    match tag {
        "float" | "integer" | "boolean" | "string" | "rgb" => &["name", "value"],
        "spectrum" => &["name", "value", "filename"],
        "path" => &["value"],
        "include" => &["filename"],
        "point" | "vector" => &["name", "value", "x", "y", "z"],
        "transform" => &["name"],
        "ref" => &["id", "name"],
        _ if PLUGIN_TAGS.contains(&tag) => &["type", "id", "name"],
        _ => &[],
    }
}

/// Parses the Mitsuba XML in `text` (read from `file`). `overrides` set `$param` values and
/// take precedence over `<default>` elements.
pub fn parse(
    file: &Path,
    text: &str,
    overrides: &[(String, String)],
) -> Result<ParsedScene, InputError> {
    let parameters = overrides.iter().cloned().collect();
    let used = Default::default();
    let mut reader = Reader {
        file,
        top: file,
        text,
        parameters,
        used,
        warnings: Vec::new(),
    };
    let mut scene = ParsedScene {
        plugins: Vec::new(),
        warnings: Vec::new(),
        paths: Vec::new(),
    };
    reader.read_scene(overrides, &mut scene, 0)?;
    reader.warn_unused_overrides(overrides);
    scene.warnings = reader.warnings;
    check_unique_ids(file, &scene.plugins)?;
    Ok(scene)
}

/// The XML document in `text`, read from `file`.
fn document<'t>(file: &Path, text: &'t str) -> Result<roxmltree::Document<'t>, InputError> {
    roxmltree::Document::parse(text).map_err(|e| {
        let position = e.pos();
        let hint = match e {
            roxmltree::Error::UnexpectedEndOfStream => {
                " (the file ends before its elements are closed: is it truncated?)"
            }
            _ => "",
        };
        InputError::at(file, position.row, format!("malformed XML: {e}{hint}"))
    })
}

/// Sets every line of `plugin` (its own, its properties', its references', its children's)
/// to `line`.
fn relocate(plugin: &mut Plugin, line: u32) {
    plugin.line = line;
    plugin.properties.values_mut().for_each(|p| p.line = line);
    plugin.references.iter_mut().for_each(|r| r.2 = line);
    plugin.children.iter_mut().for_each(|c| relocate(c, line));
}

/// Refuses two plugins with the same id: a reference to it would be ambiguous.
fn check_unique_ids(file: &Path, plugins: &[Plugin]) -> Result<(), InputError> {
    fn visit<'p>(
        plugin: &'p Plugin,
        seen: &mut HashMap<&'p str, u32>,
        file: &Path,
    ) -> Result<(), InputError> {
        if let Some(id) = plugin.id.as_deref() {
            if let Some(first) = seen.insert(id, plugin.line) {
                return Err(InputError::at(
                    file,
                    plugin.line,
                    format!("id \"{id}\" is already used on line {first}"),
                ));
            }
        }
        plugin
            .children
            .iter()
            .try_for_each(|child| visit(child, seen, file))
    }
    let mut seen = HashMap::new();
    plugins
        .iter()
        .try_for_each(|plugin| visit(plugin, &mut seen, file))
}

impl<'a> Reader<'a> {
    /// Reads this reader's file (included `depth` files deep) into `scene`: its defaults,
    /// `<path>`s, plugins and the files it includes.
    fn read_scene(
        &mut self,
        overrides: &[(String, String)],
        scene: &mut ParsedScene,
        depth: usize,
    ) -> Result<(), InputError> {
        let text = self.text;
        let document = document(self.file, text)?;
        let root = document.root_element();
        if root.tag_name().name() != "scene" {
            return Err(self.error(
                root,
                format!(
                    "the root element must be <scene>, found <{}>",
                    root.tag_name().name()
                ),
            ));
        }
        self.read_defaults(root, overrides)?;
        for child in root.children().filter(|n| n.is_element()) {
            match child.tag_name().name() {
                "default" => {}
                "path" => {
                    self.warn_unknown_attributes(child);
                    scene.paths.push(self.path_value(child, depth)?);
                }
                "include" => self.include(child, overrides, scene, depth)?,
                "ref" => return Err(self.error(child, "a <ref> at scene level refers to nothing")),
                tag if PLUGIN_TAGS.contains(&tag) => scene.plugins.push(self.plugin(child, 1)?),
                _ => return Err(self.unexpected(child, "<scene>")),
            }
        }
        Ok(())
    }

    /// A `<path>`'s folder: as written in the scene file, or made absolute against the
    /// folder of an included file.
    fn path_value(&self, node: roxmltree::Node, depth: usize) -> Result<String, InputError> {
        let value = self.attribute(node, "value")?;
        if depth == 0 || Path::new(&value).is_absolute() {
            return Ok(value);
        }
        let folder = self.file.parent().unwrap_or(Path::new("."));
        Ok(folder.join(value).to_string_lossy().into_owned())
    }

    /// Reads the scene file an `<include>` names (beside this file, else beside the scene
    /// file the reading started from) into
    /// `scene`. Its elements count as written at the `<include>`: later messages about them
    /// name this file and the `<include>`'s line; problems in the included file's own XML
    /// name that file and line.
    fn include(
        &mut self,
        node: roxmltree::Node,
        overrides: &[(String, String)],
        scene: &mut ParsedScene,
        depth: usize,
    ) -> Result<(), InputError> {
        self.warn_unknown_attributes(node);
        if depth + 1 > DEEPEST_INCLUDE {
            return Err(self.error(
                node,
                format!("files include one another more than {DEEPEST_INCLUDE} deep: a cycle?"),
            ));
        }
        let path = self.included_path(node)?;
        let text = std::fs::read_to_string(&path).map_err(|e| {
            self.error(
                node,
                format!("cannot read included {}: {e}", path.display()),
            )
        })?;
        let mut included = Reader {
            file: &path,
            top: self.top,
            text: &text,
            parameters: self.parameters.clone(),
            used: Default::default(),
            warnings: Vec::new(),
        };
        let mut inner = ParsedScene {
            plugins: Vec::new(),
            warnings: Vec::new(),
            paths: Vec::new(),
        };
        included.read_scene(overrides, &mut inner, depth + 1)?;
        // Its defaults hold for the rest of the including file too.
        for (name, value) in std::mem::take(&mut included.parameters) {
            self.parameters.entry(name).or_insert(value);
        }
        self.used.borrow_mut().extend(included.used.take());
        self.warnings.append(&mut included.warnings);
        let line = self.line(node);
        for mut plugin in inner.plugins {
            relocate(&mut plugin, line);
            scene.plugins.push(plugin);
        }
        scene.paths.extend(inner.paths);
        Ok(())
    }

    /// The file an `<include>` names: beside this file, else beside the scene file the
    /// reading started from; an error if neither exists or it cannot be read as input.
    fn included_path(&self, node: roxmltree::Node) -> Result<PathBuf, InputError> {
        let name = self.attribute(node, "filename")?;
        let folder = |file: &Path| file.parent().unwrap_or(Path::new(".")).to_path_buf();
        let beside = folder(self.file).join(&name);
        let path = if beside.exists() {
            beside
        } else {
            folder(self.top).join(&name)
        };
        if !path.exists() {
            return Err(self.error(
                node,
                format!("the included file {} does not exist", path.display()),
            ));
        }
        crate::error::check_input_file(&path, "included scene file")?;
        Ok(path)
    }

    /// Reads the `<default>`s, wherever they are, so that they apply to the whole file;
    /// command-line overrides and an including file's parameters win, and a second default
    /// of one name warns.
    fn read_defaults(
        &mut self,
        root: roxmltree::Node,
        overrides: &[(String, String)],
    ) -> Result<(), InputError> {
        let mut defaulted = std::collections::HashSet::new();
        for child in root.children().filter(|n| n.is_element()) {
            if child.tag_name().name() != "default" {
                continue;
            }
            let name = self.raw_attribute(child, "name")?;
            let value = self.raw_attribute(child, "value")?;
            if !defaulted.insert(name.to_string()) {
                let line = self.line(child);
                self.warnings.push(format!(
                    "{}:{line}: a second <default> of \"{name}\" is ignored",
                    self.file.display()
                ));
                continue;
            }
            // Command-line values, and the including file's, come first (as in Mitsuba).
            if !overrides.iter().any(|(n, _)| n == name) {
                self.parameters
                    .entry(name.to_string())
                    .or_insert_with(|| value.to_string());
            }
        }
        Ok(())
    }

    /// Warns of command-line overrides that no `$name` used.
    fn warn_unused_overrides(&mut self, overrides: &[(String, String)]) {
        let used = self.used.borrow();
        for (name, value) in overrides {
            if !used.contains(name) {
                self.warnings.push(format!(
                    "{}: -D {name}={value} is not used: the scene has no ${name}",
                    self.file.display()
                ));
            }
        }
    }

    /// Warns of attributes `node` does not read.
    fn warn_unknown_attributes(&mut self, node: roxmltree::Node) {
        let known = known_attributes(node.tag_name().name());
        for attribute in node.attributes() {
            if !known.contains(&attribute.name()) {
                let line = self.line(node);
                self.warnings.push(format!(
                    "{}:{line}: attribute \"{}\" of <{}> is ignored",
                    self.file.display(),
                    attribute.name(),
                    node.tag_name().name()
                ));
            }
        }
    }

    fn line(&self, node: roxmltree::Node) -> u32 {
        self.text[..node.range().start].matches('\n').count() as u32 + 1
    }

    fn error(&self, node: roxmltree::Node, message: impl Into<String>) -> InputError {
        InputError::at(self.file, self.line(node), message)
    }

    fn unexpected(&self, node: roxmltree::Node, parent: &str) -> InputError {
        let tag = node.tag_name().name();
        if UNSUPPORTED_TAGS.contains(&tag) {
            self.error(node, format!("<{tag}> is not supported by ais"))
        } else {
            self.error(node, format!("unexpected element <{tag}> in {parent}"))
        }
    }

    fn raw_attribute<'n>(
        &self,
        node: roxmltree::Node<'n, 'n>,
        name: &str,
    ) -> Result<&'n str, InputError> {
        node.attribute(name).ok_or_else(|| {
            self.error(
                node,
                format!("<{}> needs a \"{name}\" attribute", node.tag_name().name()),
            )
        })
    }

    /// An attribute with `$param` references substituted.
    fn attribute(&self, node: roxmltree::Node, name: &str) -> Result<String, InputError> {
        let raw = self.raw_attribute(node, name)?;
        self.substitute(node, raw)
    }

    fn optional_attribute(
        &self,
        node: roxmltree::Node,
        name: &str,
    ) -> Result<Option<String>, InputError> {
        node.attribute(name)
            .map(|raw| self.substitute(node, raw))
            .transpose()
    }

    fn substitute(&self, node: roxmltree::Node, raw: &str) -> Result<String, InputError> {
        let mut out = String::with_capacity(raw.len());
        let mut rest = raw;
        while let Some(start) = rest.find('$') {
            out.push_str(&rest[..start]);
            let after = &rest[start + 1..];
            let end = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..end];
            if name.is_empty() {
                return Err(self.error(node, format!("a lone '$' in \"{raw}\"")));
            }
            self.used.borrow_mut().insert(name.to_string());
            let value = self.parameters.get(name).ok_or_else(|| {
                self.error(
                    node,
                    format!(
                        "parameter ${name} has no <default> and was not given on the command line"
                    ),
                )
            })?;
            out.push_str(value);
            rest = &after[end..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// The plugin element `node`, nested `depth` plugins deep (at most [`DEEPEST_NESTING`]).
    fn plugin(&mut self, node: roxmltree::Node, depth: usize) -> Result<Plugin, InputError> {
        if depth > DEEPEST_NESTING {
            return Err(self.error(
                node,
                format!("plugins are nested more than {DEEPEST_NESTING} deep"),
            ));
        }
        self.warn_unknown_attributes(node);
        let tag = node.tag_name().name().to_string();
        let kind = self.attribute(node, "type")?;
        let mut plugin = Plugin {
            tag: tag.clone(),
            kind,
            id: self.optional_attribute(node, "id")?,
            name: self.optional_attribute(node, "name")?,
            properties: BTreeMap::new(),
            children: Vec::new(),
            references: Vec::new(),
            line: self.line(node),
        };
        for child in node.children().filter(|n| n.is_element()) {
            let child_tag = child.tag_name().name();
            if PLUGIN_TAGS.contains(&child_tag) {
                plugin.children.push(self.plugin(child, depth + 1)?);
            } else if child_tag == "ref" {
                let id = self.attribute(child, "id")?;
                let name = self.optional_attribute(child, "name")?;
                plugin.references.push((name, id, self.line(child)));
            } else if child_tag == "default" {
                return Err(self.error(child, "<default> must be a direct child of <scene>"));
            } else if child_tag == "include" {
                return Err(self.error(child, "<include> is only supported at scene level"));
            } else {
                self.warn_unknown_attributes(child);
                let name = self.attribute(child, "name")?;
                let value = self.property(child)?;
                let line = self.line(child);
                if plugin.properties.contains_key(&name) {
                    self.warnings.push(format!(
                        "{}:{line}: property \"{name}\" given twice; the last one wins",
                        self.file.display()
                    ));
                }
                plugin
                    .properties
                    .insert(name, LocatedProperty { value, line });
            }
        }
        Ok(plugin)
    }

    /// A `<spectrum>`: one value (uniform), wavelength:value pairs, or a `.spd` file (found
    /// next to the scene file that names it). Its colour is worked out by the plugin that
    /// reads it, since that depends on what it describes ([`crate::scene::ColourRole`]).
    fn spectrum(&self, node: roxmltree::Node) -> Result<Property, InputError> {
        if let Some(name) = self.optional_attribute(node, "filename")? {
            let path = self.file.parent().unwrap_or(Path::new(".")).join(name);
            // A device or a folder would be read until memory runs out.
            if path.exists() {
                crate::error::check_input_file(&path, "spectrum file")?;
            }
            let sampled =
                SampledSpectrum::read_file(&path).map_err(|message| self.error(node, message))?;
            return Ok(Property::Spectrum(Spectrum::Sampled(sampled)));
        }
        let text = self.attribute(node, "value")?;
        if text.contains(':') {
            let sampled =
                SampledSpectrum::parse_pairs(&text).map_err(|message| self.error(node, message))?;
            return Ok(Property::Spectrum(Spectrum::Sampled(sampled)));
        }
        match self.numbers(node, &text)?.as_slice() {
            [v] => Ok(Property::Spectrum(Spectrum::Uniform(*v))),
            _ => Err(self.error(
                node,
                format!("<spectrum> needs one value or wavelength:value pairs, got \"{text}\""),
            )),
        }
    }

    fn numbers(&self, node: roxmltree::Node, text: &str) -> Result<Vec<f64>, InputError> {
        text.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<f64>()
                    .map_err(|_| self.error(node, format!("\"{s}\" is not a number")))
            })
            .collect()
    }

    fn number(&self, node: roxmltree::Node, text: &str) -> Result<f64, InputError> {
        match self.numbers(node, text)?.as_slice() {
            [v] => Ok(*v),
            _ => Err(self.error(node, format!("expected one number, got \"{text}\""))),
        }
    }

    /// A 3-vector from `x`, `y`, `z` attributes (missing ones default to `fill`) or `value`.
    fn vector3(
        &self,
        node: roxmltree::Node,
        attribute: &str,
        fill: f64,
    ) -> Result<DVec3, InputError> {
        if let Some(text) = self.optional_attribute(node, attribute)? {
            return match self.numbers(node, &text)?.as_slice() {
                [v] => Ok(DVec3::splat(*v)),
                [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
                _ => Err(self.error(
                    node,
                    format!("\"{attribute}\" needs 1 or 3 numbers, got \"{text}\""),
                )),
            };
        }
        let mut v = [fill; 3];
        let mut any = false;
        for (slot, axis) in v.iter_mut().zip(["x", "y", "z"]) {
            if let Some(text) = self.optional_attribute(node, axis)? {
                *slot = self.number(node, &text)?;
                any = true;
            }
        }
        if !any {
            return Err(self.error(
                node,
                format!("<{}> needs x, y, z or {attribute}", node.tag_name().name()),
            ));
        }
        Ok(DVec3::from_array(v))
    }

    fn property(&self, node: roxmltree::Node) -> Result<Property, InputError> {
        let tag = node.tag_name().name();
        let value = || self.attribute(node, "value");
        Ok(match tag {
            "float" => Property::Float(self.number(node, &value()?)?),
            "integer" => {
                let text = value()?;
                Property::Integer(
                    text.trim()
                        .parse()
                        .map_err(|_| self.error(node, format!("\"{text}\" is not an integer")))?,
                )
            }
            "boolean" => match value()?.trim() {
                "true" => Property::Boolean(true),
                "false" => Property::Boolean(false),
                other => return Err(self.error(node, format!("\"{other}\" is not true or false"))),
            },
            "string" => Property::String(value()?),
            "rgb" => {
                let text = value()?;
                match self.numbers(node, &text)?.as_slice() {
                    [v] => Property::Rgb([*v; 3]),
                    [r, g, b] => Property::Rgb([*r, *g, *b]),
                    _ => {
                        return Err(
                            self.error(node, format!("<rgb> needs 1 or 3 numbers, got \"{text}\""))
                        )
                    }
                }
            }
            "spectrum" => self.spectrum(node)?,
            "point" => Property::Point(self.vector3(node, "value", 0.0)?),
            "vector" => Property::Vector(self.vector3(node, "value", 0.0)?),
            "transform" => Property::Transform(self.transform(node)?),
            _ => return Err(self.unexpected(node, "a plugin")),
        })
    }

    /// Composes the operations of a `<transform>`: each later one is applied after the earlier.
    fn transform(&self, node: roxmltree::Node) -> Result<DMat4, InputError> {
        let mut matrix = DMat4::IDENTITY;
        for op in node.children().filter(|n| n.is_element()) {
            let step = match op.tag_name().name() {
                "translate" => DMat4::from_translation(self.vector3(op, "value", 0.0)?),
                "scale" => DMat4::from_scale(self.vector3(op, "value", 1.0)?),
                "rotate" => {
                    let axis = self.vector3(op, "value", 0.0)?;
                    let angle = self.number(op, &self.attribute(op, "angle")?)?;
                    if axis.length_squared() == 0.0 {
                        return Err(self.error(op, "<rotate> needs a non-zero axis"));
                    }
                    DMat4::from_axis_angle(axis.normalize(), angle.to_radians())
                }
                "matrix" => {
                    let text = self.attribute(op, "value")?;
                    let v = self.numbers(op, &text)?;
                    match v.len() {
                        16 => DMat4::from_cols_array(&[
                            v[0], v[4], v[8], v[12], v[1], v[5], v[9], v[13], v[2], v[6], v[10],
                            v[14], v[3], v[7], v[11], v[15],
                        ]),
                        9 => DMat4::from_cols_array(&[
                            v[0], v[3], v[6], 0.0, v[1], v[4], v[7], 0.0, v[2], v[5], v[8], 0.0,
                            0.0, 0.0, 0.0, 1.0,
                        ]),
                        n => {
                            return Err(
                                self.error(op, format!("<matrix> needs 9 or 16 numbers, got {n}"))
                            )
                        }
                    }
                }
                "lookat" => {
                    let origin = self.vector3(op, "origin", 0.0)?;
                    let target = self.vector3(op, "target", 0.0)?;
                    let up = match op.attribute("up") {
                        Some(_) => self.vector3(op, "up", 0.0)?,
                        None => DVec3::Y,
                    };
                    look_at(origin, target, up).ok_or_else(|| {
                        self.error(
                            op,
                            "<lookat> has target = origin or up parallel to the view direction",
                        )
                    })?
                }
                _ => return Err(self.unexpected(op, "<transform>")),
            };
            matrix = step * matrix;
        }
        if !matrix.is_finite() || matrix.determinant().abs() < 1e-300 {
            return Err(self.error(node, "the transform is singular or not finite"));
        }
        Ok(matrix)
    }
}

/// Mitsuba's look-at: camera +z toward the target, +y up, +x to the left.
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let direction = (target - origin).try_normalize()?;
    let left = up.cross(direction).try_normalize()?;
    let new_up = direction.cross(left);
    Some(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        direction.extend(0.0),
        origin.extend(1.0),
    ))
}
