//! Comparing two renders of the same scene: how many pixels differ as the PNG shows them, the
//! RMS difference, and whether every difference sits on a silhouette edge (for backend
//! agreement tests and the error side of the benchmarks).

use crate::output::srgb_encode;
use crate::render::Frame;

/// How two renders of one scene differ.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels where some 8-bit sRGB channel differs by more than 1.
    pub differing: usize,
    /// Of those, the ones not on a silhouette edge in either frame.
    pub differing_off_edges: usize,
    /// RMS difference of linear colour over all pixels and channels.
    pub rms: f64,
}

impl Comparison {
    /// The share of pixels that differ (`differing / pixels`).
    pub fn differing_share(&self) -> f64 {
        self.differing as f64 / self.pixels.max(1) as f64
    }
}

fn byte(c: f32) -> i32 {
    (srgb_encode(c) * 255.0 + 0.5) as i32
}

/// A pixel on a silhouette: a neighbour (8-connected) sees another object, or nothing, or a
/// surface at a clearly different lookback time (rods in front of rods of one lattice).
fn is_edge(f: &Frame, x: u32, y: u32) -> bool {
    let p = f.get(x, y);
    for dy in -1i32..=1 {
        for dx in -1i32..=1 {
            let (nx, ny) = (x as i32 + dx, y as i32 + dy);
            if nx < 0 || ny < 0 || nx >= f.width as i32 || ny >= f.height as i32 {
                continue;
            }
            let q = f.get(nx as u32, ny as u32);
            let scale = p.lookback.abs().max(q.lookback.abs()).max(1e-6);
            if q.object_id != p.object_id
                || q.alpha != p.alpha
                || (q.lookback - p.lookback).abs() > 0.02 * scale
            {
                return true;
            }
        }
    }
    false
}

/// Compare two frames of the same size pixel by pixel.
pub fn compare(a: &Frame, b: &Frame) -> Comparison {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "frames of one size"
    );
    let mut c = Comparison {
        pixels: a.pixels.len(),
        differing: 0,
        differing_off_edges: 0,
        rms: 0.0,
    };
    let mut sq = 0.0;
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.get(x, y), b.get(x, y));
            let mut differs = false;
            for k in 0..3 {
                let d = (p.color[k] - q.color[k]) as f64;
                sq += d * d;
                differs |= (byte(p.color[k]) - byte(q.color[k])).abs() > 1;
            }
            if differs {
                c.differing += 1;
                if !is_edge(a, x, y) && !is_edge(b, x, y) {
                    c.differing_off_edges += 1;
                }
            }
        }
    }
    c.rms = (sq / (3 * c.pixels.max(1)) as f64).sqrt();
    c
}
