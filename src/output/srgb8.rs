//! The 8-bit sRGB code of a linear value, `round(255 · srgb_encode(c))`, from the 255 values
//! where the code steps up, instead of a `powf` per channel: a table gives the code at the
//! start of the value's bucket of floats, and a step or two up the list finds its own. The
//! steps are found once, by bisection over f32s with `srgb_encode` itself, so each code is the
//! one the formula gives (tested against it around every step and at random values).

use super::srgb_encode;
use std::sync::OnceLock;

/// The code the formula gives.
fn direct(c: f32) -> u8 {
    (srgb_encode(c) * 255.0 + 0.5) as u8
}

/// `steps[k - 1]` is the least f32 in [0, 1] whose code is at least k.
fn steps() -> &'static [f32; 255] {
    static STEPS: OnceLock<[f32; 255]> = OnceLock::new();
    STEPS.get_or_init(|| {
        std::array::from_fn(|i| {
            let k = i as u8 + 1;
            // Bisection on the bit patterns of non-negative floats, which order as the floats.
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if direct(f32::from_bits(mid)) >= k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            f32::from_bits(lo)
        })
    })
}

/// Floats per bucket of [`start_codes`]: the floats in [0, 1] in 2^15-long runs of their bit
/// patterns, each at most 1/256 of an octave wide, narrower than the codes' steps but for a
/// few in the darkest, linear part.
const BUCKET_BITS: u32 = 15;

/// The code of the first float of each bucket, so that a code is found from its bucket's with
/// a step or two up the list of steps instead of a binary search.
fn start_codes() -> &'static [u8] {
    static START: OnceLock<Vec<u8>> = OnceLock::new();
    START.get_or_init(|| {
        let buckets = (1.0f32.to_bits() >> BUCKET_BITS) + 1;
        (0..buckets)
            .map(|b| {
                let c = f32::from_bits(b << BUCKET_BITS);
                steps().partition_point(|&s| s <= c) as u8
            })
            .collect()
    })
}

/// The 8-bit sRGB code of linear `c` (clamped to [0, 1]; NaN and infinities are 0, as
/// `srgb_encode` has them).
pub(crate) fn srgb8(c: f32) -> u8 {
    if !(c > 0.0 && c.is_finite()) {
        return 0;
    }
    if c >= 1.0 {
        return 255;
    }
    let mut code = start_codes()[(c.to_bits() >> BUCKET_BITS) as usize];
    let steps = steps();
    while code < 255 && steps[code as usize] <= c {
        code += 1;
    }
    code
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_the_formulas() {
        for (k, &s) in steps().iter().enumerate() {
            let bits = s.to_bits();
            for b in bits.saturating_sub(64)..=bits + 64 {
                let c = f32::from_bits(b);
                assert_eq!(srgb8(c), direct(c), "around step {}: {c:e}", k + 1);
            }
        }
        let mut rng = crate::rng::Rng(5);
        for _ in 0..2_000_000 {
            let c = f32::from_bits((rng.next_u64() % (1.0f32.to_bits() as u64 + 1)) as u32);
            assert_eq!(srgb8(c), direct(c), "{c:e}");
        }
        for c in [
            0.0,
            -0.0,
            -1.0,
            1.0,
            2.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e-40,
        ] {
            assert_eq!(srgb8(c), direct(c), "{c:e}");
        }
    }
}
