//! What a shape's `<bsdf>` gives at each point of the shape: a material whose parameters
//! may come from textures, Mitsuba's `mask` (an opacity over a material) and `blendbsdf` (two
//! materials mixed by a weight), each of which may vary over the surface, and `null`.
//! [`Surface::at`] resolves it at a hit into the [`HitBsdf`] the gather evaluates.

use super::hit::{HitBsdf, Mixture, MixturePart};
use super::tilted_normals::{bump_map_normal, normal_map_normal, tilted_frame};
use super::{Material, NormalMapOptions, ParameterTexture, ShadingFrame};
use crate::mesh::AttributeSite;
use crate::texture::{Texture, TextureLookup};
use glam::{Vec2, Vec3};
use std::borrow::Cow;
use std::sync::Arc;

/// A shape's scattering over its surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Surface {
    /// One material; textured parameters take their textures' values at the hit.
    Material {
        /// The material (with the constants that textures replace).
        material: Material,
        /// The textures on its parameters.
        textures: Vec<ParameterTexture>,
    },
    /// Mitsuba's `mask`: the material where the surface is opaque; light passes straight
    /// through elsewhere.
    Mask {
        /// Opacity in [0, 1].
        opacity: Fraction,
        /// The material of the opaque part.
        inner: Box<Surface>,
    },
    /// Mitsuba's `blendbsdf`: `(1 - weight) first + weight second`.
    Blend {
        /// The second's share, in [0, 1].
        weight: Fraction,
        /// The first material.
        first: Box<Surface>,
        /// The second material.
        second: Box<Surface>,
    },
    /// Mitsuba's `normalmap` and `bumpmap`: the inner surface's shading normal tilted by a
    /// texture.
    Tilted {
        /// The texture and how it gives the normal.
        normals: TiltedNormals,
        /// How the tilted normal is applied.
        options: NormalMapOptions,
        /// The surface whose frame it tilts.
        inner: Box<Surface>,
    },
    /// Mitsuba's `null`: light passes straight through, nothing scatters.
    Null,
}

/// Where tilted shading normals come from.
#[derive(Clone, Debug, PartialEq)]
pub enum TiltedNormals {
    /// A tangent-space normal map, encoded as (n + 1) / 2.
    NormalMap(Arc<Texture>),
    /// A height map (a bitmap read as one channel), times `scale`.
    BumpMap {
        /// The heights.
        height: Arc<Texture>,
        /// Their scale.
        scale: f32,
    },
}

impl TiltedNormals {
    /// The tilted normal at `point`, in the frame (s, t, n_s).
    fn local_normal(&self, point: &SurfacePoint) -> Vec3 {
        match self {
            TiltedNormals::NormalMap(texture) => {
                normal_map_normal(texture.eval_at(&point.lookup()))
            }
            TiltedNormals::BumpMap { height, scale } => {
                bump_map_normal(point, *scale * height.scalar_gradient(point.uv))
            }
        }
    }
}

/// A share in [0, 1] that may vary over the surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Fraction {
    /// The same everywhere.
    Constant(f32),
    /// A texture read as one channel at the hit ([`Texture::eval_scalar`]), clamped to
    /// [0, 1].
    Texture(Arc<Texture>),
}

impl Fraction {
    /// Whether a texture gives it.
    fn is_textured(&self) -> bool {
        matches!(self, Fraction::Texture(_))
    }

    /// The share at texture coordinates `uv`.
    pub fn at(&self, at: &TextureLookup) -> f32 {
        let value = match self {
            Fraction::Constant(value) => *value,
            Fraction::Texture(texture) => texture.eval_scalar_at(at),
        };
        if value.is_nan() {
            0.0
        } else {
            value.clamp(0.0, 1.0)
        }
    }
}

/// The geometry a surface is resolved at.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint<'a> {
    /// Texture coordinates.
    pub uv: Vec2,
    /// Interpolated shading normal.
    pub shading_normal: Vec3,
    /// Geometric normal.
    pub geometric_normal: Vec3,
    /// Direction toward the viewer.
    pub wo: Vec3,
    /// ∂p/∂u: where a normal map's tangent points.
    pub dp_du: Vec3,
    /// ∂p/∂v.
    pub dp_dv: Vec3,
    /// The mesh attributes there (None off meshes).
    pub attributes: Option<AttributeSite<'a>>,
}

impl From<Material> for Surface {
    fn from(material: Material) -> Self {
        Surface::Material {
            material,
            textures: Vec::new(),
        }
    }
}

impl Surface {
    /// This surface seen from both sides (Mitsuba's `twosided` around it).
    pub fn two_sided(mut self) -> Surface {
        match &mut self {
            Surface::Material { material, .. } => material.two_sided = true,
            Surface::Mask { inner, .. } | Surface::Tilted { inner, .. } => {
                **inner = inner.as_ref().clone().two_sided()
            }
            Surface::Blend { first, second, .. } => {
                **first = first.as_ref().clone().two_sided();
                **second = second.as_ref().clone().two_sided();
            }
            Surface::Null => {}
        }
        self
    }

    /// The mesh attributes its textures read.
    pub fn attribute_names(&self) -> Vec<String> {
        let texture_names = |texture: &Texture| match texture {
            Texture::MeshAttribute { name, .. } => vec![name.clone()],
            _ => Vec::new(),
        };
        let fraction_names = |fraction: &Fraction| match fraction {
            Fraction::Texture(texture) => texture_names(texture),
            Fraction::Constant(_) => Vec::new(),
        };
        match self {
            Surface::Material { textures, .. } => (textures.iter())
                .flat_map(|t| texture_names(&t.texture))
                .collect(),
            Surface::Mask { opacity, inner } => {
                [fraction_names(opacity), inner.attribute_names()].concat()
            }
            Surface::Blend {
                weight,
                first,
                second,
            } => [
                fraction_names(weight),
                first.attribute_names(),
                second.attribute_names(),
            ]
            .concat(),
            Surface::Tilted { normals, inner, .. } => {
                let texture = match normals {
                    TiltedNormals::NormalMap(texture) => texture,
                    TiltedNormals::BumpMap { height, .. } => height,
                };
                [texture_names(texture), inner.attribute_names()].concat()
            }
            Surface::Null => Vec::new(),
        }
    }

    /// Whether anything varies over the surface by texture coordinates.
    pub fn is_textured(&self) -> bool {
        match self {
            Surface::Material { textures, .. } => !textures.is_empty(),
            Surface::Mask { opacity, inner } => opacity.is_textured() || inner.is_textured(),
            Surface::Tilted { .. } => true,
            Surface::Blend {
                weight,
                first,
                second,
            } => weight.is_textured() || first.is_textured() || second.is_textured(),
            Surface::Null => false,
        }
    }

    /// Whether the frame at a hit faces the viewer from either side: true when any of its
    /// materials is two-sided.
    fn any_two_sided(&self) -> bool {
        match self {
            Surface::Material { material, .. } => material.two_sided,
            Surface::Mask { inner, .. } | Surface::Tilted { inner, .. } => inner.any_two_sided(),
            Surface::Blend { first, second, .. } => first.any_two_sided() || second.any_two_sided(),
            Surface::Null => false,
        }
    }

    /// The BSDF at `point`, and the frame that stands for the surface there (for what
    /// keys on the normal, and for offsetting rays). (Inlined: returned from a call, the
    /// pair went through memory a field at a time and was copied whole into the gather
    /// point, and the copy waited for the writes.)
    #[inline(always)]
    pub fn at(&self, point: &SurfacePoint) -> (HitBsdf<'_>, ShadingFrame) {
        if let Surface::Material { material, textures } = self {
            let material = if textures.is_empty() {
                Cow::Borrowed(material)
            } else {
                Cow::Owned(textured(material, textures, point))
            };
            let frame = point.frame_for(&material);
            return (HitBsdf::Single { material, frame }, frame);
        }
        let mut mixture = Mixture::default();
        self.add_parts(point, 1.0, &mut mixture);
        let frame = point.frame(self.any_two_sided());
        (HitBsdf::Mixture(Box::new(mixture)), frame)
    }

    /// Adds this surface's materials, and what passes through, with `share` of the total.
    fn add_parts(&self, point: &SurfacePoint, share: f32, mixture: &mut Mixture) {
        match self {
            Surface::Material { material, textures } => {
                let material = textured(material, textures, point);
                let frame = point.frame_for(&material);
                mixture.parts.push(MixturePart {
                    weight: share,
                    material,
                    frame,
                    tilt: None,
                });
            }
            Surface::Mask { opacity, inner } => {
                let opacity = opacity.at(&point.lookup());
                inner.add_parts(point, share * opacity, mixture);
                mixture.pass_through += share * (1.0 - opacity);
            }
            Surface::Blend {
                weight,
                first,
                second,
            } => {
                let weight = weight.at(&point.lookup());
                first.add_parts(point, share * (1.0 - weight), mixture);
                second.add_parts(point, share * weight, mixture);
            }
            Surface::Tilted {
                normals,
                options,
                inner,
            } => {
                let first = mixture.parts.len();
                inner.add_parts(point, share, mixture);
                let local = normals.local_normal(point);
                for part in &mut mixture.parts[first..] {
                    let (frame, tilt) = tilted_frame(&part.frame, point, local, *options);
                    part.frame = frame;
                    part.tilt = Some(tilt);
                }
            }
            Surface::Null => mixture.pass_through += share,
        }
    }
}

/// `material` with its textured parameters set to their textures' values at `point` (the
/// roughness read as one channel, as Mitsuba reads it).
fn textured(material: &Material, textures: &[ParameterTexture], point: &SurfacePoint) -> Material {
    let mut material = material.clone();
    let lookup = point.lookup();
    for ParameterTexture { parameter, texture } in textures {
        let value = if parameter.is_scalar() {
            Vec3::splat(texture.eval_scalar_at(&lookup))
        } else {
            texture.eval_at(&lookup)
        };
        material.set_parameter(*parameter, value);
    }
    material
}

impl SurfacePoint<'_> {
    /// Where textures are looked up here.
    pub fn lookup(&self) -> TextureLookup<'_> {
        TextureLookup {
            uv: self.uv,
            attributes: self.attributes,
        }
    }

    /// The shading frame of `material` here: along the tangent for an anisotropic one.
    fn frame_for(&self, material: &Material) -> ShadingFrame {
        if material.is_anisotropic() {
            return ShadingFrame::along_tangent(
                self.shading_normal,
                self.geometric_normal,
                self.wo,
                material.two_sided,
                self.dp_du,
            );
        }
        self.frame(material.two_sided)
    }

    /// The shading frame here for a material that is (or not) two-sided.
    fn frame(&self, two_sided: bool) -> ShadingFrame {
        ShadingFrame::oriented(
            self.shading_normal,
            self.geometric_normal,
            self.wo,
            two_sided,
        )
    }
}
