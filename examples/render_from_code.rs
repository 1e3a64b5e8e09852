//! Rendering from code, as a library user would: a scene from TOML text, changed in code, rendered
//! on the default backend and written to a file.
//! `cargo run --release --example render_from_code -- out.png`

use rest_embree::spacetime::Velocity;
use rest_embree::{accel, output, scene};

const SCENE: &str = r#"
[camera]
position = [0, 0, 0]
look_at = [0, 10, 0]
time = 10
[image]
width = 320
height = 240
[[light]]
position = [0, 0, 20]
color = { blackbody = 5800, luminance = 1 }
[[group]]
name = "cube"
[[group.object]]
type = "box"
min = [-1, 9, -1]
max = [1, 11, 1]
"#;

fn main() -> rest_embree::Result<()> {
    let path = std::env::args().nth(1).unwrap_or_else(|| "cube.png".into());
    // Errors name the "file" (here a label), line and key.
    let mut scene = scene::load_str("example", SCENE, &[])?;
    // The cube passes at 0.8c along x: its geometry stays as given, in its own rest frame.
    scene.groups[0].velocity = Velocity::from_beta(glam::DVec3::X, 0.8).expect("below c");
    let backend = accel::backend_by_name(accel::default_backend_name())?;
    let (frame, stats) = rest_embree::render(&scene, backend.as_ref(), &Default::default())?;
    output::write(&frame, std::path::Path::new(&path))?;
    println!(
        "{path}: {} primary rays in {:.3} s",
        stats.primary_rays,
        stats.trace_time.as_secs_f64()
    );
    Ok(())
}
