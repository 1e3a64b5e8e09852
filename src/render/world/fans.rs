//! Primary rays as fans: where one group is seen from close by through a pinhole camera and
//! the backend has a path of its own (`Accelerator::intersect_fan`), a packet's primary rays are
//! made, boosted and traced by the backend from the camera and the lanes' image points, with the
//! same rays and hits to the bit as `CameraRays::ray` and `closest_hits` (tests/fused_primary.rs).

use super::{GroupRt, SurfaceHit, World};
use crate::accel::{Accelerator, Fan, FanHits, NO_HIT};
use crate::geometry::PACKET;
use crate::render::CameraRays;
use crate::spacetime::{NullRay, Pinhole};
use glam::DVec3;

impl World {
    /// The one group and its accelerator when primary rays through `cam` go to the backend as
    /// fans: a pinhole camera, a single group seen from close by (no clip, no group trees) and
    /// a backend with a path of its own for them.
    fn fan_group(&self, cam: &CameraRays) -> Option<(&GroupRt, &dyn Accelerator, Pinhole)> {
        let [g] = self.groups.as_slice() else {
            return None;
        };
        if !self.options.fused_primary
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
    pub fn serves_fans(&self, cam: &CameraRays) -> bool {
        self.fan_group(cam).is_some()
    }

    /// The primary rays through the image points `px` (pixels from the top-left corner, a
    /// tile's in packet order) into `rays`, and the visible hit of each: `cam.ray` of each and
    /// `closest_hits`, or, where the backend has a path for them, fans of PACKET rays made,
    /// boosted and traced by the backend, with the same rays and hits to the bit.
    pub fn primary_hits(
        &self,
        cam: &CameraRays,
        px: &[(f64, f64)],
        rays: &mut Vec<NullRay>,
        out: &mut [Option<SurfaceHit>],
    ) {
        rays.clear();
        let Some((g, accel, camera)) = self.fan_group(cam) else {
            return self.one_by_one(cam, px, rays, out);
        };
        let mut hits = FanHits::default();
        for (ps, os) in px.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
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
            if !accel.intersect_fan(&fan, &mut hits) {
                self.one_by_one(cam, ps, rays, os);
                continue;
            }
            let col = |c: &[[f64; PACKET]; 3], i: usize| DVec3::new(c[0][i], c[1][i], c[2][i]);
            for (i, o) in os.iter_mut().enumerate() {
                rays.push(NullRay::new(cam.event(), col(&hits.look, i)));
                // As `rest_ray` and `surface_hit` make them, with no shift along the ray.
                *o = (hits.prim[i] != NO_HIT).then(|| {
                    let dir = col(&hits.dir, i);
                    let origin = g.event_rest + 0.0 * dir;
                    SurfaceHit {
                        group: 0,
                        prim: hits.prim[i],
                        lambda: 0.0 + hits.t[i],
                        point: origin + hits.t[i] * dir,
                        dir,
                        s: hits.s[i],
                    }
                });
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
