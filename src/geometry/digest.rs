//! A 64-bit digest of bytes with xxh3: of the scene's serialized values (the render id,
//! `output::header::render_id`), and of a geometry's bulk data (its primitives, parts, mesh
//! vertices and indices, corner normals and texture coordinates), taken from the numbers' bits,
//! which a geometry serializes as in place of the numbers themselves: the id costs a pass over
//! the bytes, never the formatting of numbers as text.

use super::{Corners, Geometry, Implicit, IndexedMesh, Primitive};
use xxhash_rust::xxh3::Xxh3;

/// A running digest. The numbers go into a buffer that goes to xxh3 a block at a time: xxh3's
/// streaming update has a cost per call that, paid per number, was most of the digest of a big
/// mesh. A stream's digest does not depend on how it is cut, so the digest is the same as fed
/// number by number.
pub(crate) struct Digest {
    hash: Xxh3,
    buf: Vec<u8>,
}

/// The bytes buffered before they go to xxh3.
const BLOCK: usize = 1 << 16;

impl Digest {
    pub fn new() -> Digest {
        Digest {
            hash: Xxh3::new(),
            // Grown as it fills: most digests are of a few numbers.
            buf: Vec::new(),
        }
    }

    #[inline]
    fn put(&mut self, b: &[u8]) {
        if self.buf.len() + b.len() > BLOCK {
            self.hash.update(&self.buf);
            self.buf.clear();
        }
        self.buf.extend_from_slice(b);
    }

    #[inline]
    pub fn f64(&mut self, x: f64) {
        self.put(&x.to_bits().to_le_bytes());
    }

    #[inline]
    pub fn f64s(&mut self, xs: &[f64]) {
        for &x in xs {
            self.f64(x);
        }
    }

    #[inline]
    pub fn u32(&mut self, x: u32) {
        self.put(&x.to_le_bytes());
    }

    #[inline]
    pub fn u64(&mut self, x: u64) {
        self.put(&x.to_le_bytes());
    }

    /// `value`'s bytes as serialized (postcard: numbers as their bits, sequences and variants
    /// counted first), never its text.
    pub fn value(&mut self, value: &impl serde::Serialize) {
        // Writing into a digest cannot fail, nor can serializing plain data.
        postcard::to_io(value, &mut *self).expect("a value serializes");
    }

    pub fn bytes(&mut self, b: &[u8]) {
        if b.len() >= BLOCK {
            self.hash.update(&self.buf);
            self.buf.clear();
            self.hash.update(b);
        } else {
            self.put(b);
        }
    }

    pub fn finish(&self) -> u64 {
        let mut hash = self.hash.clone();
        hash.update(&self.buf);
        hash.digest()
    }
}

/// A digest worked out once, on first use, and kept beside what it digests (a mesh's numbers,
/// a texture's texels: data made once and not changed after): the render id of a scene whose
/// groups place one mesh a thousand times, or of every frame of a film, reads the data once.
/// It takes no part in comparisons, and a clone keeps it.
#[derive(Clone, Default)]
pub(crate) struct Memo(std::sync::OnceLock<u64>);

impl Memo {
    pub fn get_or(&self, make: impl FnOnce() -> u64) -> u64 {
        *self.0.get_or_init(make)
    }
}

impl PartialEq for Memo {
    fn eq(&self, _: &Memo) -> bool {
        true
    }
}

impl std::fmt::Debug for Memo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Memo")
    }
}

/// A writer into the digest: what a serializer (the render id's) feeds its bytes to.
impl std::io::Write for Digest {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.bytes(b);
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn primitive(d: &mut Digest, p: &Primitive) {
    match *p {
        Primitive::Sphere { center, radius } => {
            d.u32(0);
            d.f64s(&[center.x, center.y, center.z, radius]);
        }
        Primitive::Capsule { a, b, radius } => {
            d.u32(1);
            d.f64s(&[a.x, a.y, a.z, b.x, b.y, b.z, radius]);
        }
        Primitive::Cuboid { min, max } => {
            d.u32(2);
            d.f64s(&[min.x, min.y, min.z, max.x, max.y, max.z]);
        }
        Primitive::Triangle { v } => {
            d.u32(3);
            for p in v {
                d.f64s(&[p.x, p.y, p.z]);
            }
        }
    }
}

/// A mesh's corner data into `d`.
pub(crate) fn corners(d: &mut Digest, c: &Corners) {
    if let Some(n) = &c.normals {
        d.u32(n.len() as u32);
        for v in n.iter().flatten() {
            d.f64s(&[v.x, v.y, v.z]);
        }
    }
    if let Some(t) = &c.uvs {
        d.u32(t.len() as u32 | 1 << 31);
        for uv in t.iter().flatten() {
            d.f64s(uv);
        }
    }
}

/// A mesh's vertices and triangles into `d`: the same bytes as number by number, made a run
/// at a time in a buffer of fixed size (a loop the compiler turns into plain copies).
pub(crate) fn mesh(d: &mut Digest, m: &IndexedMesh) {
    const RUN: usize = 1024;
    let triangles = m.triangles();
    let mut positions = m.positions();
    d.u32(positions.len() as u32);
    let mut run = [0u8; RUN * 24];
    // The f64 numbers' bytes, however the mesh holds them.
    loop {
        let mut filled = 0;
        // (The run first: zip asks it before the vertices, so none is taken and dropped.)
        for (out, p) in run.chunks_exact_mut(24).zip(positions.by_ref()) {
            for (k, x) in [p.x, p.y, p.z].into_iter().enumerate() {
                out[8 * k..8 * k + 8].copy_from_slice(&x.to_bits().to_le_bytes());
            }
            filled += 24;
        }
        if filled == 0 {
            break;
        }
        d.bytes(&run[..filled]);
    }
    d.u32(triangles.len() as u32);
    for ts in triangles.chunks(RUN) {
        for (t, out) in ts.iter().zip(run.chunks_exact_mut(12)) {
            for (k, i) in t.iter().enumerate() {
                out[4 * k..4 * k + 4].copy_from_slice(&i.to_le_bytes());
            }
        }
        d.bytes(&run[..ts.len() * 12]);
    }
}

/// A mesh's digest: its vertices and triangles (`mesh`), read once for the mesh's life.
pub(crate) fn mesh_digest(m: &IndexedMesh) -> u64 {
    m.digest_memo().get_or(|| {
        let mut d = Digest::new();
        mesh(&mut d, m);
        d.finish()
    })
}

/// `item`'s data into `d` the first time it is met, and after that only which one it was:
/// an item several placements of a mesh share (one `Arc`) is read once, not a thousand times.
fn once<T>(
    d: &mut Digest,
    seen: &mut std::collections::HashMap<*const T, u32>,
    item: &std::sync::Arc<T>,
    take: impl FnOnce(&mut Digest, &T),
) {
    let n = seen.len() as u32;
    match seen.entry(std::sync::Arc::as_ptr(item)) {
        std::collections::hash_map::Entry::Occupied(first) => {
            d.u32(u32::MAX);
            d.u32(*first.get());
        }
        std::collections::hash_map::Entry::Vacant(slot) => {
            slot.insert(n);
            take(d, item);
        }
    }
}

/// The digest of everything in `g`.
pub(crate) fn geometry(g: &Geometry) -> u64 {
    let mut seen_corners = Default::default();
    let mut d = Digest::new();
    d.u32(g.prims.len() as u32);
    for p in &g.prims {
        primitive(&mut d, p);
    }
    for part in &g.parts {
        for x in [part.start, part.end, part.object, part.material] {
            d.u32(x);
        }
        if let Some(c) = &part.corners {
            once(&mut d, &mut seen_corners, c, corners);
        }
        d.value(&(
            part.corners_placed.as_deref(),
            part.placement.as_deref(),
            part.spin,
        ));
    }
    for run in &g.implicit {
        d.u32(run.first);
        match &run.shape {
            Implicit::Lattice(l) => {
                d.u32(0);
                d.value(l);
            }
            Implicit::Bars(b) => {
                d.u32(1);
                d.value(b);
            }
            Implicit::Mesh(m) => {
                d.u32(2);
                d.u64(mesh_digest(m));
            }
            Implicit::Instance(m) => {
                d.u32(3);
                d.u64(mesh_digest(&m.mesh));
                d.value(&m.place);
            }
        }
    }
    d.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The buffered digest is xxh3 of the bytes fed, in order, however many blocks they fill.
    #[test]
    fn the_digest_is_xxh3_of_the_bytes_fed() {
        for n in [0usize, 1, 1000, BLOCK / 8 + 3, 3 * BLOCK / 4 + 17] {
            let mut d = Digest::new();
            let mut bytes = Vec::new();
            for i in 0..n {
                let x = i as f64 * 0.37;
                d.f64(x);
                bytes.extend_from_slice(&x.to_bits().to_le_bytes());
                d.u32(i as u32);
                bytes.extend_from_slice(&(i as u32).to_le_bytes());
            }
            d.bytes(b"end");
            bytes.extend_from_slice(b"end");
            let big: Vec<u8> = (0..BLOCK + n).map(|i| i as u8).collect();
            d.bytes(&big);
            bytes.extend_from_slice(&big);
            assert_eq!(d.finish(), xxhash_rust::xxh3::xxh3_64(&bytes), "{n}");
            assert_eq!(d.finish(), d.finish(), "finish leaves the digest as it was");
        }
    }

    /// A mesh's digest is its numbers' bytes, number by number.
    #[test]
    fn a_mesh_digests_its_numbers_in_order() {
        // Held in f64 (square roots) and in f32 (halves): the f64 numbers' bytes either way.
        for narrow in [false, true] {
            let n = 3000;
            let last = |i: usize| if narrow { 0.25 } else { (i as f64).sqrt() };
            let positions: Vec<DVec3> = (0..n)
                .map(|i| DVec3::new(i as f64, 0.5 * i as f64, -last(i)))
                .collect();
            mesh_digest_is_of_its_numbers(positions, narrow);
        }
    }

    fn mesh_digest_is_of_its_numbers(positions: Vec<DVec3>, narrow: bool) {
        let n = positions.len();
        let triangles: Vec<[u32; 3]> = (0..n as u32 - 2).map(|i| [i, i + 1, i + 2]).collect();
        let m = IndexedMesh::new(positions.clone(), triangles.clone());
        let vertex_bytes = if narrow { 12 } else { 24 };
        assert_eq!(m.bytes(), (n * vertex_bytes + triangles.len() * 12) as u64);
        let mut bytes = (n as u32).to_le_bytes().to_vec();
        for p in &positions {
            for x in [p.x, p.y, p.z] {
                bytes.extend_from_slice(&x.to_bits().to_le_bytes());
            }
        }
        bytes.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
        for t in &triangles {
            for i in t {
                bytes.extend_from_slice(&i.to_le_bytes());
            }
        }
        let mut d = Digest::new();
        mesh(&mut d, &m);
        assert_eq!(d.finish(), xxhash_rust::xxh3::xxh3_64(&bytes));
    }

    /// Any change of a number changes the digest; the same numbers give the same one.
    #[test]
    fn a_changed_vertex_changes_the_digest() {
        let tri = |z: f64| Primitive::Triangle {
            v: [DVec3::ZERO, DVec3::X, DVec3::new(0.0, 1.0, z)],
        };
        let mut a = Geometry::default();
        a.push_part(0, 0, [tri(0.0), tri(1.0)]);
        let mut b = Geometry::default();
        b.push_part(0, 0, [tri(0.0), tri(1.0)]);
        assert_eq!(geometry(&a), geometry(&b));
        let mut c = Geometry::default();
        c.push_part(0, 0, [tri(0.0), tri(1.0 + 1e-15)]);
        assert_ne!(geometry(&a), geometry(&c));
        let mut e = Geometry::default();
        e.push_part(0, 1, [tri(0.0), tri(1.0)]);
        assert_ne!(geometry(&a), geometry(&e), "another material");
        let text = format!("{a:?}");
        assert!(text.contains("digest") && text.len() < 200, "{text}");
    }
}
