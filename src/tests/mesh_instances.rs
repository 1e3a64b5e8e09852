//! A mesh placed many times held once (`Implicit::Instance`: Embree instances of one scene, the
//! f64 BVH's shared tree walked in each placement's frame) against the same placements as
//! copies of the mesh: the same triangles to the bit, the same hits, and from a scene file the
//! same pictures, on both backends, at rest and moving.

use crate::accel::{backend_by_name, Accelerator, Hit, Ray};
use crate::geometry::{Aabb, Affine, Geometry, Implicit, IndexedMesh, MeshInstance};
use crate::rng::Rng;
use glam::{DMat3, DVec3};
use std::sync::Arc;

/// A bumpy ball of `nlat` x `nlon` quads (two triangles each) about the origin, with its
/// vertices' normals (outward, from the sphere) and texture coordinates.
struct Ball {
    positions: Vec<DVec3>,
    normals: Vec<DVec3>,
    uvs: Vec<[f64; 2]>,
    triangles: Vec<[u32; 3]>,
}

fn ball(nlat: u32, nlon: u32) -> Ball {
    let mut b = Ball {
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Vec::new(),
        triangles: Vec::new(),
    };
    for i in 0..=nlat {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(nlat);
        for j in 0..=nlon {
            let phi = std::f64::consts::TAU * f64::from(j) / f64::from(nlon);
            let dir = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            let r = 1.0 + 0.15 * (5.0 * theta).sin() * (3.0 * phi).cos();
            b.positions.push(r * dir);
            b.normals.push(dir);
            b.uvs.push([
                f64::from(j) / f64::from(nlon),
                f64::from(i) / f64::from(nlat),
            ]);
        }
    }
    let at = |i: u32, j: u32| i * (nlon + 1) + j;
    for i in 0..nlat {
        for j in 0..nlon {
            if i > 0 {
                b.triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
            }
            if i + 1 < nlat {
                b.triangles
                    .push([at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)]);
            }
        }
    }
    b
}

/// The ball as an OBJ file's text, every corner with its normal and texture coordinates.
fn obj(b: &Ball) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    for p in &b.positions {
        writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z).unwrap();
    }
    for n in &b.normals {
        writeln!(s, "vn {:?} {:?} {:?}", n.x, n.y, n.z).unwrap();
    }
    for t in &b.uvs {
        writeln!(s, "vt {:?} {:?}", t[0], t[1]).unwrap();
    }
    for t in &b.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}").unwrap();
    }
    s
}

/// Twelve placements: turned, scaled along the axes, sheared (a glTF node's matrix), and one
/// as the file has it.
fn placements() -> Vec<Affine> {
    let mut rng = Rng(0x1257_a9ce_5eed_0002);
    let mut out = vec![Affine::IDENTITY];
    for k in 0..10 {
        let axis = rng.unit();
        let scale = DVec3::new(
            rng.range(0.5, 2.0),
            rng.range(0.5, 2.0),
            rng.range(0.5, 2.0),
        );
        let at = DVec3::new(
            4.0 * f64::from(k % 4) - 6.0,
            4.0 * f64::from(k / 4) - 4.0,
            0.0,
        );
        out.push(Affine::rigid(
            scale,
            DMat3::from_axis_angle(axis, rng.range(0.0, 6.0)),
            at,
        ));
    }
    let shear = DMat3::from_cols_array(&[1.0, 0.0, 0.0, 0.6, 1.2, 0.0, 0.0, 0.3, 0.8]);
    out.push(Affine::general(shear, DVec3::new(9.0, 6.0, 1.0)).unwrap());
    out
}

/// The placements as instances of one mesh, and as copies of it; the same numbering. Among
/// them a sphere (Embree's user geometry) and a lattice held as itself (Embree's instances of
/// its blocks, whose hits carry their own instIDs).
fn geometries() -> (Geometry, Geometry) {
    let b = ball(24, 40);
    let mesh = Arc::new(IndexedMesh::new(b.positions, b.triangles));
    let (mut held, mut copies) = (Geometry::default(), Geometry::default());
    for g in [&mut held, &mut copies] {
        let sphere = crate::geometry::Primitive::Sphere {
            center: DVec3::new(1.0, -1.0, 1.5),
            radius: 0.8,
        };
        g.push_part(100, 3, [sphere]);
        let l = crate::geometry::Lattice {
            counts: [5, 4, 3],
            spacing: DVec3::splat(1.7),
            origin: DVec3::new(-4.0, -3.0, -1.5),
            rod_radius: 0.05,
            sphere_radius: 0.2,
        };
        let runs = [(l.sphere_count(), 4), (l.rod_count(), 5)];
        g.push_implicit(101, &runs, Implicit::Lattice(l)).unwrap();
    }
    for (k, place) in placements().into_iter().enumerate() {
        let inst = MeshInstance::new(mesh.clone(), place);
        let runs = [(mesh.len(), k as u32 % 3, None)];
        copies
            .push_implicit_with(k as u32, &runs, Implicit::Mesh(Arc::new(inst.copied())))
            .unwrap();
        held.push_implicit_with(k as u32, &runs, Implicit::Instance(Arc::new(inst)))
            .unwrap();
    }
    (held, copies)
}

/// Rays from around and among the placements.
fn rays(n: usize) -> Vec<Ray> {
    super::rays_toward(
        &mut Rng(0x1257_a9ce_5eed_0003),
        n,
        Aabb::new(DVec3::new(-8.0, -6.0, -2.0), DVec3::new(11.0, 8.0, 3.0)),
        30.0,
        Aabb::new(DVec3::new(-8.0, -6.0, -2.0), DVec3::new(11.0, 8.0, 2.0)),
        40.0,
    )
}

/// `scene`'s frame on `backend`, its world built with `options`.
fn frame(
    scene: &crate::scene::Scene,
    backend: &dyn crate::accel::Backend,
    options: crate::render::WorldOptions,
) -> crate::render::Frame {
    let world = crate::render::World::build_with(scene, backend, options).unwrap();
    crate::render::render_world(scene, &world).0
}

/// `accel`'s hits of `rays` and whether it finds each blocked, `width` at a time.
fn trace(accel: &dyn Accelerator, rays: &[Ray], width: usize) -> (Vec<Option<Hit>>, Vec<bool>) {
    (
        super::hits(accel, rays, width),
        super::occluded(accel, rays, width),
    )
}

#[test]
fn an_instance_is_its_copy_triangle_for_triangle() {
    let (held, copies) = geometries();
    assert_eq!(held.len(), copies.len());
    for i in (0..held.len()).step_by(7) {
        assert_eq!(held.prim(i), copies.prim(i), "triangle {i}");
    }
    // Every placement holds the one mesh.
    let meshes: Vec<_> = held
        .implicit
        .iter()
        .filter_map(|r| match &r.shape {
            Implicit::Instance(m) => Some(Arc::as_ptr(&m.mesh)),
            _ => None,
        })
        .collect();
    assert_eq!(meshes.len(), placements().len());
    assert!(meshes.iter().all(|&m| m == meshes[0]));
    // Listed, an instance is its copy listed.
    assert_eq!(held.flattened().prims, copies.flattened().prims);
}

#[test]
fn instances_hit_as_copies_on_both_backends() {
    let (held, copies) = geometries();
    let (held, copies) = (Arc::new(held), Arc::new(copies));
    let rays = rays(8000);
    let mut reference = None;
    for name in crate::accel::backend_names() {
        let backend = backend_by_name(name).unwrap();
        let a = backend.build(held.clone()).unwrap();
        let b = backend.build(copies.clone()).unwrap();
        for width in [1, 16] {
            let (ha, oa) = trace(a.as_ref(), &rays, width);
            let (hb, ob) = trace(b.as_ref(), &rays, width);
            let hit = hb.iter().filter(|h| h.is_some()).count();
            assert!(hit > rays.len() / 4, "{name}: {hit} hits of {}", rays.len());
            // Where two triangles are met at the same t (their shared edge), either is the hit.
            // Embree's sphere and lattice hits are exact f64 tests on the ray taken relative to
            // the scene's centre, the centre of its box, which the instances' corners' boxes
            // move: the same primitive, and the same t to a few units in the last place.
            let same = |x: &Option<Hit>, y: &Option<Hit>| match (x, y) {
                (Some(x), Some(y)) => {
                    x.t == y.t || (x.prim == y.prim && (x.t - y.t).abs() <= 1e-13 * x.t.abs())
                }
                (None, None) => true,
                _ => false,
            };
            let differ: Vec<usize> = (0..rays.len()).filter(|&i| !same(&ha[i], &hb[i])).collect();
            // The f64 BVH tests the same triangles exactly, so finds the same hits; Embree finds
            // its candidates in f32, in the placement's frame or in the scene's, which may
            // differ for a ray along an edge (a few in ten thousand at most).
            let allowed = if name == "bvh" { 0 } else { rays.len() / 2000 };
            assert!(
                differ.len() <= allowed,
                "{name}, {width} wide: {} of {} rays differ, first {:?}: {:?} against {:?}",
                differ.len(),
                rays.len(),
                differ.first(),
                differ.first().map(|&i| ha[i]),
                differ.first().map(|&i| hb[i]),
            );
            let blocked_differ = (0..rays.len()).filter(|&i| oa[i] != ob[i]).count();
            assert!(
                blocked_differ <= allowed,
                "{name}, {width} wide: {blocked_differ} occlusions differ"
            );
            for (h, o) in ha.iter().zip(&oa) {
                assert_eq!(h.is_some(), *o, "{name}: a hit is an occlusion");
            }
            // Both backends agree on the instances.
            match &reference {
                None => reference = Some(ha),
                Some(r) => {
                    let differ = (0..rays.len()).filter(|&i| !same(&ha[i], &r[i])).count();
                    assert!(
                        differ <= rays.len() / 2000,
                        "{name}: {differ} rays differ from the BVH's"
                    );
                }
            }
        }
    }
}

/// A scene file that places one mesh file four times (three entries naming the file, one an
/// `instance` of a named one, in a group of its own: each backend builds over the mesh once
/// for both groups), against the same placements from four files of the same
/// triangles (so each is read and placed as a copy): the same frame, on both backends, at
/// rest and moving, the placements held as instances (`instance_over` 0) or listed.
#[test]
fn a_mesh_file_placed_four_times_renders_as_four_copies() {
    use crate::render::WorldOptions;
    let dir = std::env::temp_dir().join(format!("rest-embree-instances-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = obj(&ball(24, 40));
    for name in ["ball.obj", "b1.obj", "b2.obj", "b3.obj", "b4.obj"] {
        std::fs::write(dir.join(name), &text).unwrap();
    }
    let scene = |files: [&str; 4], instance: bool, velocity: &str| {
        let fourth = if instance {
            "type = \"instance\"\nof = \"first\"".to_string()
        } else {
            format!("type = \"mesh\"\nfile = \"{}\"", files[3])
        };
        format!(
            r#"
[camera]
position = [0, -9, 3]
look_at = [0, 0, 0]
fov_y = 50

[image]
width = 96
height = 72

[[light]]
position = [5, -10, 12]
intensity = 300

[[material]]
name = "red"
color = [0.8, 0.2, 0.1]

[[material]]
name = "shiny"
color = [0.2, 0.3, 0.8]
reflect = 0.3

[[group]]
name = "balls"
velocity = {velocity}

[[group.object]]
type = "mesh"
name = "first"
file = "{}"
material = "red"

[[group.object]]
type = "mesh"
file = "{}"
material = "shiny"
translate = [3, 1, 0]
scale = [1.5, 0.7, 1.0]
rotate = {{ axis = [1, 1, 0], degrees = 40 }}

[[group.object]]
type = "mesh"
file = "{}"
translate = [-3.5, 2, 0.5]
scale = 1.3

# A group of its own, moving otherwise: the mesh shared across groups too.
[[group]]
name = "more"
velocity = [0, 0.3, 0]

[[group.object]]
{fourth}
material = "shiny"
translate = [0, 4, -1]
rotate = {{ axis = [0, 0, 1], degrees = 90 }}
"#,
            files[0], files[1], files[2]
        )
    };
    for velocity in ["[0, 0, 0]", "[0.6, 0, 0]"] {
        let shared_text = scene(["ball.obj"; 4], true, velocity);
        let copies_text = scene(["b1.obj", "b2.obj", "b3.obj", "b4.obj"], false, velocity);
        let path = dir.join("scene.toml");
        let shared = crate::scene::load_str(path.to_str().unwrap(), &shared_text, &[]).unwrap();
        let copies = crate::scene::load_str(path.to_str().unwrap(), &copies_text, &[]).unwrap();
        let held: Vec<_> = shared
            .groups
            .iter()
            .flat_map(|g| &g.geometry.implicit)
            .filter_map(|r| match &r.shape {
                Implicit::Instance(m) => Some(Arc::as_ptr(&m.mesh)),
                _ => None,
            })
            .collect();
        assert_eq!(held.len(), 4, "four placements of one mesh, in two groups");
        assert!(held.iter().all(|&m| m == held[0]));
        // The same triangles, to the bit, as the copies.
        for (g, c) in shared.groups.iter().zip(&copies.groups) {
            let (g, c) = (&g.geometry, &c.geometry);
            assert_eq!(g.len(), c.len());
            for i in (0..g.len()).step_by(5) {
                assert_eq!(g.prim(i), c.prim(i), "triangle {i}");
            }
        }
        for name in crate::accel::backend_names() {
            let backend = backend_by_name(name).unwrap();
            for instance_over in [0, u64::MAX] {
                let options = WorldOptions {
                    instance_over,
                    ..WorldOptions::default()
                };
                let a = frame(&shared, backend.as_ref(), options);
                let b = frame(&copies, backend.as_ref(), options);
                let seen = a.pixels.iter().filter(|p| p.object_id > 0).count();
                assert!(
                    seen > a.pixels.len() / 40,
                    "{name}, {velocity}: {seen} pixels see a ball"
                );
                // The same hits, but the renderer rebases rays to the near side of the
                // group's box, which for instances is their corners' box, a little larger
                // than the copies' own: the same frame to the last bits of f32, but for
                // Embree's f32 candidates along an edge (silhouettes).
                let close = |x: f32, y: f32| (x - y).abs() <= 1e-5 * x.abs().max(y.abs()).max(1e-3);
                let far = a
                    .pixels
                    .iter()
                    .zip(&b.pixels)
                    .filter(|(p, q)| {
                        p.object_id != q.object_id
                            || p.primitive_id != q.primitive_id
                            || !(0..3).all(|k| close(p.color[k], q.color[k]))
                            || !close(p.lookback, q.lookback)
                    })
                    .count();
                assert!(
                    far <= a.pixels.len() / 500,
                    "{name}, {velocity}, instance_over {instance_over}: {far} pixels differ"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_instance_of_nothing_is_a_clear_error() {
    let base = r#"
[camera]
position = [0, -10, 0]
look_at = [0, 0, 0]

[[group]]
name = "g"

[[group.object]]
type = "instance"
"#;
    let err = |extra: &str| {
        crate::scene::load_str("scene.toml", &format!("{base}{extra}"), &[])
            .expect_err("an error")
            .to_string()
    };
    let e = err("of = \"rock\"\n");
    assert!(
        e.contains("scene.toml:11")
            && e.contains("object.0.of`")
            && e.contains("no mesh object is named `rock`"),
        "{e}"
    );
    let e = err("of = \"rock\"\nfile = \"rock.ply\"\n");
    assert!(
        e.contains("object.0.file`") && e.contains("an instance places the mesh"),
        "{e}"
    );
    let e = err("");
    assert!(e.contains("object.0.of`"), "{e}");
    // A name two mesh objects of two files share (in any group) is not taken as either.
    let two =
        "of = \"rock\"\n[[group.object]]\ntype = \"mesh\"\nname = \"rock\"\nfile = \"a.ply\"\n\
               [[group.object]]\ntype = \"mesh\"\nname = \"rock\"\nfile = \"b.ply\"\n";
    let e = err(two);
    assert!(
        e.contains("object.0.of`") && e.contains("several files are named `rock`"),
        "{e}"
    );
    // A mesh given inline has no file to place.
    let inline = "of = \"tri\"\n[[group.object]]\ntype = \"mesh\"\nname = \"tri\"\n\
                  vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nindices = [[0, 1, 2]]\n";
    let e = err(inline);
    assert!(
        e.contains("object.0.of`") && e.contains("given inline"),
        "{e}"
    );
}

/// A backend keeps the structures it built over shared meshes for every group (and every
/// world) it builds; a scene read again, its mesh file changed in between (as the viewer reads
/// a scene after each edit), renders as a fresh backend renders it. (Whether the new mesh
/// lies where the old one did is the allocator's choice; the caches take an entry only for the
/// live mesh it was built for, `MeshTrees`' test holds them to that.)
#[test]
fn a_backend_reused_across_scenes_renders_each_as_a_fresh_one() {
    use crate::render::WorldOptions;
    let dir = std::env::temp_dir().join(format!("rest-embree-reuse-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = r#"
[camera]
position = [0, -9, 3]
look_at = [0, 0, 0]
[image]
width = 64
height = 48
[[light]]
position = [5, -10, 12]
intensity = 1
[[group]]
name = "a"
[[group.object]]
type = "mesh"
file = "ball.obj"
[[group]]
name = "b"
velocity = [0.3, 0, 0]
[[group.object]]
type = "mesh"
file = "ball.obj"
translate = [2.5, 0, 0]
"#;
    let options = WorldOptions {
        instance_over: 0,
        ..WorldOptions::default()
    };
    for name in crate::accel::backend_names() {
        let kept = backend_by_name(name).unwrap();
        for (nlat, nlon) in [(12, 20), (6, 8), (12, 20)] {
            std::fs::write(dir.join("ball.obj"), obj(&ball(nlat, nlon))).unwrap();
            let path = dir.join("scene.toml");
            let scene = crate::scene::load_str(path.to_str().unwrap(), text, &[]).unwrap();
            let fresh = backend_by_name(name).unwrap();
            let a = frame(&scene, kept.as_ref(), options);
            let b = frame(&scene, fresh.as_ref(), options);
            assert!(a.pixels.iter().any(|p| p.object_id > 0));
            let differ = super::differing_pixels(&a, &b);
            assert_eq!(
                differ, 0,
                "{name}, ball {nlat}x{nlon}: {differ} pixels differ"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
