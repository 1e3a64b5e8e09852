//! A procedural star field (`[sky] stars = { count, seed, ... }`): point-like blackbody stars
//! spread uniformly over the sky, their brightnesses from the count law of stars spread evenly
//! through space and their temperatures log-uniform (docs/physics.md §5.5).
//!
//! A star is far smaller than a pixel, so what a pixel shows of it is its irradiance over the
//! pixel's solid angle (`render::star_pixels`): the light it sends is the same on every image
//! size, only spread over more or fewer pixels' worth of sky.

use crate::rng::Rng;
use glam::DVec3;
use std::sync::Arc;

/// The most stars a field may have (about 40 bytes each, made when the scene is read).
pub(crate) const MAX_STARS: u64 = 10_000_000;

/// What `[sky] stars` asks for.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StarField {
    /// How many stars.
    pub count: u64,
    /// The generator's seed: the same seed gives the same sky on every machine.
    pub seed: u64,
    /// The brightest and faintest apparent magnitudes.
    pub magnitudes: [f64; 2],
    /// The irradiance of a magnitude-0 star at rest, as luminance (the Y of linear sRGB,
    /// radiance × steradians): a pixel holding it shows this over its solid angle.
    pub irradiance: f64,
    /// The coolest and hottest temperatures, K.
    pub temperatures: [f64; 2],
    /// The stars, made from the settings above.
    pub stars: Arc<[Star]>,
}

/// One star, in the frame where the sky is at rest.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Star {
    /// The unit direction toward it (a looking direction).
    pub dir: DVec3,
    /// Its temperature, K.
    pub kelvin: f64,
    /// Its irradiance, as luminance (see [`StarField::irradiance`]).
    pub irradiance: f64,
}

impl StarField {
    /// The field for these settings, its stars made.
    pub fn new(
        count: u64,
        seed: u64,
        magnitudes: [f64; 2],
        irradiance: f64,
        temperatures: [f64; 2],
    ) -> StarField {
        let stars = make(count, seed, magnitudes, irradiance, temperatures);
        StarField {
            count,
            seed,
            magnitudes,
            irradiance,
            temperatures,
            stars: stars.into(),
        }
    }
}

/// Draw the stars. Directions are uniform on the sphere (z uniform in [-1, 1], longitude
/// uniform). Magnitudes follow N(< m) ∝ 10^(0.6 m), the count of stars of equal luminosity
/// spread evenly through space, between the two limits; the irradiance is E₀ 10^(−0.4 m).
/// Temperatures are log-uniform between the two limits.
fn make(count: u64, seed: u64, [m0, m1]: [f64; 2], e0: f64, [t0, t1]: [f64; 2]) -> Vec<Star> {
    let mut rng = Rng(seed);
    let (a, b) = (10f64.powf(0.6 * m0), 10f64.powf(0.6 * m1));
    let (l0, l1) = (t0.ln(), t1.ln());
    (0..count)
        .map(|_| {
            let z = rng.range(-1.0, 1.0);
            let phi = rng.range(0.0, std::f64::consts::TAU);
            let r = (1.0 - z * z).max(0.0).sqrt();
            let dir = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let m = (a + rng.f() * (b - a)).log10() / 0.6;
            let kelvin = rng.range(l0, l1).exp();
            Star {
                dir,
                kelvin,
                irradiance: e0 * 10f64.powf(-0.4 * m),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stars_follow_their_distributions() {
        let f = StarField::new(200_000, 7, [0.0, 6.0], 1.0, [3000.0, 30000.0]);
        let n = f.stars.len() as f64;
        // Uniform on the sphere: a cap of height h holds h/2 of them.
        let cap = f.stars.iter().filter(|s| s.dir.z > 0.5).count() as f64 / n;
        assert!((cap - 0.25).abs() < 0.005, "{cap}");
        let east = f.stars.iter().filter(|s| s.dir.x > 0.0).count() as f64 / n;
        assert!((east - 0.5).abs() < 0.005, "{east}");
        // N(< m) ∝ 10^(0.6 m): those brighter than 5 are 10^(-0.6) of those brighter than 6
        // (less the few brighter than 0, none here).
        let e5 = 10f64.powf(-0.4 * 5.0);
        let bright = f.stars.iter().filter(|s| s.irradiance > e5).count() as f64 / n;
        let want = (10f64.powf(3.0) - 1.0) / (10f64.powf(3.6) - 1.0);
        assert!((bright - want).abs() < 0.005, "{bright} against {want}");
        // Log-uniform: half lie below the geometric mean.
        let mean = (3000.0f64 * 30000.0).sqrt();
        let cool = f.stars.iter().filter(|s| s.kelvin < mean).count() as f64 / n;
        assert!((cool - 0.5).abs() < 0.005, "{cool}");
        assert!(f.stars.iter().all(|s| (s.dir.length() - 1.0).abs() < 1e-12
            && (3000.0..30000.0).contains(&s.kelvin)
            && s.irradiance <= 1.0
            && s.irradiance >= 10f64.powf(-2.4)));
    }

    #[test]
    fn a_seed_is_a_sky() {
        let a = StarField::new(100, 3, [0.0, 6.0], 1.0, [3000.0, 30000.0]);
        let b = StarField::new(100, 3, [0.0, 6.0], 1.0, [3000.0, 30000.0]);
        let c = StarField::new(100, 4, [0.0, 6.0], 1.0, [3000.0, 30000.0]);
        assert_eq!(a.stars, b.stars);
        assert_ne!(a.stars, c.stars);
    }
}
