//! The scene's triangles in runs of eight, laid out lane by lane, so that the triangles a
//! BVH node hands to traversal (up to 24, numbered consecutively) are tested eight at a
//! time with the CPU's vector units rather than one after another.
//!
//! Primitive `i` sits in lane `i % 8` of run `i / 8`. A slot that holds no triangle (a
//! sphere, a quadric, an instance, or the padding after the last primitive) is all zeros, a
//! degenerate triangle that no ray hits; [`TriangleLanes::others`] names those primitives, to
//! be tested one by one. Each lane's arithmetic is the scalar Möller-Trumbore test's, in the
//! same order, so hits and distances agree with it to the bit.

use super::primitive::Packed;
use super::ray::Ray;
use glam::{Vec2, Vec3};

/// Triangles per run: one AVX register of f32.
const LANES: usize = 8;

/// Eight triangles, each coordinate of v0, v1 − v0 and v2 − v0 in a row of its own.
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
struct Run {
    v0: [[f32; LANES]; 3],
    e1: [[f32; LANES]; 3],
    e2: [[f32; LANES]; 3],
}

/// The hits of one run's triangles: which lanes hit (bit per lane), and each lane's
/// distance (infinite where it misses) and barycentrics.
struct RunHits {
    lanes: u32,
    t: [f32; LANES],
    b1: [f32; LANES],
    b2: [f32; LANES],
}

/// A triangle hit among a node's primitives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LaneHit {
    /// The primitive's index (BVH order).
    pub(crate) index: usize,
    /// Distance along the ray.
    pub(crate) t: f32,
    /// Barycentrics (b1, b2).
    pub(crate) barycentrics: Vec2,
}

/// The triangles of a BVH's primitives, in its order, in runs of eight lanes.
#[derive(Default)]
pub(crate) struct TriangleLanes {
    runs: Vec<Run>,
    /// Bit `i % 64` of word `i / 64`: primitive `i` is not a triangle.
    others: Vec<u64>,
    /// Whether any primitive is not a triangle.
    any_others: bool,
}

impl TriangleLanes {
    /// The lanes of `packed` (the primitives in BVH order).
    pub(crate) fn new(packed: &[Packed]) -> Self {
        // Room for a last, partial run, and a word past the last one: `others` reads two
        // words at a time.
        let mut runs = vec![Run::default(); packed.len() / LANES + 1];
        let mut others = vec![0u64; packed.len() / 64 + 2];
        for (i, primitive) in packed.iter().enumerate() {
            let (run, lane) = (&mut runs[i / LANES], i % LANES);
            let Packed::Triangle([v0, e1, e2]) = primitive else {
                others[i / 64] |= 1 << (i % 64);
                continue;
            };
            for axis in 0..3 {
                run.v0[axis][lane] = v0[axis];
                run.e1[axis][lane] = e1[axis];
                run.e2[axis][lane] = e2[axis];
            }
        }
        let any_others = others.iter().any(|&word| word != 0);
        TriangleLanes {
            runs,
            others,
            any_others,
        }
    }

    /// The primitives among `group` (bit k: primitive `base + k`, k < 24) that are not
    /// triangles, in the same form.
    #[inline]
    pub(crate) fn others(&self, base: u32, group: u32) -> u32 {
        if !self.any_others {
            return 0;
        }
        let (word, shift) = (base as usize / 64, base % 64);
        let low = self.others[word] >> shift;
        let high = if shift == 0 {
            0
        } else {
            self.others[word + 1] << (64 - shift)
        };
        (low | high) as u32 & group
    }

    /// A triangle among `group` (bit k: primitive `base + k`) that blocks `ray` before
    /// `t_max`, if any.
    #[inline(always)]
    pub(crate) fn any_hit(&self, base: u32, group: u32, ray: &Ray, t_max: f32) -> Option<usize> {
        let first_run = base as usize / LANES;
        let mut lanes = (group as u64) << (base as usize % LANES);
        let mut run = first_run;
        while lanes != 0 {
            let in_run = (lanes & 0xff) as u32;
            let hit = if in_run != 0 {
                self.runs[run].hits(ray, t_max).lanes & in_run
            } else {
                0
            };
            if hit != 0 {
                return Some(run * LANES + hit.trailing_zeros() as usize);
            }
            lanes >>= LANES;
            run += 1;
        }
        None
    }

    /// Whether a triangle of the run that holds primitive `index` (its seven neighbours in
    /// BVH order, and itself) blocks `ray` before `t_max`. Slots without a triangle hold a
    /// degenerate one that no ray hits.
    #[inline]
    pub(crate) fn run_blocks(&self, index: usize, ray: &Ray, t_max: f32) -> bool {
        self.runs[index / LANES].hits(ray, t_max).lanes != 0
    }

    /// The nearest triangle among `group` (bit k: primitive `base + k`) that `ray` hits
    /// before `t_max`. Of equally near ones, the one of highest index, as a test of one
    /// primitive after another from the highest down keeps.
    #[inline(always)]
    pub(crate) fn nearest(&self, base: u32, group: u32, ray: &Ray, t_max: f32) -> Option<LaneHit> {
        let first_run = base as usize / LANES;
        let lanes = (group as u64) << (base as usize % LANES);
        let mut nearest: Option<LaneHit> = None;
        let mut t_max = t_max;
        // From the last run down, and each run's lanes from the last down.
        for offset in (0..4).rev() {
            let in_run = (lanes >> (offset * LANES)) as u32 & 0xff;
            if in_run == 0 {
                continue;
            }
            let run = first_run + offset;
            let hits = self.runs[run].hits(ray, t_max);
            for lane in (0..LANES).rev() {
                if in_run & 1 << lane != 0 && hits.t[lane] < t_max {
                    t_max = hits.t[lane];
                    nearest = Some(LaneHit {
                        index: run * LANES + lane,
                        t: hits.t[lane],
                        barycentrics: Vec2::new(hits.b1[lane], hits.b2[lane]),
                    });
                }
            }
        }
        nearest
    }
}

impl Run {
    /// Möller-Trumbore on all eight lanes, each lane's arithmetic that of the scalar test
    /// (`primitive::moller_trumbore`), so that the vector units run them side by side.
    #[inline(always)]
    fn hits(&self, ray: &Ray, t_max: f32) -> RunHits {
        let mut out = RunHits {
            lanes: 0,
            t: [f32::INFINITY; LANES],
            b1: [0.0; LANES],
            b2: [0.0; LANES],
        };
        let (o, d) = (ray.origin, ray.direction);
        for lane in 0..LANES {
            let at =
                |rows: &[[f32; LANES]; 3]| Vec3::new(rows[0][lane], rows[1][lane], rows[2][lane]);
            let (v0, e1, e2) = (at(&self.v0), at(&self.e1), at(&self.e2));
            let p = d.cross(e2);
            let determinant = e1.dot(p);
            let inverse = 1.0 / determinant;
            let s = o - v0;
            let b1 = s.dot(p) * inverse;
            let q = s.cross(e1);
            let b2 = d.dot(q) * inverse;
            let t = e2.dot(q) * inverse;
            // `&`, not `&&`: every condition evaluated, no branch per lane.
            // (A NaN determinant, which the scalar test lets through, fails at `b1`.)
            let hit = (determinant.abs() >= 1e-20)
                & (0.0..=1.0).contains(&b1)
                & !((b2 < 0.0) | (b1 + b2 > 1.0))
                & (t > 0.0)
                & (t < t_max);
            out.t[lane] = if hit { t } else { f32::INFINITY };
            out.b1[lane] = b1;
            out.b2[lane] = b2;
        }
        // The hit lanes as bits, in a pass of their own (in the loop above it would keep
        // the loop from being vectorised).
        out.lanes = (0..LANES).fold(0, |bits, lane| {
            bits | ((out.t[lane] < f32::INFINITY) as u32) << lane
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::primitive::Sphere;
    use ais::rng::Pcg32;

    fn point(rng: &mut Pcg32, scale: f32) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale
    }

    /// Small triangles (every fifth primitive a sphere) crowded in a box.
    fn primitives(rng: &mut Pcg32, count: usize) -> Vec<Packed> {
        (0..count)
            .map(|i| {
                let v0 = point(rng, 4.0);
                if i % 5 == 4 {
                    return Packed::Sphere(Sphere {
                        center: v0,
                        radius: 0.3,
                    });
                }
                let e1 = point(rng, 2.0) - Vec3::ONE;
                Packed::Triangle([v0, e1, point(rng, 2.0) - Vec3::ONE])
            })
            .collect()
    }

    /// What one test after another, from the highest index down, finds among `group`.
    fn one_by_one(packed: &[Packed], base: u32, group: u32, ray: &Ray) -> Option<LaneHit> {
        let mut nearest: Option<LaneHit> = None;
        for k in (0..24).rev().filter(|k| group & 1 << k != 0) {
            let index = (base + k) as usize;
            let Packed::Triangle(_) = packed[index] else {
                continue;
            };
            let t_max = nearest.map_or(ray.t_max, |hit| hit.t);
            if let Some((t, barycentrics)) = packed[index].intersect(ray, t_max) {
                nearest = Some(LaneHit {
                    index,
                    t,
                    barycentrics,
                });
            }
        }
        nearest
    }

    #[test]
    fn lanes_find_what_one_test_after_another_finds_to_the_bit() {
        let mut rng = Pcg32::new(12, 5);
        let packed = primitives(&mut rng, 203);
        let lanes = TriangleLanes::new(&packed);
        let mut hits = 0;
        for i in 0..20_000 {
            let base = rng.next_u32() % 180;
            let reach = (packed.len() as u32 - base).min(24);
            let group = rng.next_u32() & ((1u32 << reach) - 1);
            let origin = point(&mut rng, 6.0) - Vec3::ONE;
            let direction = (point(&mut rng, 2.0) - Vec3::ONE).normalize_or(Vec3::X);
            let mut ray = Ray::new(origin, direction);
            if i % 3 == 0 {
                ray.t_max = 4.0 * rng.next_f32();
            }
            let expected = one_by_one(&packed, base, group, &ray);
            let found = lanes.nearest(base, group, &ray, ray.t_max);
            assert_eq!(
                found.map(|h| (h.index, h.t.to_bits())),
                expected.map(|h| (h.index, h.t.to_bits())),
                "ray {i}"
            );
            assert_eq!(
                found.map(|h| h.barycentrics),
                expected.map(|h| h.barycentrics)
            );
            assert_eq!(
                lanes.any_hit(base, group, &ray, ray.t_max).is_some(),
                expected.is_some()
            );
            hits += expected.is_some() as usize;
        }
        assert!(hits > 300, "the test must exercise hits: {hits}");
    }

    #[test]
    fn others_names_the_primitives_that_are_not_triangles() {
        let mut rng = Pcg32::new(3, 9);
        let packed = primitives(&mut rng, 150);
        let lanes = TriangleLanes::new(&packed);
        for base in 0..126u32 {
            let expected = (0..24)
                .filter(|&k| !matches!(packed[(base + k) as usize], Packed::Triangle(_)))
                .fold(0u32, |bits, k| bits | 1 << k);
            assert_eq!(lanes.others(base, 0xff_ffff), expected, "base {base}");
        }
        let triangles: Vec<Packed> = packed
            .into_iter()
            .filter(|p| matches!(p, Packed::Triangle(_)))
            .collect();
        assert_eq!(TriangleLanes::new(&triangles).others(0, 0xff_ffff), 0);
    }
}
