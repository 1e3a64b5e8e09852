use super::{Event, Velocity};
use crate::geometry::Real;
use glam::{DMat3, DVec3};

/// A passive Lorentz boost along any direction, evaluated in light-cone coordinates along the
/// boost axis (docs/physics.md §8.2 item 4): `u = t − x∥`, `w = t + x∥`, `u' = e^{φ} u`, `w' = e^{−φ} w`,
/// `x⊥' = x⊥`. No step subtracts nearly equal numbers, so speeds like 1 − 1e-12 stay exact.
///
/// It may carry a turn of the axes after the boost (`turned`), as the frame of a body that
/// accelerated across its motion does (a Thomas-Wigner rotation, docs/physics.md §1.4, §12.7);
/// its inverse turns them back before the boost back.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Boost {
    axis: DVec3,
    e_pos: f64,
    e_neg: f64,
    identity: bool,
    /// `Some((k, σ))` where the axis is σ times the k-th unit vector (motion along x, y or z,
    /// as in most scenes): `null_dir` then skips the products with the axis' zeros.
    aligned: Option<(usize, f64)>,
    /// The passive rotation of the axes before the boost (X ↦ R X), if any.
    before: Option<DMat3>,
    /// The passive rotation of the axes after the boost, if any.
    after: Option<DMat3>,
}

impl Boost {
    /// The boost that changes nothing.
    pub const IDENTITY: Boost = Boost {
        axis: DVec3::ZERO,
        e_pos: 1.0,
        e_neg: 1.0,
        identity: true,
        aligned: None,
        before: None,
        after: None,
    };

    /// The boost from a frame into the frame that moves at `v` relative to it
    /// (`X' = Λ(β) X`, docs/physics.md §1.3).
    pub fn to_rest(v: &Velocity) -> Boost {
        if v.is_zero() {
            return Self::IDENTITY;
        }
        let phi = v.rapidity();
        let axis = v.direction();
        Boost {
            axis,
            e_pos: phi.exp(),
            e_neg: (-phi).exp(),
            identity: false,
            aligned: aligned(axis),
            before: None,
            after: None,
        }
    }

    /// This boost, then the axes turned by the rotation `r` (a passive X ↦ r X); an identity
    /// `r` leaves it as it is.
    pub fn turned(&self, r: DMat3) -> Boost {
        if r == DMat3::IDENTITY {
            return *self;
        }
        Boost {
            after: Some(match self.after {
                Some(a) => r * a,
                None => r,
            }),
            ..*self
        }
    }

    /// Whether it turns the axes.
    #[inline]
    pub fn turns(&self) -> bool {
        self.before.is_some() || self.after.is_some()
    }

    /// The boost out of the frame moving at `v` back into the frame `v` is measured in.
    pub fn from_rest(v: &Velocity) -> Boost {
        Self::to_rest(&v.reversed())
    }

    /// The boost back (into the frame this one starts from).
    #[inline]
    pub fn inverse(&self) -> Boost {
        Boost {
            axis: self.axis,
            e_pos: self.e_neg,
            e_neg: self.e_pos,
            identity: self.identity,
            aligned: self.aligned,
            before: self.after.map(|r| r.transpose()),
            after: self.before.map(|r| r.transpose()),
        }
    }

    /// Transform an event (or any 4-vector).
    #[inline]
    pub fn event(&self, e: Event) -> Event {
        // The frame at rest: the same event (the common case of a scene at rest).
        if self.is_identity() {
            return e;
        }
        self.event_moving(e)
    }

    /// [`Boost::event`] of a boost that is not the identity.
    #[inline(never)]
    fn event_moving(&self, e: Event) -> Event {
        let e = match self.before {
            Some(r) => Event::new(e.t, r * e.x),
            None => e,
        };
        let e = if self.identity {
            e
        } else {
            let xp = e.x.dot(self.axis);
            let u = self.e_pos * (e.t - xp);
            let w = self.e_neg * (e.t + xp);
            let xp_new = 0.5 * (w - u);
            Event::new(0.5 * (u + w), e.x + (xp_new - xp) * self.axis)
        };
        match self.after {
            Some(r) => Event::new(e.t, r * e.x),
            None => e,
        }
    }

    /// Transform the past-directed null vector `(−1, a)` with `a` a unit vector. Returns the
    /// spatial part `d'` (unnormalised) and `s = −t' = |d'|`, the factor by which the frame's
    /// lookback time exceeds the original one: for a boost into a frame moving at β,
    /// `s = γ(1 + β·a)` (docs/physics.md §7.1).
    #[inline]
    pub fn null_dir(&self, a: DVec3) -> (DVec3, f64) {
        if self.is_identity() {
            return (a, 1.0);
        }
        self.null_dir_moving(a)
    }

    /// [`Boost::null_dir`] of a boost that is not the identity.
    #[inline(never)]
    fn null_dir_moving(&self, a: DVec3) -> (DVec3, f64) {
        let ([x, y, z], s) = self.null_dir_lanes([a.x, a.y, a.z]);
        (DVec3::new(x, y, z), s)
    }

    /// [`Boost::null_dir`] of a non-identity boost, written once for one direction or several
    /// at a time (`Real`): the same operations in the same order, so every lane's answer is the
    /// scalar one to the bit.
    #[inline(always)]
    pub(crate) fn null_dir_lanes<R: Real>(&self, a: [R; 3]) -> ([R; 3], R) {
        if !self.turns() {
            return self.null_dir_unturned(a);
        }
        let a = turn_lanes(self.before, a);
        let (d, s) = self.null_dir_unturned(a);
        (turn_lanes(self.after, d), s)
    }

    /// [`Boost::null_dir_lanes`] without the turns.
    #[inline(always)]
    fn null_dir_unturned<R: Real>(&self, a: [R; 3]) -> ([R; 3], R) {
        match self.aligned {
            // One copy per axis, so every index is a constant: a copy indexing by a run-time
            // axis wrote d[k] to the stack and read d back whole, a store the load could not
            // take forwarded, which stalled every call.
            Some((0, sigma)) => return self.null_dir_along::<R, 0>(a, sigma),
            Some((1, sigma)) => return self.null_dir_along::<R, 1>(a, sigma),
            Some((_, sigma)) => return self.null_dir_along::<R, 2>(a, sigma),
            None => {}
        }
        let axis = [
            R::splat(self.axis.x),
            R::splat(self.axis.y),
            R::splat(self.axis.z),
        ];
        let ap = a[0] * axis[0] + a[1] * axis[1] + a[2] * axis[2];
        let perp = [
            a[0] - ap * axis[0],
            a[1] - ap * axis[1],
            a[2] - ap * axis[2],
        ];
        let p2 = perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2];
        let (s, par) = self.along(ap, p2);
        (
            [
                perp[0] + par * axis[0],
                perp[1] + par * axis[1],
                perp[2] + par * axis[2],
            ],
            s,
        )
    }

    /// [`Boost::null_dir_lanes`] for a boost along σ e_K: a∥ = σ a_K, a⊥ = a but for its K-th
    /// component (zero), and d' = a⊥ + par σ e_K. The same numbers as the general case but for
    /// the signs of zeros.
    #[inline(always)]
    fn null_dir_along<R: Real, const K: usize>(&self, a: [R; 3], sigma: f64) -> ([R; 3], R) {
        let ap = R::splat(sigma) * a[K];
        let (i, j) = ((K + 1) % 3, (K + 2) % 3);
        let p2 = a[i] * a[i] + a[j] * a[j];
        let (s, par) = self.along(ap, p2);
        let mut d = a;
        d[K] = par * R::splat(sigma);
        (d, s)
    }

    /// For a unit direction with a∥ = `ap` along the axis and |a⊥|² = `p2` across it: the
    /// boosted null vector's s = −t' and its component along the axis.
    #[inline(always)]
    fn along<R: Real>(&self, ap: R, p2: R) -> (R, R) {
        let one = R::splat(1.0);
        let big = one + ap.abs();
        let small = p2 / big;
        let zero = R::splat(0.0);
        let one_plus = R::select(ap.ge(zero), big, small);
        let one_minus = R::select(ap.le(zero), big, small);
        let up = R::splat(self.e_pos) * one_plus;
        let wp = R::splat(self.e_neg) * one_minus;
        let half = R::splat(0.5);
        let s = half * (up + wp);
        let par = half * (up - wp);
        (s, par)
    }

    /// The most it stretches a null vector's time part: e^|φ| (`null_dir`'s s lies within
    /// [e^−|φ|, e^|φ|]).
    pub fn max_stretch(&self) -> f64 {
        self.e_pos.max(self.e_neg)
    }

    /// Whether this boost is the identity (a frame at rest relative to the one it starts from,
    /// its axes not turned).
    #[inline]
    pub fn is_identity(&self) -> bool {
        self.identity && !self.turns()
    }

    /// The unit direction of a null ray after the boost, and the factor `s` of [`Boost::null_dir`].
    #[inline]
    pub fn view_dir(&self, a: DVec3) -> (DVec3, f64) {
        if self.is_identity() {
            return (a, 1.0);
        }
        let (d, s) = self.null_dir(a);
        (d / s, s)
    }
}

/// The lanes of a direction turned by `r`, if there is one.
#[inline(always)]
fn turn_lanes<R: Real>(r: Option<DMat3>, a: [R; 3]) -> [R; 3] {
    let Some(r) = r else { return a };
    let m = |i: usize, j: usize| R::splat(r.col(j)[i]);
    let row = |i: usize| m(i, 0) * a[0] + m(i, 1) * a[1] + m(i, 2) * a[2];
    [row(0), row(1), row(2)]
}

/// `Some((k, σ))` where `axis` is σ e_k exactly.
fn aligned(axis: DVec3) -> Option<(usize, f64)> {
    let a = axis.to_array();
    let k = (0..3).find(|&k| a[k].abs() == 1.0)?;
    let others_zero = (0..3).all(|j| j == k || a[j] == 0.0);
    others_zero.then_some((k, a[k]))
}
