//! The static geometry of one velocity group in its rest frame: primitives held one by one,
//! lattices and bar arrays held as themselves, and the parts (object and material) they belong to.

use super::{Aabb, Implicit, Primitive};
use glam::DVec3;

/// A run of primitives that came from one scene object, with one material.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The first primitive of the run.
    pub start: u32,
    /// One past the last primitive of the run.
    pub end: u32,
    /// The scene object (index into [`Scene::objects`](crate::scene::Scene::objects)).
    pub object: u32,
    /// The material (index into [`Scene::materials`](crate::scene::Scene::materials)).
    pub material: u32,
    /// A mesh's data at its triangles' corners (from its file), if it has any.
    pub corners: Option<std::sync::Arc<Corners>>,
    /// Where a transform placed the object: textures are laid out in its own coordinates.
    pub placement: Option<std::sync::Arc<Placement>>,
    /// How the object spins in its group's frame, if it does (`spin`).
    pub spin: Option<Spin>,
    /// For a placement of a shared mesh (`Implicit::Instance`): its corner data is the mesh's
    /// own, shared by every placement, and its normals are turned by this placement when read.
    pub corners_placed: Option<std::sync::Arc<super::Affine>>,
}

/// A rigid rotation in the group's frame: at `omega` radians per unit of the group's time,
/// counter-clockwise about `axis` (unit) through `centre`. A body of revolution about the axis
/// keeps its shape in the group's frame while every point of its surface moves along it;
/// any other body (`turning`) is where its shape at time `epoch` turned by ω (t − epoch) puts
/// it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Spin {
    /// A point of the axis.
    pub centre: DVec3,
    /// The axis (unit).
    pub axis: DVec3,
    /// The angular velocity.
    pub omega: f64,
    /// Whether its shape turns (it is not a body of revolution about the axis): its rays are
    /// then followed to the turning shape (render/world/turning/).
    pub turning: bool,
    /// The group time at which the body stands as the scene file gives it: 0 from a file, moved
    /// by a spacetime translation of the scene (`Geometry::moved`).
    pub epoch: f64,
}

impl Spin {
    /// The velocity (units of c, group frame) of the body's point at `p`.
    pub fn velocity_at(&self, p: DVec3) -> DVec3 {
        self.omega * self.axis.cross(p - self.centre)
    }

    /// The boost from the group's frame into the rest frame of the body's point at `p`.
    pub fn boost_at(&self, p: DVec3) -> Option<crate::spacetime::Boost> {
        let v = crate::spacetime::Velocity::from_beta_vec(self.velocity_at(p)).ok()?;
        Some(crate::spacetime::Boost::to_rest(&v))
    }

    /// Where the body's point now (group time `t`) at `p` was at its epoch, by which textures
    /// stay painted on the turning body: `p` turned back by ω (t − epoch).
    pub fn unturned(&self, p: DVec3, t: f64) -> DVec3 {
        self.centre + self.back(t) * (p - self.centre)
    }

    /// The turn that takes the body as it stands at group time `t` back to its epoch.
    pub fn back(&self, t: f64) -> glam::DQuat {
        glam::DQuat::from_axis_angle(self.axis, -self.omega * (t - self.epoch))
    }

    /// A direction of the shape at its epoch as it points at group time `t`.
    pub fn turned_dir(&self, d: DVec3, t: f64) -> DVec3 {
        glam::DQuat::from_axis_angle(self.axis, self.omega * (t - self.epoch)) * d
    }
}

/// An object placed by `scale`, then `rotate`, then `translate`, and the shape it was before
/// (a box, sphere or rod; none for a mesh, whose texture coordinates are its own), so that its
/// textures turn and move with it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Placement {
    /// Scaled first, along the object's own axes (every factor > 0).
    pub scale: DVec3,
    /// Then turned.
    pub rotation: glam::DMat3,
    /// Then moved.
    pub translate: DVec3,
    /// The box, sphere or rod as given, before all three.
    pub shape: Option<Primitive>,
}

impl Placement {
    /// A point of the group's rest frame in the object's own coordinates.
    pub fn to_object(&self, p: DVec3) -> DVec3 {
        (self.rotation.transpose() * (p - self.translate)) / self.scale
    }

    /// A normal of the group's rest frame in the object's own coordinates (unit).
    pub fn normal_to_object(&self, n: DVec3) -> DVec3 {
        (self.scale * (self.rotation.transpose() * n)).normalize_or(n)
    }
}

/// Data at a mesh's triangles' corners, by triangle in the part's order: vertex normals (for
/// smooth shading) and texture coordinates.
#[derive(Clone, Default, PartialEq)]
pub struct Corners {
    /// Each corner's normal (unit, outward as the file gives it).
    pub normals: Option<Vec<[DVec3; 3]>>,
    /// Each corner's texture coordinates (u, v with v = 0 at the image's bottom, as OBJ and PLY
    /// have it).
    pub uvs: Option<Vec<[[f64; 2]; 3]>>,
}

/// Its counts and a digest of its numbers, as [`Geometry`]'s.
impl std::fmt::Debug for Corners {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = super::digest::Digest::new();
        super::digest::corners(&mut d, self);
        f.debug_struct("Corners")
            .field("normals", &self.normals.as_ref().map(Vec::len))
            .field("uvs", &self.uvs.as_ref().map(Vec::len))
            .field("digest", &format_args!("{:016x}", d.finish()))
            .finish()
    }
}

/// The static geometry of one velocity group, in its rest frame.
///
/// Primitives are numbered from 0: first those held in `prims`, then those of the objects held
/// as themselves, each a run of numbers (`ImplicitRun`). Read one by number with
/// [`prim`](Self::prim).
#[derive(Clone, Default)]
pub struct Geometry {
    /// The primitives held one by one: numbers 0 to `prims.len()`.
    pub prims: Vec<Primitive>,
    /// The runs of primitives, in order, covering every primitive.
    pub parts: Vec<Part>,
    /// Objects held as themselves (lattices, bar arrays), whose primitives are made from their
    /// numbers, after `prims`, in order.
    pub implicit: Vec<ImplicitRun>,
}

/// Its counts and a digest of its numbers (`digest.rs`), not every number as text: a mesh of
/// millions of triangles printed in full was most of the time a render took to name itself.
impl std::fmt::Debug for Geometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Geometry")
            .field("prims", &self.prims.len())
            .field("parts", &self.parts.len())
            .field("implicit", &self.implicit.len())
            .field(
                "digest",
                &format_args!("{:016x}", super::digest::geometry(self)),
            )
            .finish()
    }
}

/// As its counts and digest: the render id hashes these (`digest.rs`).
impl serde::Serialize for Geometry {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (
            self.prims.len(),
            self.parts.len(),
            self.implicit.len(),
            super::digest::geometry(self),
        )
            .serialize(s)
    }
}

/// An object held as itself: its primitives are numbers `first ..` `first + shape.len()`.
#[derive(Clone, Debug, PartialEq)]
pub struct ImplicitRun {
    /// The object.
    pub shape: Implicit,
    /// The geometry's number of the object's primitive 0.
    pub first: u32,
}

impl Geometry {
    /// Append primitives as one part.
    pub fn push_part(
        &mut self,
        object: u32,
        material: u32,
        prims: impl IntoIterator<Item = Primitive>,
    ) {
        self.push_part_with(object, material, prims, None)
    }

    /// Append primitives as one part, with data at their corners (a mesh's triangles).
    pub fn push_part_with(
        &mut self,
        object: u32,
        material: u32,
        prims: impl IntoIterator<Item = Primitive>,
        corners: Option<std::sync::Arc<Corners>>,
    ) {
        self.push_part_placed(object, material, prims, corners, None)
    }

    /// [`push_part_with`](Self::push_part_with) for a placement of a shared mesh listed
    /// triangle by triangle: its corner data the mesh's own, turned by `corners_placed`.
    fn push_part_placed(
        &mut self,
        object: u32,
        material: u32,
        prims: impl IntoIterator<Item = Primitive>,
        corners: Option<std::sync::Arc<Corners>>,
        corners_placed: Option<std::sync::Arc<super::Affine>>,
    ) {
        let start = self.prims.len() as u32;
        self.prims.extend(prims);
        let end = self.prims.len() as u32;
        if end > start {
            // Held primitives come before the implicit objects' numbers: move those along.
            let added = end - start;
            let at = self.parts.partition_point(|p| p.start < start);
            for p in &mut self.parts[at..] {
                p.start += added;
                p.end += added;
            }
            for run in &mut self.implicit {
                run.first += added;
            }
            self.parts.insert(
                at,
                Part {
                    start,
                    end,
                    object,
                    material,
                    corners,
                    placement: None,
                    spin: None,
                    corners_placed,
                },
            );
        }
    }

    /// Append an object as itself, numbered after everything else: its primitives in runs of
    /// `(count, material)` (a lattice's spheres, then its rods; a bar array's bars); an error if
    /// the geometry would hold more primitives than a `u32` numbers.
    pub fn push_implicit(
        &mut self,
        object: u32,
        runs: &[(u64, u32)],
        shape: Implicit,
    ) -> crate::Result<()> {
        let runs: Vec<_> = runs.iter().map(|&(n, m)| (n, m, None)).collect();
        self.push_implicit_with(object, &runs, shape)
    }

    /// [`push_implicit`](Self::push_implicit), each run with its corner data (a mesh's
    /// normals and texture coordinates, by triangle in the run's order).
    pub fn push_implicit_with(
        &mut self,
        object: u32,
        runs: &[(u64, u32, Option<std::sync::Arc<Corners>>)],
        shape: Implicit,
    ) -> crate::Result<()> {
        let first = self.len();
        let total = first as u64 + shape.len();
        if total > u32::MAX as u64 {
            return Err(crate::Error::Limit(format!(
                "a velocity group holds at most {} primitives; this object would make it {total}",
                u32::MAX
            )));
        }
        let mut start = first;
        for (count, material, corners) in runs.iter().filter(|(count, _, _)| *count > 0) {
            let end = start + *count as u32;
            self.parts.push(Part {
                start,
                end,
                object,
                material: *material,
                corners: corners.clone(),
                placement: None,
                spin: None,
                corners_placed: match &shape {
                    Implicit::Instance(m) if m.place != super::Affine::IDENTITY => {
                        Some(std::sync::Arc::new(m.place))
                    }
                    _ => None,
                },
            });
            start = end;
        }
        debug_assert_eq!(start as u64, total, "the runs cover the object");
        if total > first as u64 {
            self.implicit.push(ImplicitRun { shape, first });
        }
        Ok(())
    }

    /// How many primitives, held and implicit.
    pub fn len(&self) -> u32 {
        self.implicit
            .last()
            .map_or(self.prims.len() as u32, |r| r.first + r.shape.len() as u32)
    }

    /// Primitive number `id` (below [`len`](Self::len)).
    #[inline]
    pub fn prim(&self, id: u32) -> Primitive {
        match self.prims.get(id as usize) {
            Some(p) => *p,
            None => self.implicit(id),
        }
    }

    #[inline(never)]
    fn implicit(&self, id: u32) -> Primitive {
        let i = self.implicit.partition_point(|r| r.first <= id) - 1;
        let run = &self.implicit[i];
        run.shape.prim((id - run.first) as u64)
    }

    /// The same geometry with every implicit object's primitives held one by one (the same
    /// numbers).
    pub fn flattened(&self) -> Geometry {
        self.listing(u64::MAX)
    }

    /// The same geometry with the implicit objects of at most `max` primitives held one by one
    /// (after the held ones, before the objects still implicit, each in order; objects,
    /// materials and the order within an object kept).
    pub fn listing(&self, max: u64) -> Geometry {
        let held = self.prims.len() as u32;
        let mut g = Geometry {
            prims: self.prims.clone(),
            parts: self
                .parts
                .iter()
                .filter(|p| p.start < held)
                .cloned()
                .collect(),
            implicit: Vec::new(),
        };
        for (run, held_len) in self.implicit.iter().zip(self.held_lens()) {
            let end = run.first as u64 + run.shape.len();
            let parts = self
                .parts
                .iter()
                .filter(|p| p.start >= run.first && p.end as u64 <= end);
            if held_len <= max {
                for p in parts {
                    let ids = (p.start - run.first) as u64..(p.end - run.first) as u64;
                    let prims = ids.map(|id| run.shape.prim(id));
                    let placed = p.corners_placed.clone();
                    g.push_part_placed(p.object, p.material, prims, p.corners.clone(), placed);
                }
            } else {
                let runs: Vec<_> = parts
                    .clone()
                    .map(|p| ((p.end - p.start) as u64, p.material, p.corners.clone()))
                    .collect();
                let object = parts.clone().next().map_or(0, |p| p.object);
                g.push_implicit_with(object, &runs, run.shape.clone())
                    .expect("no more primitives than before");
            }
        }
        // Each object's placement, as it had it.
        let placed: std::collections::HashMap<u32, &std::sync::Arc<Placement>> = self
            .parts
            .iter()
            .filter_map(|p| Some((p.object, p.placement.as_ref()?)))
            .collect();
        if !placed.is_empty() {
            for p in &mut g.parts {
                p.placement = placed.get(&p.object).map(|&x| x.clone());
            }
        }
        g
    }

    /// How many primitives listing each run would hold: its own, or for a placement of a
    /// shared mesh those of every placement of that mesh here (listed all, or none).
    fn held_lens(&self) -> Vec<u64> {
        let mut shared: std::collections::HashMap<*const super::IndexedMesh, u64> =
            std::collections::HashMap::new();
        for r in &self.implicit {
            if let Implicit::Instance(m) = &r.shape {
                *shared.entry(std::sync::Arc::as_ptr(&m.mesh)).or_default() += m.len();
            }
        }
        self.implicit
            .iter()
            .map(|r| match &r.shape {
                Implicit::Instance(m) => shared[&std::sync::Arc::as_ptr(&m.mesh)],
                other => other.len(),
            })
            .collect()
    }

    /// This geometry with the primitives of `other` after its own (held ones before the
    /// implicit objects', both in order).
    pub fn append(&mut self, other: &Geometry) {
        let held = other.prims.len() as u32;
        let (mine, theirs) = (
            self.prims.len() as u32,
            self.len() - self.prims.len() as u32,
        );
        // Our implicit objects move along by their held primitives; their held ones follow
        // ours, and their implicit ones all of ours.
        for run in &mut self.implicit {
            run.first += held;
        }
        let mut parts = Vec::with_capacity(self.parts.len() + other.parts.len());
        let moved = |p: &Part, by: u32| Part {
            start: p.start + by,
            end: p.end + by,
            ..p.clone()
        };
        let (own_held, own_lat) = self
            .parts
            .split_at(self.parts.partition_point(|p| p.start < mine));
        let (other_held, other_lat) = other
            .parts
            .split_at(other.parts.partition_point(|p| p.start < held));
        parts.extend(own_held.iter().cloned());
        parts.extend(other_held.iter().map(|p| moved(p, mine)));
        parts.extend(own_lat.iter().map(|p| moved(p, held)));
        parts.extend(other_lat.iter().map(|p| moved(p, mine + theirs)));
        self.prims.extend_from_slice(&other.prims);
        self.implicit
            .extend(other.implicit.iter().map(|r| ImplicitRun {
                shape: r.shape.clone(),
                first: r.first + mine + theirs,
            }));
        self.parts = parts;
    }

    /// The part a primitive belongs to.
    pub fn part_of(&self, prim: u32) -> &Part {
        let i = self.parts.partition_point(|p| p.end <= prim);
        &self.parts[i]
    }

    /// At rest-frame point `p` of held triangle `prim`: its interpolated vertex normal and
    /// texture coordinates, where its mesh has them (None for other primitives).
    pub fn corners_at(&self, prim: u32, p: DVec3) -> (Option<DVec3>, Option<[f64; 2]>) {
        Self::corners_of(self.part_of(prim), &self.prim(prim), prim, p)
    }

    /// [`Geometry::corners_at`] of primitive number `prim` of `part`, `shape` (made by the
    /// caller, who has it already).
    #[inline]
    pub fn corners_of(
        part: &Part,
        shape: &Primitive,
        prim: u32,
        p: DVec3,
    ) -> (Option<DVec3>, Option<[f64; 2]>) {
        let (Some(c), Primitive::Triangle { v }) = (&part.corners, *shape) else {
            return (None, None);
        };
        let i = (prim - part.start) as usize;
        // Barycentric coordinates of p (on the triangle, up to rounding).
        let (e1, e2, q) = (v[1] - v[0], v[2] - v[0], p - v[0]);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (q1, q2) = (q.dot(e1), q.dot(e2));
        let det = d11 * d22 - d12 * d12;
        if det == 0.0 || !det.is_finite() {
            return (None, None);
        }
        let b1 = (d22 * q1 - d12 * q2) / det;
        let b2 = (d11 * q2 - d12 * q1) / det;
        let w = [1.0 - b1 - b2, b1, b2];
        let normal = c.normals.as_ref().and_then(|n| {
            let n = match &part.corners_placed {
                // Each corner turned as a placed copy's would have been.
                Some(x) => n[i].map(|c| x.normal(c)),
                None => n[i],
            };
            (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]).try_normalize()
        });
        let uv = c.uvs.as_ref().map(|t| {
            let t = t[i];
            [0, 1].map(|k| t[0][k] * w[0] + t[1][k] * w[1] + t[2][k] * w[2])
        });
        (normal, uv)
    }

    /// The index of primitive `prim` among its object's primitives (an object's parts are
    /// contiguous, whatever groups were merged around them).
    pub fn index_in_object(&self, prim: u32) -> u32 {
        let i = self.parts.partition_point(|p| p.end <= prim);
        let object = self.parts[i].object;
        let earlier: u32 = self.parts[..i]
            .iter()
            .rev()
            .take_while(|p| p.object == object)
            .map(|p| p.end - p.start)
            .sum();
        earlier + prim - self.parts[i].start
    }

    /// The box holding every primitive.
    pub fn bounds(&self) -> Aabb {
        let held = self
            .prims
            .iter()
            .fold(Aabb::EMPTY, |b, p| b.union(&p.bounds()));
        self.implicit
            .iter()
            .fold(held, |b, r| b.union(&r.shape.bounds()))
    }

    /// Whether it holds no primitive.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Give every part of `object` its placement.
    pub fn set_placement(&mut self, object: u32, placement: std::sync::Arc<Placement>) {
        for p in self.parts.iter_mut().filter(|p| p.object == object) {
            p.placement = Some(placement.clone());
        }
    }

    /// Give every part of `object` its spin.
    pub fn set_spin(&mut self, object: u32, spin: Spin) {
        for p in self.parts.iter_mut().filter(|p| p.object == object) {
            p.spin = Some(spin);
        }
    }

    /// Whether anything in it spins.
    pub fn spins(&self) -> bool {
        self.parts.iter().any(|p| p.spin.is_some())
    }

    /// Whether anything in it spins whose shape turns (not a body of revolution).
    pub fn turns(&self) -> bool {
        self.parts.iter().any(|p| p.spin.is_some_and(|s| s.turning))
    }

    /// How far `part`'s primitives reach from `centre` (their boxes' farthest corners): the
    /// ball a turning part sweeps.
    pub fn reach(&self, part: &Part, centre: DVec3) -> f64 {
        (part.start..part.end)
            .map(|i| {
                let b = self.prim(i).bounds();
                b.corners()
                    .iter()
                    .map(|c| (*c - centre).length())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    }

    /// The box holding every primitive at every time: a turning part's as the ball about its
    /// centre that holds it turned any way.
    pub fn swept_bounds(&self) -> Aabb {
        let mut b = self.bounds();
        for part in &self.parts {
            let Some(sp) = part.spin.filter(|s| s.turning) else {
                continue;
            };
            let r = DVec3::splat(self.reach(part, sp.centre));
            b = b.union(&Aabb::new(sp.centre - r, sp.centre + r));
        }
        b
    }

    /// The same geometry moved by `d`.
    pub fn translated(&self, d: DVec3) -> Geometry {
        self.moved(crate::spacetime::Event::new(0.0, d))
    }

    /// The same geometry moved by the spacetime translation `by` of its group's frame: in
    /// space by `by.x`, and its spinning bodies' epochs by `by.t`, so that a body turns to the
    /// same angle at the moved events.
    pub fn moved(&self, by: crate::spacetime::Event) -> Geometry {
        let d = by.x;
        Geometry {
            prims: self.prims.iter().map(|p| p.translated(d)).collect(),
            parts: self
                .parts
                .iter()
                .map(|p| Part {
                    spin: p.spin.map(|s| Spin {
                        centre: s.centre + d,
                        epoch: s.epoch + by.t,
                        ..s
                    }),
                    placement: p.placement.as_ref().map(|x| {
                        std::sync::Arc::new(Placement {
                            translate: x.translate + d,
                            ..(**x).clone()
                        })
                    }),
                    ..p.clone()
                })
                .collect(),
            implicit: self
                .implicit
                .iter()
                .map(|r| ImplicitRun {
                    shape: r.shape.translated(d),
                    first: r.first,
                })
                .collect(),
        }
    }
}
