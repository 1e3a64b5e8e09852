//! Which lanes of a packet may meet a user primitive, before its exact f64 test.
//!
//! Embree's traversal of coherent packets culls nodes by the packet's frustum and calls a user
//! primitive's callback with every lane still open, not only the lanes whose ray meets the
//! primitive's box: on the paper's lattice a quarter of those lanes miss the box at rest and
//! two thirds at β = 0.99 (counted). Each would cost an exact capsule test; one separating-axis
//! test of all lanes at once, in f32 and without divisions, drops them first.

use glam::DVec3;

/// Field offsets (in lanes) of Embree's N-wide SoA ray: origin x, y, z, then tnear, then
/// direction x, y, z.
use super::rtc::field::{DIR, ORG};

/// Relative padding of the box: Embree's f32 ray is the caller's f64 ray rounded (2⁻²⁴ of its
/// coordinates), and the test's own f32 products round as much again; 1e-5 is a hundredfold
/// margin, so a lane whose exact ray meets the primitive is never dropped.
const PAD: f32 = 1e-5;

/// The lanes among `valid` (n entries, nonzero = valid) whose ray may meet the box `(lo, hi)`,
/// in order.
///
/// # Safety
/// `ray` points to an n-wide SoA ray (`RTCRayN` or `RTCRayHitN`), `valid` to its n entries.
#[inline(always)]
pub(super) unsafe fn lanes_near(
    valid: *const i32,
    ray: *const f32,
    n: usize,
    lo: DVec3,
    hi: DVec3,
) -> impl Iterator<Item = usize> {
    let near = unsafe {
        match n {
            16 => near::<16>(ray, lo, hi),
            8 => near::<8>(ray, lo, hi),
            4 => near::<4>(ray, lo, hi),
            // Single rays come from Embree's per-ray traversal, which tested the box already.
            _ => u32::MAX,
        }
    };
    let mut open = 0u32;
    for i in 0..n {
        open |= u32::from(unsafe { *valid.add(i) } != 0) << i;
    }
    let mut bits = open & near;
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            i
        })
    })
}

/// `near_box` in the widest vectors this CPU has: AVX2 runs eight lanes at once, the baseline
/// x86-64 target four (SSE's packets are four wide).
unsafe fn near<const N: usize>(ray: *const f32, lo: DVec3, hi: DVec3) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return unsafe { near_avx2::<N>(ray, lo, hi) };
    }
    unsafe { near_box::<N>(ray, lo, hi) }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn near_avx2<const N: usize>(ray: *const f32, lo: DVec3, hi: DVec3) -> u32 {
    unsafe { near_box::<N>(ray, lo, hi) }
}

/// Bit i set unless lane i's line provably misses the box (padded): one of the three axes
/// perpendicular to both the line and a box edge separates them (|w × d| against the box's
/// projected half widths, w the origin relative to the box's centre). Lines, not rays: the
/// frustum traversal already keeps boxes behind a packet out, so testing the rays' ends as
/// well would add work that rarely drops a lane.
///
/// # Safety
/// `ray` points to an N-wide SoA ray, N 4 or a multiple of 8 (at most 32).
#[inline(always)]
unsafe fn near_box<const N: usize>(ray: *const f32, lo: DVec3, hi: DVec3) -> u32 {
    const { assert!((N == 4 || N.is_multiple_of(8)) && N <= 32) };
    // Lanes per step: eight (one AVX vector), or all four of a 4-wide packet.
    let step = N.min(8);
    // SAFETY: fields ORG.. and DIR.. of an N-wide SoA ray are N floats each.
    let field = |k: usize| unsafe { &*(ray.add(k * N) as *const [f32; N]) };
    let (ox, oy, oz) = (field(ORG), field(ORG + 1), field(ORG + 2));
    let (dx, dy, dz) = (field(DIR), field(DIR + 1), field(DIR + 2));
    let c = (lo + hi) * 0.5;
    let e = (hi - lo) * 0.5;
    // Sums of magnitudes bound the coordinates (and are cheaper than maxima).
    let reach = (c.abs().element_sum() + e.element_sum()) as f32;
    let (cx, cy, cz) = (c.x as f32, c.y as f32, c.z as f32);
    let (ex, ey, ez) = (e.x as f32, e.y as f32, e.z as f32);
    let mut bits = 0u32;
    // Eight lanes at a time: one AVX vector, few enough values to stay in registers.
    for k in (0..N).step_by(step) {
        let mut near = [0u8; 8];
        for (j, v) in near.iter_mut().enumerate().take(step) {
            let i = k + j;
            let (x, y, z) = (dx[i], dy[i], dz[i]);
            let pad = PAD * (reach + ox[i].abs() + oy[i].abs() + oz[i].abs());
            let (ax, ay, az) = (ex + pad, ey + pad, ez + pad);
            let (wx, wy, wz) = (ox[i] - cx, oy[i] - cy, oz[i] - cz);
            let (ux, uy, uz) = (x.abs(), y.abs(), z.abs());
            // `|`, not `||`, so the lanes stay in vectors.
            let apart = ((wy * z - wz * y).abs() > ay * uz + az * uy)
                | ((wz * x - wx * z).abs() > az * ux + ax * uz)
                | ((wx * y - wy * x).abs() > ax * uy + ay * ux);
            *v = u8::from(!apart);
        }
        let byte = near
            .iter()
            .enumerate()
            .fold(0u32, |b, (j, &v)| b | (u32::from(v) << j));
        bits |= byte << k;
    }
    bits
}
