//! The workspace of panes (egui_tiles): the render view, the scene view, the tree diagram and
//! the tree list with its detail, resizable, hideable (View menu) and re-dockable by dragging
//! their tabs. The render has the left of the workspace to itself; the scene view and the
//! tree's panes share a column on the right, so the tree's panes, which open when a pixel is
//! clicked, never move or shrink the render. The layout is part of [`super::Prefs`], so it is
//! remembered between runs; a saved layout that lacks a pane or holds one twice, or grew from
//! an older default, is replaced by the default.

use eframe::egui::{self, Ui};
use egui_tiles::{Behavior, Linear, LinearDir, SimplificationOptions, Tile, TileId};
use serde::{Deserialize, Serialize};

use super::ViewerApp;

/// One pane of the workspace.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Pane {
    Render,
    SceneView,
    Diagram,
    TreeList,
}

impl Pane {
    pub const ALL: [Pane; 4] = [Pane::Render, Pane::SceneView, Pane::Diagram, Pane::TreeList];

    pub fn title(self) -> &'static str {
        match self {
            Pane::Render => "Render",
            Pane::SceneView => "Scene view",
            Pane::Diagram => "Ray tree diagram",
            Pane::TreeList => "Ray tree",
        }
    }
}

pub type Layout = egui_tiles::Tree<Pane>;

/// The version of [`default_layout`]: a saved layout of another version is replaced.
pub const LAYOUT_VERSION: u32 = 3;

/// The render pane's share of the workspace's width in the default layout.
pub const RENDER_SHARE: f32 = 0.74;

/// The scene view's share of the right column's height once the tree's pane is open: the
/// larger part, as the 3D view is where a tree is read in space.
pub const SCENE_SHARE: f32 = 0.55;

fn tabs(tiles: &mut egui_tiles::Tiles<Pane>, pane: Pane) -> TileId {
    let id = tiles.insert_pane(pane);
    tiles.insert_tab_tile(vec![id])
}

/// The render view on the left ([`RENDER_SHARE`] of the width); on the right the scene view
/// above and the tree's diagram and list below, as two tabs of one pane (the diagram in front).
pub fn default_layout() -> Layout {
    let mut tiles = egui_tiles::Tiles::default();
    let render = tabs(&mut tiles, Pane::Render);
    let scene = tabs(&mut tiles, Pane::SceneView);
    let diagram = tiles.insert_pane(Pane::Diagram);
    let list = tiles.insert_pane(Pane::TreeList);
    let tree = tiles.insert_tab_tile(vec![diagram, list]);
    let right = tiles.insert_container(Linear::new_binary(
        LinearDir::Vertical,
        [scene, tree],
        SCENE_SHARE,
    ));
    let root = tiles.insert_container(Linear::new_binary(
        LinearDir::Horizontal,
        [render, right],
        RENDER_SHARE,
    ));
    egui_tiles::Tree::new(egui::Id::unique("raytree workspace"), root, tiles)
}

/// Whether `layout` can be used: a root, and every pane exactly once.
pub fn usable(layout: &Layout) -> bool {
    layout.root().is_some()
        && Pane::ALL.iter().all(|p| {
            layout
                .tiles
                .tiles()
                .filter(|t| matches!(t, Tile::Pane(q) if q == p))
                .count()
                == 1
        })
}

/// The tile of `pane`.
pub fn tile_of(layout: &Layout, pane: Pane) -> Option<TileId> {
    layout.tiles.find_pane(&pane)
}

/// Opens the tree's panes (diagram, list) when a tree appears and closes them when it goes,
/// so that before any click the render and scene views share the whole workspace. Only the
/// change is acted on: a pane hidden or shown from the View menu stays so meanwhile.
fn follow_tree(app: &mut ViewerApp) {
    let want = app.tree.is_some();
    if app.tree_panes_shown == Some(want) {
        return;
    }
    app.tree_panes_shown = Some(want);
    for pane in [Pane::Diagram, Pane::TreeList] {
        if let Some(id) = tile_of(&app.prefs.layout, pane) {
            app.prefs.layout.tiles.set_visible(id, want);
        }
    }
}

/// Draws what a pane shows.
pub type PaneUi = fn(&mut ViewerApp, &mut Ui, Pane);

/// Draws the panes of `app`'s layout into `ui`, each by `pane_ui`.
pub fn show(app: &mut ViewerApp, ui: &mut Ui, pane_ui: PaneUi) {
    if !usable(&app.prefs.layout) {
        app.prefs.layout = default_layout();
        app.tree_panes_shown = None;
    }
    follow_tree(app);
    let mut layout = std::mem::replace(
        &mut app.prefs.layout,
        egui_tiles::Tree::empty(egui::Id::unique("none")),
    );
    layout.ui(&mut Panes { app, pane_ui }, ui);
    app.prefs.layout = layout;
}

/// A checkbox per pane, to hide or show it (View menu).
pub fn pane_toggles(app: &mut ViewerApp, ui: &mut Ui) {
    for pane in Pane::ALL {
        if let Some(id) = tile_of(&app.prefs.layout, pane) {
            let mut visible = app.prefs.layout.tiles.is_visible(id);
            if ui.checkbox(&mut visible, pane.title()).changed() {
                app.prefs.layout.tiles.set_visible(id, visible);
            }
        }
    }
    let mut settings = app.prefs.settings_panel;
    if ui
        .checkbox(&mut settings, "Settings panel (Ctrl+B)")
        .changed()
    {
        app.toggle_settings_panel();
    }
    if ui.button("Reset layout").clicked() {
        app.prefs.layout = default_layout();
        app.prefs.settings_panel = true;
        app.tree_panes_shown = None;
    }
}

struct Panes<'a> {
    app: &'a mut ViewerApp,
    pane_ui: PaneUi,
}

impl Behavior<Pane> for Panes<'_> {
    fn pane_ui(&mut self, ui: &mut Ui, _id: TileId, pane: &mut Pane) -> egui_tiles::UiResponse {
        (self.pane_ui)(self.app, ui, *pane);
        egui_tiles::UiResponse::None
    }

    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().into()
    }

    fn simplification_options(&self) -> SimplificationOptions {
        // Every pane keeps its tab: the handle it is dragged and re-docked by.
        SimplificationOptions {
            all_panes_must_have_tabs: true,
            ..SimplificationOptions::default()
        }
    }

    fn min_size(&self) -> f32 {
        60.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_layout_is_usable_and_survives_a_round_trip() {
        let layout = default_layout();
        assert!(usable(&layout));
        let json = serde_json::to_string(&layout).expect("serialises");
        let back: Layout = serde_json::from_str(&json).expect("deserialises");
        assert!(usable(&back));
        assert!(!usable(&egui_tiles::Tree::empty(egui::Id::unique("x"))));
    }
}
