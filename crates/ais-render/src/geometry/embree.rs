//! Intel Embree 3 as the ray tracing backend (cargo feature `embree`): the same queries as
//! the CWBVH, answered by Embree's BVH and SIMD triangle tests.
//!
//! The scene holds two Embree geometries: every triangle (geometry 0) and every sphere
//! (geometry 1, Embree's sphere points). A hit's primitive is `primID` for a triangle and
//! `triangle_count + primID` for a sphere, so the renderer's packed primitives must list
//! the triangles first, in the order given here. Embree reports a triangle's barycentrics
//! as ours are defined (the hit is (1 − u − v)·v0 + u·v1 + v·v2), so shading needs no
//! change.

use super::primitive::Packed;
use super::ray::Ray;
use embree::sys::*;
use glam::Vec2;
use std::ptr;

/// A committed Embree scene, queried from any thread.
pub(super) struct EmbreeScene {
    device: RTCDevice,
    scene: RTCScene,
    triangle_count: u32,
}

// SAFETY: Embree documents that a committed scene may be queried (rtcIntersect*,
// rtcOccluded*) from many threads at once; nothing here mutates it after `build`.
unsafe impl Send for EmbreeScene {}
unsafe impl Sync for EmbreeScene {}

/// Geometry 0 holds the triangles, geometry 1 the spheres.
const SPHERES: u32 = 1;

impl EmbreeScene {
    /// Builds a scene from `packed`, whose triangles must all come before its spheres. None
    /// when Embree cannot start (no device) or reports an error while building.
    pub(super) fn build(packed: &[Packed]) -> Option<Self> {
        let triangle_count = packed
            .iter()
            .take_while(|p| matches!(p, Packed::Triangle(_)))
            .count();
        // SAFETY: every pointer passed to Embree comes from Embree itself or outlives the
        // call; buffers are filled within the sizes they were created with.
        unsafe {
            let device = rtcNewDevice(ptr::null());
            if device.is_null() {
                return None;
            }
            let scene = rtcNewScene(device);
            rtcSetSceneBuildQuality(scene, RTCBuildQuality::HIGH);
            let (triangles, spheres) = packed.split_at(triangle_count);
            attach_triangles(device, scene, triangles);
            attach_spheres(device, scene, spheres);
            rtcCommitScene(scene);
            let built = EmbreeScene {
                device,
                scene,
                triangle_count: triangle_count as u32,
            };
            (rtcGetDeviceError(device) == RTCError::NONE).then_some(built)
        }
    }

    /// The closest hit within the ray: the packed primitive's index, its distance and its
    /// barycentrics (zero for a sphere).
    #[inline]
    pub(super) fn intersect(&self, ray: &Ray) -> Option<(usize, f32, Vec2)> {
        let mut ray_hit = RTCRayHit {
            ray: embree_ray(ray),
            hit: RTCHit {
                Ng_x: 0.0,
                Ng_y: 0.0,
                Ng_z: 0.0,
                u: 0.0,
                v: 0.0,
                primID: RTC_INVALID_GEOMETRY_ID,
                geomID: RTC_INVALID_GEOMETRY_ID,
                instID: [RTC_INVALID_GEOMETRY_ID],
            },
        };
        let mut context = intersect_context();
        // SAFETY: the scene is committed; the context and ray live through the call.
        unsafe { rtcIntersect1(self.scene, &mut context, &mut ray_hit) };
        let hit = ray_hit.hit;
        if hit.geomID == RTC_INVALID_GEOMETRY_ID {
            return None;
        }
        let (index, barycentrics) = if hit.geomID == SPHERES {
            ((self.triangle_count + hit.primID) as usize, Vec2::ZERO)
        } else {
            (hit.primID as usize, Vec2::new(hit.u, hit.v))
        };
        Some((index, ray_hit.ray.tfar, barycentrics))
    }

    /// Whether anything blocks the ray before its end.
    #[inline]
    pub(super) fn occluded(&self, ray: &Ray) -> bool {
        let mut query = embree_ray(ray);
        let mut context = intersect_context();
        // SAFETY: as in `intersect`.
        unsafe { rtcOccluded1(self.scene, &mut context, &mut query) };
        // Embree marks a blocked ray by setting its end to −∞.
        query.tfar < 0.0
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: both handles were created by `build` and are released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}

/// Embree's invalid id (RTC_INVALID_GEOMETRY_ID).
const RTC_INVALID_GEOMETRY_ID: u32 = u32::MAX;

/// The default context of a single-ray query (`rtcInitIntersectContext`, an inline C
/// function the bindings do not carry).
fn intersect_context() -> RTCIntersectContext {
    RTCIntersectContext {
        flags: RTCIntersectContextFlags::INCOHERENT,
        filter: None,
        instID: [RTC_INVALID_GEOMETRY_ID],
    }
}

/// `ray` as Embree takes it, from distance 0 to its end.
#[inline]
fn embree_ray(ray: &Ray) -> RTCRay {
    RTCRay {
        org_x: ray.origin.x,
        org_y: ray.origin.y,
        org_z: ray.origin.z,
        tnear: 0.0,
        dir_x: ray.direction.x,
        dir_y: ray.direction.y,
        dir_z: ray.direction.z,
        time: 0.0,
        tfar: ray.t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// Adds the triangles (geometry 0), if any to `scene`.
///
/// # Safety
/// `device` and `scene` must be live Embree handles.
unsafe fn attach_triangles(device: RTCDevice, scene: RTCScene, triangles: &[Packed]) {
    if triangles.is_empty() {
        return;
    }
    let geometry = rtcNewGeometry(device, RTCGeometryType::TRIANGLE);
    let count = triangles.len();
    let vertices = rtcSetNewGeometryBuffer(
        geometry,
        RTCBufferType::VERTEX,
        0,
        RTCFormat::FLOAT3,
        12,
        count * 3,
    ) as *mut [f32; 3];
    let indices = rtcSetNewGeometryBuffer(
        geometry,
        RTCBufferType::INDEX,
        0,
        RTCFormat::UINT3,
        12,
        count,
    ) as *mut [u32; 3];
    if vertices.is_null() || indices.is_null() {
        rtcReleaseGeometry(geometry);
        return;
    }
    for (i, triangle) in triangles.iter().enumerate() {
        let Packed::Triangle([v0, e1, e2]) = *triangle else {
            continue;
        };
        for (k, vertex) in [v0, v0 + e1, v0 + e2].into_iter().enumerate() {
            *vertices.add(3 * i + k) = vertex.to_array();
        }
        let first = 3 * i as u32;
        *indices.add(i) = [first, first + 1, first + 2];
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene, geometry, 0);
    rtcReleaseGeometry(geometry);
}

/// Adds the spheres (geometry 1), if any to `scene`.
///
/// # Safety
/// `device` and `scene` must be live Embree handles.
unsafe fn attach_spheres(device: RTCDevice, scene: RTCScene, spheres: &[Packed]) {
    if spheres.is_empty() {
        return;
    }
    let geometry = rtcNewGeometry(device, RTCGeometryType::SPHERE_POINT);
    let points = rtcSetNewGeometryBuffer(
        geometry,
        RTCBufferType::VERTEX,
        0,
        RTCFormat::FLOAT4,
        16,
        spheres.len(),
    ) as *mut [f32; 4];
    if points.is_null() {
        rtcReleaseGeometry(geometry);
        return;
    }
    for (i, sphere) in spheres.iter().enumerate() {
        if let Packed::Sphere(s) = sphere {
            *points.add(i) = [s.center.x, s.center.y, s.center.z, s.radius];
        }
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene, geometry, SPHERES);
    rtcReleaseGeometry(geometry);
}
