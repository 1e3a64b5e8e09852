//! `rest-embree bench`: throughput and error of each backend on the same scenes, in one run.
//!
//! For every case and backend it measures the build time, the primary-ray throughput (tracing
//! only, the renderer's own tiles and packets, best of `repeat` runs), the time of a full render,
//! and the error of that render against the f64 BVH reference (share of pixels that differ in
//! the PNG, RMS of linear colour).

use crate::accel::{backend_by_name, Backend};
use crate::compare::compare;
use crate::render::{render_world, trace_primary, World};
use crate::scene::{load_str, Scene, SceneError};
use std::fmt::Write as _;
use std::time::Instant;

/// The paper's scenes, built into the binary so the benchmark runs from any directory.
pub const PAPER_SCENES: [(&str, &str); 3] = [
    (
        "calibration_cube",
        include_str!("../scenes/calibration_cube.toml"),
    ),
    ("bar_array", include_str!("../scenes/bar_array.toml")),
    ("lattice", include_str!("../scenes/lattice.toml")),
];

pub struct Case {
    pub name: String,
    pub scene: Scene,
}

impl Case {
    /// A paper scene with overrides, e.g. `("lattice", ["group.lattice.velocity=[-0.9,0,0]"])`.
    pub fn paper(name: &str, label: &str, sets: &[String]) -> Result<Case, SceneError> {
        let (_, text) = PAPER_SCENES
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| SceneError::new("bench", "", format!("no paper scene named {name}")))?;
        let sets: Vec<(String, String)> = sets
            .iter()
            .map(|s| (format!("--set {s}"), s.clone()))
            .collect();
        Ok(Case {
            name: label.to_string(),
            scene: load_str(&format!("scenes/{name}.toml"), text, &sets)?,
        })
    }
}

/// The default cases: the paper's lattice (forward view) at β = 0, 0.5, 0.9, 0.99.
pub fn default_cases(sets: &[String]) -> Result<Vec<Case>, SceneError> {
    ["0", "0.5", "0.9", "0.99"]
        .iter()
        .map(|b| {
            let mut all = vec![format!("group.lattice.velocity=[-{b},0,0]")];
            all.extend(sets.iter().cloned());
            Case::paper("lattice", &format!("lattice beta={b}"), &all)
        })
        .collect()
}

#[derive(Clone, Debug)]
pub struct Row {
    pub case: String,
    pub backend: String,
    pub width: u32,
    pub height: u32,
    pub primitives: usize,
    pub build_s: f64,
    pub primary_rays: u64,
    pub primary_s: f64,
    pub render_s: f64,
    /// Against the BVH reference render (0 for the reference itself).
    pub differing_share: f64,
    pub rms: f64,
}

impl Row {
    pub fn mrays_per_s(&self) -> f64 {
        self.primary_rays as f64 / self.primary_s.max(1e-12) / 1e6
    }
}

/// Run every case on every backend; the BVH renders the reference image of each case.
pub fn run(cases: &[Case], backends: &[String], repeat: usize) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    let bvh = backend_by_name("bvh")?;
    for case in cases {
        let reference = render_world(&case.scene, &World::build(&case.scene, bvh.as_ref())?).0;
        for name in backends {
            let backend: Box<dyn Backend> = backend_by_name(name)?;
            let t = Instant::now();
            let world = World::build(&case.scene, backend.as_ref())?;
            let build_s = t.elapsed().as_secs_f64();
            let mut primary_s = f64::INFINITY;
            let mut primary_rays = 0;
            for _ in 0..repeat.max(1) {
                let t = Instant::now();
                primary_rays = trace_primary(&case.scene, &world).0;
                primary_s = primary_s.min(t.elapsed().as_secs_f64());
            }
            let t = Instant::now();
            let (frame, _) = render_world(&case.scene, &world);
            let render_s = t.elapsed().as_secs_f64();
            let cmp = compare(&frame, &reference);
            rows.push(Row {
                case: case.name.clone(),
                backend: name.clone(),
                width: case.scene.image.frame_size().0,
                height: case.scene.image.frame_size().1,
                primitives: case.scene.primitive_count(),
                build_s,
                primary_rays,
                primary_s,
                render_s,
                differing_share: cmp.differing_share(),
                rms: cmp.rms,
            });
        }
    }
    Ok(rows)
}

pub fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| case | backend | image | primitives | build s | primary Mrays/s | render s | differing px vs bvh | RMS vs bvh |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {}x{} | {} | {:.3} | {:.2} | {:.3} | {:.3}% | {:.2e} |",
            r.case,
            r.backend,
            r.width,
            r.height,
            r.primitives,
            r.build_s,
            r.mrays_per_s(),
            r.render_s,
            100.0 * r.differing_share,
            r.rms
        );
    }
    s
}

pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from("case,backend,width,height,primitives,build_s,primary_rays,primary_s,mrays_per_s,render_s,differing_share,rms\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.6},{},{:.6},{:.4},{:.6},{:.6},{:.6e}",
            r.case,
            r.backend,
            r.width,
            r.height,
            r.primitives,
            r.build_s,
            r.primary_rays,
            r.primary_s,
            r.mrays_per_s(),
            r.render_s,
            r.differing_share,
            r.rms
        );
    }
    s
}
