//! How a render scales with threads: the paper's lattice at 0.5c rendered (every pass, no
//! output) on one thread and on all of the bench's, each the fastest of a few.

use crate::accel::backend_by_name;
use crate::render::{render_world, World};
use std::time::Instant;

/// A Markdown line: the render time on one thread and on `threads`, and their ratio.
pub(crate) fn summary(quick: bool, backend: &str) -> crate::Result<String> {
    let size = if quick { 512 } else { 1024 };
    let scene = super::paper(
        "lattice",
        &[
            format!("image.width={size}"),
            format!("image.height={size}"),
            "image.samples=1".into(),
            "group.lattice.velocity=[-0.5, 0, 0]".into(),
        ],
    )?;
    let b = backend_by_name(backend)?;
    let world = World::build(&scene, b.as_ref())?;
    let threads = rayon::current_num_threads();
    let time_on = |n: usize| -> crate::Result<f64> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| crate::Error::flag("--threads", e))?;
        Ok(pool.install(|| {
            (0..4)
                .map(|_| {
                    let t = Instant::now();
                    let _ = render_world(&scene, &world);
                    t.elapsed().as_secs_f64()
                })
                .fold(f64::INFINITY, f64::min)
        }))
    };
    let one = time_on(1)?;
    let all = time_on(threads)?;
    world.check()?;
    Ok(format!(
        "- threads, the lattice at 0.5c at {size}x{size}, 1 spp ({backend}): render {one:.3} s on 1 \
         thread, {all:.3} s on {threads} = {:.2}x as fast\n",
        one / all
    ))
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_thread_line_is_measured() {
        let line = super::summary(true, "bvh").unwrap();
        assert!(
            line.contains("on 1 thread") && line.contains("x as fast"),
            "{line}"
        );
    }
}
