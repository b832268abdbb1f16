//! Intersections against analytic answers, the BVH against brute force, and ray offsets.

use ais::rng::Pcg32;
use ais_render::geometry::{
    offset_origin, spawn_ray, spawn_ray_to, Geometry, Hit, LeavingSurface, Ray, RecentBlockers,
    Shaft, ShapeGeometry, ShapeInput, Sphere, Triangle,
};
use ais_render::mesh::TriangleMesh;
use ais_render::shapes;
use glam::{DMat4, DVec3, Vec3};

fn random_unit(rng: &mut Pcg32) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = std::f32::consts::TAU * rng.next_f32();
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn triangle_hit_distance_and_barycentrics() {
    let triangle = Triangle {
        vertices: [Vec3::ZERO, Vec3::X, Vec3::Y],
        mesh: 0,
        index: 0,
    };
    let ray = Ray::new(Vec3::new(0.25, 0.5, 3.0), Vec3::NEG_Z);
    let (t, b) = triangle.intersect(&ray, f32::INFINITY).unwrap();
    assert!((t - 3.0).abs() < 1e-6);
    assert!((b.x - 0.25).abs() < 1e-6 && (b.y - 0.5).abs() < 1e-6);
    assert!(triangle.intersect(&ray, 2.5).is_none(), "beyond t_max");
    let outside = Ray::new(Vec3::new(0.75, 0.5, 3.0), Vec3::NEG_Z);
    assert!(triangle.intersect(&outside, f32::INFINITY).is_none());
    let behind = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::NEG_Z);
    assert!(triangle.intersect(&behind, f32::INFINITY).is_none());
}

#[test]
fn sphere_hits_match_the_quadratic() {
    let sphere = Sphere {
        center: Vec3::new(0.0, 0.0, 10.0),
        radius: 2.0,
    };
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    assert!((sphere.intersect(&ray, f32::INFINITY).unwrap() - 8.0).abs() < 1e-5);
    // Grazing offset 1: the chord half-length is sqrt(3).
    let offset = Ray::new(Vec3::new(1.0, 0.0, 0.0), Vec3::Z);
    assert!(
        (sphere.intersect(&offset, f32::INFINITY).unwrap() - (10.0 - 3f32.sqrt())).abs() < 1e-5
    );
    // From inside, the far hit.
    let inside = Ray::new(Vec3::new(0.0, 0.0, 10.0), Vec3::X);
    assert!((sphere.intersect(&inside, f32::INFINITY).unwrap() - 2.0).abs() < 1e-6);
    assert!(sphere
        .intersect(&Ray::new(Vec3::ZERO, Vec3::NEG_Z), f32::INFINITY)
        .is_none());
}

#[test]
fn a_ray_from_inside_a_sphere_meets_its_far_side() {
    let geometry = Geometry::build(vec![ShapeInput {
        geometry: ShapeGeometry::Sphere(Sphere {
            center: Vec3::new(1.0, 2.0, 3.0),
            radius: 0.5,
        }),
        flip_normals: false,
        rotation: None,
    }]);
    let ray = Ray::new(Vec3::new(1.0, 2.0, 3.1), Vec3::Z);
    let hit = geometry.intersect(&ray).expect("the sphere's far side");
    assert!((hit.t - 0.4).abs() < 1e-5, "t = {}", hit.t);
    assert!(geometry.occluded(&ray));
    let short = Ray { t_max: 0.3, ..ray };
    assert!(!geometry.occluded(&short));
}

#[test]
fn rectangle_from_mitsuba_transform() {
    // Mitsuba's rectangle scaled by 2 and moved to z = 5: it covers [-2, 2]² there.
    let to_world =
        DMat4::from_translation(DVec3::new(0.0, 0.0, 5.0)) * DMat4::from_scale(DVec3::splat(2.0));
    let mesh = shapes::rectangle().transformed(to_world, false, false);
    let geometry = Geometry::build(vec![ShapeInput {
        geometry: ShapeGeometry::Mesh(mesh),
        flip_normals: false,
        rotation: None,
    }]);
    let hit = geometry
        .intersect(&Ray::new(Vec3::new(1.9, -1.9, 0.0), Vec3::Z))
        .unwrap();
    assert!((hit.t - 5.0).abs() < 1e-5);
    assert!((hit.geometric_normal - Vec3::Z).length() < 1e-6);
    assert!(geometry
        .intersect(&Ray::new(Vec3::new(2.1, 0.0, 0.0), Vec3::Z))
        .is_none());
    let flipped = Geometry::build(vec![ShapeInput {
        geometry: ShapeGeometry::Mesh(shapes::rectangle().transformed(to_world, false, true)),
        flip_normals: true,
        rotation: None,
    }]);
    let hit = flipped.intersect(&Ray::new(Vec3::ZERO, Vec3::Z)).unwrap();
    assert!((hit.geometric_normal + Vec3::Z).length() < 1e-6);
}

/// Random triangles and spheres in a box.
fn random_scene(rng: &mut Pcg32) -> Geometry {
    Geometry::build(random_shapes(rng))
}

/// The shapes of [`random_scene`].
fn random_shapes(rng: &mut Pcg32) -> Vec<ShapeInput> {
    let mut mesh = TriangleMesh::default();
    for t in 0..2000u32 {
        let center = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
        for _ in 0..3 {
            mesh.positions.push(center + random_unit(rng) * 0.6);
        }
        mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let mut shapes = vec![ShapeInput {
        geometry: ShapeGeometry::Mesh(mesh),
        flip_normals: false,
        rotation: None,
    }];
    for _ in 0..50 {
        shapes.push(ShapeInput {
            geometry: ShapeGeometry::Sphere(Sphere {
                center: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0,
                radius: 0.1 + 0.4 * rng.next_f32(),
            }),
            flip_normals: false,
            rotation: None,
        });
    }
    shapes
}

/// [`random_scene`]'s shapes over a ground of two triangles 40 wide, below them at y = -1,
/// with more area than all of theirs (the geometry keeps it out of the BVH); the ground is
/// the last shape.
fn random_scene_on_a_ground(rng: &mut Pcg32) -> (Geometry, u32) {
    let mut shapes = random_shapes(rng);
    let corners = [(-15.0, -15.0), (25.0, -15.0), (25.0, 25.0), (-15.0, 25.0)];
    let [a, b, c, d] = corners.map(|(x, z)| Vec3::new(x, -1.0, z));
    shapes.push(triangles_shape(vec![a, b, c, a, c, d]));
    let ground = shapes.len() as u32 - 1;
    (Geometry::build(shapes), ground)
}

#[test]
fn a_ground_kept_out_of_the_bvh_is_met_as_brute_force_meets_it() {
    let mut rng = Pcg32::new(41, 9);
    let (geometry, ground) = random_scene_on_a_ground(&mut rng);
    let (mut on_ground, mut from_ground_free) = (0, 0);
    for i in 0..6000 {
        let direction = random_unit(&mut rng);
        // Half the rays leave the ground (up or down, offset as the renderer offsets
        // them), half start anywhere above it.
        let origin = match i % 2 {
            0 => {
                let point = Vec3::new(
                    40.0 * rng.next_f32() - 15.0,
                    -1.0,
                    40.0 * rng.next_f32() - 15.0,
                );
                offset_origin(point, Vec3::Y, direction)
            }
            _ => Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0,
        };
        let mut ray = Ray::new(origin, direction);
        if i % 3 == 0 {
            ray.t_max = 3.0 * rng.next_f32();
        }
        let fast = geometry.intersect(&ray);
        let slow = geometry.intersect_brute_force(&ray);
        match same_hit(i, fast, slow) {
            Some(shape) => on_ground += (shape == ground) as usize,
            None => from_ground_free += (i % 2 == 0) as usize,
        }
        assert_eq!(
            geometry.occluded(&ray),
            slow.is_some(),
            "ray {i}: occlusion"
        );
        let mut blockers = RecentBlockers::default();
        for _ in 0..2 {
            let after = geometry.occluded_after(&ray, &mut blockers);
            assert_eq!(after, slow.is_some(), "ray {i}: after a blocker");
        }
    }
    assert!(
        on_ground > 300 && from_ground_free > 1000,
        "{on_ground} {from_ground_free}"
    );
}

/// Checks that ray `i`'s hit by the BVH (`fast`) is brute force's (`slow`): the same
/// shape at the same distance, or no hit for both. The shape hit, if any.
fn same_hit(i: usize, fast: Option<Hit>, slow: Option<Hit>) -> Option<u32> {
    match (fast, slow) {
        (Some(a), Some(b)) => {
            let t_agrees = (a.t - b.t).abs() <= 1e-5 * b.t.max(1.0);
            assert!(t_agrees, "ray {i}: {} vs {}", a.t, b.t);
            assert_eq!(a.shape, b.shape, "ray {i}");
            Some(b.shape)
        }
        (None, None) => None,
        (a, b) => panic!("ray {i}: BVH {a:?} vs brute force {b:?}"),
    }
}

#[test]
fn bvh_agrees_with_brute_force_on_random_rays() {
    let mut rng = Pcg32::new(31, 7);
    let geometry = random_scene(&mut rng);
    // The backend under test: Embree when the crate is built with the feature.
    let expected = if cfg!(feature = "embree") {
        "Embree 3"
    } else {
        "obvhs CWBVH"
    };
    assert_eq!(geometry.accelerator_name(), expected);
    let mut hits = 0;
    for i in 0..5000 {
        let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
        let mut ray = Ray::new(origin, random_unit(&mut rng));
        if i % 3 == 0 {
            ray.t_max = 3.0 * rng.next_f32();
        }
        let fast = geometry.intersect(&ray);
        let slow = geometry.intersect_brute_force(&ray);
        hits += same_hit(i, fast, slow).is_some() as usize;
        assert_eq!(
            geometry.occluded(&ray),
            slow.is_some(),
            "ray {i}: occlusion query"
        );
    }
    assert!(hits > 1000, "the test must exercise hits: {hits}");
}

#[test]
fn rays_from_one_origin_are_answered_alike_after_a_blocker() {
    let mut rng = Pcg32::new(17, 3);
    let geometry = random_scene(&mut rng);
    let mut blocked = 0;
    for origin in 0..400 {
        let origin_point = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
        // One gather's rays: one origin, its remembered blockers.
        let mut blockers = RecentBlockers::default();
        for i in 0..16 {
            let mut ray = Ray::new(origin_point, random_unit(&mut rng));
            if i % 3 == 0 {
                ray.t_max = 3.0 * rng.next_f32();
            }
            let expected = geometry.intersect_brute_force(&ray).is_some();
            assert_eq!(
                geometry.occluded_after(&ray, &mut blockers),
                expected,
                "origin {origin}, ray {i}"
            );
            blocked += expected as usize;
        }
    }
    assert!(
        blocked > 2000,
        "the test must exercise blocked rays: {blocked}"
    );
}

#[test]
fn a_blocker_a_hair_from_the_origin_blocks_in_the_traversal_as_after_a_blocker() {
    // A flat floor: its boxes are flat too, so a box test that started at some distance
    // would pass over a floor closer than that.
    let floor = [
        (0.0, 0.0),
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
    ];
    let geometry = Geometry::build(vec![triangles_shape(
        floor.iter().map(|&(x, z)| Vec3::new(x, 0.0, z)).collect(),
    )]);
    for height in [3e-5, 6e-5, 9e-5, 2e-4] {
        let ray = Ray::new(Vec3::new(0.3, height, 0.6), Vec3::NEG_Y);
        assert!(geometry.intersect_brute_force(&ray).is_some());
        assert!(
            geometry.occluded(&ray),
            "{height} above the floor, traversed"
        );
        let mut blockers = RecentBlockers::default();
        assert!(geometry.occluded_after(&ray, &mut blockers));
        assert!(
            geometry.occluded_after(&ray, &mut blockers),
            "{height} above the floor, after a blocker"
        );
    }
}

/// A shape of one mesh from `positions`, three per triangle.
fn triangles_shape(positions: Vec<Vec3>) -> ShapeInput {
    let triangles = (0..positions.len() as u32 / 3)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let mesh = TriangleMesh {
        positions,
        triangles,
        ..TriangleMesh::default()
    };
    ShapeInput {
        geometry: ShapeGeometry::Mesh(mesh),
        flip_normals: false,
        rotation: None,
    }
}

/// The shafts' scene: a floor (shape 0) under small triangles (shape 1) and spheres
/// (shapes 2 to 21), a square light (shape 22) and a sphere light (shape 23) above.
fn shaft_scene(rng: &mut Pcg32) -> (Geometry, [Vec3; 4], Sphere) {
    let floor = [
        (0.0, 0.0),
        (10.0, 0.0),
        (10.0, 10.0),
        (0.0, 0.0),
        (10.0, 10.0),
        (0.0, 10.0),
    ];
    let mut shapes = vec![triangles_shape(
        floor.iter().map(|&(x, z)| Vec3::new(x, 0.0, z)).collect(),
    )];
    let mut small = Vec::new();
    for _ in 0..40 {
        let centre = Vec3::new(
            10.0 * rng.next_f32(),
            0.3 + 3.0 * rng.next_f32(),
            10.0 * rng.next_f32(),
        );
        small.extend((0..3).map(|_| centre + random_unit(rng) * 0.4));
    }
    shapes.push(triangles_shape(small));
    for _ in 0..20 {
        let center = Vec3::new(
            10.0 * rng.next_f32(),
            0.3 + 3.0 * rng.next_f32(),
            10.0 * rng.next_f32(),
        );
        shapes.push(ShapeInput {
            geometry: ShapeGeometry::Sphere(Sphere {
                center,
                radius: 0.1 + 0.2 * rng.next_f32(),
            }),
            flip_normals: false,
            rotation: None,
        });
    }
    let corners =
        [(3.0, 3.0), (5.0, 3.0), (5.0, 5.0), (3.0, 5.0)].map(|(x, z)| Vec3::new(x, 4.0, z));
    let [a, b, c, d] = corners;
    shapes.push(triangles_shape(vec![a, b, c, a, c, d]));
    let light = Sphere {
        center: Vec3::new(7.0, 4.5, 6.0),
        radius: 0.6,
    };
    shapes.push(ShapeInput {
        geometry: ShapeGeometry::Sphere(light),
        flip_normals: false,
        rotation: None,
    });
    (Geometry::build(shapes), corners, light)
}

/// A random point of the rectangle of `corners`, or of `sphere`'s side seen from `apex`.
fn point_on_light(rng: &mut Pcg32, corners: &[Vec3; 4], sphere: Option<(&Sphere, Vec3)>) -> Vec3 {
    let Some((sphere, apex)) = sphere else {
        let (u, v) = (rng.next_f32(), rng.next_f32());
        return corners[0] + (corners[1] - corners[0]) * u + (corners[3] - corners[0]) * v;
    };
    loop {
        let point = sphere.center + random_unit(rng) * sphere.radius;
        if (point - sphere.center).dot(apex - point) > 0.0 {
            return point;
        }
    }
}

#[test]
fn every_ray_in_a_clear_shaft_is_free() {
    let mut rng = Pcg32::new(23, 5);
    let (geometry, corners, sphere) = shaft_scene(&mut rng);
    let (mut clear, mut not_clear) = ([0; 2], [0; 2]);
    for gather in 0..3000 {
        let point = Vec3::new(10.0 * rng.next_f32(), 0.0, 10.0 * rng.next_f32());
        let apex = offset_origin(point, Vec3::Y, Vec3::Y);
        let surface = LeavingSurface {
            point,
            normal: Vec3::Y,
            offset: apex.y - point.y,
        };
        let shafts = [
            (Shaft::to_rectangle(apex, corners, surface), 22, None),
            (
                Shaft::to_sphere(apex, sphere, surface),
                23,
                Some((&sphere, apex)),
            ),
        ];
        for (kind, (shaft, own_shape, on_sphere)) in shafts.into_iter().enumerate() {
            let shaft = shaft.expect("both lights lie wholly above the floor");
            if !geometry.shaft_is_clear(&shaft, own_shape) {
                not_clear[kind] += 1;
                continue;
            }
            clear[kind] += 1;
            for i in 0..64 {
                let target = point_on_light(&mut rng, &corners, on_sphere);
                let ray = spawn_ray_to(point, Vec3::Y, target);
                assert_eq!(ray.origin, apex);
                // Nothing but the light may block it. (A ray grazing a sphere light's rim
                // can meet the sphere itself within rounding, which a clear shaft does not
                // count: the segment to a point seen on a sphere never enters it.)
                let blocker = geometry.intersect_brute_force(&ray);
                let other = blocker.filter(|hit| hit.shape != own_shape);
                assert!(
                    other.is_none(),
                    "gather {gather}, light {kind}, ray {i}: {other:?}"
                );
            }
        }
    }
    // Both answers must be exercised, for both kinds of light. Embree's scenes cannot be
    // read by the shaft's traversal: they never answer that a shaft is clear.
    for kind in 0..2 {
        if cfg!(feature = "embree") {
            assert_eq!(clear[kind], 0, "Embree answers no shaft");
        } else {
            let both = clear[kind] > 300 && not_clear[kind] > 300;
            assert!(both, "{clear:?} clear, {not_clear:?} not");
        }
    }
}

/// A random point on the sphere or on the acne test's triangle.
fn random_surface_point(rng: &mut Pcg32, sphere: &Sphere) -> Vec3 {
    if rng.next_f32() < 0.5 {
        return sphere.center + random_unit(rng) * sphere.radius;
    }
    let (a, b) = (rng.next_f32(), rng.next_f32());
    let (a, b) = if a + b > 1.0 {
        (1.0 - a, 1.0 - b)
    } else {
        (a, b)
    };
    Vec3::new(500.0, 500.0, 500.0) * (1.0 - a - b)
        + Vec3::new(530.0, 480.0, 510.0) * a
        + Vec3::new(505.0, 530.0, 470.0) * b
}

#[test]
fn offset_rays_do_not_hit_the_surface_they_leave() {
    // A large sphere and a tilted, far-from-origin triangle: leaving the surface outward must
    // never hit the same surface (acne).
    let mut rng = Pcg32::new(8, 8);
    let sphere = Sphere {
        center: Vec3::new(100.0, -50.0, 30.0),
        radius: 20.0,
    };
    let mesh = TriangleMesh {
        positions: vec![
            Vec3::new(500.0, 500.0, 500.0),
            Vec3::new(530.0, 480.0, 510.0),
            Vec3::new(505.0, 530.0, 470.0),
        ],
        normals: None,
        texcoords: None,
        triangles: vec![[0, 1, 2]],
        attributes: Vec::new(),
    };
    let geometry = Geometry::build(vec![
        ShapeInput {
            geometry: ShapeGeometry::Sphere(sphere),
            flip_normals: false,
            rotation: None,
        },
        ShapeInput {
            geometry: ShapeGeometry::Mesh(mesh),
            flip_normals: false,
            rotation: None,
        },
    ]);
    let mut tested = 0;
    for _ in 0..20_000 {
        // A camera-like ray that hits something, then a ray leaving it on the normal's side.
        let target = random_surface_point(&mut rng, &sphere);
        let origin = target + random_unit(&mut rng) * 200.0;
        let Some(hit) = geometry.intersect(&Ray::new(origin, (target - origin).normalize())) else {
            continue;
        };
        let facing = if hit.geometric_normal.dot(origin - hit.point) > 0.0 {
            hit.geometric_normal
        } else {
            -hit.geometric_normal
        };
        let mut direction = random_unit(&mut rng);
        if direction.dot(facing) < 0.0 {
            direction = -direction;
        }
        let leaving = spawn_ray(hit.point, facing, direction);
        if let Some(again) = geometry.intersect(&leaving) {
            assert!(
                again.shape != hit.shape || again.t > 1e-2,
                "self-intersection at t = {}",
                again.t
            );
        }
        tested += 1;
    }
    assert!(tested > 10_000);
}

/// A shape group of random triangles and spheres in the unit box, as shapes.
fn random_group(rng: &mut Pcg32) -> Vec<ShapeInput> {
    let mut mesh = TriangleMesh::default();
    for t in 0..300u32 {
        let center = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        for _ in 0..3 {
            mesh.positions.push(center + random_unit(rng) * 0.1);
        }
        mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    let mut shapes = vec![ShapeInput {
        geometry: ShapeGeometry::Mesh(mesh),
        flip_normals: false,
        rotation: None,
    }];
    for _ in 0..10 {
        shapes.push(ShapeInput {
            geometry: ShapeGeometry::Sphere(Sphere {
                center: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
                radius: 0.02 + 0.08 * rng.next_f32(),
            }),
            flip_normals: false,
            rotation: None,
        });
    }
    shapes
}

/// `shape` moved by `to_world` (a rotation, a uniform scale and a translation).
fn placed(shape: &ShapeInput, to_world: glam::Affine3A) -> ShapeInput {
    let geometry = match &shape.geometry {
        ShapeGeometry::Mesh(mesh) => {
            let mut moved = mesh.clone();
            for p in &mut moved.positions {
                *p = to_world.transform_point3(*p);
            }
            ShapeGeometry::Mesh(moved)
        }
        ShapeGeometry::Sphere(s) => ShapeGeometry::Sphere(Sphere {
            center: to_world.transform_point3(s.center),
            radius: s.radius * to_world.transform_vector3(Vec3::X).length(),
        }),
        ShapeGeometry::Quadric(_) => panic!("the test's group holds no quadrics"),
    };
    ShapeInput {
        geometry,
        ..shape.clone()
    }
}

#[test]
fn instances_hit_what_copies_of_their_group_hit() {
    use ais_render::geometry::{InstanceInput, SceneShapes, ShapeGroupInput};
    let mut rng = Pcg32::new(47, 3);
    let group = random_group(&mut rng);
    let placements: Vec<glam::Affine3A> = (0..8)
        .map(|k| {
            let axis = random_unit(&mut rng);
            glam::Affine3A::from_scale_rotation_translation(
                Vec3::splat(1.0 + 2.0 * rng.next_f32()),
                glam::Quat::from_axis_angle(axis, 6.0 * rng.next_f32()),
                Vec3::new((k % 4) as f32 * 3.0, (k / 4) as f32 * 3.0, rng.next_f32()),
            )
        })
        .collect();
    let instanced = Geometry::build_instanced(SceneShapes {
        shapes: Vec::new(),
        groups: vec![ShapeGroupInput {
            shapes: group.clone(),
        }],
        instances: (placements.iter())
            .map(|&to_world| InstanceInput { group: 0, to_world })
            .collect(),
    });
    let copies = Geometry::build(
        (placements.iter())
            .flat_map(|&to_world| group.iter().map(move |shape| placed(shape, to_world)))
            .collect(),
    );
    assert_eq!(instanced.instance_count(), 8);
    assert_eq!(instanced.triangle_count(), 300, "the group is stored once");
    let mut hits = 0;
    for i in 0..4000 {
        let origin = Vec3::new(
            rng.next_f32() * 12.0,
            rng.next_f32() * 7.0,
            rng.next_f32() * 4.0,
        ) - Vec3::ONE;
        let mut ray = Ray::new(origin, random_unit(&mut rng));
        if i % 3 == 0 {
            ray.t_max = 4.0 * rng.next_f32();
        }
        let (ours, copied) = (instanced.intersect(&ray), copies.intersect(&ray));
        match (ours, copied) {
            (Some(a), Some(b)) => {
                assert!(
                    (a.t - b.t).abs() <= 1e-4 * b.t.max(1.0),
                    "ray {i}: {} vs {}",
                    a.t,
                    b.t
                );
                assert!((a.point - b.point).length() <= 1e-3, "ray {i}");
                let normals = a.geometric_normal.dot(b.geometric_normal);
                assert!(normals > 0.999, "ray {i}: normals {normals}");
                assert_eq!(a.shape == 0, b.shape % 11 == 0, "ray {i}: mesh or sphere");
                hits += 1;
            }
            (None, None) => {}
            (a, b) => panic!("ray {i}: instances {a:?} vs copies {b:?}"),
        }
        assert_eq!(instanced.occluded(&ray), copied.is_some(), "ray {i}");
        let brute = instanced.intersect_brute_force(&ray).map(|h| h.t);
        assert_eq!(brute.is_some(), copied.is_some(), "ray {i}: brute force");
    }
    assert!(hits > 300, "the test must exercise hits: {hits}");
}

#[test]
fn disks_and_cylinders_in_the_bvh_agree_with_brute_force() {
    use ais_render::geometry::Quadric;
    let mut rng = Pcg32::new(53, 5);
    let mut shapes = Vec::new();
    for k in 0..60 {
        let to_world = DMat4::from_translation(
            DVec3::new(
                rng.next_f32() as f64,
                rng.next_f32() as f64,
                rng.next_f32() as f64,
            ) * 8.0,
        ) * DMat4::from_axis_angle(
            random_unit(&mut rng).as_dvec3(),
            3.0 * rng.next_f32() as f64,
        ) * DMat4::from_scale(DVec3::new(0.3 + rng.next_f32() as f64, 0.5, 0.8));
        let quadric = if k % 2 == 0 {
            Quadric::disk(to_world)
        } else {
            Quadric::cylinder(to_world, DVec3::ZERO, DVec3::new(0.1, 0.2, 1.0), 0.4)
        };
        shapes.push(ShapeInput {
            geometry: ShapeGeometry::Quadric(quadric.unwrap()),
            flip_normals: false,
            rotation: None,
        });
    }
    let geometry = Geometry::build(shapes);
    let mut hits = 0;
    for i in 0..4000 {
        let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0 - 1.0;
        let ray = Ray::new(origin, random_unit(&mut rng));
        let (fast, slow) = (
            geometry.intersect(&ray),
            geometry.intersect_brute_force(&ray),
        );
        match (fast, slow) {
            (Some(a), Some(b)) => {
                assert!((a.t - b.t).abs() <= 1e-5 * b.t.max(1.0), "ray {i}");
                assert_eq!(a.shape, b.shape, "ray {i}");
                let on_surface = (a.point - ray.at(a.t)).length() < 1e-5;
                assert!(on_surface && a.geometric_normal.is_normalized(), "ray {i}");
                hits += 1;
            }
            (None, None) => {}
            (a, b) => panic!("ray {i}: BVH {a:?} vs brute force {b:?}"),
        }
        assert_eq!(geometry.occluded(&ray), slow.is_some(), "ray {i}");
    }
    assert!(hits > 300, "the test must exercise hits: {hits}");
}
