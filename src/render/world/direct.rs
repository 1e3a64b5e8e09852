//! Groups of a few primitives, intersected without an accelerator: each primitive against a
//! batch of rays at once, the rays in lanes (`WIDTH` at a time, in a loop compiled for AVX-512
//! and AVX2 as well as the baseline and chosen at run time, `multiversion`). Each lane runs
//! the primitive's own scalar test (`Primitive::intersect`'s arithmetic, branch-free), so a
//! ray's hit is the one the primitives tested one by one give, to the bit: the smallest t,
//! and on a tie the primitive listed first.

use super::SurfaceHit;
use crate::accel::{Hit, Ray};
use crate::geometry::{ball_crossings, Primitive};
use crate::spacetime::NullRay;
use glam::DVec3;
use multiversion::multiversion;
use std::sync::Arc;

/// Rays tested together.
const WIDTH: usize = 8;

/// A small group's primitives as the lanes test them, and the part each belongs to (so a hit
/// finds its material without a search).
pub struct DirectPrims {
    pub prims: Vec<Primitive>,
    pub parts: Vec<u32>,
}

impl DirectPrims {
    /// The primitives of `geometry`, made once.
    pub fn of(geometry: &crate::geometry::Geometry) -> DirectPrims {
        let n = geometry.len();
        let mut parts = Vec::with_capacity(n as usize);
        for (k, p) in geometry.parts.iter().enumerate() {
            parts.resize(p.end as usize, k as u32);
        }
        DirectPrims {
            prims: (0..n).map(|i| geometry.prim(i)).collect(),
            parts,
        }
    }
}

/// A chunk of rays as columns (origin, direction, interval), on the stack.
struct Chunk {
    o: [[f64; WIDTH]; 3],
    d: [[f64; WIDTH]; 3],
    tmin: [f64; WIDTH],
    /// The best hit so far (the interval's end until one is found), and its primitive.
    best: [f64; WIDTH],
    prim: [u32; WIDTH],
}

impl Chunk {
    /// Lanes without rays: each with an empty interval, and no hit.
    fn empty() -> Chunk {
        Chunk {
            o: [[0.0; WIDTH]; 3],
            d: [[1.0; WIDTH]; 3],
            tmin: [1.0; WIDTH],
            best: [0.0; WIDTH],
            prim: [u32::MAX; WIDTH],
        }
    }

    /// Lanes past the rays, and inactive rays, keep an empty interval.
    fn of(rays: &[Ray]) -> Chunk {
        let mut c = Chunk::empty();
        for (j, r) in rays.iter().enumerate() {
            for k in 0..3 {
                c.o[k][j] = r.origin[k];
                c.d[k][j] = r.dir[k];
            }
            c.tmin[j] = r.tmin;
            c.best[j] = r.tmax;
        }
        c
    }

    /// World rays as the rest rays of a group at rest in the world frame, unclipped, with
    /// the interval `span(j)` of ray j: `World::rest_ray`'s arithmetic for such a group (its
    /// origin moved by 0 along the ray, its interval by 0), so the lanes see the same numbers.
    fn of_world(rays: &[NullRay], span: impl Fn(usize) -> (f64, f64)) -> Chunk {
        let mut c = Chunk::empty();
        for (j, r) in rays.iter().enumerate() {
            let origin = r.origin.x + 0.0 * r.dir;
            for k in 0..3 {
                c.o[k][j] = origin[k];
                c.d[k][j] = r.dir[k];
            }
            let (tmin, tmax) = span(j);
            c.tmin[j] = tmin - 0.0;
            c.best[j] = tmax - 0.0;
        }
        c
    }

    #[inline(always)]
    fn ray(&self, j: usize) -> (DVec3, DVec3) {
        let v = |c: &[[f64; WIDTH]; 3]| DVec3::new(c[0][j], c[1][j], c[2][j]);
        (v(&self.o), v(&self.d))
    }
}

/// The closest hit of each ray among `prims` (None for inactive rays and misses), in lanes
/// where `simd`, else one ray at a time.
pub(super) fn intersect(prims: &[Primitive], rays: &[Ray], hits: &mut [Option<Hit>], simd: bool) {
    for (rs, hs) in rays.chunks(WIDTH).zip(hits.chunks_mut(WIDTH)) {
        let mut c = Chunk::of(rs);
        test(prims, &mut c, false, simd);
        for (j, h) in hs.iter_mut().enumerate() {
            *h = (c.prim[j] != u32::MAX).then_some(Hit {
                t: c.best[j],
                prim: c.prim[j],
            });
        }
    }
}

/// Whether anything of `prims` lies on each ray (false for inactive rays).
pub(super) fn occluded(prims: &[Primitive], rays: &[Ray], out: &mut [bool], simd: bool) {
    for (rs, os) in rays.chunks(WIDTH).zip(out.chunks_mut(WIDTH)) {
        let mut c = Chunk::of(rs);
        // Lanes past the rays count as met, so the chunk stops once its rays are.
        c.prim[rs.len()..].iter_mut().for_each(|p| *p = 0);
        test(prims, &mut c, true, simd);
        for (j, o) in os.iter_mut().enumerate() {
            *o = c.prim[j] != u32::MAX;
        }
    }
}

/// A world whose every group is small (`DirectPrims`) and at rest in the world frame, and
/// whose rays are not clipped to the groups' bounds (`World::at_rest`). There a world ray is
/// each group's rest ray, so a chunk of rays is made once, straight from the world rays, and
/// tested against every group's primitives in turn, without a rest ray or a hit made per
/// group. The hits are the ones `World::closest_hits` and `World::occluded_many` find group
/// by group, to the bit: each group's rays end at the best hit so far, which a later group
/// must beat (on a tie the earlier group keeps it).
pub struct AtRest {
    pub groups: Box<[Arc<DirectPrims>]>,
    pub simd: bool,
}

impl AtRest {
    /// The closest hit of each ray (lookback from `tmin` on) as the world's surface hit.
    pub fn closest_hits(&self, rays: &[NullRay], tmin: f64, out: &mut [Option<SurfaceHit>]) {
        for (rs, os) in rays.chunks(WIDTH).zip(out.chunks_mut(WIDTH)) {
            let mut c = Chunk::of_world(rs, |_| (tmin, f64::INFINITY));
            let mut met = [(0, u32::MAX); WIDTH];
            for (gi, g) in self.groups.iter().enumerate() {
                c.prim = [u32::MAX; WIDTH];
                test(&g.prims, &mut c, false, self.simd);
                for (m, &p) in met.iter_mut().zip(&c.prim) {
                    if p != u32::MAX {
                        *m = (gi, p);
                    }
                }
            }
            for (j, o) in os.iter_mut().enumerate() {
                let (group, prim) = met[j];
                // `hit_on` of the rest ray, moved by 0 and with lookback factor 1.
                *o = (prim != u32::MAX).then(|| {
                    let (origin, dir) = c.ray(j);
                    let t = c.best[j];
                    SurfaceHit {
                        group,
                        prim,
                        lambda: 0.0 + t,
                        point: origin + t * dir,
                        dir,
                        s: 1.0,
                    }
                });
            }
        }
    }

    /// Whether anything lies on each ray between lookback 0 and `tmax[i]`.
    pub fn occluded(&self, rays: &[NullRay], tmax: &[f64], out: &mut [bool]) {
        let chunks = rays.chunks(WIDTH).zip(tmax.chunks(WIDTH));
        for ((rs, ts), os) in chunks.zip(out.chunks_mut(WIDTH)) {
            let mut c = Chunk::of_world(rs, |j| (0.0, ts[j]));
            // Lanes past the rays count as met, so the chunk stops once its rays are; a ray
            // met in one group stays met through the next.
            c.prim[rs.len()..].iter_mut().for_each(|p| *p = 0);
            for g in self.groups.iter() {
                test(&g.prims, &mut c, true, self.simd);
                if c.prim.iter().all(|&p| p != u32::MAX) {
                    break;
                }
            }
            for (j, o) in os.iter_mut().enumerate() {
                *o = c.prim[j] != u32::MAX;
            }
        }
    }
}

/// `prims` against the chunk, in lanes where `simd`.
#[inline(always)]
fn test(prims: &[Primitive], c: &mut Chunk, any: bool, simd: bool) {
    match simd {
        true => test_lanes(prims, c, any),
        false => test_prims(prims, c, any),
    }
}

/// Every primitive against the chunk's lanes (`any`: until every lane has met something).
#[multiversion(targets("x86_64+avx512f+avx512dq+avx512vl", "x86_64+avx2"))]
fn test_lanes(prims: &[Primitive], c: &mut Chunk, any: bool) {
    test_prims(prims, c, any);
}

#[inline(always)]
fn test_prims(prims: &[Primitive], c: &mut Chunk, any: bool) {
    for (i, p) in prims.iter().enumerate() {
        if test_all(p, i as u32, c) && any {
            break;
        }
    }
}

/// Primitive `p` (number `i`) against every lane, each lane's best hit kept; whether every
/// lane has now met something. That answer is gathered in the loop that keeps the hits, from
/// the values it has at hand: read back from the chunk after it, lane by lane, it waited on
/// the vector store that had just written them.
#[inline(always)]
fn test_all(p: &Primitive, i: u32, c: &mut Chunk) -> bool {
    let mut all = true;
    match *p {
        Primitive::Sphere { center, radius } => {
            for j in 0..WIDTH {
                let (o, d) = c.ray(j);
                let t = sphere_t(center, radius, o, d, c.tmin[j], c.best[j]);
                all &= keep(c, j, t, i);
            }
        }
        Primitive::Cuboid { min, max } => {
            for j in 0..WIDTH {
                let (o, d) = c.ray(j);
                let t = cuboid_t(min, max, o, d, c.tmin[j], c.best[j]);
                all &= keep(c, j, t, i);
            }
        }
        // Rods and triangles, one ray at a time (their tests branch).
        _ => {
            for j in 0..WIDTH {
                let (o, d) = c.ray(j);
                let t = p.intersect(o, d, c.tmin[j], c.best[j]);
                all &= keep(c, j, t.unwrap_or(f64::NAN), i);
            }
        }
    }
    all
}

/// Lane j's best hit becomes t (of primitive i) where t is a hit (not NaN); whether the lane
/// has met something.
#[inline(always)]
fn keep(c: &mut Chunk, j: usize, t: f64, i: u32) -> bool {
    let hit = !t.is_nan();
    let prim = if hit { i } else { c.prim[j] };
    c.best[j] = if hit { t } else { c.best[j] };
    c.prim[j] = prim;
    prim != u32::MAX
}

/// `Primitive::intersect` of a sphere, without branches: the first crossing in (tmin, tmax),
/// else NaN.
#[inline(always)]
fn sphere_t(c: DVec3, r: f64, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> f64 {
    let (h, t0, t1) = ball_crossings((o - c).to_array(), d.to_array(), r);
    let inside = |t: f64| t > tmin && t < tmax;
    let t = if inside(t0) {
        t0
    } else if inside(t1) {
        t1
    } else {
        f64::NAN
    };
    if h >= 0.0 && d.length_squared() != 0.0 {
        t
    } else {
        f64::NAN
    }
}

/// `Primitive::intersect` of a box, without branches: the first crossing of its surface in
/// (tmin, tmax), else NaN.
#[inline(always)]
fn cuboid_t(min: DVec3, max: DVec3, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> f64 {
    let inv = d.recip();
    let a = (min - o) * inv;
    let bb = (max - o) * inv;
    let lo = a.min(bb);
    let hi = a.max(bb);
    let t0 = lo.x.max(lo.y).max(lo.z);
    let t1 = hi.x.min(hi.y).min(hi.z);
    let inside = |t: f64| t > tmin && t < tmax;
    let t = if inside(t0) {
        t0
    } else if inside(t1) {
        t1
    } else {
        f64::NAN
    };
    if t0 > t1 {
        f64::NAN
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Every lane's hit is the primitives' one-by-one hit, to the bit, in lanes and without,
    /// for rays from inside and outside, grazing and inactive.
    #[test]
    fn lanes_are_the_scalar_tests() {
        let prims = vec![
            Primitive::Cuboid {
                min: DVec3::new(-5.0, -5.5, -5.0),
                max: DVec3::new(5.0, -5.0, 5.0),
            },
            Primitive::Sphere {
                center: DVec3::new(-2.0, -3.2, -1.0),
                radius: 1.8,
            },
            Primitive::Cuboid {
                min: DVec3::new(-5.5, -5.0, -5.0),
                max: DVec3::new(-5.0, 5.0, 5.0),
            },
            Primitive::Capsule {
                a: DVec3::new(1.0, 0.0, 0.0),
                b: DVec3::new(1.0, 2.0, 0.5),
                radius: 0.3,
            },
            Primitive::Sphere {
                center: DVec3::new(0.0, 4.0, 0.0),
                radius: 0.6,
            },
            Primitive::Triangle {
                v: [
                    DVec3::new(-1.0, 0.0, -2.0),
                    DVec3::new(1.0, 0.0, -2.0),
                    DVec3::new(0.0, 1.0, -2.5),
                ],
            },
            // The same box again: ties go to the first.
            Primitive::Cuboid {
                min: DVec3::new(-5.0, -5.5, -5.0),
                max: DVec3::new(5.0, -5.0, 5.0),
            },
        ];
        let mut rng = Rng(9);
        let mut rays = Vec::new();
        for k in 0..4000 {
            let o = DVec3::new(
                rng.range(-7.0, 7.0),
                rng.range(-7.0, 7.0),
                rng.range(-7.0, 7.0),
            );
            let d = rng.unit() * rng.range(0.5, 2.0);
            let (tmin, tmax) = match k % 5 {
                0 => (0.0, f64::INFINITY),
                1 => (0.0, rng.range(0.0, 6.0)),
                2 => (1.0, 0.0),
                _ => (rng.range(0.0, 0.01), f64::INFINITY),
            };
            rays.push(Ray::new(o, d, tmin, tmax));
        }
        // Axis-parallel rays (zero components, infinite inverses).
        rays.push(Ray::new(
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::NEG_Y,
            0.0,
            f64::INFINITY,
        ));
        rays.push(Ray::new(
            DVec3::new(-5.0, 0.0, 0.0),
            DVec3::X,
            0.0,
            f64::INFINITY,
        ));
        let want: Vec<Option<Hit>> = rays
            .iter()
            .map(|r| {
                let mut best: Option<Hit> = None;
                if r.is_active() {
                    for (i, p) in prims.iter().enumerate() {
                        let tmax = best.map_or(r.tmax, |h| h.t);
                        if let Some(t) = p.intersect(r.origin, r.dir, r.tmin, tmax) {
                            best = Some(Hit { t, prim: i as u32 });
                        }
                    }
                }
                best
            })
            .collect();
        for simd in [true, false] {
            let mut got = vec![None; rays.len()];
            intersect(&prims, &rays, &mut got, simd);
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                let same = match (g, w) {
                    (Some(a), Some(b)) => a.t.to_bits() == b.t.to_bits() && a.prim == b.prim,
                    (None, None) => true,
                    _ => false,
                };
                assert!(
                    same,
                    "ray {k} ({:?}), simd {simd}: {g:?} against {w:?}",
                    rays[k]
                );
            }
            let mut blocked = vec![false; rays.len()];
            occluded(&prims, &rays, &mut blocked, simd);
            for (k, (b, w)) in blocked.iter().zip(&want).enumerate() {
                assert_eq!(*b, w.is_some(), "ray {k}, simd {simd}");
            }
        }
    }
}
