//! The paper's lattice grown to a billion nodes (10⁹ spheres, ~3·10⁹ rods) and its bar array to
//! 400 million bars render through the real command on every backend, within a memory limit
//! far below what listing them would take, Embree and the f64 BVH agreeing in every pixel; a
//! lattice too large to number is refused with its file, line and key.

mod common;
use common::cli::*;

fn lattice_scene() -> String {
    std::fs::read_to_string(format!(
        "{}/scenes/lattice.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

/// Pixels of a PNG (RGB or RGBA, 8-bit) as RGB triples.
fn pixels(path: &std::path::Path) -> Vec<[u8; 3]> {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let step = info.color_type.samples();
    buf[..info.buffer_size()]
        .chunks(step)
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

#[test]
fn a_billion_node_lattice_renders_in_little_memory() {
    let d = Dir::new("billion");
    let scene = d.file("lattice.toml", &lattice_scene());
    let s = scene.to_str().unwrap();
    let mut images = Vec::new();
    let backends: &[&str] = if cfg!(feature = "embree") {
        &["embree", "bvh"]
    } else {
        &["bvh"]
    };
    for backend in backends {
        let out = d.0.join(format!("{backend}.png"));
        let (code, err) = status(&[
            "render",
            s,
            "-o",
            out.to_str().unwrap(),
            "--backend",
            backend,
            "--max-memory",
            "1G",
            "-q",
            "--set",
            "image.width=96",
            "--set",
            "image.height=96",
            "--set",
            "image.samples=1",
            "--set",
            "group.lattice.object.lattice.counts=[1000, 1000, 1000]",
            "--set",
            "group.lattice.object.lattice.origin=[0, -499.5, -499.5]",
            "--set",
            "group.lattice.velocity=[-0.9, 0, 0]",
        ]);
        assert_eq!(code, Some(0), "{backend}: {err}");
        let px = pixels(&out);
        let lit = px.iter().filter(|p| p.iter().any(|&c| c > 10)).count();
        // At 0.9c the whole front face crowds into a disc filling most of the view.
        assert!(
            lit > px.len() / 2,
            "{backend}: {lit} of {} pixels lit",
            px.len()
        );
        images.push(px);
    }
    if images.len() == 2 {
        let differ = images[0]
            .iter()
            .zip(&images[1])
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 1))
            .count();
        assert_eq!(
            differ, 0,
            "Embree and the f64 BVH differ in {differ} pixels"
        );
    }
}

#[test]
fn a_lattice_too_large_to_number_is_refused() {
    let text = lattice_scene().replace("counts = [10, 10, 10]", "counts = [2000, 2000, 2000]");
    assert!(text.contains("[2000, 2000, 2000]"));
    let line = text.lines().position(|l| l.starts_with("counts")).unwrap() + 1;
    fails(
        "numbering",
        &text,
        &[],
        &[
            &format!("scene.toml:{line}"),
            "group.lattice.object.lattice.counts",
            "at most 4294967295 primitives",
        ],
    );
}

/// A bar array past the limit for listed objects (4·10⁸ bars) renders too, instanced, on each
/// backend, alike.
#[test]
fn a_bar_array_of_400_million_bars_renders() {
    let text = std::fs::read_to_string(format!(
        "{}/scenes/bar_array.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let d = Dir::new("bars");
    let scene = d.file("bars.toml", &text);
    let mut images = Vec::new();
    let backends: &[&str] = if cfg!(feature = "embree") {
        &["embree", "bvh"]
    } else {
        &["bvh"]
    };
    for backend in backends {
        let out = d.0.join(format!("{backend}.png"));
        let (code, err) = status(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--backend",
            backend,
            "--max-memory",
            "1G",
            "-q",
            "--set",
            "image.width=96",
            "--set",
            "image.height=96",
            "--set",
            "image.samples=1",
            "--set",
            "group.bars.object.array.counts=[20000, 20000]",
            "--set",
            "group.bars.velocity=[0.9, 0, 0]",
        ]);
        assert_eq!(code, Some(0), "{backend}: {err}");
        let px = pixels(&out);
        let lit = px.iter().filter(|p| p.iter().any(|&c| c > 40)).count();
        assert!(
            lit > px.len() / 5,
            "{backend}: {lit} of {} pixels lit",
            px.len()
        );
        images.push(px);
    }
    if images.len() == 2 {
        let differ = images[0]
            .iter()
            .zip(&images[1])
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 1))
            .count();
        assert_eq!(
            differ, 0,
            "Embree and the f64 BVH differ in {differ} pixels"
        );
    }
}
