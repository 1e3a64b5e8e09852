//! Large PNGs are rendered and written a strip of rows at a time: the strips hold exactly the
//! whole frame's pixels, and the PNG decodes to the whole frame's colours.

use crate::accel::backend_by_name;
use crate::output::srgb_encode;
use crate::render::{
    render_tile, render_world_in_strips, render_world_passes, CameraRays, Frame, Passes, Seen,
    TileScratch, View, World, TILE,
};
use crate::scene::paper::paper;
use crate::scene::Scene;
use glam::DVec3;

fn lattice(sets: &[&str]) -> crate::scene::Scene {
    let mut all: Vec<String> = vec![
        "image.width=72".into(),
        "image.height=150".into(),
        "group.lattice.velocity=[-0.9,0,0]".into(),
    ];
    all.extend(sets.iter().map(|s| s.to_string()));
    paper("lattice", &all).unwrap()
}

#[test]
fn strips_hold_the_whole_frame() {
    for sets in [
        &[][..],
        &["image.samples=2"],
        &["image.crop=[5, 7, 40, 133]"],
    ] {
        let s = lattice(sets);
        let world = World::build(&s, backend_by_name("bvh").unwrap().as_ref()).unwrap();
        let (whole, whole_stats) = render_world_passes(&s, &world, Passes::Colour);
        let (w, _) = s.image.frame_size();
        // On one thread a strip is at least two rows of tiles (32 rows): several strips.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        for min_pixels in [1, u64::from(w) * 40, u64::MAX / 2] {
            let mut pixels = Vec::new();
            let mut strips = 0;
            let stats = one
                .install(|| {
                    render_world_in_strips(&s, &world, Passes::Colour, min_pixels, None, |b| {
                        assert_eq!(b.width, w);
                        pixels.extend_from_slice(&b.pixels);
                        strips += 1;
                        Ok::<(), crate::Error>(())
                    })
                })
                .unwrap();
            assert_eq!(
                pixels, whole.pixels,
                "{sets:?}, strips of {min_pixels} pixels"
            );
            assert_eq!(stats.primary_rays, whole_stats.primary_rays);
            if min_pixels == 1 {
                assert!(strips > 1, "several strips");
            }
        }
    }
}

/// The strips of every pass, on two threads, whose tiles are shared out one by one: each pixel
/// and its mattes are where the tile rendered alone puts them, in every strip.
#[test]
fn every_tile_lands_in_its_place() {
    // 72 wide: a last column of tiles half as wide; 150 high: a last row of tiles of 6 rows;
    // and a crop of 35 x 126 at (5, 7).
    for crop in [None, Some("image.crop=[5, 7, 40, 133]")] {
        let mut sets = vec!["image.samples=2"];
        sets.extend(crop);
        tiles_land_in_their_places(&lattice(&sets));
    }
}

/// [`every_tile_lands_in_its_place`] on scene `s`.
fn tiles_land_in_their_places(s: &Scene) {
    let world = World::build(s, backend_by_name("bvh").unwrap().as_ref()).unwrap();
    let (w, h) = s.image.frame_size();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let mut frame = Frame::new(w, 0);
    let mut strips = 0;
    two.install(|| {
        render_world_in_strips(s, &world, Passes::All, 1, None, |b| {
            assert_eq!(b.mattes.len(), b.pixels.len());
            frame.pixels.extend_from_slice(&b.pixels);
            frame.mattes.extend_from_slice(&b.mattes);
            frame.height += b.height;
            strips += 1;
            Ok::<(), crate::Error>(())
        })
    })
    .unwrap();
    assert!(strips > 1, "several strips");
    assert_eq!(frame.height, h);
    let cam = CameraRays::new(&s.camera, s.image.width, s.image.height);
    let view = View {
        cam: &cam,
        cull: None,
        stars: None,
        cones: None,
        emitters: None,
        sample_base: 0,
    };
    let mut scratch = TileScratch::default();
    let (mut seen, mut hits) = (0, 0);
    for y0 in (0..h).step_by(TILE as usize) {
        for x0 in (0..w).step_by(TILE as usize) {
            let all = Passes::All;
            let tile =
                render_tile::<DVec3>(Seen::NONE, s, &world, &view, (x0, y0), all, &mut scratch);
            for p in tile.pixels {
                let at = (p.y * w + p.x) as usize;
                assert_eq!(frame.pixels[at], p.value, "pixel ({}, {})", p.x, p.y);
                assert_eq!(frame.mattes[at], p.mattes, "mattes ({}, {})", p.x, p.y);
                seen += 1;
                hits += usize::from(p.value.object_id > 0);
            }
        }
    }
    assert_eq!(seen, frame.pixels.len(), "every pixel is some tile's");
    assert!(hits > 0 && hits < seen, "objects and background both seen");
}

#[test]
fn a_png_written_in_strips_is_the_whole_frame() {
    let s = lattice(&[]);
    let world = World::build(&s, backend_by_name("bvh").unwrap().as_ref()).unwrap();
    let (whole, _) = render_world_passes(&s, &world, Passes::Colour);
    let path = std::env::temp_dir().join(format!("rest-embree-strips-{}.png", std::process::id()));
    crate::output::write_png_in_strips(&path, (whole.width, whole.height), false, None, |put| {
        render_world_in_strips(&s, &world, Passes::Colour, 1, None, |b: &Frame| put(b)).map(|_| ())
    })
    .unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let _ = std::fs::remove_file(&path);
    assert_eq!((info.width, info.height), (whole.width, whole.height));
    let expected: Vec<u8> = whole
        .pixels
        .iter()
        .flat_map(|p| p.color.map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8))
        .collect();
    assert_eq!(&buf[..info.buffer_size()], &expected[..]);
    assert!(expected.iter().any(|&b| b > 0), "something is seen");
}
