//! What a film costs beside its frames: the groups and accelerators are built once, and each
//! frame only aims the world at its imaging event. Measured on the paper's lattice at 0.9c, the
//! camera at rest, against the sum of the frames' render times and against a build per frame.

use crate::accel::backend_by_name;
use crate::render::{render_world, RestGroups, World, WorldOptions};
use std::time::Instant;

/// A Markdown line for `backend`: the film's whole time, the sum of its frames' render times,
/// and what building the world for every frame would have cost.
pub(crate) fn summary(quick: bool, backend: &str) -> crate::Result<String> {
    let frames: u64 = if quick { 24 } else { 240 };
    let size = if quick { 128 } else { 256 };
    let scene = super::paper(
        "lattice",
        &[
            format!("image.width={size}"),
            format!("image.height={size}"),
            "image.samples=1".into(),
            "group.lattice.velocity=[-0.9, 0, 0]".into(),
            "film.start=-6.0".into(),
            "film.step=0.05".into(),
            format!("film.end={}", -6.0 + 0.05 * (frames - 1) as f64),
        ],
    )?;
    let b = backend_by_name(backend)?;
    let start = Instant::now();
    let rest = RestGroups::build(&scene, b.as_ref(), WorldOptions::default())?;
    let mut rendering = 0.0;
    for k in 0..frames {
        let s = scene.film_frame(k).expect("a film");
        let world = World::aim(&s, &rest, b.as_ref())?;
        let t = Instant::now();
        let _ = render_world(&s, &world);
        rendering += t.elapsed().as_secs_f64();
        world.check()?;
    }
    let whole = start.elapsed().as_secs_f64();
    // The same frames, each with a world of its own (as separate runs would build them).
    let start = Instant::now();
    for k in 0..frames {
        let s = scene.film_frame(k).expect("a film");
        let world = World::build(&s, b.as_ref())?;
        let _ = render_world(&s, &world);
        world.check()?;
    }
    let apart = start.elapsed().as_secs_f64();
    Ok(format!(
        "- film, {frames} frames of the lattice at 0.9c at {size}x{size}, 1 spp ({backend}): \
         {whole:.2} s in all = {:.3}x the sum of its frames' render times ({rendering:.2} s); \
         a world built for every frame instead: {apart:.2} s ({:.2}x)\n",
        whole / rendering,
        apart / rendering
    ))
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_film_line_is_measured() {
        let line = super::summary(true, "bvh").unwrap();
        eprintln!("{line}");
        assert!(
            line.contains("24 frames") && line.contains("x the sum"),
            "{line}"
        );
    }
}
