//! The viewer's film: per pixel, the linear colour the latest tiles left and the sample-0 facts
//! ([`SampleInfo`]) the image modes show; writing a tile into it and into the display buffer as
//! the current image mode colours it.

use glam::Vec3;

use super::modes::{ImageMode, mode_color};
use super::viewport::DisplayState;
use crate::render::session::TileUpdate;
use crate::render::{Image, Rect};
use crate::scene_view::occlusion::DepthImage;
use crate::trace::SampleInfo;

/// The film of one image size; [`Film::resize`] starts it over at another.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: u32,
    height: u32,
    /// Linear colour: the mean of the samples done so far.
    beauty: Vec<Vec3>,
    /// Facts of each pixel's sample 0 (or of its preview block's sample).
    aux: Vec<SampleInfo>,
}

impl Film {
    /// A black `width × height` film.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            beauty: vec![Vec3::ZERO; n],
            aux: vec![SampleInfo::default(); n],
        }
    }

    /// Starts over, black, at a new size; the same size keeps the film as it is, so a restart
    /// shows the old image until the new tiles cover it.
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) != (self.width, self.height) {
            *self = Self::new(width, height);
        }
    }

    /// The colour and sample-0 facts of pixel (`x`, `y`).
    pub fn pixel(&self, x: u32, y: u32) -> (Vec3, SampleInfo) {
        let i = (y * self.width + x) as usize;
        (self.beauty[i], self.aux[i])
    }

    /// Each pixel's distance to the surface its centre ray met (INFINITY where none): the depth
    /// the overlays dim occluded rays with.
    pub fn depth(&self) -> DepthImage {
        DepthImage {
            width: self.width,
            height: self.height,
            t: self.aux.iter().map(|a| a.hit_t).collect(),
        }
    }

    /// The film as an image: the mean of the samples done so far.
    pub fn image(&self) -> Image {
        Image {
            width: self.width,
            height: self.height,
            pixels: self.beauty.clone(),
        }
    }

    /// Whether `rect` lies inside the film (a tile of a render at another size does not).
    pub fn holds(&self, rect: Rect) -> bool {
        u64::from(rect.x) + u64::from(rect.width) <= u64::from(self.width)
            && u64::from(rect.y) + u64::from(rect.height) <= u64::from(self.height)
    }

    /// Writes `tile` into the film (its facts only when it carries them) and its rectangle of
    /// `display` in `mode`'s colours, marking that rectangle for upload.
    pub fn write_tile(
        &mut self,
        tile: &TileUpdate,
        mode: ImageMode,
        max_depth: u32,
        display: &mut DisplayState,
    ) {
        let r = tile.rect;
        for j in 0..r.height {
            for i in 0..r.width {
                let src = (j * r.width + i) as usize;
                let dst = ((r.y + j) * self.width + r.x + i) as usize;
                self.beauty[dst] = tile.pixels[src];
                if let Some(aux) = &tile.aux {
                    self.aux[dst] = aux[src];
                }
                display.rgba[dst] = self.display_rgba(dst, mode, max_depth);
            }
        }
        display.mark(r);
    }

    /// Rewrites every pixel of `display` in `mode`'s colours (the caller marks it for upload
    /// with the display's new parameters).
    pub fn paint(&self, mode: ImageMode, max_depth: u32, display: &mut DisplayState) {
        for (i, px) in display.rgba.iter_mut().enumerate() {
            *px = self.display_rgba(i, mode, max_depth);
        }
    }

    /// What the display shows of pixel `i` in `mode`: the render itself, or the mode's colour
    /// of the pixel's facts.
    fn display_rgba(&self, i: usize, mode: ImageMode, max_depth: u32) -> [f32; 4] {
        let c = if mode == ImageMode::Render {
            self.beauty[i]
        } else {
            mode_color(mode, &self.aux[i], max_depth)
        };
        [c.x, c.y, c.z, 1.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::session::Pass;

    /// A 2×1 tile at (1, 1): colours (1, 2, 3) and (4, 5, 6), facts of depth 1 and 2.
    fn tile(aux: bool) -> TileUpdate {
        let info = |d| SampleInfo {
            depth_reached: d,
            rays: d,
            ..SampleInfo::default()
        };
        TileUpdate {
            generation: 1,
            pass: Pass::Samples(1),
            rect: Rect {
                x: 1,
                y: 1,
                width: 2,
                height: 1,
            },
            pixels: vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)],
            aux: aux.then(|| vec![info(1), info(2)]),
        }
    }

    /// A 4×3 film and display with [`tile`] written in `mode` (max depth 5).
    fn written(mode: ImageMode) -> (Film, DisplayState) {
        let mut film = Film::new(4, 3);
        let mut display = DisplayState::new(4, 3);
        film.write_tile(&tile(true), mode, 5, &mut display);
        (film, display)
    }

    #[test]
    fn a_tile_lands_in_its_rectangle_of_film_and_display() {
        let (film, display) = written(ImageMode::Render);
        assert_eq!(film.pixel(2, 1).0, Vec3::new(4.0, 5.0, 6.0));
        assert_eq!(film.pixel(1, 1).1.depth_reached, 1);
        assert_eq!(display.rgba[4 + 2], [4.0, 5.0, 6.0, 1.0]);
        // Everything outside the rectangle is untouched.
        let image = film.image();
        assert_eq!((image.width, image.height), (4, 3));
        let lit: Vec<usize> = (0..12).filter(|&i| image.pixels[i] != Vec3::ZERO).collect();
        assert_eq!(lit, vec![5, 6]);
        assert_eq!(display.rgba[0], [0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn a_mode_shows_the_facts_and_a_later_pass_keeps_them() {
        let (mut film, mut display) = written(ImageMode::Depth);
        let depth_1 = mode_color(ImageMode::Depth, &film.pixel(1, 1).1, 5);
        assert_eq!(display.rgba[5], [depth_1.x, depth_1.y, depth_1.z, 1.0]);
        // Later passes send colours only: the facts of sample 0 stay.
        let mut later = tile(false);
        later.pixels = vec![Vec3::splat(0.5); 2];
        film.write_tile(&later, ImageMode::Depth, 5, &mut display);
        assert_eq!(
            film.pixel(1, 1),
            (Vec3::splat(0.5), tile(true).aux.expect("facts")[0])
        );
        assert_eq!(display.rgba[5], [depth_1.x, depth_1.y, depth_1.z, 1.0]);
        // Painting in the render mode shows the colours again.
        film.paint(ImageMode::Render, 5, &mut display);
        assert_eq!(display.rgba[5], [0.5, 0.5, 0.5, 1.0]);
    }

    #[test]
    fn resizing_clears_only_at_a_new_size() {
        let (mut film, _) = written(ImageMode::Render);
        let before = film.clone();
        film.resize(4, 3);
        assert_eq!(film, before);
        film.resize(2, 2);
        assert_eq!(film, Film::new(2, 2));
        assert_eq!(film.image().pixels.len(), 4);
    }
}
