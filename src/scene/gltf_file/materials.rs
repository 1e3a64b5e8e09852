//! A glTF material as the file gives it: metallic-roughness with the transmission, IOR and
//! emissive-strength extensions, and its base-colour and emissive images.

use super::files::image;
use super::{GltfError, GltfMaterial, Image};
use glam::DVec3;
use std::path::Path;

/// A material as the file gives it.
pub(super) fn material(
    m: &gltf::Material,
    buffers: &[Vec<u8>],
    base: &Path,
    warnings: &mut Vec<String>,
) -> Result<GltfMaterial, GltfError> {
    let index = m.index().unwrap_or(0);
    let name = m
        .name()
        .map_or_else(|| format!("material{index}"), str::to_string);
    let pbr = m.pbr_metallic_roughness();
    let f = pbr.base_color_factor().map(f64::from);
    let base_color = DVec3::new(f[0], f[1], f[2]);
    let image = |info: Option<gltf::texture::Info>,
                 role: &str|
     -> Result<Option<Image>, GltfError> {
        let Some(info) = info else { return Ok(None) };
        if info.tex_coord() != 0 {
            return Err(format!(
                "material `{name}`'s {role} texture uses texture coordinates {}; only set 0 is read",
                info.tex_coord()
            ).into());
        }
        image(&info.texture().source(), buffers, base).map(Some)
    };
    let base_texture = image(pbr.base_color_texture(), "base colour")?;
    let emissive_texture = image(m.emissive_texture(), "emissive")?;
    if pbr.metallic_roughness_texture().is_some()
        || m.normal_texture().is_some()
        || m.occlusion_texture().is_some()
    {
        warnings.push(format!(
            "material `{name}`'s metallic-roughness, normal and occlusion textures are not mapped (their factors are)"
        ));
    }
    let strength = f64::from(m.emissive_strength().unwrap_or(1.0));
    let e = m.emissive_factor().map(f64::from);
    let out = GltfMaterial {
        name,
        base_color,
        base_texture,
        metallic: f64::from(pbr.metallic_factor()),
        roughness: f64::from(pbr.roughness_factor()),
        transmission: m
            .transmission()
            .map_or(0.0, |t| f64::from(t.transmission_factor())),
        ior: f64::from(m.ior().unwrap_or(1.5)),
        emissive: DVec3::new(e[0], e[1], e[2]) * strength,
        emissive_texture,
    };
    let numbers = [out.metallic, out.roughness, out.transmission, out.ior];
    if !out.base_color.is_finite()
        || !out.emissive.is_finite()
        || numbers.iter().any(|x| !x.is_finite())
    {
        return Err(format!("material `{}` has a number that is not finite", out.name).into());
    }
    // glTF 2.0 keeps these factors in [0, 1] and the emissive strength at 0 or more; a file
    // beyond is refused, not clamped into another picture (a scene's own colours beyond are
    // refused too). The scene's material takes them as they are (`gltf_object::material`).
    let factors: [(&str, &[f64]); 5] = [
        ("baseColorFactor", &f),
        ("metallicFactor", &[out.metallic]),
        ("roughnessFactor", &[out.roughness]),
        ("transmissionFactor", &[out.transmission]),
        ("emissiveFactor", &e),
    ];
    for (key, values) in factors {
        if let Some(v) = values.iter().find(|v| !(0.0..=1.0).contains(*v)) {
            return Err(format!(
                "material `{}`'s {key} holds {v}, outside [0, 1] (glTF 2.0's range)",
                out.name
            )
            .into());
        }
    }
    if strength < 0.0 {
        return Err(format!(
            "material `{}`'s emissiveStrength is {strength}; it must be 0 or more",
            out.name
        )
        .into());
    }
    // The limits a scene's own material has (`ior` 1 or more, numbers within the envelope).
    let limit = crate::scene::envelope::MAX_MAGNITUDE;
    if strength > limit {
        return Err(format!(
            "material `{}`'s emissiveStrength is {strength:e}; at most {limit:e} is taken",
            out.name
        )
        .into());
    }
    if !(1.0..=limit).contains(&out.ior) {
        return Err(format!(
            "material `{}`'s KHR_materials_ior ior is {}; it must be 1 or more (and at most {limit:e})",
            out.name, out.ior
        )
        .into());
    }
    Ok(out)
}
