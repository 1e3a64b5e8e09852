//! The ways of giving one setting (a speed as a velocity, a beta or a rapidity; a motion as a
//! velocity or a worldline; a film's rate as fps or step): a `--set` of one replaces the file's
//! others in that table.

/// The keys an override replaces in its table: the other ways of giving the same setting, so
/// `--set group.cube.one_minus_beta=1e-9` works on a file that says `velocity = [...]`.
pub(crate) fn superseded(table: &[&str], key: &str) -> &'static [&'static str] {
    let in_group = table.first() == Some(&"group") && table.len() == 2;
    let in_camera = table == ["camera"];
    let in_light = table.first() == Some(&"light") && table.len() == 2;
    match key {
        // A velocity replaces a worldline, and a worldline every way of giving a velocity
        // (a group's speed has its `direction`, the camera's and a light's their
        // `velocity_direction`; a light's `group` is its velocity too).
        "velocity" if in_group => &[
            "beta",
            "rapidity",
            "one_minus_beta",
            "direction",
            "worldline",
        ],
        "worldline" if in_group => &[
            "velocity",
            "beta",
            "rapidity",
            "one_minus_beta",
            "direction",
        ],
        "velocity" if in_light => &[
            "beta",
            "rapidity",
            "one_minus_beta",
            "velocity_direction",
            "worldline",
            "group",
        ],
        "worldline" if in_light => &[
            "velocity",
            "beta",
            "rapidity",
            "one_minus_beta",
            "velocity_direction",
            "group",
        ],
        "velocity" if in_camera => &[
            "beta",
            "rapidity",
            "one_minus_beta",
            "velocity_direction",
            "worldline",
        ],
        "worldline" if in_camera => &[
            "velocity",
            "beta",
            "rapidity",
            "one_minus_beta",
            "velocity_direction",
        ],
        "velocity" => &["beta", "rapidity", "one_minus_beta", "velocity_direction"],
        // A film's frame rate or its step: one of the two.
        "fps" if table == ["film"] => &["step"],
        "step" if table == ["film"] => &["fps"],
        "beta" => &["velocity", "rapidity", "one_minus_beta"],
        "rapidity" => &["velocity", "beta", "one_minus_beta"],
        "one_minus_beta" => &["velocity", "beta", "rapidity"],
        "direction" if in_camera => &["look_at"],
        "look_at" if in_camera => &["direction"],
        _ => &[],
    }
}
