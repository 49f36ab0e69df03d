//! The picked trees as state: the pixels whose trees are shown, in the order they were
//! picked, each with its tint; stepping through them; how each is drawn (the selected one
//! strong, the others faint); and the rectangle grid's density and depth.

use crate::scene_view::{Strength, TreeLook, tree_tint};

/// One picked pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Entry {
    pub pixel: [u32; 2],
    /// Its tint's number ([`tree_tint`]), kept while it is picked.
    pub tint: usize,
    /// Picked by a rectangle's grid: drawn faint only to the grid's depth.
    pub from_grid: bool,
}

/// The rectangle grid's settings: trees per side and the depth their faint trees are drawn to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    /// At most this many pixels across and down.
    pub per_side: u32,
    /// Faint grid trees are drawn down to this generation (the selected one whole).
    pub depth: u32,
}

/// The most pixels a rectangle's grid takes across or down.
pub const MAX_GRID_SIDE: u32 = 8;

impl Default for Grid {
    /// 4 × 4 trees to generation 2: sixteen trees leave the image readable, where 8 × 8 at full
    /// depth hid it.
    fn default() -> Self {
        Self {
            per_side: 4,
            depth: 2,
        }
    }
}

/// The picked pixels, in picking order, and the grid's settings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Picker {
    pub entries: Vec<Entry>,
    pub grid: Grid,
    /// The last rectangle gridded (image pixels), so a new density grids it again.
    pub last_rect: Option<([u32; 2], [u32; 2])>,
    /// Whether the strip lists every entry (else one line with the selected one).
    pub expanded: bool,
}

impl Picker {
    /// Adds `pixel`, with the first tint no entry wears (the palette repeats when all do).
    pub fn push(&mut self, pixel: [u32; 2], from_grid: bool) {
        let n = crate::scene_view::TREE_TINTS.len();
        let tint = (0..n)
            .find(|t| self.entries.iter().all(|e| e.tint != *t))
            .unwrap_or(self.entries.len() % n);
        self.entries.push(Entry {
            pixel,
            tint,
            from_grid,
        });
    }

    /// Where `pixel` is in the list.
    pub fn index_of(&self, pixel: [u32; 2]) -> Option<usize> {
        self.entries.iter().position(|e| e.pixel == pixel)
    }

    /// The entry of `pixel`.
    pub fn entry(&self, pixel: [u32; 2]) -> Option<&Entry> {
        self.entries.iter().find(|e| e.pixel == pixel)
    }

    /// The entries follow the trees shown (`pixels`): an entry whose tree went is dropped, a
    /// tree without an entry gets one at the end; the order and tints of the rest stay.
    pub fn follow(&mut self, pixels: &[[u32; 2]]) {
        let mut left: Vec<[u32; 2]> = pixels.to_vec();
        self.entries
            .retain(|e| match left.iter().position(|p| *p == e.pixel) {
                Some(i) => {
                    left.swap_remove(i);
                    true
                }
                None => false,
            });
        for p in pixels {
            if let Some(i) = left.iter().position(|q| q == p) {
                left.swap_remove(i);
                self.push(*p, false);
            }
        }
    }

    /// The entry `delta` places from `from` in the list, held at its ends.
    pub fn step(&self, from: [u32; 2], delta: isize) -> Option<[u32; 2]> {
        let last = self.entries.len().checked_sub(1)?;
        let i = self.index_of(from).unwrap_or(0);
        let to = (i as isize + delta).clamp(0, last as isize) as usize;
        Some(self.entries[to].pixel)
    }

    /// How the tree of `pixel` is drawn when `current` is the selected one, and the generation
    /// it is drawn down to (`None`: as the filter says).
    pub fn look(&self, pixel: [u32; 2], current: Option<[u32; 2]>) -> (TreeLook, Option<u32>) {
        let entry = self.entry(pixel);
        let tint = tree_tint(entry.map_or(0, |e| e.tint));
        if current == Some(pixel) {
            let look = TreeLook {
                tint,
                strength: Strength::Strong,
            };
            return (look, None);
        }
        let depth = entry.filter(|e| e.from_grid).map(|_| self.grid.depth);
        let look = TreeLook {
            tint,
            strength: Strength::Faint,
        };
        (look, depth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_keep_their_order_and_tints_and_follow_the_trees() {
        let mut p = Picker::default();
        for (i, px) in [[1, 1], [2, 2], [3, 3]].into_iter().enumerate() {
            p.push(px, i == 2);
        }
        assert_eq!(
            p.entries.iter().map(|e| e.tint).collect::<Vec<_>>(),
            [0, 1, 2]
        );
        // A tree went and another came: the rest keep their place and tint, the new one
        // takes the first free tint.
        p.follow(&[[3, 3], [9, 9], [1, 1]]);
        let got: Vec<_> = p.entries.iter().map(|e| (e.pixel, e.tint)).collect();
        assert_eq!(got, [([1, 1], 0), ([3, 3], 2), ([9, 9], 1)]);
        // Stepping is held at the ends.
        assert_eq!(p.step([1, 1], 1), Some([3, 3]));
        assert_eq!(p.step([3, 3], 1), Some([9, 9]));
        assert_eq!(p.step([9, 9], 1), Some([9, 9]));
        assert_eq!(p.step([1, 1], -1), Some([1, 1]));
        assert_eq!(Picker::default().step([0, 0], 1), None);
    }

    #[test]
    fn the_selected_tree_is_strong_and_grid_trees_faint_to_the_grid_depth() {
        let mut p = Picker::default();
        p.push([1, 1], false);
        p.push([2, 2], true);
        let (look, depth) = p.look([2, 2], Some([2, 2]));
        assert_eq!((look.strength, depth), (Strength::Strong, None));
        assert_eq!(look.tint, tree_tint(1));
        let (look, depth) = p.look([2, 2], Some([1, 1]));
        assert_eq!((look.strength, depth), (Strength::Faint, Some(2)));
        // A shift-clicked tree is faint but whole.
        let (look, depth) = p.look([1, 1], Some([2, 2]));
        assert_eq!((look.strength, depth), (Strength::Faint, None));
        assert_eq!(
            Grid::default(),
            Grid {
                per_side: 4,
                depth: 2
            }
        );
    }
}
