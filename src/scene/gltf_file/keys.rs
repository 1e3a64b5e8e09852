//! Keyframed translations of nodes: read, checked, and thinned to the keys a straight motion
//! needs.

use super::GltfError;
use glam::DVec3;

/// The keyframe value at file time `t` (linear between keys, held before the first and after
/// the last).
pub(crate) fn translation_at(keys: &[(f64, DVec3)], t: f64) -> DVec3 {
    let i = keys.partition_point(|&(k, _)| k <= t);
    match i {
        0 => keys[0].1,
        i if i == keys.len() => keys[i - 1].1,
        i => {
            let ((t0, a), (t1, b)) = (keys[i - 1], keys[i]);
            a + (b - a) * ((t - t0) / (t1 - t0))
        }
    }
}

/// The keyframed translations, by node index. A STEP or CUBICSPLINE translation is refused (a
/// body cannot jump, and a cubic path is not uniform segments); rotations, scales and morph
/// weights are ignored with a warning.
pub(super) fn translations(
    gltf: &gltf::Gltf,
    buffers: &[Vec<u8>],
    warnings: &mut Vec<String>,
) -> Result<std::collections::HashMap<usize, Vec<(f64, DVec3)>>, GltfError> {
    use gltf::animation::{util::ReadOutputs, Interpolation, Property};
    let mut out = std::collections::HashMap::new();
    let mut ignored = false;
    for anim in gltf.animations() {
        for (c, ch) in anim.channels().enumerate() {
            // The crate's validation leaves a channel's target unchecked (its accessors would
            // panic on a bad one): checked here, on the JSON.
            let target = &gltf.as_json().animations[anim.index()].channels[c].target;
            let property = match (&target.path, target.node.value() < gltf.nodes().len()) {
                (gltf::json::validation::Checked::Valid(p), true) => *p,
                _ => {
                    return Err(format!(
                        "animation {}'s channel {c} targets no node or no property",
                        anim.index()
                    )
                    .into())
                }
            };
            let node = ch.target().node();
            if property != Property::Translation {
                ignored = true;
                continue;
            }
            let what = || {
                format!(
                    "animation {}'s translation of node {}",
                    anim.index(),
                    node.index()
                )
            };
            match ch.sampler().interpolation() {
                Interpolation::Linear => {}
                Interpolation::Step => {
                    return Err(format!(
                        "{} is STEP: a body cannot jump from place to place (key it LINEAR)",
                        what()
                    )
                    .into())
                }
                Interpolation::CubicSpline => {
                    return Err(format!(
                        "{} is CUBICSPLINE: only LINEAR keys become uniform motion",
                        what()
                    )
                    .into())
                }
            }
            let reader = ch.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let times: Vec<f64> = reader
                .read_inputs()
                .ok_or_else(|| format!("{}: its times cannot be read", what()))?
                .map(f64::from)
                .collect();
            let values: Vec<DVec3> = match reader.read_outputs() {
                Some(ReadOutputs::Translations(v)) => {
                    v.map(|p| DVec3::from_array(p.map(f64::from))).collect()
                }
                _ => return Err(format!("{}: its values cannot be read", what()).into()),
            };
            if times.is_empty() || times.len() != values.len() {
                return Err(format!(
                    "{}: {} times and {} values",
                    what(),
                    times.len(),
                    values.len()
                )
                .into());
            }
            if let Some(i) = (0..times.len()).find(|&i| {
                !times[i].is_finite()
                    || !values[i].is_finite()
                    || (i > 0 && times[i] <= times[i - 1])
            }) {
                return Err(format!(
                    "{}: key {i} (time {}, value {}) is not finite or not after the one before",
                    what(),
                    times[i],
                    values[i]
                )
                .into());
            }
            let keys = thinned(times.into_iter().zip(values).collect());
            if out.insert(node.index(), keys).is_some() {
                return Err(format!("{} is the node's second translation", what()).into());
            }
        }
    }
    if ignored {
        warnings.push(
            "its rotation, scale and morph-weight animations are ignored (only translations become motion)".into(),
        );
    }
    Ok(out)
}

/// `keys` without those that lie on the uniform motion between the keys kept around them (to
/// a millionth of its displacement): an exporter that samples every frame (Blender's) writes a
/// straight motion as one key a frame, each rounded to f32, which would otherwise be as many
/// segments of velocities a part in 10^7 apart. What is left moves through every key given.
pub(super) fn thinned(keys: Vec<(f64, DVec3)>) -> Vec<(f64, DVec3)> {
    let on_line = |a: (f64, DVec3), c: (f64, DVec3), b: (f64, DVec3)| {
        let at = a.1 + (c.1 - a.1) * ((b.0 - a.0) / (c.0 - a.0));
        let tolerance = 1e-6
            * (c.1 - a.1)
                .length()
                .max(1e-9 * (a.1.length() + c.1.length()));
        (b.1 - at).length() <= tolerance
    };
    let mut out = vec![keys[0]];
    let mut from = 0;
    for j in 2..keys.len() {
        if !(from + 1..j).all(|i| on_line(keys[from], keys[j], keys[i])) {
            from = j - 1;
            out.push(keys[from]);
        }
    }
    if keys.len() > 1 {
        out.push(keys[keys.len() - 1]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_hold_before_and_after_and_are_linear_between() {
        let k = [(1.0, DVec3::X), (3.0, DVec3::new(3.0, 2.0, 0.0))];
        assert_eq!(translation_at(&k, 0.0), DVec3::X);
        assert_eq!(translation_at(&k, 2.0), DVec3::new(2.0, 1.0, 0.0));
        assert_eq!(translation_at(&k, 9.0), DVec3::new(3.0, 2.0, 0.0));
    }

    #[test]
    fn keys_on_a_straight_motion_are_one_segment() {
        // A baked motion: a key a frame, rounded to f32, then a stop and a turn.
        let mut keys: Vec<(f64, DVec3)> = (1..=49)
            .map(|f| {
                let t = f64::from(f as f32 / 24.0);
                (t, DVec3::new(f64::from((f - 1) as f32 / 24.0), -1.5, -10.0))
            })
            .collect();
        keys.push((3.0, keys[48].1));
        keys.push((4.0, keys[48].1 + DVec3::Y));
        let kept = thinned(keys.clone());
        assert_eq!(kept, vec![keys[0], keys[48], keys[49], keys[50]]);
        // A curve keeps its keys.
        let curve: Vec<(f64, DVec3)> = (0..10)
            .map(|i| {
                (
                    f64::from(i),
                    DVec3::new(f64::from(i), f64::from(i * i), 0.0),
                )
            })
            .collect();
        assert_eq!(thinned(curve.clone()), curve);
        assert_eq!(thinned(vec![curve[0]]), vec![curve[0]]);
    }
}
