//! Scene geometry: triangle meshes, spheres and instances of shape groups in an obvhs
//! CWBVH (or, with the cargo feature `embree` and no instances, in Intel Embree 3), with
//! closest-hit and occlusion queries.

mod basis;
mod cwbvh_traversal;
#[cfg(feature = "embree")]
mod embree;
mod ground;
mod instances;
mod outer_box;
mod primitive;
mod quadric;
mod ray;
mod recent_blockers;
mod shaft;
mod slab;
mod triangle_lanes;

pub use basis::basis;
use instances::{GroupGeometry, Instance};
pub use instances::{InstanceInput, SceneShapes, ShapeGroupInput};
use primitive::Packed;
pub use primitive::{Primitive, Sphere, Triangle};
pub use quadric::{Quadric, QuadricKind, QuadricSample, QuadricSurface};
pub use ray::{offset_origin, spawn_ray, spawn_ray_to, Ray, RayOrigins};
pub use recent_blockers::RecentBlockers;
pub use shaft::{LeavingSurface, Shaft};

use crate::mesh::{AttributeSite, MeshAttribute, TriangleMesh};
use cwbvh_traversal::LanedBvh;
use glam::{Vec2, Vec3};
use ground::Ground;
use std::time::{Duration, Instant};

/// What one shape contributes, in world space.
#[derive(Clone, Debug)]
pub enum ShapeGeometry {
    /// A triangle mesh.
    Mesh(TriangleMesh),
    /// An analytic sphere.
    Sphere(Sphere),
    /// An exact disk or cylinder.
    Quadric(Quadric),
}

/// A shape for [`Geometry::build`].
#[derive(Clone, Debug)]
pub struct ShapeInput {
    /// The geometry, in world space.
    pub geometry: ShapeGeometry,
    /// Whether to flip its normals (Mitsuba's `flip_normals`).
    pub flip_normals: bool,
    /// A sphere's rotation from its own frame to the world's (its `to_world` without the
    /// scale), which its texture coordinates and tangents follow; `None`: none.
    pub rotation: Option<glam::Mat3>,
}

/// A ray-surface intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f32,
    /// World-space point.
    pub point: Vec3,
    /// Unit geometric normal (flipped if the shape says so).
    pub geometric_normal: Vec3,
    /// Unit shading normal (interpolated vertex normals, else the geometric normal).
    pub shading_normal: Vec3,
    /// Index of the shape (in the order given to [`Geometry::build`]).
    pub shape: u32,
    /// Texture coordinates (Mitsuba's conventions; zero on a mesh without them).
    pub uv: Vec2,
    /// How the point moves with u (∂p/∂u, as Mitsuba defines it): where a normal map's
    /// tangent space points. On a mesh without texture coordinates, the first edge (the
    /// parameterisation is barycentric); zero where the coordinates are degenerate.
    pub dp_du: Vec3,
    /// How the point moves with v (∂p/∂v), likewise.
    pub dp_dv: Vec3,
    /// The primitive hit (its index among the geometry's primitives, or among its shape
    /// group's when `instance` is set).
    pub primitive: u32,
    /// Barycentric coordinates of the point on a triangle (zero on a sphere).
    pub barycentrics: Vec2,
    /// The instance of a shape group that was hit, if any (by index).
    pub instance: Option<u32>,
}

/// Per-mesh data needed to shade a triangle hit.
#[derive(Clone, Debug)]
struct MeshShading {
    normals: Option<Vec<Vec3>>,
    texcoords: Option<Vec<Vec2>>,
    triangles: Vec<[u32; 3]>,
    attributes: Vec<MeshAttribute>,
}

/// The scene's primitives in a CWBVH.
pub struct Geometry {
    /// Primitives as given, until the BVH is built.
    primitives: Vec<Primitive>,
    /// Primitives in BVH order, packed for intersection (the BVH's primitive index is the
    /// position here).
    packed: Vec<Packed>,
    /// For each packed primitive: its shape, and for a triangle its mesh and index there.
    sources: Vec<PrimitiveSource>,
    meshes: Vec<MeshShading>,
    /// Per shape added (its slot): the shape's index in the scene.
    shape_ids: Vec<u32>,
    /// Per slot: whether the shape's normals flip.
    shape_flips: Vec<bool>,
    /// Per slot, the rotation of a rotated sphere (world to its own frame).
    sphere_rotations: Vec<Option<glam::Mat3>>,
    /// The shape groups that instances place, each in its own BVH.
    groups: Vec<GroupGeometry>,
    /// The instances (primitives of this geometry's BVH).
    instances: Vec<Instance>,
    /// The disks and cylinders (primitives of this geometry's BVH).
    quadrics: Vec<Quadric>,
    accelerator: Option<Accelerator>,
    triangle_count: usize,
    /// Centre and radius of a sphere around everything.
    bounds: (Vec3, f32),
    build_time: Duration,
}

/// What answers ray queries.
enum Accelerator {
    /// obvhs's compressed wide BVH (the default), its triangles in lanes.
    Cwbvh(LanedBvh),
    /// Intel Embree 3.
    #[cfg(feature = "embree")]
    Embree(embree::EmbreeScene),
}

/// Where a primitive came from: what shading a hit on it needs.
#[derive(Clone, Copy, Debug)]
struct PrimitiveSource {
    /// The shape's slot (see `Geometry::shape_ids`).
    shape: u32,
    /// The triangle's mesh (unused for a sphere).
    mesh: u32,
    /// The triangle's index in its mesh (unused for a sphere).
    index: u32,
}

/// The closest hit found so far in a traversal.
enum Closest {
    /// A primitive of this geometry, to be shaded.
    Primitive {
        index: usize,
        t: f32,
        barycentrics: Vec2,
    },
    /// A primitive of an instance, already shaded in world space.
    Instance(Hit),
}

impl Closest {
    /// A triangle hit found in the lanes.
    #[inline(always)]
    fn of(hit: triangle_lanes::LaneHit) -> Self {
        Closest::Primitive {
            index: hit.index,
            t: hit.t,
            barycentrics: hit.barycentrics,
        }
    }

    fn t(&self) -> f32 {
        match self {
            Closest::Primitive { t, .. } => *t,
            Closest::Instance(hit) => hit.t,
        }
    }
}

impl Geometry {
    /// Builds the BVH over all shapes.
    pub fn build(shapes: Vec<ShapeInput>) -> Self {
        Self::build_instanced(SceneShapes {
            shapes,
            ..SceneShapes::default()
        })
    }

    /// Builds the BVH over the scene's shapes and the instances of its shape groups: each
    /// group once, in a BVH of its own, whatever the number of its instances. Shapes are
    /// numbered in order, the scene's first, then the groups' (group after group). An
    /// instance whose transform cannot be inverted is left out.
    pub fn build_instanced(scene: SceneShapes) -> Self {
        let started = Instant::now();
        let mut geometry = Geometry::empty();
        let mut next_shape = 0u32;
        for shape in scene.shapes {
            geometry.add(next_shape, shape);
            next_shape += 1;
        }
        for group in scene.groups {
            let mut inner = Geometry::empty();
            for shape in group.shapes {
                inner.add(next_shape, shape);
                next_shape += 1;
            }
            let bounds = primitive_bounds(&inner.primitives);
            geometry.triangle_count += inner.triangle_count;
            inner.finish();
            geometry.groups.push(GroupGeometry {
                geometry: inner,
                bounds,
            });
        }
        for input in &scene.instances {
            let Some(group) = geometry.groups.get(input.group as usize) else {
                continue;
            };
            let Some(instance) = Instance::new(input) else {
                continue;
            };
            let bounds = instance.world_bounds(&group.bounds);
            let index = geometry.instances.len() as u32;
            geometry.instances.push(instance);
            geometry
                .primitives
                .push(Primitive::Instance { index, bounds });
            geometry.sources.push(PrimitiveSource {
                shape: 0,
                mesh: 0,
                index,
            });
        }
        geometry.finish();
        geometry.build_time = started.elapsed();
        geometry
    }

    /// A geometry of nothing.
    fn empty() -> Self {
        Geometry {
            primitives: Vec::new(),
            packed: Vec::new(),
            sources: Vec::new(),
            meshes: Vec::new(),
            shape_ids: Vec::new(),
            shape_flips: Vec::new(),
            sphere_rotations: Vec::new(),
            groups: Vec::new(),
            instances: Vec::new(),
            quadrics: Vec::new(),
            accelerator: None,
            triangle_count: 0,
            bounds: (Vec3::ZERO, 0.0),
            build_time: Duration::ZERO,
        }
    }

    /// Bounds the primitives added and builds the accelerator over them.
    fn finish(&mut self) {
        let bounds = primitive_bounds(&self.primitives);
        self.bounds = if bounds.valid() {
            let centre = Vec3::from(bounds.center());
            (centre, bounds.diagonal().length() * 0.5)
        } else {
            (Vec3::ZERO, 0.0)
        };
        self.build_bvh();
    }

    /// Appends a shape's primitives; the shape is number `shape_index` in the scene.
    fn add(&mut self, shape_index: u32, shape: ShapeInput) {
        let slot = self.shape_ids.len() as u32;
        self.shape_ids.push(shape_index);
        self.shape_flips.push(shape.flip_normals);
        self.sphere_rotations
            .push(shape.rotation.map(|r| r.transpose()));
        match shape.geometry {
            ShapeGeometry::Sphere(sphere) => {
                self.primitives.push(Primitive::Sphere(sphere));
                self.sources.push(PrimitiveSource {
                    shape: slot,
                    mesh: 0,
                    index: 0,
                });
            }
            ShapeGeometry::Quadric(quadric) => {
                let index = self.quadrics.len() as u32;
                self.quadrics.push(quadric);
                self.primitives.push(Primitive::Quadric { index, quadric });
                self.sources.push(PrimitiveSource {
                    shape: slot,
                    mesh: 0,
                    index,
                });
            }
            ShapeGeometry::Mesh(mesh) => {
                let mesh_index = self.meshes.len() as u32;
                for (index, &[a, b, c]) in mesh.triangles.iter().enumerate() {
                    self.primitives.push(Primitive::Triangle(Triangle {
                        vertices: [
                            mesh.positions[a as usize],
                            mesh.positions[b as usize],
                            mesh.positions[c as usize],
                        ],
                        mesh: mesh_index,
                        index: index as u32,
                    }));
                    self.sources.push(PrimitiveSource {
                        shape: slot,
                        mesh: mesh_index,
                        index: index as u32,
                    });
                }
                self.triangle_count += mesh.triangles.len();
                self.meshes.push(MeshShading {
                    normals: mesh.normals,
                    texcoords: mesh.texcoords,
                    triangles: mesh.triangles,
                    attributes: mesh.attributes,
                });
            }
        }
    }

    /// Builds the accelerator: Embree when the feature is on and Embree starts, else the
    /// CWBVH.
    fn build_bvh(&mut self) {
        #[cfg(feature = "embree")]
        if self.instances.is_empty() && self.quadrics.is_empty() && self.build_embree() {
            return;
        }
        self.build_cwbvh();
    }

    /// Builds the CWBVH over the primitives but a ground (see [`ground`]), and packs them
    /// in its order, so that traversal needs no indirection, the ground's last.
    fn build_cwbvh(&mut self) {
        let primitives = std::mem::take(&mut self.primitives);
        if primitives.is_empty() {
            return;
        }
        let ground = ground::choose(&primitives);
        let in_bvh: Vec<u32> = (0..primitives.len() as u32)
            .filter(|&i| !ground.contains(&(i as usize)))
            .collect();
        let bvh_primitives: Vec<Primitive> =
            in_bvh.iter().map(|&i| primitives[i as usize]).collect();
        let bvh = obvhs::cwbvh::builder::build_cwbvh(
            &bvh_primitives,
            obvhs::BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let order: Vec<u32> = (bvh.primitive_indices.iter())
            .map(|&i| in_bvh[i as usize])
            .chain(ground.iter().map(|&i| i as u32))
            .collect();
        self.pack_in_order(&primitives, &order);
        let first = bvh.primitive_indices.len();
        let ground = (!ground.is_empty()).then(|| Ground::new(&self.packed, first));
        self.accelerator = Some(Accelerator::Cwbvh(LanedBvh::new(bvh, &self.packed, ground)));
    }

    /// Packs the primitives with the triangles first, as Embree's scene numbers them, and
    /// builds it. False (primitives kept) when Embree cannot start.
    #[cfg(feature = "embree")]
    fn build_embree(&mut self) -> bool {
        let mut order: Vec<u32> = (0..self.primitives.len() as u32).collect();
        order.sort_by_key(|&i| matches!(self.primitives[i as usize], Primitive::Sphere(_)));
        let packed: Vec<Packed> = order
            .iter()
            .map(|&i| Packed::new(&self.primitives[i as usize]))
            .collect();
        let Some(scene) = embree::EmbreeScene::build(&packed) else {
            return false;
        };
        let primitives = std::mem::take(&mut self.primitives);
        self.pack_in_order(&primitives, &order);
        self.accelerator = Some(Accelerator::Embree(scene));
        true
    }

    /// Keeps the primitives packed in `order`, with their sources.
    fn pack_in_order(&mut self, primitives: &[Primitive], order: &[u32]) {
        self.packed = order
            .iter()
            .map(|&i| Packed::new(&primitives[i as usize]))
            .collect();
        self.sources = order.iter().map(|&i| self.sources[i as usize]).collect();
    }

    /// The name of the backend that answers ray queries.
    pub fn accelerator_name(&self) -> &'static str {
        match &self.accelerator {
            #[cfg(feature = "embree")]
            Some(Accelerator::Embree(_)) => "Embree 3",
            _ => "obvhs CWBVH",
        }
    }

    /// Number of triangles, each instanced group's counted once.
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Number of primitives in the scene's BVH (triangles, spheres and instances).
    pub fn primitive_count(&self) -> usize {
        self.packed.len()
    }

    /// Number of instances of shape groups.
    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// Centre and radius of a sphere enclosing every primitive (zero for an empty scene).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        self.bounds
    }

    /// Wall time of [`Geometry::build`].
    pub fn build_time(&self) -> Duration {
        self.build_time
    }

    /// The hit of `ray` on primitive `index` before `t_max`, if any.
    #[inline]
    fn intersect_primitive(&self, index: usize, ray: &Ray, t_max: f32) -> Option<Closest> {
        match self.packed[index] {
            Packed::Instance(k) => {
                let instance = &self.instances[k as usize];
                let group = &self.groups[instance.group as usize].geometry;
                let hit = instance.intersect(group, ray, t_max)?;
                Some(Closest::Instance(Hit {
                    instance: Some(k),
                    ..hit
                }))
            }
            Packed::Quadric(k) => {
                self.quadrics[k as usize]
                    .intersect(ray, t_max)
                    .map(|t| Closest::Primitive {
                        index,
                        t,
                        barycentrics: Vec2::ZERO,
                    })
            }
            packed => packed
                .intersect(ray, t_max)
                .map(|(t, barycentrics)| Closest::Primitive {
                    index,
                    t,
                    barycentrics,
                }),
        }
    }

    /// The distance at which primitive `index` blocks `ray` before `t_max` (infinity: it
    /// does not; an instance that blocks it answers 0).
    #[inline]
    fn blocking_distance(&self, index: usize, ray: &Ray, t_max: f32) -> f32 {
        match self.packed[index] {
            Packed::Instance(k) => {
                let instance = &self.instances[k as usize];
                let group = &self.groups[instance.group as usize].geometry;
                if instance.occludes(group, ray, t_max) {
                    0.0
                } else {
                    f32::INFINITY
                }
            }
            Packed::Quadric(k) => self.quadrics[k as usize]
                .intersect(ray, t_max)
                .unwrap_or(f32::INFINITY),
            packed => packed
                .intersect(ray, t_max)
                .map_or(f32::INFINITY, |(t, _)| t),
        }
    }

    /// The closest hit along the ray, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let closest = match self.accelerator.as_ref()? {
            Accelerator::Cwbvh(bvh) => bvh.nearest(ray, |index, t_max| {
                self.intersect_primitive(index, ray, t_max)
            })?,
            #[cfg(feature = "embree")]
            Accelerator::Embree(scene) => {
                let (index, t, barycentrics) = scene.intersect(ray)?;
                Closest::Primitive {
                    index,
                    t,
                    barycentrics,
                }
            }
        };
        Some(self.resolve(closest, ray))
    }

    /// The hit that `closest` stands for.
    fn resolve(&self, closest: Closest, ray: &Ray) -> Hit {
        match closest {
            Closest::Primitive {
                index,
                t,
                barycentrics,
            } => self.shade(index, ray, t, barycentrics),
            Closest::Instance(hit) => hit,
        }
    }

    /// The closest hit by testing every primitive: the reference the BVH is tested against.
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Closest> = None;
        for index in 0..self.packed.len() {
            let t_max = best.as_ref().map_or(ray.t_max, Closest::t);
            if let Some(closest) = self.intersect_primitive(index, ray, t_max) {
                best = Some(closest);
            }
        }
        best.map(|closest| self.resolve(closest, ray))
    }

    /// Whether anything blocks the ray before `t_max` (any-hit query).
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_after(ray, &mut RecentBlockers::default())
    }

    /// Whether anything blocks the ray before `t_max`, trying first near what blocked the
    /// rays before it (`blockers`, which then remembers this ray's blocker). The rays of
    /// one gather share an origin, and the blocked ones mostly meet the same few surfaces
    /// (a wall, a ceiling): a test of eight triangles then stands in for a traversal. The
    /// answer is [`Geometry::occluded`]'s, but for a ray that grazes the edge of a box of
    /// the BVH within float rounding (a traversal might pass by a triangle that the test of
    /// its run hits).
    pub fn occluded_after(&self, ray: &Ray, blockers: &mut RecentBlockers) -> bool {
        match &self.accelerator {
            None => false,
            Some(Accelerator::Cwbvh(bvh)) => {
                // A ray that passes everything by is free, known before a blocker's test
                // (where the gather's rays mostly do).
                let mut passes_box = None;
                if blockers.tries_box_first() {
                    let passes = bvh.passes_box(ray);
                    blockers.box_tried(passes);
                    if passes && !bvh.may_meet_ground(ray) {
                        blockers.note_free();
                        return false;
                    }
                    passes_box = Some(passes);
                }
                let blocks = |index, t_max| self.blocking_distance(index, ray, t_max) < t_max;
                let tried = blockers.how_many_to_try();
                for at in 0..tried {
                    if bvh.near_blocks(blockers.index(at), ray, blocks) {
                        blockers.blocked_by(at);
                        return true;
                    }
                }
                blockers.missed(tried);
                let blocker = bvh.blocker(ray, blocks, passes_box);
                match blocker {
                    Some(index) => blockers.remember(index, bvh.near_test(index)),
                    None => blockers.note_free(),
                }
                blocker.is_some()
            }
            // Embree answers from its own traversal; `blockers` stay as they were.
            #[cfg(feature = "embree")]
            Some(Accelerator::Embree(scene)) => scene.occluded(ray),
        }
    }

    /// Whether nothing but shape `own_shape` (the light the shaft aims at, which its rays
    /// end before) reaches into `shaft`: then every ray from the shaft's apex toward the
    /// light is free. `false` means only that some primitive may block some of those rays
    /// (Embree's scenes, which this traversal cannot read, always answer `false`).
    pub fn shaft_is_clear(&self, shaft: &Shaft, own_shape: u32) -> bool {
        match &self.accelerator {
            None => true,
            Some(Accelerator::Cwbvh(bvh)) => {
                bvh.clear_of(shaft, |index| self.outside_shaft(index, shaft, own_shape))
            }
            #[cfg(feature = "embree")]
            Some(Accelerator::Embree(_)) => false,
        }
    }

    /// Whether primitive `index` surely lies outside `shaft`, or belongs to `own_shape`.
    fn outside_shaft(&self, index: usize, shaft: &Shaft, own_shape: u32) -> bool {
        let excluded = match self.packed[index] {
            Packed::Triangle([v0, e1, e2]) => shaft.excludes_triangle([v0, v0 + e1, v0 + e2]),
            Packed::Sphere(sphere) => shaft.excludes_sphere(&sphere),
            Packed::Quadric(_) | Packed::Instance(_) => return false,
        };
        excluded || self.shape_of(index) == own_shape
    }

    /// The scene's index of the shape primitive `index` belongs to (not an instance).
    fn shape_of(&self, index: usize) -> u32 {
        self.shape_ids[self.sources[index].shape as usize]
    }

    fn shade(&self, index: usize, ray: &Ray, t: f32, barycentrics: Vec2) -> Hit {
        let point = ray.at(t);
        let source = self.sources[index];
        let flip = if self.shape_flips[source.shape as usize] {
            -1.0
        } else {
            1.0
        };
        let (geometric_normal, shading_normal, uv, [dp_du, dp_dv]) = match &self.packed[index] {
            Packed::Quadric(k) => {
                let surface = self.quadrics[*k as usize].surface_at(point);
                let n = surface.normal * flip;
                (n, n, surface.uv, [surface.dp_du, surface.dp_dv])
            }
            // Instances are shaded by their group (see `intersect_primitive`).
            Packed::Instance(_) => (Vec3::Z, Vec3::Z, Vec2::ZERO, [Vec3::X, Vec3::Y]),
            Packed::Sphere(s) => {
                let outward = (point - s.center).normalize();
                // Texture coordinates and tangents in the sphere's own frame.
                let rotation = self.sphere_rotations[source.shape as usize];
                let local = rotation.map_or(outward, |to_local| to_local * outward);
                let uv = sphere_texcoords(local);
                let partials = sphere_partials(local, s.radius)
                    .map(|v| rotation.map_or(v, |to_local| to_local.transpose() * v));
                (outward * flip, outward * flip, uv, partials)
            }
            Packed::Triangle([_, e1, e2]) => {
                let n = e1.cross(*e2).normalize() * flip;
                let shading = self.interpolated_normal(source, barycentrics).unwrap_or(n);
                // The triangle's texture coordinates, read once for both uses.
                let corners = self.triangle_texcoords(source);
                let uv = interpolated_texcoords(corners, barycentrics);
                (n, shading, uv, uv_partials(corners, *e1, *e2))
            }
        };
        Hit {
            t,
            point,
            geometric_normal,
            shading_normal,
            shape: self.shape_ids[source.shape as usize],
            uv,
            dp_du,
            dp_dv,
            primitive: index as u32,
            barycentrics,
            instance: None,
        }
    }

    /// The texture coordinates at a triangle's corners (None: its mesh has none).
    fn triangle_texcoords(&self, source: PrimitiveSource) -> Option<[Vec2; 3]> {
        let mesh = &self.meshes[source.mesh as usize];
        let texcoords = mesh.texcoords.as_ref()?;
        Some(mesh.triangles[source.index as usize].map(|i| texcoords[i as usize]))
    }

    /// Where the mesh attributes of `hit`'s mesh are looked up (None on a sphere).
    pub fn attribute_site(&self, hit: &Hit) -> Option<AttributeSite<'_>> {
        if let Some(k) = hit.instance {
            let group = &self.groups[self.instances[k as usize].group as usize].geometry;
            return group.attribute_site(&Hit {
                instance: None,
                ..*hit
            });
        }
        let source = self.sources[hit.primitive as usize];
        if !matches!(self.packed[hit.primitive as usize], Packed::Triangle(_)) {
            return None;
        }
        let mesh = &self.meshes[source.mesh as usize];
        Some(AttributeSite {
            attributes: &mesh.attributes,
            triangle: source.index as usize,
            vertices: mesh.triangles[source.index as usize],
            barycentrics: hit.barycentrics,
        })
    }

    /// The vertex normals of a triangle's mesh interpolated at `barycentrics` (None: the mesh
    /// has none, or they cancel out).
    fn interpolated_normal(&self, source: PrimitiveSource, barycentrics: Vec2) -> Option<Vec3> {
        let mesh = &self.meshes[source.mesh as usize];
        let normals = mesh.normals.as_ref()?;
        let [a, b, c] = mesh.triangles[source.index as usize];
        let interpolated = normals[a as usize] * (1.0 - barycentrics.x - barycentrics.y)
            + normals[b as usize] * barycentrics.x
            + normals[c as usize] * barycentrics.y;
        // Vertex normals were already flipped with the mesh.
        let s = interpolated.normalize_or_zero();
        (s != Vec3::ZERO).then_some(s)
    }
}

/// Mitsuba's texture coordinates on a sphere at the unit `outward` direction from its
/// centre: (azimuth about z / 2π, polar angle from +z / π). A sphere here keeps no rotation,
/// so these are in world axes.
pub fn sphere_texcoords(outward: Vec3) -> Vec2 {
    let mut u = outward.y.atan2(outward.x) / std::f32::consts::TAU;
    if u < 0.0 {
        u += 1.0;
    }
    Vec2::new(u, outward.z.clamp(-1.0, 1.0).acos() / std::f32::consts::PI)
}

/// Texture coordinates at `barycentrics` from a triangle's `corners` (zero without them).
fn interpolated_texcoords(corners: Option<[Vec2; 3]>, barycentrics: Vec2) -> Vec2 {
    let Some([a, b, c]) = corners else {
        return Vec2::ZERO;
    };
    a * (1.0 - barycentrics.x - barycentrics.y) + b * barycentrics.x + c * barycentrics.y
}

/// ∂p/∂u and ∂p/∂v over a triangle with edges `e1`, `e2`, from the texture coordinates at
/// its `corners` (the edges themselves without them, zero when they do not span the plane).
fn uv_partials(corners: Option<[Vec2; 3]>, e1: Vec3, e2: Vec3) -> [Vec3; 2] {
    let Some([a, b, c]) = corners else {
        return [e1, e2];
    };
    let (duv1, duv2) = (b - a, c - a);
    let determinant = duv1.x * duv2.y - duv1.y * duv2.x;
    if determinant.abs() <= f32::MIN_POSITIVE || !determinant.is_finite() {
        return [Vec3::ZERO; 2];
    }
    [
        (e1 * duv2.y - e2 * duv1.y) / determinant,
        (e2 * duv1.x - e1 * duv2.x) / determinant,
    ]
}

/// ∂p/∂u and ∂p/∂v on a sphere of `radius` at the unit `outward` direction, for the texture
/// coordinates of [`sphere_texcoords`] (Mitsuba's: 2π and π times the unit sphere's).
fn sphere_partials(outward: Vec3, radius: f32) -> [Vec3; 2] {
    let tau = std::f32::consts::TAU;
    let dp_du = Vec3::new(-outward.y, outward.x, 0.0) * (tau * radius);
    let planar = outward.x.hypot(outward.y);
    let dp_dv = if planar > 0.0 {
        let (cos_phi, sin_phi) = (outward.x / planar, outward.y / planar);
        Vec3::new(outward.z * cos_phi, outward.z * sin_phi, -planar)
    } else {
        Vec3::X
    };
    [dp_du, dp_dv * (std::f32::consts::PI * radius)]
}

/// The box around `primitives` (empty for none).
fn primitive_bounds(primitives: &[Primitive]) -> obvhs::aabb::Aabb {
    use obvhs::Boundable;
    primitives
        .iter()
        .fold(obvhs::aabb::Aabb::empty(), |bounds, p| {
            bounds.union(&p.aabb())
        })
}
