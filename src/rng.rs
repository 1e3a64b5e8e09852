//! Deterministic random numbers (splitmix64, Steele, Lea & Flood 2014): the path integrator's
//! per-sample generator, the pixel samples' hashes, generated scenes and tests. The same
//! sequence on every machine, so a render and a generated scene are the same everywhere.

use glam::DVec3;

/// splitmix64's step: `z` advanced by the golden-ratio increment and mixed. As a hash it
/// spreads every input bit over the output; as a generator it is [`Rng`].
#[inline]
pub fn splitmix64(z: u64) -> u64 {
    let mut z = z.wrapping_add(GOLDEN);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// Uniform in [0, 1) from 64 random bits (their top 53).
#[inline]
pub fn unit_f64(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A splitmix64 generator.
pub struct Rng(
    /// The state: any value is a seed.
    pub u64,
);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let bits = splitmix64(self.0);
        self.0 = self.0.wrapping_add(GOLDEN);
        bits
    }

    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f64 {
        unit_f64(self.next_u64())
    }

    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.f()
    }

    /// A random unit vector (uniform on the sphere).
    pub fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}
