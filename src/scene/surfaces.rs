//! The scene's surfaces: `[[material]]` tables, the `[[texture]]` tables they may name
//! (checkers, images) and the `[sky]`.

use super::model::Material;
use super::reader::{SceneResult, Table};
use super::Texture;
use crate::spectrum::{Colour, Role};
use glam::DVec3;
use std::sync::Arc;

/// The image file `key` names (beside the scene file): its path and linear texels.
fn image_beside(
    t: &Table,
    key: &str,
) -> SceneResult<(std::path::PathBuf, usize, usize, super::texture::Texels)> {
    let node = t.get(key).expect("the caller read it");
    let path = t.path_beside(t.req_string(key)?);
    let (w, h, texels) = super::texture::read_image(&path)
        .map_err(|why| t.error_at(node, key, format!("{}: {why}", path.display())))?;
    Ok((path, w, h, texels))
}

/// A texture read for each role a material may give it (its colours uplifted as reflectances
/// for `color`, as emitters for `emission`).
pub(super) struct ReadTexture {
    name: String,
    reflectance: Arc<Texture>,
    emitter: Arc<Texture>,
}

/// The `[[texture]]` tables.
pub(super) fn textures(root: &Table) -> SceneResult<Vec<ReadTexture>> {
    let mut out: Vec<ReadTexture> = Vec::new();
    for t in root.tables("texture")? {
        let name = t.req_string("name")?.to_string();
        if out.iter().any(|x| x.name == name) {
            return Err(t.error("name", format!("a texture named `{name}` is defined twice")));
        }
        let (reflectance, emitter) = match (t.table("checker")?, t.string("image")?) {
            (Some(_), Some(_)) => {
                return Err(t.error("image", "a texture is a checker or an image, not both"))
            }
            (Some(c), None) => checker(&c)?,
            (None, Some(_)) => {
                let (path, w, h, texels) = image_beside(&t, "image")?;
                let shown = path.display().to_string();
                let image = |role| {
                    Arc::new(Texture::Image(super::ImageTexture::new(
                        shown.clone(),
                        w,
                        h,
                        texels.clone(),
                        role,
                    )))
                };
                (image(Role::Reflectance), image(Role::Emitter))
            }
            (None, None) => {
                return Err(t.error(
                    "checker",
                    "missing: a texture is a `checker = { size, color1, color2 }` or an `image = \"file.png\"` (or .exr)",
                ))
            }
        };
        t.finish(&["name", "checker", "image"])?;
        out.push(ReadTexture {
            name,
            reflectance,
            emitter,
        });
    }
    Ok(out)
}

/// The `[sky]` table: `map` (an equirectangular image), `rotate`, `intensity`, `stars`,
/// `velocity` (or `beta` with `velocity_direction`, ...).
pub(super) fn sky(t: &Table) -> SceneResult<super::Sky> {
    let map = match t.has("map") {
        true => {
            let (path, w, h, texels) = image_beside(t, "map")?;
            let shown = path.display().to_string();
            Some(Arc::new(super::ImageTexture::new(
                shown,
                w,
                h,
                texels,
                Role::Emitter,
            )))
        }
        false => None,
    };
    let stars = t.table("stars")?.map(|s| stars(&s)).transpose()?;
    if map.is_none() && stars.is_none() {
        return Err(t.error(
            "map",
            "missing: a sky is a `map = \"sky.exr\"` (equirectangular), `stars = { count = ... }`, or both",
        ));
    }
    let rotation = super::transform::Transform::read_rotation(t)?.unwrap_or(glam::DMat3::IDENTITY);
    let intensity = t.f64_where("intensity", Some(1.0), |v| v >= 0.0, "0 or more")?;
    let velocity = super::speed::velocity(t, "velocity_direction")?
        .unwrap_or(crate::spacetime::Velocity::ZERO);
    t.finish(&[
        "map",
        "rotate",
        "intensity",
        "stars",
        "velocity",
        "beta",
        "rapidity",
        "one_minus_beta",
        "velocity_direction",
    ])?;
    Ok(super::Sky {
        map,
        rotation,
        intensity,
        stars,
        velocity,
    })
}

/// `[sky] stars = { count, seed, magnitudes, irradiance, temperatures }`.
fn stars(t: &Table) -> SceneResult<super::stars::StarField> {
    use super::stars::{StarField, MAX_STARS};
    let count = t.uint("count", None, 1, MAX_STARS)?;
    let seed = t.uint("seed", Some(1), 0, 1 << 53)?;
    let pair = |key: &str, default: [f64; 2], ok: &dyn Fn(f64) -> bool, what: &str| {
        let Some(n) = t.get(key) else {
            return Ok(default);
        };
        let v = t.numbers_of(n, key, Some(2))?;
        if !(ok(v[0]) && ok(v[1]) && v[0] <= v[1]) {
            return Err(t.error_at(
                n,
                key,
                format!("give [low, high], low <= high, each {what}"),
            ));
        }
        Ok([v[0], v[1]])
    };
    let magnitudes = pair(
        "magnitudes",
        [0.0, 6.0],
        &|v: f64| v.is_finite() && v.abs() <= 30.0,
        "between -30 and 30",
    )?;
    let temperatures = pair(
        "temperatures",
        [3000.0, 30000.0],
        &|v: f64| (100.0..=1e6).contains(&v),
        "from 100 to 1000000 K",
    )?;
    let irradiance = t.f64_where(
        "irradiance",
        Some(2e-5),
        |v| v > 0.0 && v.is_finite(),
        "greater than 0",
    )?;
    t.finish(&["count", "seed", "magnitudes", "irradiance", "temperatures"])?;
    let what = format!("a star field of {count} stars");
    let need = count.saturating_mul(crate::memory::BYTES_PER_STAR);
    if let Some(why) = crate::memory::too_much(need, &what) {
        return Err(t.error("count", why));
    }
    Ok(StarField::new(
        count,
        seed,
        magnitudes,
        irradiance,
        temperatures,
    ))
}

/// A checker texture's table, read for both roles.
fn checker(c: &Table) -> SceneResult<(Arc<Texture>, Arc<Texture>)> {
    let size = match c.get("size") {
        None => return Err(c.error("size", "missing: the checker's square size (a number, or [sx, sy, sz] with 0 for no change along an axis)")),
        Some(n) => {
            let s = match n.val {
                super::doc::Val::Array(_) => c.vec3_of(n, "size")?,
                _ => DVec3::splat(c.f64_or("size", 1.0)?),
            };
            if s.cmplt(DVec3::ZERO).any() || s == DVec3::ZERO {
                return Err(c.error_at(n, "size", "sizes must be 0 or more, and one greater than 0"));
            }
            s
        }
    };
    let both = |role| -> SceneResult<[crate::spectrum::Colour; 2]> {
        let get = |k: &str| {
            c.colour(k, role)?.ok_or_else(|| {
                c.error(
                    k,
                    "missing: give the checker's two colours, color1 and color2",
                )
            })
        };
        Ok([get("color1")?, get("color2")?])
    };
    let reflectance = Arc::new(Texture::Checker {
        size,
        colors: both(Role::Reflectance)?,
    });
    let emitter = Arc::new(Texture::Checker {
        size,
        colors: both(Role::Emitter)?,
    });
    c.finish(&["size", "color1", "color2"])?;
    Ok((reflectance, emitter))
}

/// A material's colour key: a colour, or the name of a texture (with the colour to hold in
/// its place: the texture's first).
fn colour_or_texture(
    t: &Table,
    key: &str,
    role: Role,
    textures: &[ReadTexture],
) -> SceneResult<(Option<crate::spectrum::Colour>, Option<Arc<Texture>>)> {
    let Some(name) = t.get(key).and_then(|n| match &n.val {
        super::doc::Val::Str(s) => Some(s.as_str()),
        _ => None,
    }) else {
        return Ok((t.colour(key, role)?, None));
    };
    let _ = t.string(key)?;
    let Some(found) = textures.iter().find(|x| x.name == name) else {
        let known: Vec<&str> = textures.iter().map(|x| x.name.as_str()).collect();
        let n = t.get(key).expect("read above");
        return Err(t.error_at(
            n,
            key,
            format!(
                "expected a colour, found a string: no texture is named `{name}` (textures: {}), \
                 and colours have no names (red is [0.8, 0.1, 0.1]); a colour is {}",
                if known.is_empty() {
                    "none defined".to_string()
                } else {
                    known.join(", ")
                },
                super::colour::FORMS
            ),
        ));
    };
    let texture = match role {
        Role::Emitter => found.emitter.clone(),
        _ => found.reflectance.clone(),
    };
    let first = texture
        .colours()
        .next()
        .expect("a texture has colours")
        .clone();
    Ok((Some(first), Some(texture)))
}

/// `medium = { sigma_a, sigma_s, g }`: coefficients per unit length, any non-negative colour
/// (RGB is read as a reflectance scaled by its largest component, so a grey is flat).
pub(super) fn medium(t: &Table, also: &[&str]) -> SceneResult<crate::scene::Medium> {
    let coefficient = |key: &str| -> SceneResult<Colour> {
        let Some(c) = t.colour(key, Role::Emitter)? else {
            return Ok(Colour::grey(0.0, Role::Reflectance));
        };
        if !c.from_rgb {
            return Ok(c);
        }
        let m = c.rgb.max_element();
        if c.rgb.min_element() < 0.0 || !m.is_finite() {
            return Err(t.error(key, "must be 0 or more per unit length"));
        }
        if m == 0.0 {
            return Ok(Colour::grey(0.0, Role::Reflectance));
        }
        Ok(Colour::rgb(c.rgb / m, Role::Reflectance).scaled(m))
    };
    if !t.has("sigma_a") && !t.has("sigma_s") {
        return Err(t.error(
            "sigma_a",
            "missing: give `sigma_a` (absorption) or `sigma_s` (scattering) per unit length",
        ));
    }
    let m = crate::scene::Medium {
        sigma_a: coefficient("sigma_a")?,
        sigma_s: coefficient("sigma_s")?,
        g: t.f64_where(
            "g",
            Some(0.0),
            |g| g > -1.0 && g < 1.0,
            "between -1 and 1 (not either)",
        )?,
    };
    let mut known = vec!["sigma_a", "sigma_s", "g"];
    known.extend_from_slice(also);
    t.finish(&known)?;
    Ok(m)
}

pub(super) fn material(t: &Table, textures: &[ReadTexture]) -> SceneResult<Material> {
    let d = Material::default_white();
    let unit = |v: f64| (0.0..=1.0).contains(&v);
    let (color, color_texture) = colour_or_texture(t, "color", Role::Reflectance, textures)?;
    let (emission, emission_texture) = colour_or_texture(t, "emission", Role::Emitter, textures)?;
    let m = Material {
        name: t.req_string("name")?.to_string(),
        color: color.unwrap_or(d.color),
        specular: t
            .colour("specular", Role::Reflectance)?
            .unwrap_or(d.specular),
        shininess: t.f64_where("shininess", Some(d.shininess), |v| v >= 0.0, "0 or more")?,
        reflect: t.f64_where("reflect", Some(0.0), unit, "between 0 and 1")?,
        transmit: t.f64_where("transmit", Some(0.0), unit, "between 0 and 1")?,
        ior: t.f64_where("ior", Some(d.ior), |v| v >= 1.0, "1 or more")?,
        roughness: t.f64_where("roughness", Some(d.roughness), unit, "between 0 and 1")?,
        emission,
        color_texture,
        emission_texture,
        medium: match t.table("medium")? {
            Some(m) => Some(medium(&m, &[])?),
            None => None,
        },
    };
    if m.is_invisible() {
        // Its surface is nothing but where the medium begins: what would shade it is a mistake.
        for key in ["color", "specular", "reflect", "roughness", "emission"] {
            if t.has(key) {
                return Err(t.error(
                    key,
                    "a material with a `medium` and no `transmit` has no surface (light crosses \
                     it unchanged): leave this out, or give `transmit` for a glass boundary",
                ));
            }
        }
    }
    if m.medium.is_some() && m.emission.is_some() {
        return Err(t.error(
            "emission",
            "a medium does not glow (give its object another material)",
        ));
    }
    t.finish(&[
        "medium",
        "name",
        "color",
        "specular",
        "shininess",
        "reflect",
        "transmit",
        "ior",
        "roughness",
        "emission",
    ])?;
    Ok(m)
}
