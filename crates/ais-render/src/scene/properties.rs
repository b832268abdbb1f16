//! Plugin descriptions as read from Mitsuba XML: a type, an id, named properties and nested
//! plugins, before any interpretation.

use super::spectrum::{ColourRole, Spectrum};
use glam::{DMat4, DVec3, Vec3};
use std::collections::BTreeMap;

/// One property value of a plugin.
#[derive(Clone, Debug, PartialEq)]
pub enum Property {
    /// `<float>`.
    Float(f64),
    /// `<integer>`.
    Integer(i64),
    /// `<boolean>`.
    Boolean(bool),
    /// `<string>`.
    String(String),
    /// `<rgb>` (a single value is replicated).
    Rgb([f64; 3]),
    /// `<spectrum>`: one value, or values at wavelengths.
    Spectrum(Spectrum),
    /// `<point>`.
    Point(DVec3),
    /// `<vector>`.
    Vector(DVec3),
    /// `<transform>`: the composed matrix.
    Transform(DMat4),
}

impl Property {
    /// A short name of the property's kind, for error messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Property::Float(_) => "float",
            Property::Integer(_) => "integer",
            Property::Boolean(_) => "boolean",
            Property::String(_) => "string",
            Property::Rgb(_) => "rgb",
            Property::Spectrum(_) => "spectrum",
            Property::Point(_) => "point",
            Property::Vector(_) => "vector",
            Property::Transform(_) => "transform",
        }
    }
}

/// A property with the line it was written on.
#[derive(Clone, Debug, PartialEq)]
pub struct LocatedProperty {
    /// The value.
    pub value: Property,
    /// 1-based line in the scene file.
    pub line: u32,
}

/// A plugin element (`shape`, `bsdf`, `emitter`, `sensor`, `film`, `sampler`, `texture`,
/// `integrator`, `rfilter`) with its properties and nested plugins.
#[derive(Clone, Debug, PartialEq)]
pub struct Plugin {
    /// The element's tag, e.g. `shape`.
    pub tag: String,
    /// The `type` attribute, e.g. `obj`.
    pub kind: String,
    /// The `id` attribute.
    pub id: Option<String>,
    /// The `name` attribute (for nested plugins that fill a named slot).
    pub name: Option<String>,
    /// Properties by name.
    pub properties: BTreeMap<String, LocatedProperty>,
    /// Nested plugins, in order.
    pub children: Vec<Plugin>,
    /// `<ref id="..."/>` references, with their `name` attribute and line.
    pub references: Vec<(Option<String>, String, u32)>,
    /// 1-based line of the element.
    pub line: u32,
}

impl Plugin {
    /// A float property (integers are accepted too), or `default`.
    pub fn float(&self, name: &str, default: f64) -> Result<f64, (u32, String)> {
        match self.properties.get(name) {
            None => Ok(default),
            Some(LocatedProperty {
                value: Property::Float(v),
                ..
            }) => Ok(*v),
            Some(LocatedProperty {
                value: Property::Integer(v),
                ..
            }) => Ok(*v as f64),
            Some(p) => Err(self.wrong_kind(name, p, "float")),
        }
    }

    /// An integer property, or `default`.
    pub fn integer(&self, name: &str, default: i64) -> Result<i64, (u32, String)> {
        match self.properties.get(name) {
            None => Ok(default),
            Some(LocatedProperty {
                value: Property::Integer(v),
                ..
            }) => Ok(*v),
            Some(p) => Err(self.wrong_kind(name, p, "integer")),
        }
    }

    /// A boolean property, or `default`.
    pub fn boolean(&self, name: &str, default: bool) -> Result<bool, (u32, String)> {
        match self.properties.get(name) {
            None => Ok(default),
            Some(LocatedProperty {
                value: Property::Boolean(v),
                ..
            }) => Ok(*v),
            Some(p) => Err(self.wrong_kind(name, p, "boolean")),
        }
    }

    /// A string property, if present.
    pub fn string(&self, name: &str) -> Result<Option<&str>, (u32, String)> {
        match self.properties.get(name) {
            None => Ok(None),
            Some(LocatedProperty {
                value: Property::String(v),
                ..
            }) => Ok(Some(v)),
            Some(p) => Err(self.wrong_kind(name, p, "string")),
        }
    }

    /// A transform property, or the identity.
    pub fn transform(&self, name: &str) -> Result<DMat4, (u32, String)> {
        match self.properties.get(name) {
            None => Ok(DMat4::IDENTITY),
            Some(LocatedProperty {
                value: Property::Transform(m),
                ..
            }) => Ok(*m),
            Some(p) => Err(self.wrong_kind(name, p, "transform")),
        }
    }

    /// A point property, or `default`.
    pub fn point(&self, name: &str, default: DVec3) -> Result<DVec3, (u32, String)> {
        match self.properties.get(name) {
            None => Ok(default),
            Some(LocatedProperty {
                value: Property::Point(v) | Property::Vector(v),
                ..
            }) => Ok(*v),
            Some(p) => Err(self.wrong_kind(name, p, "point")),
        }
    }

    /// A colour property given as an rgb, a float or a spectrum, as linear sRGB for a
    /// property of `role` (`None` when not given). Spectra become colours as Mitsuba's RGB
    /// variants make them ([`Spectrum::to_rgb`]).
    pub fn colour(&self, name: &str, role: ColourRole) -> Result<Option<Vec3>, (u32, String)> {
        let Some(property) = self.properties.get(name) else {
            return Ok(None);
        };
        let rgb = match &property.value {
            Property::Rgb(c) => *c,
            Property::Float(v) => [*v; 3],
            Property::Spectrum(spectrum) => spectrum.to_rgb(role),
            _ => return Err(self.wrong_kind(name, property, "rgb, float or spectrum")),
        };
        Ok(Some(Vec3::from_array(rgb.map(|c| c as f32))))
    }

    fn wrong_kind(&self, name: &str, property: &LocatedProperty, wanted: &str) -> (u32, String) {
        (
            property.line,
            format!(
                "property \"{name}\" of {} \"{}\" must be a {wanted}, not a {}",
                self.tag,
                self.kind,
                property.value.kind()
            ),
        )
    }

    /// Names of properties not in `known`, with their lines (for warnings).
    pub fn unknown_properties(&self, known: &[&str]) -> Vec<(String, u32)> {
        self.properties
            .iter()
            .filter(|(name, _)| !known.contains(&name.as_str()))
            .map(|(name, p)| (name.clone(), p.line))
            .collect()
    }
}
