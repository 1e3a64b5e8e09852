//! The exact f64 tests of one primitive for every lane of a packet that may meet it, several
//! lanes at once.
//!
//! Embree's coherent traversal calls a user primitive's callback with a whole packet; on the
//! paper's lattice 9.7 lanes per call pass the lane cull at rest, 6.8 at β = 0.9 and 3.6 at
//! β = 0.99 (counted). Tested one by one, each lane's rod or sphere costs a chain of a square
//! root and divisions; here the lanes are gathered into columns and the same branch-free
//! arithmetic (`cylinder_crossings`, `ball_crossings`, shared with the scalar tests, so the
//! results are the same to the bit) runs four lanes per AVX2 vector. A lane whose answer needs
//! a branch (the entry, or for a ray that starts inside or past the rod the exit, beyond a rod's
//! end, so its end ball decides; a ray along the axis) is left undecided, and the callback asks
//! the scalar test.

#[cfg(target_arch = "x86_64")]
use super::f64x4::F4;
use crate::geometry::AxisRod;
#[cfg(target_arch = "x86_64")]
use crate::geometry::{ball_crossings, cylinder_crossings, Real};
use glam::DVec3;
use std::mem::MaybeUninit;

/// A capsule (or with a = b, a sphere).
#[derive(Clone, Copy, Debug)]
pub struct Round {
    pub a: DVec3,
    pub b: DVec3,
    pub radius: f64,
}

/// The most lanes of a packet (Embree's widest, 16).
pub(super) const MAX: usize = 16;

/// The rays of the lanes to test, as columns (relative to the Embree scene's centre), each with
/// its packet lane and its interval (tmin, tmax).
///
/// Left uninitialised but for the fours that hold the entries set (the rest zeros): Embree
/// calls back for each primitive a ray may meet, and clearing all of it each time costs as much
/// as the few tests it feeds where packets are sparse (near c).
pub(super) struct LaneRays {
    /// Origin x, y, z, direction x, y, z, tmin, tmax.
    cols: [[MaybeUninit<f64>; MAX]; 8],
    lane: [u8; MAX],
    len: usize,
}

const TMIN: usize = 6;
const TMAX: usize = 7;

impl LaneRays {
    #[inline(always)]
    pub fn new() -> Self {
        LaneRays {
            cols: [[MaybeUninit::uninit(); MAX]; 8],
            lane: [0; MAX],
            len: 0,
        }
    }

    /// Sets the rays `(lane, origin, direction, tmin, tmax)`, at most MAX.
    #[inline(always)]
    pub fn gather(&mut self, rays: impl Iterator<Item = (usize, DVec3, DVec3, f64, f64)>) {
        let mut j = 0;
        for (lane, o, d, tmin, tmax) in rays.take(MAX) {
            if j % 4 == 0 {
                // A new four: zeros first, so the entries not set are numbers too (one vector
                // store per column; a loop over what is left would call memset).
                for col in &mut self.cols {
                    col[j..j + 4].copy_from_slice(&[MaybeUninit::new(0.0); 4]);
                }
            }
            let values = [o.x, o.y, o.z, d.x, d.y, d.z, tmin, tmax];
            for (col, v) in self.cols.iter_mut().zip(values) {
                col[j] = MaybeUninit::new(v);
            }
            self.lane[j] = lane as u8;
            j += 1;
        }
        self.len = j;
    }

    pub fn len(&self) -> usize {
        self.len
    }

    /// Column k's entries, through the end of the last four.
    #[inline(always)]
    fn col(&self, k: usize) -> &[f64] {
        let set = self.len.next_multiple_of(4);
        // SAFETY: `gather` initialised entries 0..set of every column.
        unsafe { std::slice::from_raw_parts(self.cols[k].as_ptr().cast::<f64>(), set) }
    }

    /// Entry j: packet lane, origin, direction, tmin, tmax.
    #[inline(always)]
    pub fn get(&self, j: usize) -> (usize, DVec3, DVec3, f64, f64) {
        let v = |k: usize| self.col(k)[j];
        (
            self.lane[j] as usize,
            DVec3::new(v(0), v(1), v(2)),
            DVec3::new(v(3), v(4), v(5)),
            v(TMIN),
            v(TMAX),
        )
    }
}

/// The answer for each entry: its hit's t; `f64::INFINITY`, no hit in (tmin, tmax); NaN, not
/// decided here (ask the primitive's scalar test).
pub(super) type Answers = [f64; MAX];

/// The rod's or sphere's answers for the entries; all NaN for a rod that is not along x, y or
/// z, or on a CPU without AVX2.
#[inline]
pub(super) fn round_hits(prim: &Round, rays: &LaneRays, out: &mut Answers) {
    let kernel = if prim.a == prim.b {
        Kernel::Sphere {
            c: prim.a,
            r: prim.radius,
        }
    } else {
        match AxisRod::of(prim.a, prim.b) {
            Some(rod) => Kernel::Rod {
                rod,
                rr: prim.radius * prim.radius,
            },
            None => return out.fill(f64::NAN),
        }
    };
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just now).
        return unsafe { run_avx2(&kernel, rays, out) };
    }
    let _ = (kernel, rays);
    out.fill(f64::NAN)
}

enum Kernel {
    /// A rod along a coordinate axis, of radius² rr.
    Rod {
        rod: AxisRod,
        rr: f64,
    },
    Sphere {
        c: DVec3,
        r: f64,
    },
}

/// Four entries at a time; the entries past `len` in the last four are computed and ignored.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2(kernel: &Kernel, rays: &LaneRays, out: &mut Answers) {
    for c in (0..rays.len).step_by(4) {
        // SAFETY: this function runs with AVX2.
        let load = |k: usize| unsafe { F4::load(rays.col(k)[c..c + 4].try_into().unwrap()) };
        let (tmin, tmax) = (load(TMIN), load(TMAX));
        let ans = match *kernel {
            Kernel::Rod {
                rod: AxisRod { k, lo, len, .. },
                rr,
            } => {
                let (u, v) = ((k + 1) % 3, (k + 2) % 3);
                let oa = [
                    load(k) - F4::splat(lo[k]),
                    load(u) - F4::splat(lo[u]),
                    load(v) - F4::splat(lo[v]),
                ];
                let d = [load(3 + k), load(3 + u), load(3 + v)];
                rod(oa, d, len, rr, tmin, tmax)
            }
            Kernel::Sphere { c, r } => {
                let oc = [
                    load(0) - F4::splat(c.x),
                    load(1) - F4::splat(c.y),
                    load(2) - F4::splat(c.z),
                ];
                let d = [load(3), load(4), load(5)];
                sphere(oc, d, r, tmin, tmax)
            }
        };
        out[c..c + 4].copy_from_slice(&ans.store());
    }
}

/// Four entries against a rod along the first axis of `oa` (origins from the rod's lower end,
/// axis component first), as `capsule_hit` decides them where the entry lies beside the segment:
/// the entry if it comes after tmin, else (a ray from inside, or a rod behind it: shadow rays
/// leaving a surface) the exit, if that lies beside the segment too.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn rod(oa: [F4; 3], d: [F4; 3], len: f64, rr: f64, tmin: F4, tmax: F4) -> F4 {
    let (h, c0, c1) = cylinder_crossings(oa[1], oa[2], d[1], d[2], F4::splat(rr));
    let (zero, inf, nan, len) = (
        F4::splat(0.0),
        F4::splat(f64::INFINITY),
        F4::splat(f64::NAN),
        F4::splat(len),
    );
    let beside = |t: F4| {
        let y = oa[0] + t * d[0];
        zero.lt(y).and(y.lt(len))
    };
    let (beside0, beside1) = (beside(c0), beside(c1));
    let entry = F4::select(c0.lt(tmax), c0, inf);
    let exit = F4::select(tmin.lt(c1).and(c1.lt(tmax)), c1, inf);
    let decided = F4::select(beside0.and(beside1).and(tmin.ge(c0)), exit, nan);
    let decided = F4::select(beside0.and(tmin.lt(c0)), entry, decided);
    // A miss of the infinite cylinder, which holds the capsule, is a miss.
    let decided = F4::select(h.lt(zero), inf, decided);
    // Along the axis the cylinder's roots are undefined.
    F4::select((d[1] * d[1] + d[2] * d[2]).ne_zero(), decided, nan)
}

/// Four entries against a sphere, as `sphere_hit` decides them.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn sphere(oc: [F4; 3], d: [F4; 3], r: f64, tmin: F4, tmax: F4) -> F4 {
    let (h, t0, t1) = ball_crossings(oc, d, F4::splat(r));
    let t = F4::select(tmin.lt(t0), t0, t1);
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let ok = dd
        .ne_zero()
        .and(h.ge(F4::splat(0.0)))
        .and(tmin.lt(t))
        .and(t.lt(tmax));
    F4::select(ok, t, F4::splat(f64::INFINITY))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::embree::exact::Shape;

    use crate::rng::Rng;

    fn vec(r: &mut Rng, s: f64) -> DVec3 {
        DVec3::new(r.range(-s, s), r.range(-s, s), r.range(-s, s))
    }

    /// Every answer the several-ray test decides is the scalar test's, to the bit: rods along
    /// each axis (either end first) and spheres; rays from near and far (up to 1e6 away), from
    /// inside, along the axis, grazing; intervals that cut the hit off.
    #[test]
    fn decided_answers_are_the_scalar_tests() {
        let mut rng = Rng(11);
        let (mut decided, mut hits, mut total) = (0, 0, 0);
        // Rays from inside a rod (the entry before tmin: the exit decides), and how many of
        // them were decided here.
        let (mut inside, mut inside_decided) = (0, 0);
        for case in 0..4000 {
            let a = vec(&mut rng, 2.0);
            let b = match case % 4 {
                0 => a,
                k => {
                    let mut e = DVec3::ZERO;
                    e[k - 1] = rng.range(-3.0, 3.0);
                    a + e
                }
            };
            let prim = Round {
                a,
                b,
                radius: rng.range(0.01, 0.5),
            };
            let rays: Vec<(usize, DVec3, DVec3, f64, f64)> = (0..1 + case % MAX)
                .map(|lane| {
                    let far = [1.0, 10.0, 1e3, 1e6][lane % 4];
                    let target =
                        a + (b - a) * rng.range(-0.2, 1.2) + vec(&mut rng, prim.radius * 1.5);
                    let o = match lane % 7 {
                        // From inside.
                        0 => a + (b - a) * rng.f() + vec(&mut rng, prim.radius * 0.5),
                        _ => target + vec(&mut rng, 1.0).normalize() * far,
                    };
                    let mut d = (target - o) * rng.range(0.1, 3.0);
                    if lane % 11 == 5 {
                        // Along the axis (a rod's), or straight through the centre.
                        d = (b - a).normalize_or(DVec3::X);
                    }
                    if d == DVec3::ZERO {
                        d = DVec3::Y;
                    }
                    let tmin = if lane % 5 == 0 { 0.5 } else { 0.0 };
                    let tmax = if lane % 3 == 0 {
                        rng.range(0.5, 2.0) * far / d.length()
                    } else {
                        f64::INFINITY
                    };
                    (lane, o, d, tmin, tmax)
                })
                .collect();
            let mut lanes = LaneRays::new();
            lanes.gather(rays.iter().copied());
            let mut out = [0.0; MAX];
            round_hits(&prim, &lanes, &mut out);
            for (j, &(lane, o, d, tmin, tmax)) in rays.iter().enumerate() {
                assert_eq!(lanes.get(j), (lane, o, d, tmin, tmax));
                let want = prim.hit(o, d, tmin, tmax);
                total += 1;
                hits += want.is_some() as usize;
                inside += usize::from(case % 4 != 0 && lane % 7 == 0);
                if out[j].is_nan() {
                    continue;
                }
                decided += 1;
                if case % 4 != 0 && lane % 7 == 0 {
                    inside_decided += 1;
                }
                let got = (out[j] < f64::INFINITY).then_some(out[j]);
                assert_eq!(
                    got, want,
                    "case {case} lane {lane}: {prim:?}, ray {o} + t {d}, ({tmin}, {tmax})"
                );
            }
        }
        assert!(hits > total / 5, "only {hits} of {total} rays hit");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            assert!(decided > total / 2, "only {decided} of {total} decided");
            assert!(
                inside_decided > inside / 4,
                "only {inside_decided} of {inside} rays from inside a rod decided"
            );
        }
    }
}
