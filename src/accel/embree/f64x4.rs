//! Four f64 in one AVX vector, as a `Real`, for the several-ray primitive tests (`lane_hits`)
//! and the fans of primary rays (`fan_kernel.rs`).
//!
//! Written with the intrinsics rather than left to the compiler's vectoriser, which kept the
//! rod test scalar (it paired one ray's two square roots instead of four rays' one). An `F4` is
//! made only by `F4::load` and `Real::splat`, whose callers run with AVX2 enabled (`lane_hits`
//! and `fan` check the CPU first); the operations are inlined into them.

use crate::geometry::Real;
use std::arch::x86_64::*;
use std::ops::{Add, Div, Mul, Neg, Sub};

#[derive(Clone, Copy)]
pub(super) struct F4(__m256d);

impl F4 {
    /// Four consecutive values.
    ///
    /// # Safety
    /// The CPU has AVX (as every caller of this module's operations must).
    #[inline(always)]
    pub unsafe fn load(x: &[f64; 4]) -> Self {
        F4(unsafe { _mm256_loadu_pd(x.as_ptr()) })
    }

    #[inline(always)]
    pub fn store(self) -> [f64; 4] {
        let mut out = [0.0; 4];
        // SAFETY: an F4 exists only where the CPU has AVX (see the module's comment).
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), self.0) };
        out
    }

    /// The four values rounded to f32 (to nearest, as `as f32`), into `out`.
    #[inline(always)]
    pub fn store_f32(self, out: &mut [f32; 4]) {
        // SAFETY: as for `store`; `out` holds four f32.
        unsafe { _mm_storeu_ps(out.as_mut_ptr(), _mm256_cvtpd_ps(self.0)) };
    }

    /// Lane by lane: all ones where self < o (ordered), else zero.
    #[inline(always)]
    pub fn lt(self, o: Self) -> Self {
        // SAFETY: as for `store`.
        F4(unsafe { _mm256_cmp_pd::<_CMP_LT_OQ>(self.0, o.0) })
    }

    /// Lane by lane: all ones where self >= o (ordered), else zero.
    #[inline(always)]
    pub fn ge(self, o: Self) -> Self {
        // SAFETY: as for `store`.
        F4(unsafe { _mm256_cmp_pd::<_CMP_GE_OQ>(self.0, o.0) })
    }

    /// Lane by lane: the mask of both masks.
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        // SAFETY: as for `store`.
        F4(unsafe { _mm256_and_pd(self.0, o.0) })
    }
}

macro_rules! op {
    ($tr:ident, $f:ident, $intr:ident) => {
        impl $tr for F4 {
            type Output = F4;
            #[inline(always)]
            fn $f(self, o: F4) -> F4 {
                // SAFETY: as for `F4::store`.
                F4(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}
op!(Add, add, _mm256_add_pd);
op!(Sub, sub, _mm256_sub_pd);
op!(Mul, mul, _mm256_mul_pd);
op!(Div, div, _mm256_div_pd);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        // SAFETY: as for `F4::store`.
        F4(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}

impl Real for F4 {
    type Mask = F4;
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: as for `F4::store`.
        F4(unsafe { _mm256_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn signum(self) -> Self {
        // SAFETY: as for `F4::store`. 1 with self's sign bit: `1f64.copysign`.
        unsafe {
            let sign = _mm256_and_pd(self.0, _mm256_set1_pd(-0.0));
            F4(_mm256_or_pd(sign, _mm256_set1_pd(1.0)))
        }
    }
    // Where neither is NaN, as f64::min and f64::max (a NaN lane is never an answer).
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        // SAFETY: as for `F4::store`.
        F4(unsafe { _mm256_min_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // SAFETY: as for `F4::store`.
        F4(unsafe { _mm256_max_pd(self.0, o.0) })
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: as for `F4::store`.
        F4(unsafe { _mm256_set1_pd(x) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: as for `F4::store`. The sign bit cleared, as `f64::abs`.
        F4(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
    }
    #[inline(always)]
    fn ge(self, o: Self) -> F4 {
        F4::ge(self, o)
    }
    #[inline(always)]
    fn le(self, o: Self) -> F4 {
        // SAFETY: as for `F4::store`. Ordered, as f64's `<=`.
        F4(unsafe { _mm256_cmp_pd::<_CMP_LE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    fn ne_zero(self) -> F4 {
        // SAFETY: as for `F4::store`. Unordered, as f64's `!=` (NaN != 0).
        F4(unsafe { _mm256_cmp_pd::<_CMP_NEQ_UQ>(self.0, _mm256_setzero_pd()) })
    }
    #[inline(always)]
    fn select(m: F4, a: Self, b: Self) -> Self {
        // SAFETY: as for `F4::store`.
        F4(unsafe { _mm256_blendv_pd(b.0, a.0, m.0) })
    }
    #[inline(always)]
    fn both(a: F4, b: F4) -> F4 {
        a.and(b)
    }
}
