//! The workspace of panes (egui_tiles): the render view, the scene view, the tree diagram and
//! the tree list with its detail, resizable, hideable (View menu) and re-dockable by dragging
//! their tabs. The tree's panes open when a pixel is clicked. The layout is part of [`super::Prefs`], so it is remembered between runs; a saved
//! layout that lacks a pane or holds one twice is replaced by the default.

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

fn tabs(tiles: &mut egui_tiles::Tiles<Pane>, pane: Pane) -> TileId {
    let id = tiles.insert_pane(pane);
    tiles.insert_tab_tile(vec![id])
}

/// Render view and scene view side by side on top (two thirds of the height), the diagram and
/// the tree list below.
pub fn default_layout() -> Layout {
    let mut tiles = egui_tiles::Tiles::default();
    let render = tabs(&mut tiles, Pane::Render);
    let scene = tabs(&mut tiles, Pane::SceneView);
    let diagram = tabs(&mut tiles, Pane::Diagram);
    let list = tabs(&mut tiles, Pane::TreeList);
    let top = tiles.insert_container(Linear::new_binary(
        LinearDir::Horizontal,
        [render, scene],
        0.5,
    ));
    let bottom = tiles.insert_container(Linear::new_binary(
        LinearDir::Horizontal,
        [diagram, list],
        0.55,
    ));
    let root = tiles.insert_container(Linear::new_binary(LinearDir::Vertical, [top, bottom], 0.68));
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
    if ui.button("Default layout").clicked() {
        app.prefs.layout = default_layout();
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
