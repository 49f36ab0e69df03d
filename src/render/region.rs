//! Rendering part of an image, for a render spread over machines: a rectangle of the full
//! image (`raytree render --region`), or part I of N (`--tile I/N`), an even split into row
//! bands that `raytree merge` puts back together.
//!
//! A pixel's samples are keyed by its coordinates in the full image (the camera frame is the
//! full image's, [`crate::scene::primary_ray`] takes global x and y), so a pixel rendered in a
//! part is bit for bit the same pixel of the full render.

use super::{Image, Rect, RenderError, RenderStats, trace_tile};
use crate::trace::Tracer;

/// A region or tile that does not fit the image: one sentence.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum RegionError {
    #[error(
        "the region {x},{y},{w},{h} is empty: its width and height must be at least 1",
        x = .0.x, y = .0.y, w = .0.width, h = .0.height
    )]
    Empty(Rect),
    #[error(
        "the region {x},{y},{w},{h} reaches outside the {iw}x{ih} image (it must lie within \
         0..{iw} across and 0..{ih} down)",
        x = .0.x, y = .0.y, w = .0.width, h = .0.height, iw = .1, ih = .2
    )]
    Outside(Rect, u32, u32),
    #[error("tile {0}/{1} does not exist: tiles are numbered 0 to {max} of {1}", max = .1.saturating_sub(1))]
    TileIndex(u32, u32),
    #[error("cannot split the {0}-row image into {1} tiles: at most one tile a row")]
    TooManyTiles(u32, u32),
}

/// The whole `width × height` image as a rectangle.
pub fn full(width: u32, height: u32) -> Rect {
    Rect {
        x: 0,
        y: 0,
        width,
        height,
    }
}

/// Checks that `region` is non-empty and lies inside a `width × height` image.
pub fn check_region(region: Rect, width: u32, height: u32) -> Result<Rect, RegionError> {
    if region.width == 0 || region.height == 0 {
        return Err(RegionError::Empty(region));
    }
    let right = u64::from(region.x) + u64::from(region.width);
    let bottom = u64::from(region.y) + u64::from(region.height);
    if right > u64::from(width) || bottom > u64::from(height) {
        return Err(RegionError::Outside(region, width, height));
    }
    Ok(region)
}

/// Tile `index` of `count` (0-based) of a `width × height` image: the row band from row
/// `⌊index·height/count⌋` to the next tile's first row, full width. The bands cover the image
/// once and differ in height by at most one row.
pub fn tile_rect(width: u32, height: u32, index: u32, count: u32) -> Result<Rect, RegionError> {
    if count == 0 || index >= count {
        return Err(RegionError::TileIndex(index, count));
    }
    if count > height {
        return Err(RegionError::TooManyTiles(height, count));
    }
    let row = |i: u32| (u64::from(i) * u64::from(height) / u64::from(count)) as u32;
    let (top, bottom) = (row(index), row(index + 1));
    Ok(Rect {
        x: 0,
        y: top,
        width,
        height: bottom - top,
    })
}

/// Renders the pixels of `region` (inside the tracer's `[render]` size) with `samples` samples
/// per pixel on `threads` threads (0: all cores): an image of the region's size whose pixels
/// equal, bit for bit, the same pixels of [`super::render`]'s full image. `progress` gets
/// (pixels done, pixels in the region). The statistics' width and height are the region's.
pub fn render_region(
    tracer: &Tracer,
    region: Rect,
    samples: u32,
    threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Image, RenderStats), RenderError> {
    super::render_part_with(tracer, region, samples, threads, progress, &trace_tile)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_are_even_row_bands_covering_once() {
        for (h, n) in [(100, 4), (101, 4), (7, 7), (1000, 3), (5, 1)] {
            let mut next = 0;
            for i in 0..n {
                let r = tile_rect(64, h, i, n).expect("tile");
                assert_eq!((r.x, r.width, r.y), (0, 64, next), "{h} rows, tile {i}/{n}");
                assert!(r.height == h / n || r.height == h / n + 1);
                next += r.height;
            }
            assert_eq!(next, h);
        }
        assert_eq!(tile_rect(64, 10, 4, 4), Err(RegionError::TileIndex(4, 4)));
        assert_eq!(tile_rect(64, 10, 0, 0), Err(RegionError::TileIndex(0, 0)));
        assert_eq!(tile_rect(64, 3, 0, 4), Err(RegionError::TooManyTiles(3, 4)));
    }

    #[test]
    fn regions_outside_or_empty_are_refused() {
        let r = |x, y, width, height| Rect {
            x,
            y,
            width,
            height,
        };
        assert!(check_region(r(0, 0, 10, 10), 10, 10).is_ok());
        assert!(check_region(r(9, 9, 1, 1), 10, 10).is_ok());
        assert!(matches!(
            check_region(r(5, 0, 6, 10), 10, 10),
            Err(RegionError::Outside(..))
        ));
        assert!(matches!(
            check_region(r(u32::MAX, 0, 2, 1), 10, 10),
            Err(RegionError::Outside(..))
        ));
        assert!(matches!(
            check_region(r(0, 0, 0, 3), 10, 10),
            Err(RegionError::Empty(..))
        ));
        let text = check_region(r(5, 0, 6, 10), 10, 10)
            .expect_err("outside")
            .to_string();
        assert_eq!(
            text,
            "the region 5,0,6,10 reaches outside the 10x10 image (it must lie within 0..10 \
             across and 0..10 down)"
        );
    }
}
