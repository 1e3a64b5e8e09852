//! Textures: a colour that varies over a surface, named by a material's `color` or `emission`
//! (`[[texture]]`). A checker alternates two colours in cubes laid out in the rest frame of the
//! object's group, so the pattern moves and deforms with the object exactly as its geometry does.

use crate::spectrum::Colour;
use glam::DVec3;

/// A colour that varies over a surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Texture {
    /// Boxes of `size` (0 along an axis: no change along it) alternating between two colours,
    /// in the group's rest frame; the box from the origin toward +x, +y, +z has the first.
    Checker {
        /// The boxes' sides along x, y and z (0: no change along that axis).
        size: DVec3,
        /// The colour of the box at the origin, and the other.
        colors: [Colour; 2],
    },
}

impl Texture {
    /// The colour at rest-frame point `p` of a surface whose outward normal there is
    /// `outward`. A checker is read just inside the surface (by a billionth of its smallest
    /// square): a face lying on a boundary between squares, as a box's faces do on a grid of
    /// its own size, takes the colour of the square behind it, not the one rounding picks.
    #[inline]
    pub fn colour_at(&self, p: DVec3, outward: DVec3) -> &Colour {
        match self {
            Texture::Checker { size, colors } => {
                let smallest = [size.x, size.y, size.z]
                    .into_iter()
                    .filter(|&s| s > 0.0)
                    .fold(f64::INFINITY, f64::min);
                let inside = p - outward * (1e-9 * smallest);
                &colors[checker_cell(*size, inside)]
            }
        }
    }

    /// Every colour the texture may give.
    pub fn colours(&self) -> impl Iterator<Item = &Colour> {
        match self {
            Texture::Checker { colors, .. } => colors.iter(),
        }
    }
}

/// Which of a checker's two colours lies at `p`: the parity of the sum of its cell indices
/// along the axes whose size is not 0.
#[inline]
fn checker_cell(size: DVec3, p: DVec3) -> usize {
    let mut sum = 0i64;
    for k in 0..3 {
        if size[k] > 0.0 {
            sum += (p[k] / size[k]).floor() as i64;
        }
    }
    sum.rem_euclid(2) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_cells_alternate() {
        let s = DVec3::new(0.5, 0.5, 0.0);
        assert_eq!(checker_cell(s, DVec3::new(0.1, 0.1, 7.0)), 0);
        assert_eq!(checker_cell(s, DVec3::new(0.6, 0.1, -3.0)), 1);
        assert_eq!(checker_cell(s, DVec3::new(0.6, 0.6, 0.0)), 0);
        assert_eq!(checker_cell(s, DVec3::new(-0.1, 0.1, 0.0)), 1);
        assert_eq!(checker_cell(s, DVec3::new(-0.1, -0.1, 0.0)), 0);
        assert_eq!(
            checker_cell(DVec3::splat(1.0), DVec3::new(0.5, 0.5, 1.5)),
            1
        );
    }
}
