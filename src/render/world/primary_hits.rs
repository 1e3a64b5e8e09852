//! Primary rays as fans: where one group is seen from close by through a pinhole camera and
//! the backend has a path of its own (`Accelerator::intersect_fan`), a packet's primary rays are
//! made, boosted and traced by the backend from the camera and the lanes' image points, with the
//! same rays and hits to the bit as `CameraRays::ray` and `closest_hits` (src/tests/fused_primary.rs).

use super::{SurfaceHit, World, WorldGroup};
use crate::accel::{Accelerator, Fan, FanHits, NO_HIT};
use crate::geometry::PACKET;
use crate::render::tile::ImagePoints;
use crate::render::CameraRays;
use crate::spacetime::{Event, NullRay, Pinhole};
use glam::DVec3;

impl World {
    /// The one group and its accelerator when primary rays through `cam` go to the backend as
    /// fans: a pinhole camera, a single group seen from close by (no clip, no group trees) and
    /// a backend with a path of its own for them.
    fn fan_group(&self, cam: &CameraRays) -> Option<(&WorldGroup, &dyn Accelerator, Pinhole)> {
        let [g] = self.groups.as_slice() else {
            return None;
        };
        if !self.options.fused_primary
            || g.window.is_some()
            || g.spins
            || self.clip_rays
            || self.primary_tree.is_some()
            || cam.event() != self.event
        {
            return None;
        }
        let accel = g.accel.as_deref().filter(|a| a.serves_fans())?;
        Some((g, accel, *cam.pinhole()?))
    }

    /// Whether `primary_hits` hands the primary rays through `cam` to the backend as fans.
    #[cfg(all(test, feature = "embree"))]
    pub fn serves_fans(&self, cam: &CameraRays) -> bool {
        self.fan_group(cam).is_some()
    }

    /// The primary rays through the image points `points` (pixels from the top-left corner,
    /// a tile's in packet order) and the visible hit of each, into `out`: `cam.ray` of each and
    /// `closest_hits`, or, where the backend has a path for them, fans of PACKET rays made,
    /// boosted and traced by the backend, left in its columns, with the same rays and hits to
    /// the bit. Points with times in the exposure are seen from their events on the camera's
    /// worldline (`CameraRays::ray_in_exposure`), one by one.
    pub fn primary_hits(&self, cam: &CameraRays, points: &ImagePoints, out: &mut PrimaryHits) {
        let px = points.px.as_slice();
        out.len = px.len();
        let fans = self.fan_group(cam).filter(|_| points.times.is_empty());
        let Some((g, accel, camera)) = fans else {
            out.fan = None;
            out.hits.resize(px.len(), None);
            out.rays.clear();
            if !points.times.is_empty() {
                let shifted = px.iter().zip(&points.times);
                let rays = shifted.map(|(&(x, y), &f)| cam.ray_in_exposure(x, y, f));
                out.rays.extend(rays);
                return self.closest_hits(&out.rays, 0.0, &mut out.hits);
            }
            return self.one_by_one(cam, px, &mut out.rays, &mut out.hits);
        };
        out.fan = Some((cam.event(), g.event_rest));
        let packets = px.len().div_ceil(PACKET);
        out.fans
            .resize_with(packets.max(out.fans.len()), FanHits::default);
        for (ps, hits) in px.chunks(PACKET).zip(out.fans.iter_mut()) {
            let mut fan = Fan {
                camera: &camera,
                to_rest: &g.boost,
                origin: g.event_rest,
                u: [0.0; PACKET],
                v: [0.0; PACKET],
                n: ps.len(),
            };
            for (i, &(x, y)) in ps.iter().enumerate() {
                (fan.u[i], fan.v[i]) = cam.centred(x, y);
            }
            if accel.intersect_fan(&fan, hits) {
                continue;
            }
            // Declined: made one by one, into the columns. The one group's primary rays are
            // not shifted along themselves (no clip), so the hits are read back the same.
            // (Its buffer for rays made one by one is free in this mode.)
            let mut found = [None; PACKET];
            out.rays.clear();
            self.one_by_one(cam, ps, &mut out.rays, &mut found[..ps.len()]);
            for (i, (r, h)) in out.rays.iter().zip(&found).enumerate() {
                for k in 0..3 {
                    hits.look[k][i] = r.dir[k];
                }
                hits.prim[i] = NO_HIT;
                if let Some(h) = h {
                    for k in 0..3 {
                        hits.dir[k][i] = h.dir[k];
                    }
                    (hits.s[i], hits.t[i], hits.prim[i]) = (h.s, h.lambda, h.prim);
                }
            }
        }
    }

    /// `primary_hits` without fans: each image point's ray made by `cam.ray` (appended to
    /// `rays`), then `closest_hits` of them.
    fn one_by_one(
        &self,
        cam: &CameraRays,
        px: &[(f64, f64)],
        rays: &mut Vec<NullRay>,
        out: &mut [Option<SurfaceHit>],
    ) {
        let start = rays.len();
        rays.extend(px.iter().map(|&(x, y)| cam.ray(x, y)));
        self.closest_hits(&rays[start..], 0.0, out);
    }
}

/// A tile's primary rays and their visible hits (`World::primary_hits`), ray by ray: made one
/// by one, as rays and hits; or from fans, as the backend left them, in its columns, read back
/// when asked for (writing out every ray and hit costs more than reading the few the renderer
/// asks for, once or twice each). Kept from one tile to the
/// next, so its buffers are allocated once.
#[derive(Default)]
pub struct PrimaryHits {
    len: usize,
    rays: Vec<NullRay>,
    hits: Vec<Option<SurfaceHit>>,
    /// From fans: the imaging event, where every ray starts, and its position in the one
    /// group's rest frame; the fans' columns, PACKET rays each.
    fan: Option<(Event, DVec3)>,
    fans: Vec<FanHits>,
}

impl PrimaryHits {
    pub fn len(&self) -> usize {
        self.len
    }

    fn lane(&self, i: usize) -> (&FanHits, usize) {
        (&self.fans[i / PACKET], i % PACKET)
    }

    /// The world-frame primary ray i.
    #[inline]
    pub fn ray(&self, i: usize) -> NullRay {
        assert!(i < self.len, "primary ray {i} of {}", self.len);
        let Some((event, _)) = self.fan else {
            return self.rays[i];
        };
        let (f, j) = self.lane(i);
        NullRay::new(event, DVec3::new(f.look[0][j], f.look[1][j], f.look[2][j]))
    }

    /// How many of the primary rays meet anything.
    pub fn hit_count(&self) -> usize {
        if self.fan.is_none() {
            return self.hits.iter().filter(|h| h.is_some()).count();
        }
        // Packet by packet (a flat iterator over the lanes adds a division per lane).
        let (whole, rest) = (self.len / PACKET, self.len % PACKET);
        let count = |prim: &[u32]| {
            prim.iter()
                .map(|&p| usize::from(p != NO_HIT))
                .sum::<usize>()
        };
        let full: usize = self.fans[..whole].iter().map(|f| count(&f.prim)).sum();
        full + self.fans.get(whole).map_or(0, |f| count(&f.prim[..rest]))
    }

    /// Whether primary ray i meets anything.
    #[inline]
    pub fn is_hit(&self, i: usize) -> bool {
        assert!(i < self.len, "primary ray {i} of {}", self.len);
        match self.fan {
            None => self.hits[i].is_some(),
            Some(_) => {
                let (f, j) = self.lane(i);
                f.prim[j] != NO_HIT
            }
        }
    }

    /// The visible hit of primary ray i.
    #[inline]
    pub fn hit(&self, i: usize) -> Option<SurfaceHit> {
        assert!(i < self.len, "primary ray {i} of {}", self.len);
        let Some((_, event_rest)) = self.fan else {
            return self.hits[i];
        };
        let (f, j) = self.lane(i);
        // As `rest_ray` and `surface_hit` make them, with no shift along the ray.
        (f.prim[j] != NO_HIT).then(|| {
            let dir = DVec3::new(f.dir[0][j], f.dir[1][j], f.dir[2][j]);
            let origin = event_rest + 0.0 * dir;
            SurfaceHit {
                group: 0,
                prim: f.prim[j],
                lambda: 0.0 + f.t[j],
                point: origin + f.t[j] * dir,
                dir,
                s: f.s[j],
            }
        })
    }
}
