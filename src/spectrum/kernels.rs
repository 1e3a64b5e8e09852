//! The loops over the camera's wavelengths, compiled for AVX2 as well as the baseline and
//! chosen at run time (the `multiversion` crate). Every element is computed by the same
//! operations in the same order either way (no fused multiply-add, explicit partial sums), so
//! the result is the same to the bit on any x86-64 machine.

use super::SAMPLES;
use multiversion::multiversion;

type Lanes = [f64; SAMPLES];

/// `out[i] = lo[i] + t (hi[i] − lo[i])`.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn lerp(lo: &[f64], hi: &[f64], t: f64, out: &mut Lanes) {
    let (lo, hi) = (&lo[..SAMPLES], &hi[..SAMPLES]);
    for i in 0..SAMPLES {
        out[i] = lo[i] + t * (hi[i] - lo[i]);
    }
}

/// The three dot products of `rows` with `v`, each in four partial sums.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn dot3(rows: &[Lanes; 3], v: &Lanes) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (o, w) in out.iter_mut().zip(rows) {
        let mut acc = [0.0; 4];
        for (w, v) in w.chunks_exact(4).zip(v.chunks_exact(4)) {
            for k in 0..4 {
                acc[k] += w[k] * v[k];
            }
        }
        *o = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    }
    out
}

/// `a[i] *= b[i]`.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn mul(a: &mut Lanes, b: &Lanes) {
    for i in 0..SAMPLES {
        a[i] *= b[i];
    }
}

/// `a[i] += b[i]`.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn add(a: &mut Lanes, b: &Lanes) {
    for i in 0..SAMPLES {
        a[i] += b[i];
    }
}

/// `a[i] *= k`.
#[multiversion(targets("x86_64+avx2"))]
pub fn scale(a: &mut Lanes, k: f64) {
    for x in a.iter_mut() {
        *x *= k;
    }
}

/// `acc[i] += light[i] · (diffuse[i] · ndl + spec[i] · h) · a`, or without the specular part
/// `acc[i] += light[i] · (diffuse[i] · (ndl · a))`: a light's term at a surface.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn add_lit(
    acc: &mut Lanes,
    light: &Lanes,
    diffuse: &Lanes,
    ndl: f64,
    glint: Option<(&Lanes, f64)>,
    a: f64,
) {
    match glint {
        Some((spec, h)) => {
            for i in 0..SAMPLES {
                acc[i] += light[i] * ((diffuse[i] * ndl + spec[i] * h) * a);
            }
        }
        None => {
            let k = ndl * a;
            for i in 0..SAMPLES {
                acc[i] += light[i] * (diffuse[i] * k);
            }
        }
    }
}
