//! Arithmetic written once for one f64 and for several at a time: the ray-primitive tests that
//! the Embree backend also runs on four rays per AVX2 vector (its `F4`) are generic over
//! `Real`, so both run the same operations in the same order and agree to the bit.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A number or four: the operations a ray-primitive test needs, without branches.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Copy;
    fn sqrt(self) -> Self;
    /// ±1 with the sign of self (`f64::signum` but for NaN).
    fn signum(self) -> Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn splat(x: f64) -> Self;
    fn abs(self) -> Self;
    fn ne_zero(self) -> Self::Mask;
    /// `self >= other`, lane by lane (false where either is NaN).
    fn ge(self, other: Self) -> Self::Mask;
    /// `self <= other`, lane by lane (false where either is NaN).
    fn le(self, other: Self) -> Self::Mask;
    /// `if m { a } else { b }`, lane by lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Both masks, lane by lane (both evaluated, so the scalar form does not branch either).
    /// (The Embree backend's rule for directions uses it, `accel::embree::scale`.)
    #[cfg_attr(not(feature = "embree"), expect(dead_code))]
    fn both(a: Self::Mask, b: Self::Mask) -> Self::Mask;
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn signum(self) -> Self {
        1f64.copysign(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f64::max(self, other)
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn ne_zero(self) -> bool {
        self != 0.0
    }
    #[inline(always)]
    fn ge(self, other: Self) -> bool {
        self >= other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn both(a: bool, b: bool) -> bool {
        a & b
    }
}
