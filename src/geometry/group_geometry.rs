//! The static geometry of one velocity group in its rest frame: primitives held one by one,
//! lattices held as themselves, and the parts (object and material) they belong to.

use super::{Aabb, Lattice, Primitive};
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
}

/// The static geometry of one velocity group, in its rest frame.
///
/// Primitives are numbered from 0: first those held in `prims`, then those of the implicit
/// lattices, each a run of numbers (`LatticeRun`). Read one by number with [`prim`](Self::prim).
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// The primitives held one by one: numbers 0 to `prims.len()`.
    pub prims: Vec<Primitive>,
    /// The runs of primitives, in order, covering every primitive.
    pub parts: Vec<Part>,
    /// Lattices whose primitives are made from their numbers, after `prims`, in order.
    pub lattices: Vec<LatticeRun>,
}

/// A lattice held as itself: its primitives are numbers `first ..` `first + lattice.len()`.
#[derive(Clone, Debug, PartialEq)]
pub struct LatticeRun {
    /// The lattice.
    pub lattice: Lattice,
    /// The geometry's number of the lattice's primitive 0.
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
        let start = self.prims.len() as u32;
        self.prims.extend(prims);
        let end = self.prims.len() as u32;
        if end > start {
            // Held primitives come before the lattices' numbers: move those along.
            let added = end - start;
            let at = self.parts.partition_point(|p| p.start < start);
            for p in &mut self.parts[at..] {
                p.start += added;
                p.end += added;
            }
            for run in &mut self.lattices {
                run.first += added;
            }
            self.parts.insert(
                at,
                Part {
                    start,
                    end,
                    object,
                    material,
                },
            );
        }
    }

    /// Append a lattice as itself (its spheres one part, its rods another), numbered after
    /// everything else; an error if the geometry would hold more primitives than a `u32`
    /// numbers.
    pub fn push_lattice(
        &mut self,
        object: u32,
        sphere_material: u32,
        rod_material: u32,
        lattice: Lattice,
    ) -> Result<(), String> {
        let first = self.len();
        let total = first as u64 + lattice.len();
        if total > u32::MAX as u64 {
            return Err(format!(
                "a velocity group holds at most {} primitives; this lattice would make it {total}",
                u32::MAX
            ));
        }
        let mid = first + lattice.sphere_count() as u32;
        let end = total as u32;
        for (start, end, material) in [(first, mid, sphere_material), (mid, end, rod_material)] {
            if end > start {
                self.parts.push(Part {
                    start,
                    end,
                    object,
                    material,
                });
            }
        }
        if end > first {
            self.lattices.push(LatticeRun { lattice, first });
        }
        Ok(())
    }

    /// How many primitives, held and implicit.
    pub fn len(&self) -> u32 {
        self.lattices.last().map_or(self.prims.len() as u32, |r| {
            r.first + r.lattice.len() as u32
        })
    }

    /// How many primitives the implicit lattices make.
    pub fn implicit_len(&self) -> u64 {
        self.lattices.iter().map(|r| r.lattice.len()).sum()
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
        let i = self.lattices.partition_point(|r| r.first <= id) - 1;
        let run = &self.lattices[i];
        run.lattice.prim((id - run.first) as u64)
    }

    /// The same geometry with every lattice's primitives held one by one (the same numbers).
    pub fn flattened(&self) -> Geometry {
        let mut prims = Vec::with_capacity(self.len() as usize);
        prims.extend_from_slice(&self.prims);
        for run in &self.lattices {
            prims.extend(run.lattice.spheres().chain(run.lattice.rods()));
        }
        Geometry {
            prims,
            parts: self.parts.clone(),
            lattices: Vec::new(),
        }
    }

    /// This geometry with the primitives of `other` after its own (held ones before the
    /// lattices', both in order).
    pub fn append(&mut self, other: &Geometry) {
        let held = other.prims.len() as u32;
        let (mine, theirs) = (
            self.prims.len() as u32,
            self.len() - self.prims.len() as u32,
        );
        // Our lattices move along by their held primitives; their held ones follow ours, and
        // their lattices all of ours.
        for run in &mut self.lattices {
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
        self.lattices
            .extend(other.lattices.iter().map(|r| LatticeRun {
                lattice: r.lattice.clone(),
                first: r.first + mine + theirs,
            }));
        self.parts = parts;
    }

    /// The part a primitive belongs to.
    pub fn part_of(&self, prim: u32) -> &Part {
        let i = self.parts.partition_point(|p| p.end <= prim);
        &self.parts[i]
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
        self.lattices
            .iter()
            .fold(held, |b, r| b.union(&r.lattice.bounds()))
    }

    /// Whether it holds no primitive.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The same geometry moved by `d`.
    pub fn translated(&self, d: DVec3) -> Geometry {
        Geometry {
            prims: self.prims.iter().map(|p| p.translated(d)).collect(),
            parts: self.parts.clone(),
            lattices: self
                .lattices
                .iter()
                .map(|r| LatticeRun {
                    lattice: r.lattice.translated(d),
                    first: r.first,
                })
                .collect(),
        }
    }
}
