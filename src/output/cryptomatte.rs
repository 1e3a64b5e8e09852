//! Cryptomatte layers: anti-aliased mattes of every object and material, by the Cryptomatte
//! specification (Friedman & Jones, Psyop, 2015, v1.2): per pixel the ids with the largest
//! coverage, two ranks to an RGBA layer (`CryptoObject00.R` = id, `.G` = coverage, `.B` and
//! `.A` the next rank; `CryptoObject01` the next two, …). An id is the MurmurHash3 (32-bit,
//! seed 0) of the name, read as the bits of an f32 with the exponent's all-zero and all-one
//! patterns avoided; the header carries, per layer under `cryptomatte/<key>/`, its name, the
//! hash and conversion used, and a manifest from names to ids (hexadecimal).

use super::Attribute;
use crate::render::{Mattes, MATTE_RANKS};

/// The name of each object and material, by index, for the mattes' manifests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MatteNames {
    /// Each `[[group.object]]`'s name, in file order.
    pub objects: Vec<String>,
    /// Each material's name, by index.
    pub materials: Vec<String>,
}

/// MurmurHash3, 32 bits, seed 0, of `name`'s UTF-8 bytes.
pub(crate) fn murmur3(name: &str) -> u32 {
    murmur3::murmur3_32(&mut std::io::Cursor::new(name.as_bytes()), 0).expect("reading memory")
}

/// The id of a name as Cryptomatte stores it: its hash as f32 bits, with the exponent's
/// all-zero and all-one patterns (denormals, infinities, NaNs) flipped out of the way.
pub fn id(name: &str) -> f32 {
    let mut h = murmur3(name);
    let exponent = (h >> 23) & 0xff;
    if exponent == 0 || exponent == 0xff {
        h ^= 1 << 23;
    }
    f32::from_bits(h)
}

/// A pixel's ranks of one kind of matte: (id, share), most first.
pub type Ranks = [(u32, f32); MATTE_RANKS];
/// Which of a pixel's mattes a layer holds.
pub type Pick = fn(&Mattes) -> &Ranks;
/// Channels by name, with their values in pixel order.
pub type Channels = Vec<(String, Vec<f32>)>;

/// The Cryptomatte layers a render writes: its objects' mattes, then its materials'.
pub(crate) const LAYERS: [&str; 2] = ["CryptoObject", "CryptoMaterial"];

/// The name of column `c` of `layer`: rank c / 2's id (c even) or share (c odd), as R, G, B
/// or A of the layer's level c / 4 (`CryptoObject00.R`, …).
pub(crate) fn channel_name(layer: &str, c: usize) -> String {
    format!("{layer}{:02}.{}", c / 4, ["R", "G", "B", "A"][c % 4])
}

/// The ids of `names` by index + 1, as a pixel's mattes number them: 0.0 (no object) first.
pub(crate) fn id_table(names: &[String]) -> Vec<f32> {
    std::iter::once(0.0)
        .chain(names.iter().map(|n| id(n)))
        .collect()
}

/// The channels and header attributes of one kind of matte (`layer`, e.g. `CryptoObject`),
/// `pick` choosing the ranks from a pixel's mattes and `names` naming each index (ids are
/// index + 1).
pub fn layer(
    layer: &str,
    mattes: &[Mattes],
    pick: Pick,
    names: &[String],
) -> (Channels, Vec<(String, Attribute)>) {
    use rayon::prelude::*;
    let ids = id_table(names);
    // Column c holds rank c / 2's id (c even) or share (c odd): RGBA of level c / 4. The
    // columns are made in parallel, each in one pass over the pixels.
    let channels = (0..2 * MATTE_RANKS)
        .into_par_iter()
        .map(|c| {
            let rank = c / 2;
            let values: Vec<f32> = if c % 2 == 0 {
                mattes
                    .iter()
                    .map(|m| ids[pick(m)[rank].0 as usize])
                    .collect()
            } else {
                mattes.iter().map(|m| pick(m)[rank].1).collect()
            };
            (channel_name(layer, c), values)
        })
        .collect();
    let manifest: serde_json::Map<String, serde_json::Value> = names
        .iter()
        .zip(&ids[1..])
        .map(|(n, i)| (n.clone(), format!("{:08x}", i.to_bits()).into()))
        .collect();
    let key = &format!("{:08x}", murmur3(layer))[..7];
    let attr =
        |field: &str, value: String| (format!("cryptomatte/{key}/{field}"), Attribute::Text(value));
    let attributes = vec![
        attr("name", layer.into()),
        attr("hash", "MurmurHash3_32".into()),
        attr("conversion", "uint32_to_float32".into()),
        attr("manifest", serde_json::Value::Object(manifest).to_string()),
    ];
    (channels, attributes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn murmur3_matches_the_reference_and_ids_are_ordinary_floats() {
        // MurmurHash3_x86_32 reference values (seed 0).
        assert_eq!(murmur3(""), 0);
        assert_eq!(murmur3("hello"), 0x248b_fa47);
        assert_eq!(
            murmur3("The quick brown fox jumps over the lazy dog"),
            0x2e4f_f723
        );
        for name in ["cube", "floor", "lattice", "white", "", "a"] {
            let f = id(name);
            assert!(f.is_finite() && (f == 0.0 || f.is_normal()), "{name}: {f}");
        }
    }
}
