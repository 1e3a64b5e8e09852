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
        }
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

    /// γ_c(1 + β_c·a): the camera's lookback factor for a world-frame looking direction `a`;
    /// the Doppler factor of a surface with factor s is this over s.
    pub fn lookback_factor(&self, dir_world: DVec3) -> f64 {
        self.to_camera.null_dir(dir_world).1
    }
}
