//! A light buffer (Haines & Greenberg, "The Light Buffer: A Shadow-Testing Accelerator", IEEE
//! CG&A 6(9), 1986): culling over boxes for rays that all start at one point, a light. The
//! directions around the light are the six faces of a cube; each face carries a grid of cells
//! over the part of it the boxes cover, and each cell lists the boxes whose directions from the
//! light meet it, nearest first. A ray looks up the one cell its direction falls in and tests
//! that cell's boxes until they lie beyond its far end: no tree walk, and no box that does not
//! lie in the ray's direction.
//!
//! Conservative by construction: a box seen from the light projects onto a face (central
//! projection) inside the rectangle of its corners' projections when every corner lies in front
//! of the face's plane; a box that crosses that plane is listed on the whole face; a box that
//! holds the light is tested by every ray. Cell indices of rays and of rectangles come from one
//! monotone function, so a ray always finds the boxes whose rectangles hold its direction.

use super::Aabb;
use glam::DVec3;

/// Grid cells per box listed on a face, about: finer cells list each box in more of them.
const CELLS_PER_BOX: f64 = 0.5;
/// The cells a face's typical rectangle spans along a side, at most (the geometric mean of its
/// median width along u and along v, so about CELLS_ACROSS² cells in area): where the boxes'
/// shadows overlap many deep (many groups swept over a slice of time), finer cells list each
/// box in ever more of them while a ray meets as many boxes as before, those overlapping in its
/// direction; the entries then cost more time and memory to make than the rays save. Where
/// most of a face's rectangles are large, the small ones on it get these coarser cells too.
const CELLS_ACROSS: f64 = 2.0;
/// The most cells along a face's side.
const MAX_RES: usize = 1024;
/// Rectangles grow by this much (in face coordinates) for rounding in the projections.
const PAD: f64 = 1e-9;

/// One face's grid: over [lo, lo + res / inv_w] in both face coordinates.
#[derive(Clone, Copy, Debug, Default)]
struct Face {
    lo: [f64; 2],
    inv_w: [f64; 2],
    res: usize,
    /// Its first cell in the buffer's cell list.
    first: usize,
}

impl Face {
    /// The cell column (k = 0) or row (k = 1) of face coordinate x: monotone in x.
    #[inline]
    fn cell(&self, k: usize, x: f64) -> usize {
        // Truncation is floor from 0 up (and a NaN goes to cell 0).
        let c = (x - self.lo[k]) * self.inv_w[k];
        if c >= 0.0 {
            (c as usize).min(self.res - 1)
        } else {
            0
        }
    }
}

/// Boxes around one point, for rays from it.
pub struct LightBuffer {
    origin: DVec3,
    /// The boxes nearest first (to the origin), their items, and their distances from it.
    boxes: Vec<Aabb>,
    items: Vec<u32>,
    near: Vec<f64>,
    faces: [Face; 6],
    /// Per cell (faces one after the other), its range in `entries`: `start[c]..start[c + 1]`.
    start: Vec<u32>,
    /// Indices into `boxes`, nearest first within each cell.
    entries: Vec<u32>,
    /// Boxes that hold the origin (or touch it): every ray tests them.
    everywhere: Vec<u32>,
}

/// The face a direction lies on: its major axis a and sign, and its coordinates there.
#[inline]
fn face_of(d: DVec3) -> Option<(usize, [f64; 2])> {
    let m = d.abs();
    let a = if m.x >= m.y && m.x >= m.z {
        0
    } else if m.y >= m.z {
        1
    } else {
        2
    };
    let depth = d[a];
    if depth == 0.0 || !depth.is_finite() {
        return None;
    }
    let face = 2 * a + usize::from(depth < 0.0);
    let inv = 1.0 / depth.abs();
    Some((face, [d[(a + 1) % 3] * inv, d[(a + 2) % 3] * inv]))
}

/// The rectangles (u0, v0, u1, v1), face by face, that hold the directions of box b's points
/// from `o`: None on a face no such direction lies on. (A plain loop over the faces, inlined
/// into the build: a closure per face was left as a call, per box and face, in the build of
/// every slice.)
#[inline(always)]
fn footprints(b: &Aabb, o: DVec3) -> [Option<[f64; 4]>; 6] {
    let (lo, hi) = (b.min - o, b.max - o);
    // How close to 0 each coordinate of the box's points comes.
    let gap = lo.max(-hi).max(DVec3::ZERO);
    let mut out = [None; 6];
    for (f, slot) in out.iter_mut().enumerate() {
        let (a, sign) = (f / 2, if f % 2 == 0 { 1.0 } else { -1.0 });
        let (b1, b2) = ((a + 1) % 3, (a + 2) % 3);
        // A direction on this face has sign · p[a] ≥ |p[b1]|, |p[b2]| > 0.
        let reach = if sign > 0.0 { hi[a] } else { -lo[a] };
        if reach <= 0.0 || reach < gap[b1] || reach < gap[b2] {
            continue;
        }
        // The corners' depths below the face take two values, so two divisions serve all
        // eight corners (each corner's u is p[b1] · (1 / depth), the same to the bit).
        let (d0, d1) = (sign * lo[a], sign * hi[a]);
        if d0 <= 0.0 || d1 <= 0.0 {
            // The box crosses the face's plane: its directions may reach any of the face.
            *slot = Some([-1.0 - PAD, -1.0 - PAD, 1.0 + PAD, 1.0 + PAD]);
            continue;
        }
        let (i0, i1) = (1.0 / d0, 1.0 / d1);
        let span = |k: usize| {
            let q = [lo[k] * i0, lo[k] * i1, hi[k] * i0, hi[k] * i1];
            let (mut min, mut max) = (q[0], q[0]);
            for x in &q[1..] {
                if *x < min {
                    min = *x;
                }
                if *x > max {
                    max = *x;
                }
            }
            (min, max)
        };
        let ((u0, u1), (v0, v1)) = (span(b1), span(b2));
        let r = [u0, v0, u1, v1];
        let r = [
            (r[0] - PAD).max(-1.0 - PAD),
            (r[1] - PAD).max(-1.0 - PAD),
            (r[2] + PAD).min(1.0 + PAD),
            (r[3] + PAD).min(1.0 + PAD),
        ];
        *slot = (r[0] <= r[2] && r[1] <= r[3]).then_some(r);
    }
    out
}

/// The median of `x` (the upper one of an even count), which it reorders; 0 for none.
fn median(x: &mut [f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let mid = x.len() / 2;
    *x.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The distance from `o` to the box (0 inside).
fn distance(b: &Aabb, o: DVec3) -> f64 {
    (b.min - o).max(o - b.max).max(DVec3::ZERO).length()
}

impl LightBuffer {
    /// Over `boxes` (item i is `boxes[i]`), for rays from `origin`.
    pub fn build(origin: DVec3, boxes: &[Aabb]) -> LightBuffer {
        // Nearest first: distances are ≥ 0, so their bits sort as they do.
        let mut keyed: Vec<(u64, u32)> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| (distance(b, origin).to_bits(), i as u32))
            .collect();
        keyed.sort_unstable();
        let mut lb = LightBuffer {
            origin,
            boxes: keyed.iter().map(|&(_, i)| boxes[i as usize]).collect(),
            items: keyed.iter().map(|&(_, i)| i).collect(),
            near: keyed.iter().map(|&(d, _)| f64::from_bits(d)).collect(),
            faces: [Face::default(); 6],
            start: Vec::new(),
            entries: Vec::new(),
            everywhere: Vec::new(),
        };
        // Each box's rectangles, face by face, nearest box first.
        let mut rects: Vec<(u32, u8, [f64; 4])> = Vec::with_capacity(2 * lb.boxes.len());
        for (k, b) in lb.boxes.iter().enumerate() {
            if lb.near[k] == 0.0 {
                lb.everywhere.push(k as u32);
                continue;
            }
            for (f, r) in footprints(b, origin).into_iter().enumerate() {
                if let Some(r) = r {
                    rects.push((k as u32, f as u8, r));
                }
            }
        }
        // Each face's span of rectangles and their widths along u and v (as many as it has).
        let mut spans = [[f64::INFINITY, f64::INFINITY, -f64::INFINITY, -f64::INFINITY]; 6];
        let mut widths: [(Vec<f64>, Vec<f64>); 6] = Default::default();
        for &(_, f, r) in &rects {
            let span = &mut spans[f as usize];
            *span = [
                span[0].min(r[0]),
                span[1].min(r[1]),
                span[2].max(r[2]),
                span[3].max(r[3]),
            ];
            widths[f as usize].0.push(r[2] - r[0]);
            widths[f as usize].1.push(r[3] - r[1]);
        }
        // Each face's grid over the rectangles on it.
        let mut first = 0;
        for ((face, span), (wu, wv)) in lb.faces.iter_mut().zip(spans).zip(&mut widths) {
            let count = wu.len();
            if count == 0 {
                *face = Face {
                    lo: [0.0; 2],
                    inv_w: [0.0; 2],
                    res: 1,
                    first,
                };
                first += 1;
                continue;
            }
            let by_count = (count as f64 * CELLS_PER_BOX).sqrt().ceil();
            // The median widths' shares of the span along u and along v: cells of about
            // 1 / CELLS_ACROSS of their geometric mean (none where the span is empty).
            let share = median(wu) / (span[2] - span[0]) * median(wv) / (span[3] - span[1]);
            let by_size = CELLS_ACROSS / share.sqrt();
            let res = match by_size.is_finite() && by_size > 0.0 {
                true => by_count.min(by_size.ceil()),
                false => by_count,
            };
            let res = (res as usize).clamp(1, MAX_RES);
            let inv_w = |lo: f64, hi: f64| {
                let w = (hi - lo) / res as f64;
                if w > 0.0 {
                    1.0 / w
                } else {
                    0.0
                }
            };
            *face = Face {
                lo: [span[0], span[1]],
                inv_w: [inv_w(span[0], span[2]), inv_w(span[1], span[3])],
                res,
                first,
            };
            first += res * res;
        }
        // Cells' lists (counted, then filled in nearest-first order). Each rectangle's cells are
        // worked out once for both passes: its face's first cell and width, and its columns
        // u0..u1 and rows v0..v1 (ends excluded).
        let spans: Vec<(u32, [usize; 6])> = rects
            .iter()
            .map(|&(k, f, r)| {
                let face = &lb.faces[f as usize];
                let (u0, u1) = (face.cell(0, r[0]), face.cell(0, r[2]) + 1);
                let (v0, v1) = (face.cell(1, r[1]), face.cell(1, r[3]) + 1);
                (k, [face.first, face.res, u0, u1, v0, v1])
            })
            .collect();
        let mut start = vec![0u32; first + 1];
        for (_, [base, res, u0, u1, v0, v1]) in &spans {
            for v in *v0..*v1 {
                for c in &mut start[base + v * res + u0 + 1..base + v * res + u1 + 1] {
                    *c += 1;
                }
            }
        }
        for c in 0..first {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut entries = vec![0u32; start[first] as usize];
        for (k, [base, res, u0, u1, v0, v1]) in &spans {
            for v in *v0..*v1 {
                for c in base + v * res + u0..base + v * res + u1 {
                    entries[fill[c] as usize] = *k;
                    fill[c] += 1;
                }
            }
        }
        lb.start = start;
        lb.entries = entries;
        lb
    }

    /// How many boxes it holds.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.boxes.len()
    }

    /// How many entries its cells list, in all.
    #[cfg(test)]
    pub fn entries(&self) -> usize {
        self.entries.len()
    }

    /// Whether it holds no box.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.boxes.is_empty()
    }

    /// The rays from `o` along `dirs` (each searched in `(tmin[i], tmax[i])`), one by one:
    /// `visit(item, ray, tmax)` for every item whose box the ray meets before its tmax (nearest
    /// boxes first), returning the ray's new tmax; one below its tmin ends the ray. Rays from
    /// elsewhere than the buffer's origin test every box.
    pub fn traverse(
        &self,
        o: DVec3,
        dirs: &[DVec3],
        tmin: &[f64],
        tmax: &mut [f64],
        visit: &mut dyn FnMut(u32, usize, f64) -> f64,
    ) {
        for (i, &d) in dirs.iter().enumerate() {
            let inv = d.recip();
            let mut test = |k: u32, tmax: &mut f64| {
                let k = k as usize;
                if self.boxes[k].clip(o, inv, tmin[i], *tmax).is_some() {
                    *tmax = visit(self.items[k], i, *tmax);
                }
            };
            if o != self.origin {
                for k in 0..self.boxes.len() as u32 {
                    if tmax[i] < tmin[i] {
                        break;
                    }
                    test(k, &mut tmax[i]);
                }
                continue;
            }
            for &k in &self.everywhere {
                if tmax[i] < tmin[i] {
                    break;
                }
                test(k, &mut tmax[i]);
            }
            let Some((f, uv)) = face_of(d) else {
                continue;
            };
            let face = &self.faces[f];
            let c = face.first + face.cell(1, uv[1]) * face.res + face.cell(0, uv[0]);
            // Beyond this distance from the origin the ray has ended (with rounding slack).
            let len = d.length();
            for &k in &self.entries[self.start[c] as usize..self.start[c + 1] as usize] {
                if tmax[i] < tmin[i] || self.near[k as usize] > tmax[i] * len * (1.0 + 1e-12) {
                    break;
                }
                test(k, &mut tmax[i]);
            }
        }
    }
}
