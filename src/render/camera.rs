use crate::scene::{Camera, Projection};
use crate::spacetime::{Boost, Event, NullRay, Pinhole};
use glam::DVec3;
use std::f64::consts::PI;

/// Primary rays: a pixel's direction is defined in the camera's rest frame and boosted into the
/// world frame, so a moving camera sees the aberrated sky (docs/physics.md §7.2).
pub struct CameraRays {
    camera: Camera,
    event: Event,
    to_world: Boost,
    to_camera: Boost,
    width: f64,
    height: f64,
    focal: f64,
    /// Used for pinhole projections only (its focal length is 0 for the others).
    pinhole: Pinhole,
    /// How far the camera moves, in the world frame, over the whole exposure:
    /// `(γ s, γβ s)` for a shutter s of proper time.
    exposure: Event,
}

impl CameraRays {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let focal = match camera.projection {
            Projection::Pinhole { fov_y } => 0.5 * height as f64 / (0.5 * fov_y).tan(),
            _ => 0.0,
        };
        let to_world = Boost::from_rest(&camera.velocity);
        let pinhole = Pinhole::new([focal * camera.forward, camera.right, camera.up], to_world);
        Self {
            camera: camera.clone(),
            event: camera.imaging_event(),
            to_world,
            to_camera: Boost::to_rest(&camera.velocity),
            width: width as f64,
            height: height as f64,
            focal,
            pinhole,
            exposure: to_world.event(Event::new(camera.shutter, DVec3::ZERO)),
        }
    }

    /// Whether the shutter stays open for a while (samples then see from different events).
    pub fn has_shutter(&self) -> bool {
        self.camera.shutter > 0.0
    }

    /// [`CameraRays::ray`] from the event `f` of the exposure after the imaging event (`f`
    /// from −½ to ½): the same direction, its origin moved along the camera's worldline.
    pub fn ray_in_exposure(&self, px: f64, py: f64, f: f64) -> NullRay {
        if let Some(line) = self.camera.worldline.as_ref().filter(|w| !w.is_uniform()) {
            // On a worldline that changes velocity: the event a proper time f·s on, seen with
            // the velocity there (its clock from the worldline's anchor).
            let tau = line.proper_time(self.event.t) + f * self.camera.shutter;
            let t = line.world_time(tau);
            let to_world = Boost::from_rest(&line.velocity(t));
            return self.ray_from(px, py, Event::new(t, line.position(t)), &to_world);
        }
        let r = self.ray(px, py);
        let shift = Event::new(f * self.exposure.t, f * self.exposure.x);
        NullRay::new(r.origin + shift, r.dir)
    }

    /// [`CameraRays::ray`] as the camera sees from `event`, moving with the boost `to_world`
    /// out of its rest frame there (a sample of an exposure on a worldline that changes
    /// velocity).
    fn ray_from(&self, px: f64, py: f64, event: Event, to_world: &Boost) -> NullRay {
        let c = &self.camera;
        let (u, v) = self.centred(px, py);
        let (origin, dir_cam) = match c.projection {
            Projection::Pinhole { .. } => (
                event,
                (self.focal * c.forward + u * c.right + v * c.up).normalize(),
            ),
            Projection::Orthographic { view_height } => {
                let offset = (u * c.right + v * c.up) * (view_height / self.height);
                (event + to_world.event(Event::new(0.0, offset)), c.forward)
            }
            Projection::Equirectangular => {
                let lon = (px / self.width - 0.5) * 2.0 * PI;
                let lat = (0.5 - py / self.height) * PI;
                let d =
                    lat.cos() * (lon.cos() * c.forward + lon.sin() * c.right) + lat.sin() * c.up;
                (event, d)
            }
        };
        NullRay::new(origin, to_world.view_dir(dir_cam).0)
    }

    /// The pinhole camera's looking directions (None for other projections).
    pub fn pinhole(&self) -> Option<&Pinhole> {
        matches!(self.camera.projection, Projection::Pinhole { .. }).then_some(&self.pinhole)
    }

    /// Image point (px, py), in pixels from the top-left corner, as (u, v): pixels right of and
    /// above the image centre.
    #[inline(always)]
    pub fn centred(&self, px: f64, py: f64) -> (f64, f64) {
        (px - 0.5 * self.width, 0.5 * self.height - py)
    }

    /// The imaging event, where every ray of a pinhole camera starts.
    pub fn event(&self) -> Event {
        self.event
    }

    /// The world-frame past null ray through image point (px, py), in pixels from the top-left
    /// corner (pixel (i, j) has its centre at (i + 0.5, j + 0.5)).
    pub fn ray(&self, px: f64, py: f64) -> NullRay {
        let c = &self.camera;
        let (u, v) = self.centred(px, py);
        let (origin, dir_cam) = match c.projection {
            Projection::Pinhole { .. } => {
                // Boosted into the world frame already.
                let [x, y, z] = self.pinhole.look(u, v);
                return NullRay::new(self.event, DVec3::new(x, y, z));
            }
            Projection::Orthographic { view_height } => {
                let s = view_height / self.height;
                let offset = (u * c.right + v * c.up) * s;
                // The image plane is simultaneous in the camera's rest frame.
                (
                    self.event + self.to_world.event(Event::new(0.0, offset)),
                    c.forward,
                )
            }
            Projection::Equirectangular => {
                let lon = (px / self.width - 0.5) * 2.0 * PI;
                let lat = (0.5 - py / self.height) * PI;
                let d =
                    lat.cos() * (lon.cos() * c.forward + lon.sin() * c.right) + lat.sin() * c.up;
                (self.event, d)
            }
        };
        let (dir, _) = self.to_world.view_dir(dir_cam);
        NullRay::new(origin, dir)
    }

    /// A pinhole camera's looking direction (in the camera's rest frame, not normalised)
    /// through image point (px, py); None for other projections.
    pub fn pinhole_toward(&self, px: f64, py: f64) -> Option<DVec3> {
        matches!(self.camera.projection, Projection::Pinhole { .. })
            .then(|| self.toward(px - 0.5 * self.width, 0.5 * self.height - py))
    }

    /// A vector along the pinhole direction through (u, v), not normalised.
    fn toward(&self, u: f64, v: f64) -> DVec3 {
        let c = &self.camera;
        self.focal * c.forward + u * c.right + v * c.up
    }

    /// The full image's width and height in pixels.
    pub fn image_size(&self) -> (f64, f64) {
        (self.width, self.height)
    }

    /// A pinhole camera's focal length in pixels (0 for other projections): image points L
    /// pixels apart look in directions at most L / focal radians apart.
    pub fn focal_px(&self) -> f64 {
        self.focal
    }

    /// A world-frame looking direction as the camera sees it (unit, camera's rest frame).
    pub fn to_camera_dir(&self, world_dir: DVec3) -> DVec3 {
        self.to_camera.view_dir(world_dir).0
    }

    /// The image point (in pixels from the top-left corner) a camera-frame looking direction
    /// `d` (unit) falls on, with the solid angle of the pixel holding it; None where it falls
    /// outside the image, and always for an orthographic camera (all of whose rays look one
    /// way, so it sees no point of the sky).
    pub fn pixel_toward(&self, d: DVec3) -> Option<((u32, u32), f64)> {
        let c = &self.camera;
        let (f, r, u) = (d.dot(c.forward), d.dot(c.right), d.dot(c.up));
        let (px, py) = match c.projection {
            Projection::Pinhole { .. } => {
                if f <= 0.0 {
                    return None;
                }
                let k = self.focal / f;
                (r * k + 0.5 * self.width, 0.5 * self.height - u * k)
            }
            Projection::Equirectangular => {
                let lon = r.atan2(f);
                let lat = u.clamp(-1.0, 1.0).asin();
                (
                    (lon / (2.0 * PI) + 0.5) * self.width,
                    (0.5 - lat / PI) * self.height,
                )
            }
            Projection::Orthographic { .. } => return None,
        };
        if !(px >= 0.0 && py >= 0.0 && px < self.width && py < self.height) {
            return None;
        }
        let (x, y) = (px as u32, py as u32);
        Some(((x, y), self.pixel_solid_angle(x, y)))
    }

    /// The solid angle (camera frame, sr) pixel (x, y) looks into, exactly: for a pinhole the
    /// rectangle's solid angle seen from the focal distance (docs/physics.md §5.5), for the
    /// equirectangular projection Δlon (sin lat₀ − sin lat₁). 0 for an orthographic camera.
    pub fn pixel_solid_angle(&self, x: u32, y: u32) -> f64 {
        let (x0, y0) = self.centred(f64::from(x), f64::from(y));
        let (x1, y1) = (x0 + 1.0, y0 - 1.0);
        match self.camera.projection {
            Projection::Pinhole { .. } => {
                let f = self.focal;
                // The solid angle of [0, a] × [0, b] seen from distance f over the corner at
                // the axis, signed (odd in a and in b), so sums of four give any rectangle.
                let corner = |a: f64, b: f64| (a * b / (f * (f * f + a * a + b * b).sqrt())).atan();
                (corner(x1, y0) - corner(x0, y0) - corner(x1, y1) + corner(x0, y1)).abs()
            }
            Projection::Equirectangular => {
                let lat = |py: f64| (0.5 - py / self.height) * PI;
                let (top, bottom) = (lat(f64::from(y)), lat(f64::from(y) + 1.0));
                2.0 * PI / self.width * (top.sin() - bottom.sin())
            }
            Projection::Orthographic { .. } => 0.0,
        }
    }

    /// γ_c(1 + β_c·a): the camera's lookback factor for a world-frame looking direction `a`;
    /// the Doppler factor of a surface with factor s is this over s.
    pub fn lookback_factor(&self, dir_world: DVec3) -> f64 {
        self.to_camera.null_dir(dir_world).1
    }

    /// [`CameraRays::lookback_factor`] of a primary ray, with the camera's velocity where the
    /// ray starts: on a worldline that changes velocity, a sample of an exposure sees with the
    /// velocity at its own event.
    pub fn lookback_factor_of(&self, ray: &NullRay) -> f64 {
        match self.camera.worldline.as_ref() {
            Some(line) if self.has_shutter() && !line.is_uniform() => {
                let v = line.velocity(ray.origin.t);
                Boost::to_rest(&v).null_dir(ray.dir).1
            }
            _ => self.lookback_factor(ray.dir),
        }
    }
}
