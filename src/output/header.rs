//! What an EXR's header says about its render beside its pixels: the scene file and its
//! overrides, the backend, samples, the camera's time and velocity, every group's velocity, and
//! the camera as the matrices compositors read (`worldToCamera`, `worldToNDC`).
//!
//! The matrices describe the camera at the imaging event, its position and axes, as if at rest.
//! They are exact for a camera at rest in the world frame. A moving camera sees the world
//! aberrated, which no 4 × 4 matrix expresses; for it, `Pcam` and `Z` (depth) hold the positions
//! it sees.

use super::cryptomatte::MatteNames;
use super::Attribute;
use crate::scene::{Camera, ImageSettings, Projection, Scene};

/// OpenEXR's camera space: x right, y up, z along the view; a row vector times the matrix
/// (row-major, as Imath's `M44f`).
pub(crate) fn world_to_camera(cam: &Camera) -> [f64; 16] {
    let (r, u, f, e) = (cam.right, cam.up, cam.forward, cam.position);
    [
        r.x,
        u.x,
        f.x,
        0.0,
        r.y,
        u.y,
        f.y,
        0.0,
        r.z,
        u.z,
        f.z,
        0.0,
        -e.dot(r),
        -e.dot(u),
        -e.dot(f),
        1.0,
    ]
}

/// OpenEXR's normalized device coordinates: (0, 0) at the top left corner of the display
/// window, which is the full image (a crop is a data window inside it), (1, 1) at the bottom
/// right, y down; a row vector `[x y z 1]` times the matrix, divided by its last component.
/// None for projections no matrix gives (equirectangular).
pub(crate) fn world_to_ndc(cam: &Camera, image: &ImageSettings) -> Option<[f64; 16]> {
    let (w, h) = (f64::from(image.width), f64::from(image.height));
    let (fw, fh) = (w, h);
    let (cx, cy) = (0.5, 0.5);
    let camera_to_ndc = match cam.projection {
        Projection::Pinhole { fov_y } => {
            let f = h / 2.0 / (fov_y / 2.0).tan();
            [
                f / fw,
                0.0,
                0.0,
                0.0,
                0.0,
                -f / fh,
                0.0,
                0.0,
                cx,
                cy,
                1.0,
                1.0,
                0.0,
                0.0,
                0.0,
                0.0,
            ]
        }
        Projection::Orthographic { view_height } => {
            let s = h / view_height;
            [
                s / fw,
                0.0,
                0.0,
                0.0,
                0.0,
                -s / fh,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0,
                0.0,
                cx,
                cy,
                0.0,
                1.0,
            ]
        }
        Projection::Equirectangular => return None,
    };
    Some(product(&world_to_camera(cam), &camera_to_ndc))
}

/// The product of two row-major 4 × 4 matrices.
fn product(a: &[f64; 16], b: &[f64; 16]) -> [f64; 16] {
    std::array::from_fn(|k| {
        let (i, j) = (k / 4, k % 4);
        (0..4).map(|n| a[4 * i + n] * b[4 * n + j]).sum()
    })
}

/// The header attributes of a render of `scene` on `backend` from `scene_file` with the
/// command line's `overrides`.
pub fn attributes(
    scene: &Scene,
    backend: &str,
    scene_file: &str,
    overrides: &[String],
) -> Vec<(String, Attribute)> {
    use Attribute as A;
    let cam = &scene.camera;
    let as_f32 = |m: [f64; 16]| m.map(|x| x as f32);
    let beta = |v: &crate::spacetime::Velocity| v.beta_vec().to_array().map(|x| x as f32);
    const SHOWN_GROUPS: usize = 1000;
    let mut groups: Vec<String> = scene
        .groups
        .iter()
        .take(SHOWN_GROUPS)
        .enumerate()
        .map(|(i, g)| {
            // β to 13 significant digits: the rapidity it is kept as rounds 0.5 to 0.49999….
            let b = g
                .velocity
                .beta_vec()
                .to_array()
                .map(|x| format!("{x:.12e}").parse::<f64>().unwrap_or(x));
            match scene.worldline_piece(i) {
                Some((k, n)) => format!(
                    "{}: beta = {b:?} (piece {k} of {n} of its worldline)",
                    g.name
                ),
                None => format!("{}: beta = {b:?}", g.name),
            }
        })
        .collect();
    if scene.groups.len() > SHOWN_GROUPS {
        groups.push(format!("and {} more", scene.groups.len() - SHOWN_GROUPS));
    }
    let mut attributes = vec![
        ("renderScene".into(), A::Text(scene_file.into())),
        ("renderBackend".into(), A::Text(backend.into())),
        ("renderSamples".into(), A::Int(scene.image.samples as i32)),
        ("cameraTime".into(), A::Number(cam.time)),
        ("cameraVelocity".into(), A::Vector(beta(&cam.velocity))),
        (
            "worldToCamera".into(),
            A::Matrix(as_f32(world_to_camera(cam))),
        ),
    ];
    if let Some(m) = world_to_ndc(cam, &scene.image) {
        attributes.push(("worldToNDC".into(), A::Matrix(as_f32(m))));
    }
    attributes.push((
        RENDER_ID.into(),
        A::Text(render_id(scene, backend, overrides)),
    ));
    // OpenEXR has no empty list of strings.
    for (name, list) in [
        ("renderOverrides", overrides.to_vec()),
        ("groupVelocities", groups),
    ] {
        if !list.is_empty() {
            attributes.push((name.into(), A::Texts(list)));
        }
    }
    attributes
}

/// The header attribute (and PNG text) holding `render_id`.
pub(crate) const RENDER_ID: &str = "renderId";

/// What identifies a render's settings, as hex: a hash of the whole scene as loaded (every
/// value, the view time and the image settings but the crop included, overrides applied), the
/// backend, the overrides as given and the renderer's version. Two files with the same id are
/// frames of the same render settings: `--resume` skips only a frame whose file says so. The
/// scene's values are serialized to bytes (postcard: every number its bits, every sequence its
/// length first) into xxh3 (`geometry::digest`), never formatted as text; a geometry's bulk
/// (primitives, mesh vertices and indices, corner data) and a texture's texels stand there as
/// their digests, each made once for the data's life, and a colour's tables, made from its
/// spectrum, are left out.
pub(crate) fn render_id(scene: &Scene, backend: &str, overrides: &[String]) -> String {
    // Field by field, the image without its crop: the tiles of one render share its id.
    let image = crate::scene::ImageSettings {
        crop: None,
        ..scene.image.clone()
    };
    let Scene {
        camera,
        render,
        materials,
        lights,
        groups,
        objects,
        film,
        sky,
        fog,
        image: _,
        warnings: _,
        inputs: _,
    } = scene;
    // The renderer's version too: another version may draw the same settings otherwise, and
    // `--resume` must not keep its frames.
    let fields = (
        env!("CARGO_PKG_VERSION"),
        camera,
        &image,
        render,
        materials,
        lights,
        groups,
        objects,
        film,
        sky,
        fog,
        backend,
        overrides,
    );
    let mut digest = crate::geometry::digest::Digest::new();
    digest.value(&fields);
    format!("{:016x}", digest.finish())
}

/// The names of the scene's objects and materials for the Cryptomatte manifests: an object's
/// `name`, or where it has none its group, kind and place in the file.
pub(crate) fn matte_names(scene: &Scene) -> MatteNames {
    let objects = scene
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| match &o.name {
            Some(n) => n.clone(),
            None => format!("{}/{}{i}", scene.groups[o.group].name, o.kind),
        })
        .collect();
    let materials = scene.materials.iter().map(|m| m.name.clone()).collect();
    MatteNames::new(objects, materials)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn ndc(m: &[f64; 16], p: DVec3) -> (f64, f64) {
        let v = [p.x, p.y, p.z, 1.0];
        let out: [f64; 4] = std::array::from_fn(|j| (0..4).map(|i| v[i] * m[4 * i + j]).sum());
        (out[0] / out[3], out[1] / out[3])
    }

    /// Points land where the renderer's pixels see them: the view's centre at (0.5, 0.5), a
    /// point f px right and up of it one pixel per unit of NDC over the width and height, and
    /// a crop changes nothing (NDC are the display window's, the full image's).
    #[test]
    fn world_to_ndc_puts_points_on_their_pixels() {
        let text = "[camera]\nposition = [1, 2, 3]\ndirection = [0, 1, 0]\nfov_y = 90\n\
                    [image]\nwidth = 200\nheight = 100\n[[group]]\nname = \"g\"\n\
                    [[group.object]]\ntype = \"sphere\"\ncenter = [0, 9, 0]\nradius = 1\n";
        let mut s = crate::scene::load_str("t.toml", text, &[]).unwrap();
        let m = world_to_ndc(&s.camera, &s.image).unwrap();
        let (x, y) = ndc(&m, DVec3::new(1.0, 12.0, 3.0));
        assert!((x - 0.5).abs() < 1e-12 && (y - 0.5).abs() < 1e-12);
        // f = 50 px: a point 1 right and 1 up at distance 10 is 5 px right and 5 px up.
        let (x, y) = ndc(&m, DVec3::new(2.0, 12.0, 4.0));
        assert!((x - 105.0 / 200.0).abs() < 1e-12 && (y - 45.0 / 100.0).abs() < 1e-12);
        s.image.crop = Some([100, 0, 50, 50]);
        let m = world_to_ndc(&s.camera, &s.image).unwrap();
        let (x, y) = ndc(&m, DVec3::new(2.0, 12.0, 4.0));
        assert!((x - 105.0 / 200.0).abs() < 1e-12 && (y - 45.0 / 100.0).abs() < 1e-12);
    }

    fn id_of(text: &str, overrides: &[(String, String)]) -> String {
        let scene = crate::scene::load_str("t.toml", text, overrides).unwrap();
        render_id(&scene, "embree", &[])
    }

    const SCENE: &str = "[camera]\nposition = [0, -10, 0]\nlook_at = [0, 0, 0]\n\
        [image]\nwidth = 8\nheight = 8\n\
        [[material]]\nname = \"red\"\ncolor = [0.8, 0.1, 0.1]\n\
        [[group]]\nname = \"g\"\nvelocity = [0.5, 0, 0]\n\
        [[group.object]]\ntype = \"mesh\"\nmaterial = \"red\"\n\
        vertices = [[0, 0, 0], [1, 0, 0], [0, 0, 1]]\nindices = [[0, 1, 2]]\n\
        [[group.object]]\ntype = \"sphere\"\ncenter = [3, 0, 0]\nradius = 1\n\
        [[light]]\nposition = [0, -10, 5]\n";

    /// The id names the settings: the same scene loaded twice, or cut into tiles, has one id;
    /// a change of any value's last bit (a velocity, a mesh's vertex, a colour, a sphere's
    /// radius), of the backend or of the overrides as given, another.
    #[test]
    fn the_render_id_follows_every_value_and_only_the_settings() {
        let base = id_of(SCENE, &[]);
        assert_eq!(base.len(), 16);
        assert!(base.bytes().all(|b| b.is_ascii_hexdigit()));
        assert_eq!(base, id_of(SCENE, &[]));
        let cropped = SCENE.replace("height = 8\n", "height = 8\ncrop = [0, 0, 4, 4]\n");
        assert_eq!(base, id_of(&cropped, &[]));
        let next = |x: f64| format!("{:?}", f64::from_bits(x.to_bits() + 1));
        let changed = [
            SCENE.replace("velocity = [0.5,", &format!("velocity = [{},", next(0.5))),
            SCENE.replace(
                "[1, 0, 0], [0, 0, 1]",
                &format!("[{}, 0, 0], [0, 0, 1]", next(1.0)),
            ),
            SCENE.replace("[0.8, 0.1, 0.1]", &format!("[0.8, {}, 0.1]", next(0.1))),
            SCENE.replace("radius = 1\n", &format!("radius = {}\n", next(1.0))),
            SCENE.replace("[0, -10, 5]", &format!("[0, -10, {}]", next(5.0))),
            format!("{SCENE}[fog]\ngroup = \"g\"\nsigma_a = 0.01\n"),
        ];
        let mut seen = std::collections::HashSet::from([base.clone()]);
        for text in &changed {
            assert_ne!(text, SCENE);
            assert!(seen.insert(id_of(text, &[])), "{text}");
        }
        let set = |s: &str| (format!("--set {s}"), s.to_string());
        assert!(seen.insert(id_of(SCENE, &[set("image.samples=2")])));
        assert_eq!(
            id_of(SCENE, &[set("image.width=8")]),
            base,
            "a value set as it was"
        );
        let scene = crate::scene::load_str("t.toml", SCENE, &[]).unwrap();
        assert_eq!(render_id(&scene, "embree", &[]), base);
        assert!(seen.insert(render_id(&scene, "bvh", &[])));
        assert!(seen.insert(render_id(&scene, "embree", &["image.samples=1".into()])));
    }
}
