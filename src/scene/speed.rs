//! How a speed is given: `velocity = [bx, by, bz]`, or a direction with one of `beta`,
//! `rapidity` or `one_minus_beta` (the forms that stay exact near c, docs/physics.md §8).

use super::reader::{SceneResult, Table};
use crate::spacetime::Velocity;

/// A velocity: `velocity = [bx, by, bz]`, or `<dir_key> = [...]` with one of `beta`,
/// `rapidity`, `one_minus_beta`. None when none of these keys is present.
pub(super) fn velocity(t: &Table, dir_key: &str) -> SceneResult<Option<Velocity>> {
    let forms: Vec<&str> = ["beta", "rapidity", "one_minus_beta"]
        .into_iter()
        .filter(|k| t.has(k))
        .collect();
    if t.has("velocity") {
        if let Some(k) = forms.first().copied().or(t.has(dir_key).then_some(dir_key)) {
            return Err(t.error(
                k,
                format!("give either `velocity = [...]` or `{dir_key}` with one speed, not both"),
            ));
        }
        let n = t.get("velocity").expect("checked");
        let v = t.vec3("velocity")?.expect("checked");
        return Velocity::from_beta_vec(v)
            .map(Some)
            .map_err(|e| t.error_at(n, "velocity", e.to_string()));
    }
    if forms.is_empty() {
        if let Some(n) = t.get(dir_key) {
            return Err(t.error_at(
                n,
                dir_key,
                "give the speed too: one of beta, rapidity, one_minus_beta",
            ));
        }
        return Ok(None);
    }
    if forms.len() > 1 {
        return Err(t.error(
            forms[1],
            format!(
                "give only one of beta, rapidity, one_minus_beta (found {})",
                forms.join(", ")
            ),
        ));
    }
    let form = forms[0];
    let dir = t.vec3(dir_key)?.ok_or_else(|| {
        t.error(
            dir_key,
            format!("`{form}` needs a direction: {dir_key} = [x, y, z]"),
        )
    })?;
    let n = t.get(form).expect("checked");
    let s = t.f64(form)?.expect("checked");
    let v = match form {
        "beta" => Velocity::from_beta(dir, s),
        "rapidity" => Velocity::from_rapidity(dir, s),
        _ => Velocity::from_one_minus_beta(dir, s),
    };
    // A zero direction is the direction's fault; the rest, the speed's.
    let v = v.map_err(|e| match e {
        crate::spacetime::VelocityError::ZeroDirection => t.error(dir_key, e.to_string()),
        _ => t.error_at(n, form, e.to_string()),
    })?;
    if let Some(why) = super::envelope::too_fast(v.rapidity()) {
        return Err(t.error_at(n, form, why));
    }
    Ok(Some(v))
}
