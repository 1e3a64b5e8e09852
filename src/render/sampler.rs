//! Reproducible stratified pixel samples: the same scene gives the same image on any number of
//! threads, because every sample's jitter is a hash of its pixel and index.

use crate::rng::{splitmix64 as splitmix, unit_f64 as unit};

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

/// Where in the shutter sample `s` of `n` of pixel (x, y) sees, as a fraction of the exposure
/// from −½ to ½ (in a round of samples that starts at `base`): the samples' times are strata of
/// the exposure, shifted together by a hash of the pixel and the round (Cranley–Patterson), so
/// each is uniform over the exposure and a pixel's `n` samples cover it evenly. The strata
/// follow the sample's index while its place in the pixel follows its cell: each is uniform on
/// its own, so the mean over the pixel and the exposure is unbiased.
pub(crate) fn shutter_offset(x: u32, y: u32, s: u32, n: u32, base: u32) -> f64 {
    const SALT: u64 = 0x5348_5554_5445_5221;
    let h = splitmix(((x as u64) << 40) ^ ((y as u64) << 16) ^ (u64::from(base) << 32) ^ SALT);
    let t = (s as f64 + 0.5) / n.max(1) as f64 + unit(h);
    t - t.floor() - 0.5
}
