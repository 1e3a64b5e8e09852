//! Which passes an EXR holds beside colour and alpha (`[image] passes`, `--passes`): a set of
//! named passes. The names are the scene format's; what channels each pass writes is the
//! output's business (`output/exr_out.rs`).

use std::fmt;

/// A pass an EXR may hold beside colour and alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Distance along the camera's look axis to the emission event.
    Depth,
    /// How long before the imaging event the light left the surface.
    Lookback,
    /// The Doppler factor of the primary hit.
    Doppler,
    /// 1 + the index of the object hit.
    ObjectId,
    /// 1 + the index of the material hit.
    MaterialId,
    /// 1 + the index of the primitive hit among its object's.
    PrimitiveId,
    /// The surface normal in the surface's rest frame.
    Normal,
    /// The emission event's position in the world frame.
    Position,
    /// The same point in its group's rest frame.
    RestPosition,
    /// The emission event relative to the camera, on the camera's axes.
    CameraPosition,
    /// Cryptomatte mattes of objects and materials.
    Cryptomatte,
}

impl Pass {
    /// Every pass, in the order the names are listed.
    pub const ALL: [Pass; 11] = [
        Pass::Depth,
        Pass::Lookback,
        Pass::Doppler,
        Pass::ObjectId,
        Pass::MaterialId,
        Pass::PrimitiveId,
        Pass::Normal,
        Pass::Position,
        Pass::RestPosition,
        Pass::CameraPosition,
        Pass::Cryptomatte,
    ];

    /// The pass's name in the scene format and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Pass::Depth => "depth",
            Pass::Lookback => "lookback",
            Pass::Doppler => "doppler",
            Pass::ObjectId => "object_id",
            Pass::MaterialId => "material_id",
            Pass::PrimitiveId => "primitive_id",
            Pass::Normal => "normal",
            Pass::Position => "position",
            Pass::RestPosition => "rest_position",
            Pass::CameraPosition => "camera_position",
            Pass::Cryptomatte => "cryptomatte",
        }
    }

    fn bit(self) -> u16 {
        1 << Pass::ALL.iter().position(|&p| p == self).expect("listed")
    }
}

/// Names that stand for several passes.
pub(crate) const SHORTHANDS: [(&str, &[Pass]); 4] = [
    ("all", &Pass::ALL),
    ("none", &[]),
    (
        "ids",
        &[Pass::ObjectId, Pass::MaterialId, Pass::PrimitiveId],
    ),
    ("relativity", &[Pass::Lookback, Pass::Doppler]),
];

/// A set of passes; colour and alpha are always written and are not in it.
#[derive(Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub struct PassSet(u16);

impl PassSet {
    /// Every pass (the default).
    pub const ALL: PassSet = PassSet((1 << Pass::ALL.len()) - 1);
    /// No pass: colour and alpha alone.
    pub const NONE: PassSet = PassSet(0);

    /// Whether the set holds `pass`.
    pub fn has(self, pass: Pass) -> bool {
        self.0 & pass.bit() != 0
    }

    /// Whether the set is empty (colour and alpha alone).
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The set with `pass` added.
    pub fn with(self, pass: Pass) -> PassSet {
        PassSet(self.0 | pass.bit())
    }

    /// The set of the passes `names` name (a pass's name or a shorthand), or the first name
    /// that names nothing.
    pub fn from_names<'a>(names: impl IntoIterator<Item = &'a str>) -> Result<PassSet, &'a str> {
        let mut set = PassSet::NONE;
        for name in names {
            if let Some(p) = Pass::ALL.iter().find(|p| p.name() == name) {
                set = set.with(*p);
            } else if let Some((_, passes)) = SHORTHANDS.iter().find(|(n, _)| *n == name) {
                set = passes.iter().fold(set, |s, &p| s.with(p));
            } else {
                return Err(name);
            }
        }
        Ok(set)
    }

    /// Every name a list may hold, for messages.
    pub fn accepted() -> String {
        let names: Vec<&str> = Pass::ALL
            .iter()
            .map(|p| p.name())
            .chain(SHORTHANDS.iter().map(|(n, _)| *n))
            .collect();
        names.join(", ")
    }

    /// The passes in the set, in [`Pass::ALL`]'s order.
    pub fn passes(self) -> impl Iterator<Item = Pass> {
        Pass::ALL.into_iter().filter(move |&p| self.has(p))
    }
}

impl Default for PassSet {
    fn default() -> PassSet {
        PassSet::ALL
    }
}

/// As a list of names (what messages show).
impl fmt::Debug for PassSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list()
            .entries(self.passes().map(Pass::name))
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_shorthands_make_sets() {
        let s = PassSet::from_names(["depth", "ids"]).unwrap();
        assert!(s.has(Pass::Depth) && s.has(Pass::ObjectId) && s.has(Pass::PrimitiveId));
        assert!(!s.has(Pass::Lookback) && !s.has(Pass::Cryptomatte));
        assert_eq!(PassSet::from_names(["all"]).unwrap(), PassSet::ALL);
        assert_eq!(PassSet::from_names([]).unwrap(), PassSet::NONE);
        assert_eq!(PassSet::from_names(["none"]).unwrap(), PassSet::NONE);
        assert!(PassSet::from_names(["lookback", "dopler"]) == Err("dopler"));
        assert_eq!(PassSet::ALL.passes().count(), Pass::ALL.len());
        assert_eq!(
            format!("{:?}", PassSet::from_names(["relativity"]).unwrap()),
            r#"["lookback", "doppler"]"#
        );
    }
}
