//! The optics both integrators share, in one convention: directions point away from the
//! surface (`wo` toward where the light goes, the normal on its side) and `eta` = n_t / n_i,
//! the index of the side the light enters over the side it comes from (docs/physics.md §10).

use glam::DVec3;

/// Unpolarised Fresnel reflectance at a boundary met at `cos_i` (> 0) from the side of index
/// n_i, with `eta` = n_t / n_i; 1 on total internal reflection.
pub(crate) fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// `wo` mirrored about `n`.
pub(crate) fn reflect(wo: DVec3, n: DVec3) -> DVec3 {
    2.0 * wo.dot(n) * n - wo
}

/// `wo` refracted through a boundary with normal `n` (on its side), `eta` = n_t / n_i; None on
/// total internal reflection. Unit when `wo` and `n` are.
pub(crate) fn refract(wo: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let c = wo.dot(n);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-wo / eta + (c / eta - cos_t) * n)
}

/// Phong's lobe, `cos^shininess` (cos ≥ 0): by repeated multiplication for a whole-number
/// exponent, the usual case (`powf` is a large share of shading), else `powf`.
pub(crate) fn phong(cos: f64, shininess: f64) -> f64 {
    if shininess.fract() == 0.0 && shininess <= 1024.0 {
        cos.powi(shininess as i32)
    } else {
        cos.powf(shininess)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lobe by multiplication is `powf`'s to within rounding, whole exponents or not, and
    /// `0^0 = 1` as `powf` has it (a shininess of 0 lights the whole surface).
    #[test]
    fn phong_is_powf() {
        for shininess in [
            0.0, 1.0, 2.0, 7.0, 40.0, 60.0, 128.0, 1024.0, 0.5, 12.25, 2000.0,
        ] {
            for k in 0..=100 {
                let cos = f64::from(k) / 100.0;
                let (got, want) = (phong(cos, shininess), cos.powf(shininess));
                let err = (got - want).abs() / want.max(f64::MIN_POSITIVE);
                assert!(
                    err < 1e-13 || (got - want).abs() < 1e-300,
                    "cos {cos} ^ {shininess}: {got} vs powf {want}"
                );
            }
        }
        assert_eq!(phong(0.0, 0.0), 1.0);
        assert_eq!(phong(0.0, 40.0), 0.0);
        assert_eq!(phong(1.0, 60.0), 1.0);
    }

    /// Normal incidence on glass reflects ((n−1)/(n+1))² = 4%; inside it beyond the critical
    /// angle all of it; Snell's law holds for the refracted direction, which is unit; the
    /// mirror keeps the angle.
    #[test]
    fn fresnel_snell_and_mirror() {
        assert!((fresnel(1.0, 1.5) - 0.04).abs() < 1e-15);
        assert_eq!(fresnel(0.5, 1.0 / 1.5), 1.0);
        let n = DVec3::Z;
        for deg in [0.0f64, 10.0, 30.0, 60.0, 89.0] {
            let (s, c) = deg.to_radians().sin_cos();
            let wo = DVec3::new(s, 0.0, c);
            let t = refract(wo, n, 1.5).unwrap();
            assert!((t.length() - 1.0).abs() < 1e-15);
            assert!(t.z < 0.0);
            assert!((t.x.abs() * 1.5 - s).abs() < 1e-15, "Snell at {deg}°");
            let r = reflect(wo, n);
            assert!((r - DVec3::new(-s, 0.0, c)).length() < 1e-15);
        }
        // Out of glass at 45°: sin θt = 1.5 sin 45° > 1.
        let wo = DVec3::new(0.5f64.sqrt(), 0.0, 0.5f64.sqrt());
        assert!(refract(wo, n, 1.0 / 1.5).is_none());
    }
}
