//! Whitted shading against optics with known answers: Fresnel transmission and the lateral shift
//! through a glass slab, a mirror's virtual image, a shadow's extent, and a relativistic case:
//! a mirror moving along its own plane reflects exactly like a mirror at rest (the boost along
//! the plane commutes with the reflection).

use crate::common::*;

const NO_LIGHT: &str = "[render]\nambient = 0\nmax_depth = 8\n";

/// Column (image x) where the red channel of the centre row first reaches half of `level`.
fn first_bright_column(f: &rest_embree::render::Frame, level: f32) -> Option<u32> {
    let y = f.height / 2;
    (0..f.width).find(|&x| f.get(x, y).color[0] >= 0.5 * level)
}

#[test]
fn glass_slab_at_normal_incidence_transmits_fresnel() {
    // Backdrop E = 1 seen through a slab of n = 1.5: T²/(1 − R²) with R = ((n−1)/(n+1))² = 0.04
    // summed over the internal bounces: 0.9216/(1 − 0.0016) = 0.923077 (depth 8 reaches it).
    let text = format!(
        r#"{NO_LIGHT}
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = 20
[image]
width = 21
height = 21
[[material]]
name = "glass"
color = 0
transmit = 1
ior = 1.5
[[material]]
name = "lamp"
emission = 1
[[group]]
name = "g"
[[group.object]]
type = "box"
min = [-5, 5, -5]
max = [5, 6, 5]
material = "glass"
[[group.object]]
type = "box"
min = [-50, 20, -50]
max = [50, 21, 50]
material = "lamp"
"#
    );
    for backend in backends() {
        let f = render_with(&scene(&text), backend);
        let c = f.get(10, 10).color[0] as f64;
        assert_close(
            c,
            0.9216 / (1.0 - 0.0016),
            5e-4,
            &format!("{backend}: transmitted radiance"),
        );
    }
}

#[test]
fn tilted_slab_shifts_an_edge_by_the_snell_offset() {
    // A slab of thickness 2 with its normal at 45° to parallel (orthographic) rays: the ray
    // leaves parallel, displaced by d·sin(θi − θt)/cos θt = 0.658255 across its direction, here
    // along x. The backdrop's lit half starts at x = 0, so its edge moves to x = −0.658255.
    let (d, n) = (2.0f64, 1.5f64);
    let (ti, tt) = (45f64.to_radians(), (45f64.to_radians().sin() / n).asin());
    let shift = d * (ti - tt).sin() / tt.cos();
    // Slab faces: planes through (0, 5, 0) and (0, 5, 0) + d·m with normal m = (1, 1, 0)/√2.
    let m = [0.5f64.sqrt(), 0.5f64.sqrt()];
    let (p, q) = (20.0, 4.0); // half extents along the face (in-plane x-y direction) and z
    let corner = |s: f64, along: f64, z: f64| {
        let base = [s * d * m[0], 5.0 + s * d * m[1]];
        [base[0] + along * -m[1], base[1] + along * m[0], z]
    };
    let mut verts = Vec::new();
    for s in [0.0, 1.0] {
        for along in [-p, p] {
            for z in [-q, q] {
                verts.push(corner(s, along, z));
            }
        }
    }
    // Vertex index = 4 s + 2 a + z; the 6 faces of the slab, 2 triangles each.
    let faces = [
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ];
    let fmt = |v: &[f64; 3]| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
    let vs: Vec<String> = verts.iter().map(fmt).collect();
    let fs: Vec<String> = faces
        .iter()
        .map(|f| format!("[{}, {}, {}]", f[0], f[1], f[2]))
        .collect();
    let text = format!(
        r#"{NO_LIGHT}
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
projection = "orthographic"
view_height = 0.6
[image]
width = 601
height = 11
[[material]]
name = "glass"
color = 0
transmit = 1
ior = 1.5
[[material]]
name = "lamp"
emission = 1
[[group]]
name = "g"
[[group.object]]
type = "mesh"
vertices = [{}]
indices = [{}]
material = "glass"
[[group.object]]
type = "box"
min = [0, 30, -50]
max = [50, 31, 50]
material = "lamp"
"#,
        vs.join(", "),
        fs.join(", ")
    );
    // Pixel size 0.6/11 wide units; column x has its centre at world x = (x + 0.5 − 300.5)·px.
    let px = 0.6 / 11.0;
    for backend in backends() {
        let f = render_with(&scene(&text), backend);
        let col = first_bright_column(&f, 0.9).expect("the lit half is seen") as f64;
        let x_edge = (col + 0.5 - 300.5) * px;
        assert!(
            (x_edge + shift).abs() <= 1.5 * px,
            "{backend}: edge at x = {x_edge:.4}, expected {:.4} (pixel {px:.4})",
            -shift
        );
    }
}

fn mirror_scene(mirror_velocity: &str) -> String {
    format!(
        r#"{NO_LIGHT}
[camera]
position = [0, 0, 0]
direction = [0, 1, 0]
fov_y = 40
time = 0
[image]
width = 201
height = 101
[[material]]
name = "mirror"
color = 0
reflect = 1
[[material]]
name = "lamp"
emission = [1, 0.5, 0.25]
[[group]]
name = "mirror"
velocity = {mirror_velocity}
[[group.object]]
type = "box"
min = [-5000, 10, -5000]
max = [5000, 11, 5000]
material = "mirror"
[[group]]
name = "lamp"
[[group.object]]
type = "sphere"
center = [2, 5, 0]
radius = 0.5
material = "lamp"
"#
    )
}

#[test]
fn mirror_shows_the_virtual_image() {
    // The lamp at (2, 5, 0) mirrored in the plane y = 10 sits at (2, 15, 0): its disk is centred
    // at u = f·2/15 with radius about f·0.5/15 (seen directly it is at u = f·2/5).
    let s = scene(&mirror_scene("[0, 0, 0]"));
    let f_px = 0.5 * 101.0 / (20f64.to_radians()).tan();
    for backend in backends() {
        let fr = render_with(&s, backend);
        let y = fr.height / 2;
        let lit: Vec<u32> = (0..fr.width)
            .filter(|&x| fr.get(x, y).object_id == 1 && fr.get(x, y).color[0] > 0.5)
            .collect();
        assert!(!lit.is_empty(), "{backend}: the reflection is seen");
        let centre = (lit[0] + lit[lit.len() - 1]) as f64 / 2.0 + 0.5 - 100.5;
        let want = f_px * 2.0 / 15.0;
        assert!(
            (centre - want).abs() <= 1.0,
            "{backend}: reflection centred at u = {centre}, expected {want:.2}"
        );
        let width = lit.len() as f64;
        let want_w = 2.0
            * f_px
            * (0.5f64 / (15.0f64.powi(2) + 4.0).sqrt()).asin().tan()
            * (15.0 / (15.0f64.powi(2) + 4.0).sqrt()).recip();
        assert!(
            (width - want_w).abs() <= 2.0,
            "{backend}: reflection {width} px wide, expected about {want_w:.1}"
        );
    }
}

#[test]
fn mirror_moving_along_its_plane_reflects_like_a_mirror_at_rest() {
    let rest = scene(&mirror_scene("[0, 0, 0]"));
    for v in ["[0.9, 0, 0]", "[0, 0, 0.6]", "[-0.99, 0, 0]"] {
        let moving = scene(&mirror_scene(v));
        for backend in backends() {
            let a = render_with(&rest, backend);
            let b = render_with(&moving, backend);
            let differ = a
                .pixels
                .iter()
                .zip(&b.pixels)
                .filter(|(p, q)| (0..3).any(|k| (p.color[k] - q.color[k]).abs() > 1e-3))
                .count();
            assert!(
                differ <= 4,
                "{backend} mirror velocity {v}: {differ} pixels differ from the mirror at rest"
            );
        }
    }
}

#[test]
fn a_sphere_casts_the_classical_shadow() {
    // Light at (0, 10, 10) straight above a sphere of radius 1 at (0, 10, 3); the floor z = 0 is
    // dark within radius 10·sin(α)/cos(α)... exactly: the shadow cone from the point light has
    // half-angle asin(1/7) about the vertical, so on z = 0 its radius is 10·tan(asin(1/7)).
    let text = r#"
[render]
ambient = 0
[camera]
position = [0, 10, 30]
look_at = [0, 10, 0]
up = [0, 1, 0]
projection = "orthographic"
view_height = 8
[image]
width = 201
height = 201
[[light]]
position = [0, 10, 10]
[[group]]
name = "g"
[[group.object]]
type = "box"
min = [-20, -10, -1]
max = [20, 30, 0]
[[group.object]]
type = "sphere"
center = [0, 10, 3]
radius = 1
"#;
    let r_shadow = 10.0 * (1.0f64 / 7.0).asin().tan();
    let px = 8.0 / 201.0;
    for backend in backends() {
        let f = render_with(&scene(text), backend);
        let y = 100;
        // Along the centre row, floor pixels (object 1) that are dark, beyond the sphere's disk.
        let dark: Vec<f64> = (0..f.width)
            .filter(|&x| f.get(x, y).object_id == 1 && f.get(x, y).color[0] < 1e-6)
            .map(|x| ((x as f64 + 0.5 - 100.5) * px).abs())
            .collect();
        let edge = dark.iter().cloned().fold(0.0, f64::max);
        assert!(!dark.is_empty(), "{backend}: the shadow is seen");
        assert!(
            (edge - r_shadow).abs() <= 1.5 * px,
            "{backend}: shadow radius {edge:.4}, expected {r_shadow:.4}"
        );
    }
}

/// Two facing half-mirrors that also transmit half: the ray tree doubles at every bounce, so
/// `max_depth = 64` would never end without the ray budget (`render.max_rays`). A budget that
/// holds the full tree changes no pixel; a smaller one ends, with every pixel finite, and a
/// larger budget comes closer to a much larger one.
#[test]
fn the_ray_budget_bounds_a_doubling_ray_tree() {
    let text = |depth: u32, rays: u32| {
        format!(
            r#"
[camera]
position = [0, 5, 0]
look_at = [0.3, 10, 0.2]
[image]
width = 24
height = 24
[render]
max_depth = {depth}
max_rays = {rays}
[[light]]
position = [0, 5, 3]
[[material]]
name = "half"
color = 0.5
reflect = 0.5
transmit = 0.5
[[group]]
name = "walls"
[[group.object]]
type = "box"
min = [-5, 8, -5]
max = [5, 8.5, 5]
material = "half"
[[group.object]]
type = "box"
min = [-5, 1.5, -5]
max = [5, 2, 5]
material = "half"
"#
        )
    };
    let mean_diff = |a: &rest_embree::render::Frame, b: &rest_embree::render::Frame| {
        let d: f64 = a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(p, q)| {
                (0..3)
                    .map(|k| (p.color[k] - q.color[k]).abs() as f64)
                    .sum::<f64>()
            })
            .sum();
        d / (3 * a.pixels.len()) as f64
    };
    for backend in backends() {
        // Depth 5: 62 secondary rays at most, so a budget of 62 is the full tree.
        let full = render_with(&scene(&text(5, 62)), backend);
        let large = render_with(&scene(&text(5, 65536)), backend);
        assert_eq!(
            full.pixels, large.pixels,
            "{backend}: the full tree either way"
        );
        let [small, medium, reference] =
            [32, 256, 4096].map(|rays| render_with(&scene(&text(64, rays)), backend));
        for f in [&small, &medium, &reference] {
            assert_all_finite(f, backend);
        }
        let (far, near) = (
            mean_diff(&small, &reference),
            mean_diff(&medium, &reference),
        );
        assert!(
            near < far && far > 0.0,
            "{backend}: more rays come closer ({near} against {far})"
        );
    }
}
