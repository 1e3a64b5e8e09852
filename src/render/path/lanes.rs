//! Lanes of diffuse vertices: the per-vertex arithmetic of the commonest vertex, a Lambert
//! surface in a frame at rest in the world frame, lit by a glowing sphere in such a frame, done
//! for many paths at once. The vertices of a bounce of a tile's paths are laid out as
//! structure-of-arrays (`DiffuseLanes`); one loop over them, compiled for AVX-512 and AVX2 as
//! well as the baseline and chosen at run time (the `multiversion` crate), runs the BSDF's draw
//! and the geometry of next-event estimation (the sphere's cone, the point on it, the shadow
//! ray, the densities and the multiple-importance weight) in vector registers, 8 or 4 paths
//! to an instruction. The loop's body is the scalar path's own functions (`draws.rs`,
//! `Basis`), in the same order, so each lane's numbers are what `PathTracer::scatter_surface`
//! computes for that vertex, to the bit; the band's arithmetic (colours, spectra) and the
//! rays stay per path.

use super::draws::{cosine_dir, cosine_pdf, power, sphere_cone, sphere_point, Basis};
use glam::DVec3;
use multiversion::multiversion;
use std::f64::consts::PI;

/// Lanes run together: a block of vertices, a column per input and per result.
const WIDTH: usize = 8;

/// A diffuse vertex as the lanes take it.
pub(super) struct DiffuseIn {
    /// The shading normal, toward the side the path came from (surface frame = world frame).
    pub nf: DVec3,
    /// The direction the path looked along to reach it.
    pub v: DVec3,
    /// Where it is.
    pub x: DVec3,
    /// Its group's offset off surfaces.
    pub epsilon: f64,
    /// The two uniform numbers of the BSDF's draw.
    pub u: [f64; 2],
    /// The glowing sphere drawn for next-event estimation (centre, radius; a radius of 0:
    /// none), the probability it was picked with, and the two uniform numbers of the draw on it.
    pub sphere: (DVec3, f64),
    pub p_pick: f64,
    pub ue: [f64; 2],
}

/// The input columns.
mod col_in {
    pub const NF: usize = 0;
    pub const V: usize = 3;
    pub const X: usize = 6;
    pub const CENTER: usize = 9;
    pub const RADIUS: usize = 12;
    pub const EPSILON: usize = 13;
    pub const U1: usize = 14;
    pub const U2: usize = 15;
    pub const P_PICK: usize = 16;
    pub const UE1: usize = 17;
    pub const UE2: usize = 18;
    pub const COUNT: usize = 19;
}

/// A vertex's results, as the lanes give them.
#[derive(Clone, Copy, Default)]
pub(super) struct DiffuseOut {
    /// The BSDF's draw: whether it leaves light, its density, the factor |cos| / pdf of its
    /// weight, and its world direction.
    pub drawn: bool,
    pub pdf: f64,
    pub weight: f64,
    pub wi: DVec3,
    /// Where the next leg starts: ε off the surface on the side the light leaves toward.
    pub next: DVec3,
    /// Next-event estimation: whether the sphere was drawn from its cone at both ends (else
    /// the scalar path draws it), whether the draw sends light that way, the point drawn, the
    /// shadow ray's start and direction and its lookback limit, |cos| at the vertex, and the
    /// weight w / p_light.
    pub coned: bool,
    pub lit: bool,
    pub point: DVec3,
    pub from: DVec3,
    pub look: DVec3,
    pub tmax: f64,
    pub cos: f64,
    pub factor: f64,
}

/// The output columns.
mod col_out {
    pub const DRAWN: usize = 0;
    pub const PDF: usize = 1;
    pub const WEIGHT: usize = 2;
    pub const WI: usize = 3;
    pub const CONED: usize = 6;
    pub const LIT: usize = 7;
    pub const POINT: usize = 8;
    pub const FROM: usize = 11;
    pub const LOOK: usize = 14;
    pub const TMAX: usize = 17;
    pub const COS: usize = 18;
    pub const FACTOR: usize = 19;
    pub const NEXT: usize = 20;
    pub const COUNT: usize = 23;
}

/// A block of `WIDTH` vertices' inputs, a column each (as the lanes read them).
type InBlock = [[f64; WIDTH]; col_in::COUNT];
/// A block of `WIDTH` vertices' results, a column each.
type OutBlock = [[f64; WIDTH]; col_out::COUNT];

/// A bounce's diffuse vertices, in and out, in blocks of `WIDTH` laid out as the lanes run
/// them (vertex i is lane i % WIDTH of block i / WIDTH), so a run reads and writes its
/// vector registers straight from them. The lanes past the last vertex are zeros.
#[derive(Default)]
pub(super) struct DiffuseLanes {
    ins: Vec<InBlock>,
    outs: Vec<OutBlock>,
    len: usize,
}

impl DiffuseLanes {
    pub fn clear(&mut self) {
        self.ins.clear();
        self.len = 0;
    }

    pub fn len(&self) -> usize {
        self.len
    }

    #[inline]
    pub fn push(&mut self, d: &DiffuseIn) {
        let (c, r) = d.sphere;
        let j = self.len % WIDTH;
        if j == 0 {
            self.ins.push([[0.0; WIDTH]; col_in::COUNT]);
        }
        let block = self.ins.last_mut().expect("a block for the vertex");
        let row = [
            d.nf.x, d.nf.y, d.nf.z, d.v.x, d.v.y, d.v.z, d.x.x, d.x.y, d.x.z, c.x, c.y, c.z, r,
            d.epsilon, d.u[0], d.u[1], d.p_pick, d.ue[0], d.ue[1],
        ];
        for (column, v) in block.iter_mut().zip(row) {
            column[j] = v;
        }
        self.len += 1;
    }

    /// Vertex i's shading normal and the direction its path looked along (as pushed).
    pub fn normal_and_look(&self, i: usize) -> (DVec3, DVec3) {
        use col_in::*;
        let (b, j) = (&self.ins[i / WIDTH], i % WIDTH);
        let v3 = |k: usize| DVec3::new(b[k][j], b[k + 1][j], b[k + 2][j]);
        (v3(NF), v3(V))
    }

    /// Vertex i's results (after [`DiffuseLanes::run`]).
    #[inline]
    pub fn out(&self, i: usize) -> DiffuseOut {
        use col_out::*;
        let (o, j) = (&self.outs[i / WIDTH], i % WIDTH);
        let v3 = |k: usize| DVec3::new(o[k][j], o[k + 1][j], o[k + 2][j]);
        DiffuseOut {
            drawn: o[DRAWN][j] != 0.0,
            pdf: o[PDF][j],
            weight: o[WEIGHT][j],
            wi: v3(WI),
            next: v3(NEXT),
            coned: o[CONED][j] != 0.0,
            lit: o[LIT][j] != 0.0,
            point: v3(POINT),
            from: v3(FROM),
            look: v3(LOOK),
            tmax: o[TMAX][j],
            cos: o[COS][j],
            factor: o[FACTOR][j],
        }
    }

    /// Run every lane (in vector registers where `simd`, else one by one).
    pub fn run(&mut self, simd: bool) {
        self.outs
            .resize(self.ins.len(), [[0.0; WIDTH]; col_out::COUNT]);
        if simd {
            run_lanes(&self.ins, &mut self.outs);
        } else {
            for (b, (block, res)) in self.ins.iter().zip(self.outs.iter_mut()).enumerate() {
                for j in 0..(self.len - b * WIDTH).min(WIDTH) {
                    lane(block, res, j);
                }
            }
        }
    }
}

/// Every block's lanes, in a loop the compiler vectorises for the CPU it runs on.
#[multiversion(targets("x86_64+avx512f+avx512dq+avx512vl", "x86_64+avx2"))]
fn run_lanes(ins: &[InBlock], outs: &mut [OutBlock]) {
    for (block, res) in ins.iter().zip(outs.iter_mut()) {
        for j in 0..WIDTH {
            lane(block, res, j);
        }
    }
}

/// Lane j: `PathTracer::scatter_surface` of a Lambert surface whose frame is the world's,
/// `emitter_light` for a glowing sphere in such a frame seen from outside, and
/// `Lobes::sample` (docs/physics.md §10).
#[inline(always)]
fn lane<const W: usize>(
    cols: &[[f64; W]; col_in::COUNT],
    res: &mut [[f64; W]; col_out::COUNT],
    j: usize,
) {
    use col_in::*;
    let get = |k: usize| DVec3::new(cols[k][j], cols[k + 1][j], cols[k + 2][j]);
    let mut set = |k: usize, v: f64| res[k][j] = v;
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    let nf = get(NF);
    let x = get(X);
    let basis = Basis::new(nf);
    let wo = basis.to_local(-get(V));
    // The BSDF's draw (lobe 0, the only one), its density and weight.
    let wi = cosine_dir(cols[U1][j], cols[U2][j]);
    let pdf = cosine_pdf(wi.z);
    let wi_w = basis.to_world(wi);
    set(
        col_out::DRAWN,
        flag(wo.z > 0.0 && wi.z != 0.0 && wi.is_finite() && pdf > 0.0),
    );
    set(col_out::PDF, pdf);
    set(col_out::WEIGHT, wi.z.abs() / pdf);
    set(col_out::WI, wi_w.x);
    set(col_out::WI + 1, wi_w.y);
    set(col_out::WI + 2, wi_w.z);
    // The next leg leaves on the normal's side (a Lambert draw is never below it), as
    // `Shader::pushed_off` puts it in a frame at rest.
    let next = x + cols[EPSILON][j] * nf;
    set(col_out::NEXT, next.x);
    set(col_out::NEXT + 1, next.y);
    set(col_out::NEXT + 2, next.z);
    // Next-event estimation: a point on the sphere, drawn in the cone it fills from the
    // vertex; the shadow ray leaves ε off the surface on the light's side.
    let (center, radius) = (get(CENTER), cols[RADIUS][j]);
    let (omc, coned) = sphere_cone(center, radius, x);
    let pt = sphere_point(center, radius, x, omc, [cols[UE1][j], cols[UE2][j]]);
    let toward = pt - x;
    let side = if toward.dot(nf) > 0.0 { nf } else { -nf };
    let from = x + cols[EPSILON][j] * side;
    let delta = pt - from;
    let dist = delta.length();
    let look = delta / dist;
    let lz = basis.to_local(look).z;
    let pdf_own = cosine_pdf(lz);
    // The density of the draw, per solid angle, from the shadow ray's start.
    let (omc_from, coned_from) = sphere_cone(center, radius, from);
    let pdf_e = 1.0 / (2.0 * PI * omc_from);
    let p_light = cols[P_PICK][j] * pdf_e;
    set(col_out::CONED, flag(coned && coned_from));
    let lit = dist != 0.0 && dist.is_finite() && wo.z > 0.0 && lz > 0.0;
    set(col_out::LIT, flag(lit));
    for (k, v) in [
        (col_out::POINT, pt),
        (col_out::FROM, from),
        (col_out::LOOK, look),
    ] {
        set(k, v.x);
        set(k + 1, v.y);
        set(k + 2, v.z);
    }
    set(col_out::TMAX, dist * (1.0 - 1e-6));
    set(col_out::COS, lz.abs());
    set(col_out::FACTOR, power(p_light, pdf_own) / p_light);
}
