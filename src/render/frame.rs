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
pub const MATTE_RANKS: usize = 6;

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
        let f = pass(name)?;
        Some(self.pixels.iter().map(f).collect())
    }
}

/// Where the pass of a channel named `name` (one of [`CHANNELS`]) lies in a pixel.
pub fn pass(name: &str) -> Option<fn(&PixelValue) -> f32> {
    let f: fn(&PixelValue) -> f32 = match name {
        "R" => |p| p.color[0],
        "G" => |p| p.color[1],
        "B" => |p| p.color[2],
        "A" => |p| p.alpha,
        "relativity.lookback" => |p| p.lookback,
        "relativity.doppler" => |p| p.doppler,
        "depth.Z" => |p| p.depth,
        "Pcam.X" => |p| p.camera_position[0],
        "Pcam.Y" => |p| p.camera_position[1],
        "Pcam.Z" => |p| p.camera_position[2],
        "material_id" => |p| p.material_id as f32,
        "primitive_id" => |p| p.primitive_id as f32,
        "object_id" => |p| p.object_id as f32,
        "N.X" => |p| p.normal[0],
        "N.Y" => |p| p.normal[1],
        "N.Z" => |p| p.normal[2],
        "P.X" => |p| p.position[0],
        "P.Y" => |p| p.position[1],
        "P.Z" => |p| p.position[2],
        "Pref.X" => |p| p.rest_position[0],
        "Pref.Y" => |p| p.rest_position[1],
        "Pref.Z" => |p| p.rest_position[2],
        _ => return None,
    };
    Some(f)
}

/// Channel names written to EXR, in this order.
pub const CHANNELS: [&str; 22] = [
    "R",
    "G",
    "B",
    "A",
    "depth.Z",
    "relativity.lookback",
    "relativity.doppler",
    "object_id",
    "material_id",
    "primitive_id",
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
