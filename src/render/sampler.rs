//! Reproducible stratified pixel samples: the same scene gives the same image on any number of
//! threads, because every sample's jitter is a hash of its pixel and index.

pub(super) fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn unit(h: u64) -> f64 {
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Offset in [0, 1)² of sample `s` of `n` in pixel (x, y), in a round of samples that starts at
/// sample `base` of the pixel (a progressive render's; 0 otherwise): the centre when n = 1 in
/// the first round, else a jittered point in its cell of a k × ⌈n/k⌉ grid, k = ⌈√n⌉, the jitter
/// a hash of the pixel and the sample's index in the whole render.
pub(crate) fn sample_offset(x: u32, y: u32, s: u32, n: u32, base: u32) -> (f64, f64) {
    if n <= 1 && base == 0 {
        return (0.5, 0.5);
    }
    let k = (n as f64).sqrt().ceil() as u32;
    let rows = n.div_ceil(k);
    let (cx, cy) = (s % k, s / k);
    // As it always was in the first round (`base` 0), so renders without rounds are unchanged.
    let index = u64::from(s) ^ (u64::from(base) << 32);
    let h = splitmix(((x as u64) << 40) ^ ((y as u64) << 16) ^ index);
    let jx = unit(h);
    let jy = unit(splitmix(h));
    ((cx as f64 + jx) / k as f64, (cy as f64 + jy) / rows as f64)
}
