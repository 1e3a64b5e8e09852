//! `--tiles NxM --tile I`: one tile of a grid over the image, rendered as a crop into an EXR
//! that knows its place (its data window inside the full display window), for
//! `rest-embree assemble` to join with the others.

use crate::{output, scene, Error};

/// The crop of tile `index` of `grid` over `scene`'s image, or why `scene` and `format` cannot
/// be tiled (tiles divide a still's whole image and are EXRs); `shown` names the flags.
pub(super) fn tile_crop(
    scene: &scene::Scene,
    format: output::Format,
    grid: (u32, u32),
    index: u32,
    shown: &str,
) -> crate::Result<[u32; 4]> {
    let why = if format != output::Format::Exr {
        Some("tiles are EXRs, assembled by `rest-embree assemble`: give -o a .exr")
    } else if scene.image.crop.is_some() {
        Some("the scene has an [image] crop already; tiles divide the whole image")
    } else if scene.film.is_some() {
        Some("tiles divide a still; the scene is a film (its frames are rendered one per task)")
    } else {
        None
    };
    if let Some(why) = why {
        return Err(Error::flag(shown, why));
    }
    let size = (scene.image.width, scene.image.height);
    let c = crop(size, grid, index).map_err(|m| Error::flag(shown, m))?;
    // Every tile of the grid must be one render's frame, not only this one: the grid is
    // refused as a whole, by any of its tasks and before a farm submits it.
    let (tw, th) = (size.0.div_ceil(grid.0), size.1.div_ceil(grid.1));
    if u64::from(tw) * u64::from(th) > scene::MAX_FRAME_PIXELS {
        return Err(Error::flag(
            shown,
            format!(
                "tiles of the {}x{} image in a {}x{} grid are up to {tw}x{th}, too large for \
                 one render (at most 2^28 pixels): use a finer grid",
                size.0, size.1, grid.0, grid.1
            ),
        ));
    }
    Ok(c)
}

/// `NxM`: N columns, M rows.
pub(super) fn parse_grid(text: &str) -> Result<(u32, u32), String> {
    let (a, b) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{text}` is not a grid: give columns x rows, e.g. 2x2"))?;
    let count = |t: &str| match t.trim().parse::<u64>() {
        Ok(n) if n >= 1 => u32::try_from(n).map_err(|_| {
            format!(
                "`{t}` in `{text}` is more tiles than an image has pixels (at most {} a side)",
                u32::MAX
            )
        }),
        _ => Err(format!(
            "`{t}` in `{text}` is not a count of tiles (1 or more)"
        )),
    };
    Ok((count(a)?, count(b)?))
}

/// The crop `[x, y, w, h]` of tile `index` (row by row from the top left, from 0) of a grid of
/// `columns x rows` over a `width x height` image: column c spans pixels
/// `c·width/columns .. (c+1)·width/columns`, rows alike.
pub(super) fn crop(
    (width, height): (u32, u32),
    (columns, rows): (u32, u32),
    index: u32,
) -> crate::Result<[u32; 4]> {
    if columns > width || rows > height {
        return Err(Error::invalid(format!(
            "a grid of {columns}x{rows} tiles does not fit a {width}x{height} image (a tile is at least one pixel)"
        )));
    }
    let tiles = u64::from(columns) * u64::from(rows);
    if u64::from(index) >= tiles {
        return Err(Error::invalid(format!(
            "tile {index} is not in a {columns}x{rows} grid: tiles are 0..{}",
            tiles - 1
        )));
    }
    let edge = |i: u32, n: u32, size: u32| (u64::from(i) * u64::from(size) / u64::from(n)) as u32;
    let (c, r) = (index % columns, index / columns);
    let (x0, x1) = (edge(c, columns, width), edge(c + 1, columns, width));
    let (y0, y1) = (edge(r, rows, height), edge(r + 1, rows, height));
    Ok([x0, y0, x1 - x0, y1 - y0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        for (size, grid) in [((7, 5), (3, 2)), ((64, 48), (2, 2)), ((5, 5), (5, 5))] {
            let mut seen = vec![0u8; (size.0 * size.1) as usize];
            for i in 0..grid.0 * grid.1 {
                let [x, y, w, h] = crop(size, grid, i).unwrap();
                assert!(w >= 1 && h >= 1);
                for yy in y..y + h {
                    for xx in x..x + w {
                        seen[(yy * size.0 + xx) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{size:?} {grid:?}");
        }
        assert!(crop((4, 4), (5, 1), 0).is_err());
        assert!(crop((4, 4), (2, 2), 4).is_err());
        assert_eq!(parse_grid("3x2"), Ok((3, 2)));
        assert!(parse_grid("0x2").is_err() && parse_grid("2").is_err());
    }
}
