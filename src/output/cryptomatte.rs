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
#[derive(Clone, Debug, Default)]
pub struct MatteNames {
    /// Each `[[group.object]]`'s name, in file order.
    objects: Vec<String>,
    /// Each material's name, by index.
    materials: Vec<String>,
    /// What [`MatteNames::made`] makes from the names, kept.
    made: std::sync::OnceLock<[Made; 2]>,
}

/// Names are equal when their names are (whether their ids are made yet does not count).
impl PartialEq for MatteNames {
    fn eq(&self, other: &MatteNames) -> bool {
        (&self.objects, &self.materials) == (&other.objects, &other.materials)
    }
}

/// A layer's ids by index + 1 ([`id_table`]) and its header attributes (the manifest), made
/// from the names alone: once, for the header and the blocks alike.
#[derive(Clone, Debug)]
pub(crate) struct Made {
    /// The layer's name ([`LAYERS`]).
    pub layer: &'static str,
    pub ids: Vec<f32>,
    pub attributes: Vec<(String, Attribute)>,
}

impl MatteNames {
    /// The names of the objects and the materials, by index.
    pub fn new(objects: Vec<String>, materials: Vec<String>) -> MatteNames {
        MatteNames {
            objects,
            materials,
            made: Default::default(),
        }
    }

    /// Each layer's ([`LAYERS`]) ids and attributes, made on first use (100,000 objects'
    /// hashes and manifest take a tenth of a second: a render makes them beside its build).
    pub(crate) fn made(&self) -> &[Made; 2] {
        self.made.get_or_init(|| {
            [(LAYERS[0], &self.objects), (LAYERS[1], &self.materials)].map(|(layer, names)| {
                let ids = id_table(names);
                let attributes = attributes(layer, names, &ids);
                Made {
                    layer,
                    ids,
                    attributes,
                }
            })
        })
    }
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

/// The channels and header attributes of one kind of matte (`made`: its ids and attributes,
/// from [`MatteNames::made`]), `pick` choosing the ranks from a pixel's mattes.
pub(crate) fn layer(
    mattes: &[Mattes],
    pick: Pick,
    made: &Made,
) -> (Channels, Vec<(String, Attribute)>) {
    use rayon::prelude::*;
    let (ids, layer) = (&made.ids, made.layer);
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
    (channels, made.attributes.clone())
}

/// The header attributes of `layer` whose `names` have `ids` (by index + 1): its name, hash,
/// conversion and manifest, under `cryptomatte/<key>/`.
fn attributes(layer: &str, names: &[String], ids: &[f32]) -> Vec<(String, Attribute)> {
    let key = &format!("{:08x}", murmur3(layer))[..7];
    let attr =
        |field: &str, value: String| (format!("cryptomatte/{key}/{field}"), Attribute::Text(value));
    vec![
        attr("name", layer.into()),
        attr("hash", "MurmurHash3_32".into()),
        attr("conversion", "uint32_to_float32".into()),
        attr("manifest", manifest(names, ids)),
    ]
}

/// The manifest: a JSON object from each name to its id's bits in hexadecimal, in the order
/// of the names' bytes, each name once (as a `serde_json::Map` writes it, without a map of
/// 100,000 entries on the way).
fn manifest(names: &[String], ids: &[f32]) -> String {
    use std::io::Write as _;
    let mut pairs: Vec<(&str, u32)> = names
        .iter()
        .map(String::as_str)
        .zip(ids[1..].iter().map(|i| i.to_bits()))
        .collect();
    // One name has one id, so which of its entries is kept does not matter.
    pairs.sort_unstable_by(|a, b| a.0.cmp(b.0));
    pairs.dedup_by(|a, b| a.0 == b.0);
    let mut json = Vec::with_capacity(pairs.iter().map(|p| p.0.len() + 14).sum::<usize>() + 2);
    json.push(b'{');
    for (k, (name, bits)) in pairs.iter().enumerate() {
        if k > 0 {
            json.push(b',');
        }
        serde_json::to_writer(&mut json, name).expect("a string is written to memory");
        write!(json, ":\"{bits:08x}\"").expect("written to memory");
    }
    json.push(b'}');
    String::from_utf8(json).expect("JSON of UTF-8 names")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The manifest is the JSON a `serde_json::Map` of the names writes, byte for byte: names
    /// in byte order, escaped, each once.
    #[test]
    fn the_manifest_is_serde_jsons() {
        let names: Vec<String> = [
            "cube",
            "floor",
            "a \"quoted\" \\ name",
            "tab\there",
            "\u{1}",
            "雪",
            "cube",
            "",
            "Zed",
            "zed",
            "é",
        ]
        .map(String::from)
        .to_vec();
        let ids = id_table(&names);
        let map: serde_json::Map<String, serde_json::Value> = names
            .iter()
            .zip(&ids[1..])
            .map(|(n, i)| (n.clone(), format!("{:08x}", i.to_bits()).into()))
            .collect();
        assert_eq!(
            manifest(&names, &ids),
            serde_json::Value::Object(map).to_string()
        );
        assert_eq!(manifest(&[], &[0.0]), "{}");
    }

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
