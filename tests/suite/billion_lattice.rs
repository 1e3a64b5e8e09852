//! The paper's lattice grown to a billion nodes (10⁹ spheres, ~3·10⁹ rods) and its bar array to
//! 400 million bars render through the real command on every backend, within a memory limit
//! far below what listing them would take, Embree and the f64 BVH agreeing in every pixel; a
//! lattice too large to number is refused with its file, line and key.

use crate::common::cli::*;

/// The text of `scenes/NAME.toml`.
fn paper_scene(name: &str) -> String {
    std::fs::read_to_string(format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))).unwrap()
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

/// Render the paper scene `name` at 96², 1 spp, with `sets`, through the command on every
/// backend under `--max-memory 1G`; assert more than `share` of the pixels have a channel above
/// `level`, and that the backends agree in every pixel (within 1 of 255).
fn renders_alike_in_little_memory(name: &str, sets: &[&str], level: u8, share: f64) {
    let d = Dir::new(name);
    let scene = d.file("scene.toml", &paper_scene(name));
    let backends: &[&str] = if cfg!(feature = "embree") {
        &["embree", "bvh"]
    } else {
        &["bvh"]
    };
    let mut images = Vec::new();
    for backend in backends {
        let out = d.0.join(format!("{backend}.png"));
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--backend",
            backend,
            "--max-memory",
            "1G",
            "-q",
        ];
        for set in ["image.width=96", "image.height=96", "image.samples=1"]
            .iter()
            .chain(sets)
        {
            args.extend(["--set", set]);
        }
        let (code, err) = status(&args);
        assert_eq!(code, Some(0), "{name}, {backend}: {err}");
        let px = pixels(&out);
        let lit = px.iter().filter(|p| p.iter().any(|&c| c > level)).count();
        assert!(
            lit as f64 > share * px.len() as f64,
            "{name}, {backend}: {lit} of {} pixels lit",
            px.len()
        );
        images.push(px);
    }
    if let [a, b] = &images[..] {
        let differ = a
            .iter()
            .zip(b)
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 1))
            .count();
        assert_eq!(
            differ, 0,
            "{name}: Embree and the f64 BVH differ in {differ} pixels"
        );
    }
}

#[test]
fn a_billion_node_lattice_renders_in_little_memory() {
    // At 0.9c the whole front face crowds into a disc filling most of the view.
    renders_alike_in_little_memory(
        "lattice",
        &[
            "group.lattice.object.lattice.counts=[1000, 1000, 1000]",
            "group.lattice.object.lattice.origin=[0, -499.5, -499.5]",
            "group.lattice.velocity=[-0.9, 0, 0]",
        ],
        10,
        0.5,
    );
}

/// A bar array past the limit for listed objects (4·10⁸ bars) renders too, instanced.
#[test]
fn a_bar_array_of_400_million_bars_renders() {
    renders_alike_in_little_memory(
        "bar_array",
        &[
            "group.bars.object.array.counts=[20000, 20000]",
            "group.bars.velocity=[0.9, 0, 0]",
        ],
        40,
        0.2,
    );
}

#[test]
fn a_lattice_too_large_to_number_is_refused() {
    let text =
        paper_scene("lattice").replace("counts = [10, 10, 10]", "counts = [2000, 2000, 2000]");
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
