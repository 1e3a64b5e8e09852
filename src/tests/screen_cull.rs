//! The screen-space cull (a 4 × 4 block of pixels whose rays cannot reach any group's apparent
//! box is background without tracing) changes no pixel: every pixel a ray hits without it lies
//! in a block it keeps, every block it keeps lies in a tile it keeps, and renders with and
//! without bounds culling agree.

use crate::render::{render_world, CameraRays, ScreenCull, World, WorldOptions, TILE};
use crate::scene::paper::paper;
use crate::scene::Scene;

fn scenes() -> Vec<(String, Scene)> {
    let mut out = Vec::new();
    for beta in ["0", "0.5", "0.9", "0.99"] {
        for dir in ["[1, 0, 0]", "[1, 0, 1]", "[1, -1, 1]"] {
            let sets = vec![
                format!("group.lattice.velocity=[-{beta}, 0, 0]"),
                format!("camera.direction={dir}"),
                "image.width=96".into(),
                "image.height=96".into(),
                "image.samples=2".into(),
            ];
            out.push((
                format!("lattice beta {beta} view {dir}"),
                paper("lattice", &sets).unwrap(),
            ));
        }
    }
    // A crop window; and the camera inside the lattice, where the cull cannot apply.
    out.push((
        "lattice cropped".into(),
        paper(
            "lattice",
            &[
                "group.lattice.velocity=[-0.99, 0, 0]".into(),
                // An offset that is no multiple of 4 (blocks are aligned in the frame), around
                // the edge of the small lattice.
                "image.crop=[201, 183, 120, 100]".into(),
            ],
        )
        .unwrap(),
    ));
    out.push((
        "camera inside the lattice".into(),
        paper(
            "lattice",
            &[
                "camera.position=[4.5, 0.2, 0.3]".into(),
                "image.width=64".into(),
                "image.height=64".into(),
            ],
        )
        .unwrap(),
    ));
    // Near c, with the camera moving instead of the lattice, and far from the origin.
    let small = ["image.width=96".to_string(), "image.height=96".to_string()];
    // Near c the lattice is seen only in a tiny cone, if the imaging event is not inside its
    // rest-frame bounds (at 1 - 1e-9 and t0 = 3 it is: no cull), so this looks from a little
    // earlier through a narrow lens.
    let extreme = [
        "group.lattice.direction=[-1, 0, 0]".to_string(),
        "group.lattice.one_minus_beta=1e-4".to_string(),
        "camera.time=2.9".to_string(),
        "camera.fov_y=5".to_string(),
    ];
    out.push((
        "lattice 1 - beta = 1e-4".into(),
        paper("lattice", &[&extreme[..], &small[..]].concat()).unwrap(),
    ));
    out.push((
        "camera moving at 0.99".into(),
        paper(
            "lattice",
            &[&["camera.velocity=[0.99, 0, 0]".to_string()], &small[..]].concat(),
        )
        .unwrap(),
    ));
    let far = paper(
        "lattice",
        &[
            &["group.lattice.velocity=[-0.9, 0, 0]".to_string()],
            &small[..],
        ]
        .concat(),
    )
    .unwrap()
    .translated(crate::spacetime::Event::new(
        1e6,
        glam::DVec3::new(-1e6, 3e5, 1e6),
    ));
    out.push(("lattice at 0.9 translated by 1e6".into(), far));
    for beta in ["0.5", "0.99"] {
        out.push((
            format!("bar array beta {beta}"),
            paper(
                "bar_array",
                &[
                    format!("group.bars.velocity=[{beta}, 0, 0]"),
                    "image.width=96".into(),
                    "image.height=96".into(),
                ],
            )
            .unwrap(),
        ));
    }
    out
}

#[test]
fn every_pixel_that_sees_a_group_is_kept() {
    let backend = crate::accel::backend_by_name("bvh").unwrap();
    let (mut culled_somewhere, mut whole_tiles) = (false, false);
    for (name, s) in scenes() {
        let cam = CameraRays::new(&s.camera, s.image.width, s.image.height);
        let uncull = World::build_with(
            &s,
            backend.as_ref(),
            WorldOptions {
                bounds_cull: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(
            ScreenCull::new(&uncull, &cam).is_none(),
            "{name}: off means off"
        );
        let world = World::build(&s, backend.as_ref()).unwrap();
        let plain = render_world(&s, &uncull).0;
        let fast = render_world(&s, &world).0;
        // It does not apply where the imaging event is inside a group's bounding sphere (the
        // lattice close up, the camera inside it); it must where the scene is far and small.
        let must = [
            "beta 0.9 view [1, 0, 0]",
            "beta 0.99 view",
            // Tilted views: the lattice fills part of the image, so the cull must apply even
            // where its cone holds a corner or two.
            "view [1, 0, 1]",
            "view [1, -1, 1]",
            "bar array",
            "1e-4",
            "camera moving",
            "translated",
            "cropped",
        ];
        // Where a group's cone holds the whole image every block would be kept: no cull
        // (the lattice at 0.5c fills the view straight ahead).
        if name == "lattice beta 0.5 view [1, 0, 0]" {
            assert!(
                ScreenCull::new(&world, &cam).is_none(),
                "{name}: fills the view"
            );
        }
        let Some(cull) = ScreenCull::new(&world, &cam) else {
            assert!(
                !must.iter().any(|m| name.contains(m)),
                "{name}: the cull should apply"
            );
            eprintln!("{name}: no cull");
            continue;
        };
        let (ox, oy) = s.image.frame_offset();
        let (mut hit, mut kept, mut dropped, mut tiles_dropped) = (0, 0, 0, 0);
        for y in 0..plain.height {
            for x in 0..plain.width {
                // The renderer's blocks are aligned in the frame (its tiles and packets).
                let visible = cull.block_visible(&cam, (x & !3) + ox, (y & !3) + oy);
                // A tile no group's cone reaches has none of its blocks tested: it must hold
                // no block the blocks' own test keeps.
                let t = !(TILE - 1);
                let tile = cull.tile_visible(&cam, (x & t) + ox, (y & t) + oy);
                assert!(
                    tile || !visible,
                    "{name}: block at ({x}, {y}) kept, its tile not"
                );
                tiles_dropped += u32::from(!tile);
                if plain.get(x, y).alpha > 0.0 {
                    hit += 1;
                    assert!(
                        visible,
                        "{name}: pixel ({x}, {y}) sees a group but was culled"
                    );
                }
                if visible {
                    kept += 1;
                } else {
                    dropped += 1;
                }
            }
        }
        // At 0.99c aberration squeezes the lattice out of the tilted views entirely.
        assert!(
            hit > 0 || name.contains("0.99 view [1, "),
            "{name}: something is in view"
        );
        if must.iter().any(|m| name.contains(m)) {
            assert!(dropped > 0, "{name}: background blocks are skipped");
        }
        culled_somewhere |= dropped > 0;
        whole_tiles |= tiles_dropped > 0;
        // Without the cull nothing else changes but where rays are rebased (f64 rounding).
        for (a, b) in plain.pixels.iter().zip(&fast.pixels) {
            assert_eq!(
                a.object_id, b.object_id,
                "{name}: same object in every pixel"
            );
            for c in 0..3 {
                assert!((a.color[c] - b.color[c]).abs() < 1e-5, "{name}: colour");
            }
        }
        eprintln!("{name}: {hit} pixels see a group, {kept} kept, {dropped} culled");
    }
    assert!(
        culled_somewhere,
        "the cull skips background blocks somewhere"
    );
    assert!(whole_tiles, "the cull skips whole tiles somewhere");
}
