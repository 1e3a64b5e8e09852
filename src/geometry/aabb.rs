use glam::DVec3;

/// Componentwise min and max as plain selects (one instruction each; boxes hold no NaN), where
/// f64::min / f64::max pay for NaN handling: tree builds spend most of their time here.
#[inline]
fn lower(a: DVec3, b: DVec3) -> DVec3 {
    let m = |x: f64, y: f64| if x < y { x } else { y };
    DVec3::new(m(a.x, b.x), m(a.y, b.y), m(a.z, b.z))
}

#[inline]
fn upper(a: DVec3, b: DVec3) -> DVec3 {
    let m = |x: f64, y: f64| if x > y { x } else { y };
    DVec3::new(m(a.x, b.x), m(a.y, b.y), m(a.z, b.z))
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The least corner.
    pub min: DVec3,
    /// The greatest corner.
    pub max: DVec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box: the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box between two corners.
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// Whether it holds no point (min > max on some axis).
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// The smallest box holding both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb::new(lower(self.min, o.min), upper(self.max, o.max))
    }

    /// Whether the two boxes share a point.
    pub fn overlaps(&self, o: &Aabb) -> bool {
        self.min.cmple(o.max).all() && o.min.cmple(self.max).all()
    }

    /// Grow to hold `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = lower(self.min, p);
        self.max = upper(self.max, p);
    }

    /// The eight corners (bit 0, 1, 2 of the index: max rather than min in x, y, z).
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|k| {
            DVec3::new(
                if k & 1 == 0 { self.min.x } else { self.max.x },
                if k & 2 == 0 { self.min.y } else { self.max.y },
                if k & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The centre.
    pub fn centroid(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// The edge lengths.
    pub fn extent(&self) -> DVec3 {
        (self.max - self.min).max(DVec3::ZERO)
    }

    /// The length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.extent().length()
        }
    }

    /// The surface area (0 for an empty box).
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The farthest the box reaches along `dir`: the largest p·dir over its points.
    pub fn support(&self, dir: DVec3) -> f64 {
        let pick = |k: usize| {
            let (lo, hi) = (self.min[k] * dir[k], self.max[k] * dir[k]);
            lo.max(hi)
        };
        pick(0) + pick(1) + pick(2)
    }

    /// The box about this one turned by the rotation `r` (its corners turned).
    pub fn turned(&self, r: glam::DMat3) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        let mut b = Aabb::EMPTY;
        for c in self.corners() {
            b.grow(r * c);
        }
        b
    }

    /// The largest absolute coordinate of the box.
    pub fn max_abs(&self) -> f64 {
        self.min.abs().max(self.max.abs()).max_element()
    }

    /// Slab test: the parameter interval `[t0, t1]` of `o + t d` inside the box, clipped to
    /// `[tmin, tmax]`, or None.
    pub fn clip(&self, o: DVec3, inv_d: DVec3, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
        let a = (self.min - o) * inv_d;
        let b = (self.max - o) * inv_d;
        // Plain comparisons (one instruction each): a NaN (0 · inf on a slab boundary) fails
        // every comparison, so it never replaces the interval's ends.
        let (mut t0, mut t1) = (tmin, tmax);
        for k in 0..3 {
            let (lo, hi) = if a[k] < b[k] {
                (a[k], b[k])
            } else {
                (b[k], a[k])
            };
            if lo > t0 {
                t0 = lo;
            }
            if hi < t1 {
                t1 = hi;
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }
}
