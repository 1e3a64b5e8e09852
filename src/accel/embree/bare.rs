//! Bare Embree, for the benchmark's baseline: prepared f32 rays traced in the same packets,
//! with nothing else (no boosts, no rebasing, no f64 refinement, no hit bookkeeping), so the
//! cost of the relativistic layer is a ratio measured in the same run.

use super::exact::Lanes;
use super::packet::{flush_denormals, single, Query};
use super::{EmbreeAccel, EmbreeRay};
use embree_sys::*;
use glam::DVec3;

/// A ray already in a scene's rest frame, in f32, relative to the scene's centre.
#[derive(Clone, Copy, Debug, Default)]
pub struct BareRay {
    pub org: [f32; 3],
    pub dir: [f32; 3],
}

impl EmbreeAccel {
    /// A bare ray from a rest-frame origin and (unit) direction.
    pub fn bare_ray(&self, origin: DVec3, dir: DVec3) -> BareRay {
        let o = origin - self.scene.center;
        BareRay {
            org: [o.x as f32, o.y as f32, o.z as f32],
            dir: [dir.x as f32, dir.y as f32, dir.z as f32],
        }
    }

    /// Trace with bare Embree in this accelerator's packet width; returns the hit count.
    pub fn trace_bare(&self, rays: &[BareRay]) -> usize {
        flush_denormals();
        // No f64 rays: user geometry tests Embree's own f32 rays.
        let lanes = Lanes::<16>::new(&[], self.pullback);
        let mut context = self.context(Query::Intersect, &[], &lanes);
        let ctx = context.raw();
        let mut hits = 0;
        let w = self.width.clamp(1, 16);
        for chunk in rays.chunks(w) {
            hits += match w {
                16 => self.bare16(chunk, ctx),
                8 => self.bare8(chunk, ctx),
                4 => self.bare4(chunk, ctx),
                _ => chunk
                    .iter()
                    .map(|r| {
                        let mut rh = RTCRayHit {
                            ray: single(&r.lane()),
                            hit: RTCHit {
                                geomID: RTC_INVALID_GEOMETRY_ID,
                                ..Default::default()
                            },
                        };
                        unsafe { self.scene.rtc.intersect1(ctx, &mut rh) };
                        usize::from(rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
                    })
                    .sum(),
            };
        }
        self.settle(&context);
        hits
    }
}

impl BareRay {
    /// As the packet code's ray: from the origin, nothing excluded.
    pub(super) fn lane(&self) -> EmbreeRay {
        EmbreeRay {
            org: self.org,
            dir: self.dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
            active: true,
            offset: 0.0,
        }
    }
}
