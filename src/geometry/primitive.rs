use super::Aabb;
use glam::DVec3;

/// One rest-frame primitive. Boxes are axis-aligned; rods are capsules (a cylinder with round
/// caps, the shape of Embree's round linear curves).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    Sphere { center: DVec3, radius: f64 },
    Capsule { a: DVec3, b: DVec3, radius: f64 },
    Cuboid { min: DVec3, max: DVec3 },
    Triangle { v: [DVec3; 3] },
}

/// A run of primitives that came from one scene object, with one material.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub start: u32,
    pub end: u32,
    pub object: u32,
    pub material: u32,
}

/// The static geometry of one velocity group, in its rest frame.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    pub prims: Vec<Primitive>,
    pub parts: Vec<Part>,
}

impl Geometry {
    /// Append primitives as one part.
    pub fn push_part(
        &mut self,
        object: u32,
        material: u32,
        prims: impl IntoIterator<Item = Primitive>,
    ) {
        let start = self.prims.len() as u32;
        self.prims.extend(prims);
        let end = self.prims.len() as u32;
        if end > start {
            self.parts.push(Part {
                start,
                end,
                object,
                material,
            });
        }
    }

    /// The part a primitive belongs to.
    pub fn part_of(&self, prim: u32) -> &Part {
        let i = self.parts.partition_point(|p| p.end <= prim);
        &self.parts[i]
    }

    pub fn bounds(&self) -> Aabb {
        self.prims
            .iter()
            .fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()))
    }

    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// The same geometry moved by `d`.
    pub fn translated(&self, d: DVec3) -> Geometry {
        Geometry {
            prims: self.prims.iter().map(|p| p.translated(d)).collect(),
            parts: self.parts.clone(),
        }
    }
}

/// Both roots of a·t² + 2b·t + c = 0, ascending.
fn quadratic_roots(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    let disc = b * b - a * c;
    if disc < 0.0 || a == 0.0 {
        return None;
    }
    let q = -(b + b.signum() * disc.sqrt());
    let (t0, t1) = (q / a, if q != 0.0 { c / q } else { q / a });
    Some((t0.min(t1), t0.max(t1)))
}

fn sphere_hit(c: DVec3, r: f64, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
    let oc = o - c;
    let a = d.length_squared();
    let b = oc.dot(d);
    // c − b²/a computed as |oc − (b/a) d|² − r² loses nothing when the ray passes close by.
    let l = oc - (b / a) * d;
    let h = r * r - l.length_squared();
    if h < 0.0 {
        return None;
    }
    let cc = oc.length_squared() - r * r;
    let sq = (a * h).sqrt();
    let q = -(b + b.signum() * sq);
    let (mut t0, mut t1) = (q / a, if q != 0.0 { cc / q } else { q / a });
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
}

impl Primitive {
    /// The same primitive moved by `d`.
    pub fn translated(&self, d: DVec3) -> Primitive {
        match *self {
            Primitive::Sphere { center, radius } => Primitive::Sphere {
                center: center + d,
                radius,
            },
            Primitive::Capsule { a, b, radius } => Primitive::Capsule {
                a: a + d,
                b: b + d,
                radius,
            },
            Primitive::Cuboid { min, max } => Primitive::Cuboid {
                min: min + d,
                max: max + d,
            },
            Primitive::Triangle { v } => Primitive::Triangle {
                v: v.map(|p| p + d),
            },
        }
    }

    pub fn bounds(&self) -> Aabb {
        match *self {
            Primitive::Sphere { center, radius } => {
                Aabb::new(center - DVec3::splat(radius), center + DVec3::splat(radius))
            }
            Primitive::Capsule { a, b, radius } => {
                let r = DVec3::splat(radius);
                Aabb::new(a.min(b) - r, a.max(b) + r)
            }
            Primitive::Cuboid { min, max } => Aabb::new(min, max),
            Primitive::Triangle { v } => {
                Aabb::new(v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]))
            }
        }
    }

    /// The first intersection of `o + t d` with `tmin < t < tmax`.
    pub fn intersect(&self, o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
        match *self {
            Primitive::Sphere { center, radius } => sphere_hit(center, radius, o, d, tmin, tmax),
            Primitive::Capsule { a, b, radius } => capsule_hit(a, b, radius, o, d, tmin, tmax),
            Primitive::Cuboid { min, max } => {
                let inv = d.recip();
                let a = (min - o) * inv;
                let bb = (max - o) * inv;
                let lo = a.min(bb);
                let hi = a.max(bb);
                let t0 = lo.x.max(lo.y).max(lo.z);
                let t1 = hi.x.min(hi.y).min(hi.z);
                if t0 > t1 {
                    return None;
                }
                [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
            }
            Primitive::Triangle { v } => triangle_hit(v, o, d, tmin, tmax),
        }
    }

    /// The outward geometric normal at a point on the surface (unit).
    pub fn normal(&self, p: DVec3) -> DVec3 {
        match *self {
            Primitive::Sphere { center, .. } => (p - center).normalize_or(DVec3::Z),
            Primitive::Capsule { a, b, .. } => {
                let ab = b - a;
                let s =
                    ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                (p - (a + s * ab)).normalize_or(DVec3::Z)
            }
            Primitive::Cuboid { min, max } => {
                let c = 0.5 * (min + max);
                let h = (0.5 * (max - min)).max(DVec3::splat(f64::MIN_POSITIVE));
                let q = (p - c) / h;
                let aq = q.abs();
                if aq.x >= aq.y && aq.x >= aq.z {
                    DVec3::new(q.x.signum(), 0.0, 0.0)
                } else if aq.y >= aq.z {
                    DVec3::new(0.0, q.y.signum(), 0.0)
                } else {
                    DVec3::new(0.0, 0.0, q.z.signum())
                }
            }
            Primitive::Triangle { v } => (v[1] - v[0]).cross(v[2] - v[0]).normalize_or(DVec3::Z),
        }
    }
}

fn capsule_hit(
    a: DVec3,
    b: DVec3,
    r: f64,
    o: DVec3,
    d: DVec3,
    tmin: f64,
    tmax: f64,
) -> Option<f64> {
    let ba = b - a;
    let oa = o - a;
    let baba = ba.length_squared();
    if baba == 0.0 {
        return sphere_hit(a, r, o, d, tmin, tmax);
    }
    let bard = ba.dot(d);
    let baoa = ba.dot(oa);
    // Cylinder body, in coordinates perpendicular to the axis (no large-number cancellation).
    let dp = d - (bard / baba) * ba;
    let op = oa - (baoa / baba) * ba;
    let mut best: Option<f64> = None;
    let mut take = |t: f64| {
        if t > tmin && t < tmax && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    };
    if let Some((t0, t1)) =
        quadratic_roots(dp.length_squared(), op.dot(dp), op.length_squared() - r * r)
    {
        for t in [t0, t1] {
            let y = baoa + t * bard;
            if y > 0.0 && y < baba {
                take(t);
            }
        }
    }
    // Round caps: only the parts of each sphere beyond its end of the axis.
    for (c, beyond) in [(a, -1.0), (b, 1.0)] {
        let oc = o - c;
        let aa = d.length_squared();
        let bb = oc.dot(d);
        let l = oc - (bb / aa) * d;
        let h = r * r - l.length_squared();
        if h < 0.0 {
            continue;
        }
        if let Some((t0, t1)) = quadratic_roots(aa, bb, oc.length_squared() - r * r) {
            for t in [t0, t1] {
                let y = baoa + t * bard;
                let outside = if beyond < 0.0 { y <= 0.0 } else { y >= baba };
                if outside {
                    take(t);
                }
            }
        }
    }
    best
}

fn triangle_hit(v: [DVec3; 3], o: DVec3, d: DVec3, tmin: f64, tmax: f64) -> Option<f64> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let w = d.dot(q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > tmin && t < tmax).then_some(t)
}
