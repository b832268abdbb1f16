//! Textures on BSDF parameters: Mitsuba's `checkerboard` and `bitmap`, looked up at a hit's
//! texture coordinates with Mitsuba's conventions.
//!
//! - `checkerboard`: `color0` (default 0.4) where the fractional parts of u and v lie on the
//!   same side of ½, `color1` (default 0.2) elsewhere.
//! - `bitmap`: (0, 0) is the top-left corner of the image and v runs down it; `bilinear`
//!   (default) interpolates between texel centres at ((i + ½) / W, (j + ½) / H), `nearest`
//!   takes the texel under (u W, v H); `wrap_mode` is `repeat` (default), `mirror` or `clamp`.
//!   8-bit and 16-bit images are sRGB-encoded unless `raw` is true, and are converted to
//!   linear once, when read; EXR and HDR images are linear.
//! - Read as one channel (an opacity, a blend weight), a texture gives its colour's
//!   luminance; a checkerboard's colours then swap places, as in Mitsuba 3.
//! - `to_uv` transforms the coordinates first (its 2-D part: scale, rotation about z,
//!   translation).

use crate::error::InputError;
use crate::image_io::{read_image, RgbImage};
use crate::mesh::AttributeSite;
use crate::scene::{ColourRole, FileResolver, Plugin};
use glam::{DMat4, Vec2, Vec3};
use std::path::Path;

/// A texture.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// Two colours in a checkerboard of unit squares in (u, v).
    Checkerboard {
        /// Where the fractional parts of u and v lie on the same side of ½.
        color0: Vec3,
        /// Elsewhere.
        color1: Vec3,
        /// Applied to the coordinates first.
        to_uv: UvTransform,
    },
    /// An image.
    Bitmap(Box<Bitmap>),
    /// Mitsuba's `rawconstant`: one value everywhere, taken as is (no colour conversion).
    Constant(Vec3),
    /// Mitsuba's `mesh_attribute`: a mesh's per-vertex (interpolated) or per-face value,
    /// times `scale`.
    MeshAttribute {
        /// The attribute's name, `vertex_…` or `face_…`.
        name: String,
        /// What the value is multiplied by.
        scale: f32,
    },
}

/// Where a texture is looked up.
#[derive(Clone, Copy, Debug)]
pub struct TextureLookup<'a> {
    /// Texture coordinates.
    pub uv: Vec2,
    /// The mesh attributes there (None off meshes).
    pub attributes: Option<AttributeSite<'a>>,
}

/// An image texture.
#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    /// Linear RGB texels, top row first.
    pub image: RgbImage,
    /// Bilinear (true) or nearest-texel lookup.
    pub bilinear: bool,
    /// What lies beyond [0, 1).
    pub wrap: Wrap,
    /// Applied to the coordinates first.
    pub to_uv: UvTransform,
}

/// Mitsuba's `wrap_mode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane.
    Repeat,
    /// The image tiles the plane, every other copy mirrored.
    Mirror,
    /// The edge texels extend outward.
    Clamp,
}

/// The 2-D affine part of a `to_uv` transform: u' = a u + b v + c, v' = d u + e v + f.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform([f32; 6]);

impl UvTransform {
    /// The identity.
    pub const IDENTITY: UvTransform = UvTransform([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);

    /// The 2-D part of a 4 × 4 transform (its action on points of the z = 0 plane).
    pub fn from_mat4(m: DMat4) -> Self {
        let u = m.transform_point3(glam::DVec3::X) - m.transform_point3(glam::DVec3::ZERO);
        let v = m.transform_point3(glam::DVec3::Y) - m.transform_point3(glam::DVec3::ZERO);
        let origin = m.transform_point3(glam::DVec3::ZERO);
        UvTransform([u.x, v.x, origin.x, u.y, v.y, origin.y].map(|x| x as f32))
    }

    /// Applies the transform.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [a, b, c, d, e, f] = self.0;
        Vec2::new(a * uv.x + b * uv.y + c, d * uv.x + e * uv.y + f)
    }
}

impl Texture {
    /// The texture's value at `at`: [`Texture::eval`], or a mesh attribute's value (zero
    /// where the mesh has no such attribute).
    #[inline]
    pub fn eval_at(&self, at: &TextureLookup) -> Vec3 {
        match self {
            Texture::MeshAttribute { name, scale } => at
                .attributes
                .and_then(|site| site.value(name))
                .map_or(Vec3::ZERO, |(value, _)| value * *scale),
            other => other.eval(at.uv),
        }
    }

    /// [`Texture::eval_scalar`] at `at`; a mesh attribute of one value gives it, of several
    /// their luminance.
    pub fn eval_scalar_at(&self, at: &TextureLookup) -> f32 {
        match self {
            Texture::MeshAttribute { name, scale } => at
                .attributes
                .and_then(|site| site.value(name))
                .map_or(0.0, |(value, dimension)| {
                    *scale
                        * if dimension == 1 {
                            value.x
                        } else {
                            luminance(value)
                        }
                }),
            other => other.eval_scalar(at.uv),
        }
    }

    /// The texture's value at texture coordinates `uv` (a mesh attribute needs
    /// [`Texture::eval_at`]: zero here).
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                let uv = to_uv.apply(uv);
                let upper = |x: f32| x - x.floor() > 0.5;
                if upper(uv.x) == upper(uv.y) {
                    *color0
                } else {
                    *color1
                }
            }
            Texture::Bitmap(bitmap) => bitmap.eval(bitmap.to_uv.apply(uv)),
            Texture::Constant(value) => *value,
            Texture::MeshAttribute { .. } => Vec3::ZERO,
        }
    }

    /// The texture read as one channel (an opacity, a blend weight), as Mitsuba 3 reads it:
    /// the luminance of the colour, except that a checkerboard's one-channel lookup puts
    /// `color0` where its colour lookup puts `color1` (and the reverse).
    pub fn eval_scalar(&self, uv: Vec2) -> f32 {
        let colour = match self {
            Texture::Checkerboard {
                color0,
                color1,
                to_uv,
            } => {
                let swapped = Texture::Checkerboard {
                    color0: *color1,
                    color1: *color0,
                    to_uv: *to_uv,
                };
                return luminance(swapped.eval(uv));
            }
            Texture::Bitmap(bitmap) => bitmap.eval(bitmap.to_uv.apply(uv)),
            Texture::Constant(value) => *value,
            Texture::MeshAttribute { .. } => Vec3::ZERO,
        };
        luminance(colour)
    }

    /// The mean luminance over the unit square of texture coordinates (a light's power): a
    /// bitmap's mean texel, a checkerboard's mean colour; zero for a mesh attribute.
    pub fn mean_luminance(&self) -> f32 {
        match self {
            Texture::Checkerboard { color0, color1, .. } => luminance((*color0 + *color1) * 0.5),
            Texture::Bitmap(bitmap) => {
                let pixels = &bitmap.image.pixels;
                let sum: f64 = (pixels.iter())
                    .map(|p| luminance(Vec3::from(*p)) as f64)
                    .sum();
                (sum / pixels.len().max(1) as f64) as f32
            }
            Texture::Constant(value) => luminance(*value),
            Texture::MeshAttribute { .. } => 0.0,
        }
    }

    /// The gradient of [`Texture::eval_scalar`] over (u, v) ([`Bitmap::scalar_gradient`]);
    /// zero for a checkerboard, which is flat almost everywhere.
    pub fn scalar_gradient(&self, uv: Vec2) -> Vec2 {
        match self {
            Texture::Checkerboard { .. } | Texture::Constant(_) | Texture::MeshAttribute { .. } => {
                Vec2::ZERO
            }
            Texture::Bitmap(bitmap) => bitmap.scalar_gradient(uv),
        }
    }
}

impl Bitmap {
    /// The gradient of the one-channel lookup with respect to (u, v), as Mitsuba's
    /// `eval_1_grad` gives it: zero for nearest filtering; for bilinear, the partials over
    /// pixel coordinates taken through the transpose of `to_uv`'s linear part, then scaled
    /// by the resolution.
    pub fn scalar_gradient(&self, uv: Vec2) -> Vec2 {
        if !self.bilinear {
            return Vec2::ZERO;
        }
        let size = Vec2::new(self.image.width as f32, self.image.height as f32);
        let position = self.to_uv.apply(uv) * size - 0.5;
        if !position.is_finite() {
            return Vec2::ZERO;
        }
        let corner = position.floor();
        let w1 = position - corner;
        let w0 = Vec2::ONE - w1;
        let (x, y) = (corner.x as i64, corner.y as i64);
        let f = |dx: i64, dy: i64| luminance(self.texel(x + dx, y + dy));
        let (f00, f10, f01, f11) = (f(0, 0), f(1, 0), f(0, 1), f(1, 1));
        let dx = w0.y * (f10 - f00) + w1.y * (f11 - f01);
        let dy = w0.x * (f01 - f00) + w1.x * (f11 - f10);
        let [a, b, _, d, e, _] = self.to_uv.0;
        Vec2::new(a * dx + d * dy, b * dx + e * dy) * size
    }
}

/// Rec. 709 luminance of linear RGB (Mitsuba's one-channel reading of a colour).
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::new(0.212_671, 0.715_160, 0.072_169))
}

impl Bitmap {
    /// The texel in column `x`, row `y`, wrapped.
    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let (width, height) = (self.image.width, self.image.height);
        let (x, y) = (self.wrap.index(x, width), self.wrap.index(y, height));
        Vec3::from(self.image.pixels[y * width + x])
    }

    /// The lookup at transformed coordinates `uv`.
    fn eval(&self, uv: Vec2) -> Vec3 {
        let size = Vec2::new(self.image.width as f32, self.image.height as f32);
        let position = uv * size;
        if !position.is_finite() {
            return Vec3::ZERO;
        }
        if !self.bilinear {
            return self.texel(position.x.floor() as i64, position.y.floor() as i64);
        }
        let p = position - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
}

impl Wrap {
    /// The texel index in `0..size` that `i` stands for.
    fn index(self, i: i64, size: usize) -> usize {
        let n = size as i64;
        match self {
            Wrap::Repeat => i.rem_euclid(n) as usize,
            Wrap::Clamp => i.clamp(0, n - 1) as usize,
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                (if m >= n { 2 * n - 1 - m } else { m }) as usize
            }
        }
    }
}

/// The properties each texture type reads.
fn known_properties(kind: &str) -> &'static [&'static str] {
    match kind {
        "checkerboard" => &["color0", "color1", "to_uv"],
        "rawconstant" => &["value"],
        "mesh_attribute" => &["name", "scale"],
        // `format` only chooses Mitsuba's storage precision; ais stores f32.
        _ => &[
            "filename",
            "filter_type",
            "wrap_mode",
            "raw",
            "to_uv",
            "format",
        ],
    }
}

/// Reads a `<texture>` of the scene `file` (images found through `files`).
pub fn read_texture(
    file: &Path,
    files: &FileResolver,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<Texture, InputError> {
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    if !matches!(
        plugin.kind.as_str(),
        "checkerboard" | "bitmap" | "rawconstant" | "mesh_attribute"
    ) {
        return Err(InputError::at(
            file,
            plugin.line,
            format!(
                "texture type \"{}\" is not supported (checkerboard, bitmap, rawconstant, \
                 mesh_attribute)",
                plugin.kind
            ),
        ));
    }
    crate::scene::warn_unknown(file, plugin, known_properties(&plugin.kind), warnings);
    let to_uv = UvTransform::from_mat4(plugin.transform("to_uv").map_err(at)?);
    if plugin.kind == "rawconstant" {
        return raw_constant(file, plugin);
    }
    if plugin.kind == "mesh_attribute" {
        return mesh_attribute(file, plugin);
    }
    if plugin.kind == "checkerboard" {
        let colour = |name: &str, default: f32| colour_property(file, plugin, name, default);
        return Ok(Texture::Checkerboard {
            color0: colour("color0", 0.4)?,
            color1: colour("color1", 0.2)?,
            to_uv,
        });
    }
    let bitmap = read_bitmap(file, files, plugin, warnings)?;
    Ok(Texture::Bitmap(Box::new(Bitmap { to_uv, ..bitmap })))
}

/// A `mesh_attribute`: its `name` (required, `vertex_…` or `face_…`) and `scale`.
fn mesh_attribute(file: &Path, plugin: &Plugin) -> Result<Texture, InputError> {
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    let name = plugin
        .string("name")
        .map_err(at)?
        .ok_or_else(|| InputError::at(file, plugin.line, "a mesh_attribute needs its \"name\""))?;
    if !(name.starts_with("vertex_") || name.starts_with("face_")) {
        let message = format!("mesh attribute \"{name}\" must start with vertex_ or face_");
        return Err(InputError::at(file, plugin.line, message));
    }
    let scale = plugin.float("scale", 1.0).map_err(at)? as f32;
    if !scale.is_finite() {
        let message = format!("a mesh_attribute's scale must be finite, not {scale}");
        return Err(InputError::at(file, plugin.line, message));
    }
    Ok(Texture::MeshAttribute {
        name: name.to_string(),
        scale,
    })
}

/// A `rawconstant`'s `value`: a float, a vector or an rgb, taken as is (default 1).
fn raw_constant(file: &Path, plugin: &Plugin) -> Result<Texture, InputError> {
    use crate::scene::Property;
    let value = match plugin.properties.get("value") {
        None => Vec3::ONE,
        Some(p) => match &p.value {
            Property::Float(v) => Vec3::splat(*v as f32),
            Property::Integer(v) => Vec3::splat(*v as f32),
            Property::Vector(v) | Property::Point(v) => v.as_vec3(),
            Property::Rgb(v) => glam::DVec3::from_array(*v).as_vec3(),
            other => {
                let message = format!(
                    "\"value\" of a rawconstant must be a float, vector or rgb, not a {}",
                    other.kind()
                );
                return Err(InputError::at(file, p.line, message));
            }
        },
    };
    if !value.is_finite() {
        let message = "\"value\" of a rawconstant must be finite";
        return Err(InputError::at(file, plugin.line, message));
    }
    Ok(Texture::Constant(value))
}

/// A constant colour of a texture (rgb or float; nested textures are refused).
fn colour_property(
    file: &Path,
    plugin: &Plugin,
    name: &str,
    default: f32,
) -> Result<Vec3, InputError> {
    if let Some(nested) = plugin
        .children
        .iter()
        .find(|c| c.name.as_deref() == Some(name))
    {
        return Err(InputError::at(
            file,
            nested.line,
            format!("a texture inside a texture (\"{name}\") is not supported"),
        ));
    }
    match plugin.colour(name, ColourRole::Reflectance) {
        Ok(value) => Ok(value.unwrap_or(Vec3::splat(default))),
        Err((line, message)) => Err(InputError::at(file, line, message)),
    }
}

/// A `bitmap`'s image and lookup settings (its `to_uv` is read by the caller).
fn read_bitmap(
    file: &Path,
    files: &FileResolver,
    plugin: &Plugin,
    warnings: &mut Vec<String>,
) -> Result<Bitmap, InputError> {
    let at = |(line, message): (u32, String)| InputError::at(file, line, message);
    let name = plugin
        .string("filename")
        .map_err(at)?
        .ok_or_else(|| InputError::at(file, plugin.line, "bitmap needs a \"filename\""))?;
    let bilinear = match plugin.string("filter_type").map_err(at)? {
        None | Some("bilinear") => true,
        Some("nearest") => false,
        Some(other) => {
            return Err(InputError::at(
                file,
                plugin.line,
                format!("unknown filter_type \"{other}\" (bilinear, nearest)"),
            ))
        }
    };
    let wrap = match plugin.string("wrap_mode").map_err(at)? {
        None | Some("repeat") => Wrap::Repeat,
        Some("mirror") => Wrap::Mirror,
        Some("clamp") => Wrap::Clamp,
        Some(other) => {
            return Err(InputError::at(
                file,
                plugin.line,
                format!("unknown wrap_mode \"{other}\" (repeat, mirror, clamp)"),
            ))
        }
    };
    let raw = plugin.boolean("raw", false).map_err(at)?;
    let path = files.resolve(name);
    let image = if is_hdr(&path) {
        let loaded = read_image(&path)?;
        warnings.extend(loaded.warning);
        loaded.image
    } else {
        crate::image_io::read_ldr_image(&path, !raw)?
    };
    Ok(Bitmap {
        image,
        bilinear,
        wrap,
        to_uv: UvTransform::IDENTITY,
    })
}

/// Whether the image file holds linear radiance (EXR, HDR) rather than encoded colours.
fn is_hdr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("hdr"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_two(bilinear: bool, wrap: Wrap) -> Bitmap {
        Bitmap {
            image: RgbImage {
                width: 2,
                height: 2,
                pixels: vec![
                    [1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, 1.0],
                    [1.0, 1.0, 1.0],
                ],
            },
            bilinear,
            wrap,
            to_uv: UvTransform::IDENTITY,
        }
    }

    // The values below were read from Mitsuba 3.9.1's own textures at the same coordinates.
    #[test]
    fn checkerboard_and_bitmap_follow_mitsuba() {
        let board = Texture::Checkerboard {
            color0: Vec3::X,
            color1: Vec3::Z,
            to_uv: UvTransform::IDENTITY,
        };
        for (u, v, expected) in [
            (0.1, 0.1, Vec3::X),
            (0.6, 0.1, Vec3::Z),
            (0.1, 0.6, Vec3::Z),
        ] {
            assert_eq!(board.eval(Vec2::new(u, v)), expected);
        }
        assert_eq!(board.eval(Vec2::new(0.6, 0.6)), Vec3::X);
        assert_eq!(board.eval(Vec2::new(1.1, 0.1)), Vec3::X);
        let nearest = two_by_two(false, Wrap::Repeat);
        assert_eq!(nearest.eval(Vec2::new(0.75, 0.25)), Vec3::Y);
        assert_eq!(nearest.eval(Vec2::new(0.25, 0.75)), Vec3::Z);
        assert_eq!(nearest.eval(Vec2::new(1.25, 0.25)), Vec3::X);
        let bilinear = two_by_two(true, Wrap::Repeat);
        assert_eq!(
            bilinear.eval(Vec2::new(0.5, 0.25)),
            Vec3::new(0.5, 0.5, 0.0)
        );
        assert_eq!(
            bilinear.eval(Vec2::new(0.25, 0.5)),
            Vec3::new(0.5, 0.0, 0.5)
        );
        assert_eq!(
            bilinear.eval(Vec2::new(0.0, 0.25)),
            Vec3::new(0.5, 0.5, 0.0)
        );
    }

    #[test]
    fn wrap_modes_index_beyond_the_image() {
        assert_eq!(Wrap::Repeat.index(-1, 4), 3);
        assert_eq!(Wrap::Clamp.index(-1, 4), 0);
        assert_eq!(Wrap::Clamp.index(9, 4), 3);
        assert_eq!(Wrap::Mirror.index(4, 4), 3);
        assert_eq!(Wrap::Mirror.index(-1, 4), 0);
        assert_eq!(Wrap::Mirror.index(8, 4), 0);
    }
}
