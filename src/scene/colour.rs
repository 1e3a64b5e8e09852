//! Reading a colour: an RGB triple or a grey number, or a spectrum written as a table
//! (`{ blackbody = T }`, `{ line = NM, fwhm = NM }`, `{ wavelengths = [...], values = [...] }`).

use super::doc::Val;
use super::reader::{SceneResult, Table};
use crate::spectrum::{camera, Colour, Role, Spectrum};

pub(super) const FORMS: &str = "[r, g, b] (linear, e.g. [0.8, 0.8, 0.8]), a grey number (0.8), { blackbody = T }, { line = NM, fwhm = NM } or { wavelengths = [...], values = [...] }";

impl Table<'_> {
    /// A colour for `role`. Reflectances take RGB and tables only.
    pub fn colour(&self, key: &str, role: Role) -> SceneResult<Option<Colour>> {
        let Some(n) = self.get(key) else {
            return Ok(None);
        };
        if !matches!(
            n.val,
            Val::Table(_) | Val::Array(_) | Val::Float(_) | Val::Int(_)
        ) {
            let named = if matches!(n.val, Val::Str(_)) {
                " (colours have no names: red is [0.8, 0.1, 0.1])"
            } else {
                ""
            };
            return Err(self.error_at(
                n,
                key,
                format!(
                    "expected a colour, found {}{named}; a colour is {FORMS}",
                    n.kind()
                ),
            ));
        }
        if !matches!(n.val, Val::Table(_)) {
            let rgb = self.color(key)?.expect("present");
            return Ok(Some(Colour::rgb(rgb, role)));
        }
        let t = self.table(key)?.expect("present");
        let spectrum = if t.has("blackbody") {
            let kelvin = t.f64_where(
                "blackbody",
                None,
                |v| v > 0.0,
                "a temperature in kelvin above 0",
            )?;
            if role == Role::Reflectance {
                return Err(self.error_at(n, key, "a reflectance cannot be a blackbody (blackbodies and lines are for emission, lights and the background); give [r, g, b] or { wavelengths = [...], values = [...] }"));
            }
            Spectrum::Blackbody { kelvin, scale: 1.0 }
        } else if t.has("line") {
            if role == Role::Reflectance {
                return Err(self.error_at(n, key, "a reflectance cannot be an emission line (blackbodies and lines are for emission, lights and the background); give [r, g, b] or { wavelengths = [...], values = [...] }"));
            }
            Spectrum::Line {
                centre: t.f64_where("line", None, |v| v > 0.0, "a wavelength in nm above 0")?,
                fwhm: t.f64_where("fwhm", None, |v| v > 0.0, "a width in nm above 0")?,
                scale: 1.0,
            }
        } else if t.has("wavelengths") || t.has("values") {
            tabulated(&t)?
        } else {
            return Err(self.error_at(n, key, format!("expected {FORMS}")));
        };
        let scaled = match (t.f64("scale")?, t.f64("luminance")?) {
            (Some(_), Some(_)) => {
                return Err(t.error("luminance", "give either `scale` or `luminance`, not both"))
            }
            (Some(s), None) if s < 0.0 => {
                return Err(t.error_at(
                    t.get("scale").expect("read"),
                    "scale",
                    format!("must not be negative (got {s:?})"),
                ))
            }
            (Some(s), None) => s,
            (None, Some(y)) => {
                if y < 0.0 {
                    return Err(t.error_at(
                        t.get("luminance").expect("read"),
                        "luminance",
                        format!("must not be negative (got {y:?})"),
                    ));
                }
                if role == Role::Reflectance {
                    return Err(t.error(
                        "luminance",
                        "a reflectance has no luminance; scale its values instead",
                    ));
                }
                let at_rest = camera::xyz(&crate::spectrum::Sampled::of(&spectrum, 1.0)).y;
                if at_rest <= 0.0 || !at_rest.is_finite() {
                    return Err(t.error("luminance", format!("this spectrum is dark at every visible wavelength (luminance {at_rest}), so it cannot be scaled to a luminance; give `scale`")));
                }
                y / at_rest
            }
            (None, None) => 1.0,
        };
        t.finish(&[
            "blackbody",
            "line",
            "fwhm",
            "wavelengths",
            "values",
            "scale",
            "luminance",
        ])?;
        let colour = Colour::spectral(spectrum, role).scaled(scaled);
        if !colour.rgb.is_finite() {
            return Err(self.error_at(
                n,
                key,
                "this spectrum's values overflow at visible wavelengths; give a smaller scale",
            ));
        }
        Ok(Some(colour))
    }

    pub fn bool_or(&self, key: &str, default: bool) -> SceneResult<bool> {
        match self.get(key) {
            None => Ok(default),
            Some(n) => match n.val {
                Val::Bool(b) => Ok(b),
                _ => Err(self.error_at(
                    n,
                    key,
                    format!("expected true or false, found {}", n.kind()),
                )),
            },
        }
    }
}

/// `{ wavelengths = [...], values = [...] }`: nm strictly increasing, values ≥ 0.
fn tabulated(t: &Table) -> SceneResult<Spectrum> {
    let wn = t.get("wavelengths").ok_or_else(|| {
        t.error(
            "wavelengths",
            "missing: give the wavelengths in nm, increasing",
        )
    })?;
    let vn = t
        .get("values")
        .ok_or_else(|| t.error("values", "missing: give one value per wavelength"))?;
    let wavelengths = t.numbers_of(wn, "wavelengths", None)?;
    let values = t.numbers_of(vn, "values", None)?;
    if wavelengths.is_empty() {
        return Err(t.error_at(wn, "wavelengths", "give at least one wavelength"));
    }
    if wavelengths.len() != values.len() {
        return Err(t.error_at(
            vn,
            "values",
            format!(
                "{} values for {} wavelengths: give one value per wavelength",
                values.len(),
                wavelengths.len()
            ),
        ));
    }
    if let Some(w) = wavelengths.iter().find(|&&w| w <= 0.0) {
        return Err(t.error_at(
            wn,
            "wavelengths",
            format!("wavelengths must be above 0 nm (got {w:?})"),
        ));
    }
    if let Some(k) = (1..wavelengths.len()).find(|&k| wavelengths[k] <= wavelengths[k - 1]) {
        return Err(t.error_at(
            wn,
            "wavelengths",
            format!(
                "wavelengths must increase: {} follows {}",
                wavelengths[k],
                wavelengths[k - 1]
            ),
        ));
    }
    if let Some(v) = values.iter().find(|&&v| v < 0.0) {
        return Err(t.error_at(
            vn,
            "values",
            format!("values must not be negative (got {v:?})"),
        ));
    }
    Ok(Spectrum::Tabulated {
        wavelengths: wavelengths.into(),
        values: values.into(),
    })
}
