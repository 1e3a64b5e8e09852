/// One pixel's values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelValue {
    /// Linear sRGB colour.
    pub color: [f32; 3],
    /// Coverage: the share of the pixel's samples that hit a surface.
    pub alpha: f32,
    /// World-frame lookback time of the primary hit (0 where nothing was hit).
    pub lookback: f32,
    /// Frequency ratio camera / surface of the primary hit (0 where nothing was hit).
    pub doppler: f32,
    /// Index + 1 of the scene object hit by the primary ray; 0 for background.
    pub object_id: u32,
    /// Rest-frame outward normal of the primary hit's surface (0 for background).
    pub normal: [f32; 3],
    /// World-frame position of the primary hit's emission event: where the surface point was
    /// when it sent the light (its apparent position; 0 for background).
    pub position: [f32; 3],
    /// The primary hit's point in its group's rest frame (a reference position that follows
    /// the object, for texturing in compositing; 0 for background).
    pub rest_position: [f32; 3],
    /// Distance along the camera's look axis, in the camera's rest frame, from the imaging
    /// event to the primary hit's emission event ([`DEPTH_FAR`] where nothing was hit).
    pub depth: f32,
    /// The emission event relative to the imaging event in the camera's rest frame, on its
    /// axes (right, up, look): what a relighting tool needs from a moving camera (0 for
    /// background). Its z is `depth`.
    pub camera_position: [f32; 3],
    /// 1 + index of the primary hit's material; 0 for background.
    pub material_id: u32,
    /// 1 + index of the primitive hit among its object's (with `object_id`, one primitive of
    /// a lattice or a mesh); 0 for background.
    pub primitive_id: u32,
}

/// `depth` where nothing was hit: farther than anything a valid scene holds, and finite.
pub const DEPTH_FAR: f32 = f32::MAX;

/// How many objects (and materials) a pixel's mattes keep, by coverage.
pub(crate) const MATTE_RANKS: usize = 6;

/// What a pixel's samples saw, for anti-aliased mattes (Cryptomatte): the objects and the
/// materials with the largest shares of the samples, largest first, as (index + 1, share);
/// (0, 0) where fewer were seen. The shares add up to the pixel's alpha when no more than
/// [`MATTE_RANKS`] were seen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mattes {
    /// `[[group.object]]`s, by their `object_id`.
    pub object: [(u32, f32); MATTE_RANKS],
    /// Materials, by index + 1 in [`Scene::materials`](crate::scene::Scene::materials).
    pub material: [(u32, f32); MATTE_RANKS],
}

/// The rendered image and its extra passes, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The pixels, row by row from the top.
    pub pixels: Vec<PixelValue>,
    /// Each pixel's mattes, in the order of `pixels`; empty in a render of colour alone.
    pub mattes: Vec<Mattes>,
}

impl Frame {
    /// A frame of empty pixels, without mattes.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![PixelValue::default(); (width * height) as usize],
            mattes: Vec::new(),
        }
    }

    /// The pixel at column `x`, row `y` from the top.
    pub fn get(&self, x: u32, y: u32) -> &PixelValue {
        &self.pixels[(y * self.width + x) as usize]
    }

    /// A channel by its EXR name.
    pub fn channel(&self, name: &str) -> Option<Vec<f32>> {
        let i = pass(name)?;
        Some(self.pixels.iter().map(|p| p.values()[i]).collect())
    }
}

impl PixelValue {
    /// The pixel's value in each of [`CHANNELS`], in that order (ids as f32).
    #[inline]
    pub fn values(&self) -> [f32; CHANNELS.len()] {
        let [r, g, b] = self.color;
        let [nx, ny, nz] = self.normal;
        let [px, py, pz] = self.position;
        let [qx, qy, qz] = self.rest_position;
        let [cx, cy, cz] = self.camera_position;
        [
            r,
            g,
            b,
            self.alpha,
            self.depth,
            self.lookback,
            self.doppler,
            self.object_id as f32,
            self.material_id as f32,
            self.primitive_id as f32,
            nx,
            ny,
            nz,
            px,
            py,
            pz,
            qx,
            qy,
            qz,
            cx,
            cy,
            cz,
        ]
    }
}

/// Which of [`CHANNELS`] (and of [`PixelValue::values`]) is the channel named `name`.
pub fn pass(name: &str) -> Option<usize> {
    CHANNELS.iter().position(|&c| c == name)
}

/// Channel names written to EXR, in this order.
pub(crate) const CHANNELS: [&str; 22] = [
    "R",
    "G",
    "B",
    "A",
    "Z",
    "lookback.V",
    "doppler.V",
    "object_id.V",
    "material_id.V",
    "primitive_id.V",
    "N.X",
    "N.Y",
    "N.Z",
    "P.X",
    "P.Y",
    "P.Z",
    "Pref.X",
    "Pref.Y",
    "Pref.Z",
    "Pcam.X",
    "Pcam.Y",
    "Pcam.Z",
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Each channel holds the field its name says.
    #[test]
    fn channels_hold_their_fields() {
        let p = PixelValue {
            color: [1.0, 2.0, 3.0],
            alpha: 4.0,
            lookback: 5.0,
            doppler: 6.0,
            object_id: 7,
            normal: [8.0, 9.0, 10.0],
            position: [11.0, 12.0, 13.0],
            rest_position: [14.0, 15.0, 16.0],
            depth: 17.0,
            camera_position: [18.0, 19.0, 20.0],
            material_id: 21,
            primitive_id: 22,
        };
        let frame = Frame {
            pixels: vec![p],
            ..Frame::new(1, 1)
        };
        let want = [
            ("R", 1.0),
            ("G", 2.0),
            ("B", 3.0),
            ("A", 4.0),
            ("lookback.V", 5.0),
            ("doppler.V", 6.0),
            ("object_id.V", 7.0),
            ("N.X", 8.0),
            ("N.Y", 9.0),
            ("N.Z", 10.0),
            ("P.X", 11.0),
            ("P.Y", 12.0),
            ("P.Z", 13.0),
            ("Pref.X", 14.0),
            ("Pref.Y", 15.0),
            ("Pref.Z", 16.0),
            ("Z", 17.0),
            ("Pcam.X", 18.0),
            ("Pcam.Y", 19.0),
            ("Pcam.Z", 20.0),
            ("material_id.V", 21.0),
            ("primitive_id.V", 22.0),
        ];
        assert_eq!(want.len(), CHANNELS.len());
        for (name, v) in want {
            assert_eq!(frame.channel(name), Some(vec![v]), "{name}");
        }
        assert_eq!(frame.channel("depth.Z"), None);
    }
}
