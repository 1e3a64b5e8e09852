//! OpenEXR's ZIP compression of a block, done here rather than by the exr crate: the block's
//! lines run through the format's predictor as a source makes them (`zip_lines`), and the
//! predicted bytes deflated by zlib-rs, each thread keeping its compressor and buffers.

/// The zlib level of ZIP blocks: OpenEXR's own default since 3.1.3 (before, 6), about twice as
/// fast for a slightly larger file.
const ZIP_LEVEL: i32 = 4;

/// [`zip_lines`] of `data` whole, as the tests check it.
#[cfg(test)]
fn zip_bytes(data: &[u8]) -> Option<Vec<u8>> {
    ZIP.with_borrow_mut(|(z, t, out)| {
        predicted(data, t);
        deflated(z, t, out)
    })
}

thread_local! {
    /// Each thread's compressor and its two buffers, kept from one block to the next (a
    /// block's fresh buffers cost their zeroing and page faults each time).
    static ZIP: std::cell::RefCell<(Option<zlib_rs::Deflate>, Vec<u8>, Vec<u8>)> =
        Default::default();
}

/// OpenEXR's ZIP of a block's little-endian bytes, `size` of them, that `lines` hands on in
/// runs of whole pairs of bytes (the block's lines): the bytes at even offsets, then those at
/// odd ones; each byte then replaced by its difference from the one before plus 128 (mod
/// 256); then a zlib stream of that (read back by any inflate). Each run's part of the
/// prediction is made as it comes, so the block's own bytes are never made whole (its
/// predicted bytes are). None where the runs are not `size` bytes of whole pairs, or deflate
/// fails (the block is then stored as it is).
///
/// Deflated by [zlib-rs](https://crates.io/crates/zlib-rs): on this renderer's blocks it is
/// faster than libdeflate at the same level, and its files slightly smaller. The thread's
/// buffers are borrowed while `lines` runs: a source must not zip a block from within it (it
/// does not; rayon could otherwise run a second block there).
pub(super) fn zip_lines(size: usize, lines: impl FnOnce(&mut dyn FnMut(&[u8]))) -> Option<Vec<u8>> {
    ZIP.with_borrow_mut(|(z, t, out)| {
        // Every byte is written below (or the block is not zipped).
        t.resize(size, 0);
        let (even, odd) = t.split_at_mut(size / 2);
        let (mut pairs, mut before, mut first, mut whole) =
            (0, (0, 0), None, size.is_multiple_of(2));
        lines(&mut |run: &[u8]| {
            let n = run.len() / 2;
            if !whole || !run.len().is_multiple_of(2) || pairs + n > even.len() {
                whole = false;
                return;
            }
            if n > 0 {
                first.get_or_insert((run[0], run[1]));
            }
            before = predicted_pairs(
                run,
                &mut even[pairs..pairs + n],
                &mut odd[pairs..pairs + n],
                before,
            );
            pairs += n;
        });
        if !whole || 2 * pairs != size {
            return None;
        }
        // The stream's first byte is itself; the odd half's first follows the even half's
        // last.
        if let Some((e, o)) = first {
            even[0] = e;
            odd[0] = delta(before.0, o);
        }
        deflated(z, t, out)
    })
}

/// The zlib stream of `t` at [`ZIP_LEVEL`], made with `z` in `out`.
fn deflated(z: &mut Option<zlib_rs::Deflate>, t: &[u8], out: &mut Vec<u8>) -> Option<Vec<u8>> {
    use zlib_rs::{Deflate, DeflateFlush, Status};
    let z = z.get_or_insert_with(|| Deflate::new(ZIP_LEVEL, true, 15));
    z.reset();
    out.resize(zlib_rs::compress_bound(t.len()), 0);
    let start = z.total_out();
    match z.compress(t, out, DeflateFlush::Finish) {
        Ok(Status::StreamEnd) => Some(out[..(z.total_out() - start) as usize].to_vec()),
        _ => None,
    }
}

/// `b − a + 128` (mod 256): the predictor's byte for `b` after `a`.
#[inline(always)]
fn delta(a: u8, b: u8) -> u8 {
    b.wrapping_sub(a).wrapping_add(128)
}

/// The bytes ZIP deflates: `data`'s bytes at even offsets, then those at odd ones, each but
/// the first replaced by its difference from the one before it plus 128 (mod 256).
#[cfg(test)]
fn predicted(data: &[u8], t: &mut Vec<u8>) {
    let n = data.len();
    let half = n.div_ceil(2);
    // Every byte is written below.
    t.resize(n, 0);
    let Some(&first) = data.first() else {
        return;
    };
    let (even, odd) = t.split_at_mut(half);
    let pairs = n / 2;
    let (last_even, _) = predicted_pairs(
        &data[..2 * pairs],
        &mut even[..pairs],
        &mut odd[..pairs],
        (0, 0),
    );
    even[0] = first;
    if n % 2 == 1 && n > 1 {
        // The unpaired last byte ends the even half.
        even[half - 1] = delta(last_even, data[n - 1]);
    }
    if pairs > 0 {
        // The odd half starts after the even half's last byte.
        odd[0] = delta(data[2 * (half - 1)], data[1]);
    }
}

/// The predictor over whole pairs of bytes (`data`) that follow bytes whose last even and odd
/// ones were `before`: each pair's even byte as its difference from the even byte before it
/// (plus 128, mod 256) in `even`, its odd byte likewise in `odd`; the last pair's bytes
/// returned. Eight pairs at a time in a u64 each way (`evens`, `byte_deltas`), the rest byte
/// by byte.
fn predicted_pairs(data: &[u8], even: &mut [u8], odd: &mut [u8], before: (u8, u8)) -> (u8, u8) {
    let pairs = data.len() / 2;
    let words = pairs / 8;
    // Pairs 8k .. 8k + 8: their even and odd bytes as two words, each less the same word of
    // the pairs before (shifted in by a byte).
    let (mut even_before, mut odd_before) = (u64::from(before.0) << 56, u64::from(before.1) << 56);
    for (k, chunk) in data[..16 * words].chunks_exact(16).enumerate() {
        let lo = u64::from_le_bytes(chunk[..8].try_into().expect("8 bytes"));
        let hi = u64::from_le_bytes(chunk[8..].try_into().expect("8 bytes"));
        let e = evens(lo) | evens(hi) << 32;
        let o = evens(lo >> 8) | evens(hi >> 8) << 32;
        let de = byte_deltas(e, e << 8 | even_before >> 56);
        let dd = byte_deltas(o, o << 8 | odd_before >> 56);
        even[8 * k..8 * k + 8].copy_from_slice(&de.to_le_bytes());
        odd[8 * k..8 * k + 8].copy_from_slice(&dd.to_le_bytes());
        (even_before, odd_before) = (e, o);
    }
    let mut last = ((even_before >> 56) as u8, (odd_before >> 56) as u8);
    for i in 8 * words..pairs {
        let (e, o) = (data[2 * i], data[2 * i + 1]);
        even[i] = delta(last.0, e);
        odd[i] = delta(last.1, o);
        last = (e, o);
    }
    last
}

/// Bytes 0, 2, 4 and 6 of `x` (little-endian) as bytes 0 to 3.
#[inline(always)]
fn evens(x: u64) -> u64 {
    let x = x & 0x00ff_00ff_00ff_00ff;
    let x = (x | x >> 8) & 0x0000_ffff_0000_ffff;
    (x | x >> 16) & 0x0000_0000_ffff_ffff
}

/// Byte by byte, `a − b + 128` (mod 256): the top bits set in `a` and cleared in `b`, so that
/// no byte's difference borrows from the next; then the top bits put right.
#[inline(always)]
fn byte_deltas(a: u64, b: u64) -> u64 {
    const TOP: u64 = 0x8080_8080_8080_8080;
    ((a | TOP) - (b & !TOP)) ^ ((a ^ b) & TOP)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block zipped a run of lines at a time is the block zipped whole, to the byte, however
    /// it is cut (runs of one pair, empty runs, runs across the predictor's words); runs that
    /// are not whole pairs, or not the size, are refused (the block is then stored as it is).
    #[test]
    fn zipped_by_lines_is_zipped_whole() {
        let mut rng = crate::rng::Rng(5);
        for n in [0usize, 2, 4, 16, 18, 34, 1000, 4098, 60_000] {
            // Smooth numbers (as pixels are) and noise, half and half.
            let data: Vec<u8> = (0..n)
                .map(|i| match i < n / 2 {
                    true => (i / 7) as u8,
                    false => rng.next_u64() as u8,
                })
                .collect();
            let whole = zip_bytes(&data).expect("deflated");
            for cut in [2, 4, 14, 16, 18, 30, 1000] {
                let runs: Vec<&[u8]> = data.chunks(cut).collect();
                // The thread's buffer holds other bytes first, so a byte not written fails.
                ZIP.with_borrow_mut(|(_, t, _)| t.iter_mut().for_each(|b| *b ^= 0xa5));
                let got = zip_lines(n, |each| {
                    each(&[]);
                    for r in &runs {
                        each(r);
                    }
                });
                assert_eq!(got.as_ref(), Some(&whole), "{n} bytes in runs of {cut}");
            }
        }
        let data = [1u8, 2, 3, 4, 5, 6];
        assert_eq!(
            zip_lines(6, |each| {
                each(&data[..3]);
                each(&data[3..]);
            }),
            None,
            "a run of an odd length"
        );
        assert_eq!(zip_lines(8, |each| each(&data)), None, "too few bytes");
        assert_eq!(zip_lines(4, |each| each(&data)), None, "too many bytes");
    }

    /// The predictor is OpenEXR's, written the plain way: split, then differences.
    #[test]
    fn predicted_is_split_then_differences() {
        let mut rng = crate::rng::Rng(3);
        for n in [0, 1, 2, 3, 4, 5, 8, 15, 16, 17, 31, 32, 33, 64, 1001, 4099] {
            let data: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
            let split: Vec<u8> = data
                .iter()
                .step_by(2)
                .chain(data.iter().skip(1).step_by(2))
                .copied()
                .collect();
            let mut want = split.clone();
            for i in 1..n {
                want[i] = split[i].wrapping_sub(split[i - 1]).wrapping_add(128);
            }
            // Into a buffer that held a longer block before.
            let mut t = vec![7; 2000];
            predicted(&data, &mut t);
            assert_eq!(t, want, "{n} bytes");
        }
    }
}
