//! The paper's scenes (Hsiung & Dunn 1989: the calibration cube, the bar array, the lattice),
//! built into the program so the bench and the tests load them from any directory.

use super::{load_str, SceneError};

/// The paper's scenes, built into the binary so the benchmark runs from any directory.
pub(crate) const PAPER_SCENES: [(&str, &str); 3] = [
    (
        "calibration_cube",
        include_str!("../../scenes/calibration_cube.toml"),
    ),
    ("bar_array", include_str!("../../scenes/bar_array.toml")),
    ("lattice", include_str!("../../scenes/lattice.toml")),
];

/// A paper scene with overrides (`--set` texts).
pub(crate) fn paper(name: &str, sets: &[String]) -> Result<super::Scene, SceneError> {
    let (_, text) = PAPER_SCENES
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| SceneError::new("bench", "", format!("no paper scene named {name}")))?;
    let sets: Vec<(String, String)> = sets
        .iter()
        .map(|s| (format!("--set {s}"), s.clone()))
        .collect();
    load_str(&format!("scenes/{name}.toml"), text, &sets)
}
