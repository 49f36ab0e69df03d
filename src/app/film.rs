//! The viewer's film: per pixel, the linear colour the latest tiles left and the sample-0 facts
//! ([`SampleInfo`]) the image modes show; writing a tile into it and into the display buffer as
//! the current image mode colours it.

use glam::Vec3;

use super::modes::{ImageMode, mode_color};
use super::viewport::DisplayState;
use crate::render::session::{Pass, TileUpdate};
use crate::render::{Image, Rect};
use crate::scene_view::occlusion::DepthImage;
use crate::scene_view::outline::{Seen, lift, on_outline};
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
    /// Whether the render is drawn with the scene view's outlines
    /// ([`crate::scene_view::outline`]).
    outlined: bool,
    /// Whether a pixel's facts are its own sample 0's (not yet, or a preview block's, when
    /// false): outlines are drawn only between such pixels.
    own_facts: Vec<bool>,
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
            outlined: false,
            own_facts: vec![false; n],
        }
    }

    /// [`Film::new`] for the scene view: the render drawn with outlines.
    pub fn outlined(width: u32, height: u32) -> Self {
        Self {
            outlined: true,
            ..Self::new(width, height)
        }
    }

    /// Starts over, black, at a new size; the same size keeps the film as it is, so a restart
    /// shows the old image until the new tiles cover it.
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) != (self.width, self.height) {
            *self = Self {
                outlined: self.outlined,
                ..Self::new(width, height)
            };
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

    /// What pixel (`x`, `y`)'s centre ray met, as far as the film knows it.
    fn seen(&self, x: u32, y: u32) -> Seen {
        let i = (y * self.width + x) as usize;
        if self.own_facts[i] {
            Seen::of(self.aux[i].hit_t, self.aux[i].normal)
        } else {
            Seen::Unknown
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
        let own = tile.pass != Pass::Preview;
        for j in 0..r.height {
            for i in 0..r.width {
                let src = (j * r.width + i) as usize;
                let dst = ((r.y + j) * self.width + r.x + i) as usize;
                self.beauty[dst] = tile.pixels[src];
                if let Some(aux) = &tile.aux {
                    self.aux[dst] = aux[src];
                    self.own_facts[dst] = own;
                }
            }
        }
        // An outline depends on the neighbours' facts: the pixels around the tile are drawn
        // again with it.
        let grow = u32::from(self.outlined && tile.aux.is_some());
        let (x0, y0) = (r.x.saturating_sub(grow), r.y.saturating_sub(grow));
        let x1 = (r.x + r.width + grow).min(self.width);
        let y1 = (r.y + r.height + grow).min(self.height);
        for y in y0..y1 {
            for x in x0..x1 {
                let dst = (y * self.width + x) as usize;
                display.rgba[dst] = self.display_rgba(dst, mode, max_depth);
            }
        }
        display.mark(Rect {
            x: x0,
            y: y0,
            width: x1 - x0,
            height: y1 - y0,
        });
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
            let (x, y) = (i as u32 % self.width, i as u32 / self.width);
            if self.outlined && on_outline(self.width, self.height, x, y, |x, y| self.seen(x, y)) {
                lift(self.beauty[i])
            } else {
                self.beauty[i]
            }
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

    /// A black 4×3 film of the scene view, a black surface at distance 2 in its left two
    /// columns and the background in the right ones, written as two 2×3 tiles of `pass`.
    fn outlined_film(pass: Pass) -> (Film, DisplayState) {
        let mut film = Film::outlined(4, 3);
        let mut display = DisplayState::new(4, 3);
        for x in [0, 2] {
            let hit = |column: u32| SampleInfo {
                hit_t: if column < 2 { 2.0 } else { f32::INFINITY },
                normal: Vec3::Z,
                ..SampleInfo::default()
            };
            let tile = TileUpdate {
                generation: 1,
                pass,
                rect: Rect {
                    x,
                    y: 0,
                    width: 2,
                    height: 3,
                },
                pixels: vec![Vec3::ZERO; 6],
                aux: Some((0..6).map(|i| hit(x + i % 2)).collect()),
            };
            film.write_tile(&tile, ImageMode::Render, 0, &mut display);
        }
        (film, display)
    }

    #[test]
    fn the_scene_views_film_outlines_a_dark_surface_against_the_background() {
        let (film, display) = outlined_film(Pass::Samples(1));
        let level = crate::scene_view::outline::OUTLINE_LEVEL;
        for y in 0..3 {
            for x in 0..4 {
                let [r, g, b, _] = display.rgba[(y * 4 + x) as usize];
                // The surface's column beside the background is outline, drawn when the
                // second tile brought the background: the first tile's edge was drawn again.
                let want = if x == 1 { level } else { 0.0 };
                assert!(
                    (r - want).abs() < 1e-6 && r == g && g == b,
                    "pixel ({x}, {y}): {r}, {g}, {b}"
                );
            }
        }
        // The film keeps the render's own colours: the outline is only drawn.
        assert!(film.image().pixels.iter().all(|&p| p == Vec3::ZERO));
        // A preview's block-filled facts are not the pixels' own: no outline from them, and
        // the render view's film never outlines.
        let (_, preview) = outlined_film(Pass::Preview);
        assert!(preview.rgba.iter().all(|p| p[..3] == [0.0; 3]));
        let mut plain = Film::new(4, 3);
        let mut display = DisplayState::new(4, 3);
        let (outlined, _) = outlined_film(Pass::Samples(1));
        plain.aux = outlined.aux.clone();
        plain.own_facts = outlined.own_facts.clone();
        plain.paint(ImageMode::Render, 0, &mut display);
        assert!(display.rgba.iter().all(|p| p[..3] == [0.0; 3]));
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
        // The scene view's film stays outlined at its new size.
        let mut outlined = Film::outlined(4, 3);
        outlined.resize(2, 2);
        assert_eq!(outlined, Film::outlined(2, 2));
    }
}
