//! The workspace of panes (egui_tiles): the render view, the scene view, the tree diagram and
//! the tree list with its detail, resizable, hideable (View menu) and re-dockable by dragging
//! their tabs; and the rest of the window's state around them: the preferences, the settings
//! panel, the file dialog and the windows (help, export, the sweep).
//!
//! The render has the left of the workspace to itself; the scene view and the tree's panes
//! share a column on the right, so the tree's panes, which open when a pixel is clicked, never
//! move or shrink the render. The layout is part of [`Prefs`], so it is
//! remembered between runs; a saved layout that lacks a pane or holds one twice, or grew from
//! an older default, is replaced by the default.

use std::path::{Path, PathBuf};

use eframe::egui::{self, Ui};
use egui_tiles::{Behavior, Linear, LinearDir, SimplificationOptions, Tile, TileId};
use serde::{Deserialize, Serialize};

use super::dialog::{self, BrowseFor, FileBrowser};
use super::messages::Messages;
use super::modes::ImageMode;
use super::sweep::SweepWindow;
use super::viewport::Tonemap;
use super::{Command, ViewerApp};
use crate::scene;

/// UI state kept between runs.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default)]
pub struct Prefs {
    pub exposure: f32,
    pub tonemap: Tonemap,
    pub mode: ImageMode,
    pub last_dir: Option<PathBuf>,
    /// The panes' arrangement (replaced by the default when unusable).
    pub layout: Layout,
    /// Degrees the camera orbits for a drag across the whole image width.
    pub orbit_degrees: f32,
    /// The version of the default layout `layout` grew from: an older one is replaced (the
    /// preferences of a run before versions were kept read as 0).
    #[serde(default)]
    pub layout_version: u32,
    /// Samples per pixel the viewer refines to before it idles (the scene's `samples` is the
    /// batch render's, for export and the command line).
    pub viewer_samples: u32,
    /// Render at the render pane's pixel size (the scene's width and height are kept for
    /// export and saving); off: render at the scene's size.
    pub pane_size: bool,
    /// Whether the settings panel on the left is shown (Ctrl+B).
    pub settings_panel: bool,
}

/// The viewer's default sample target.
pub const VIEWER_SAMPLES: u32 = 64;

/// The narrowest window (points) whose first run shows the settings panel: below it the render
/// would get less than half the window, so the panel starts hidden (Ctrl+B shows it).
pub const SETTINGS_MIN_WIDTH: f32 = 1300.0;

impl Default for Prefs {
    fn default() -> Self {
        Self {
            exposure: 1.0,
            tonemap: Tonemap::Clamp,
            mode: ImageMode::Render,
            last_dir: None,
            layout: default_layout(),
            orbit_degrees: 180.0,
            layout_version: LAYOUT_VERSION,
            viewer_samples: VIEWER_SAMPLES,
            pane_size: true,
            settings_panel: true,
        }
    }
}

impl Prefs {
    /// Saved preferences made usable: a layout of another version replaced, the sample target
    /// within the loader's limits.
    pub fn checked(mut self) -> Self {
        if self.layout_version != LAYOUT_VERSION {
            self.layout = default_layout();
            self.layout_version = LAYOUT_VERSION;
        }
        self.viewer_samples = self.viewer_samples.clamp(1, scene::rules::MAX_SAMPLES);
        self
    }

    /// Samples per pixel the viewer refines to (then it idles).
    pub fn viewer_target(&self) -> u32 {
        self.viewer_samples.max(1)
    }
}

/// Whether the tree's panes were last opened or closed (for want of a tree).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TreePanes {
    Open,
    Closed,
}

/// The window's state around the render: preferences, the settings panel, the file dialog
/// and the windows over the panes.
#[derive(Default)]
pub struct Workspace {
    pub prefs: Prefs,
    /// Whether the settings panel's visibility is settled: by the window's width on the first
    /// frame ([`Workspace::settle_settings_panel`]), or by an explicit choice before it.
    settings_settled: bool,
    /// Whether the window was narrower than [`SETTINGS_MIN_WIDTH`] on the last frame (`None`:
    /// no frame yet).
    was_narrow: Option<bool>,
    /// The settings panel was hidden because the window became narrow, not by the user: it
    /// comes back when the window is wide again, and is saved as shown.
    settings_auto_hidden: bool,
    /// How the tree's panes were last set (`None`: not yet, or the layout was reset).
    tree_panes: Option<TreePanes>,
    /// The workspace's width when the tree's column was last given its room
    /// ([`make_room_for_tree`]); `None`: not yet, or the layout was replaced.
    room_width: Option<f32>,
    pub(super) browser: Option<FileBrowser>,
    pub(super) show_help: bool,
    /// The Ctrl+S window: which picture to export.
    pub(super) export_choice: bool,
    /// The "Speed vs accuracy" window and its background sweep.
    pub sweep: SweepWindow,
    /// Focus on the tree: the arrangement to give back when it ends.
    focus: Option<Arrangement>,
    /// The tree's panes are in their own native window.
    pub popped_out: bool,
    /// The folder of the open scene's file (`None`: a built-in scene), where opening and
    /// saving start.
    pub scene_dir: Option<PathBuf>,
}

/// What focus mode changes and gives back when it ends: the panes' layout and whether the
/// settings panel is shown.
#[derive(Clone, Debug)]
struct Arrangement {
    layout: Layout,
    settings_panel: bool,
}

impl Workspace {
    pub fn new(prefs: Prefs) -> Self {
        Self {
            prefs,
            ..Self::default()
        }
    }

    /// Where the file dialog for `purpose` starts: opening and saving a scene in the open
    /// scene file's folder, exports where the last file was chosen; else the other, else the
    /// current folder.
    pub fn start_dir(&self, purpose: BrowseFor) -> PathBuf {
        let last = self.prefs.last_dir.clone();
        let scene = self.scene_dir.clone();
        let (first, then) = match purpose {
            BrowseFor::Open | BrowseFor::SaveScene | BrowseFor::Lesson => (scene, last),
            _ => (last, scene),
        };
        first
            .or(then)
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("."))
    }

    /// Opens the file dialog for `purpose`, offering `name`.
    pub fn browse(&mut self, purpose: BrowseFor, name: &str) {
        self.browser = Some(FileBrowser::new(purpose, self.start_dir(purpose), name));
    }

    /// Draws the file dialog, if one is open; a file chosen is the command for its purpose,
    /// and the next dialog starts in its folder.
    pub fn show_browser(&mut self, ctx: &egui::Context) -> Option<Command> {
        let browser = self.browser.as_mut()?;
        match browser.show(ctx) {
            dialog::Outcome::Open => None,
            dialog::Outcome::Cancel => {
                self.browser = None;
                None
            }
            dialog::Outcome::Chose(purpose, path) => {
                self.prefs.last_dir = path.parent().map(Path::to_path_buf);
                self.browser = None;
                Some(match purpose {
                    BrowseFor::Open => Command::OpenFile(path),
                    BrowseFor::Lesson => Command::OpenLesson(super::LessonArg::File(path)),
                    BrowseFor::SaveScene => Command::SaveScene(path),
                    BrowseFor::Export => Command::Export(path),
                    BrowseFor::ExportFull => Command::ExportFull(path),
                    BrowseFor::ExportOverlay => Command::ExportOverlay(path),
                    BrowseFor::ExportSceneView => Command::ExportSceneView(path),
                    BrowseFor::ExportTree => Command::ExportTree(path),
                    BrowseFor::ExportDiagram => Command::ExportDiagram(path),
                })
            }
        }
    }

    /// Shows or hides the settings panel (whatever the window's width).
    pub fn set_settings_panel(&mut self, shown: bool) {
        self.prefs.settings_panel = shown;
        self.settings_settled = true;
        self.settings_auto_hidden = false;
    }

    /// Shows the settings panel, or hides it (saying how it comes back).
    pub fn toggle_settings_panel(&mut self, messages: &mut Messages) {
        self.prefs.settings_panel = !self.prefs.settings_panel;
        self.settings_auto_hidden = false;
        if !self.prefs.settings_panel {
            messages.notice("settings hidden: Ctrl+B or View > Settings panel shows them");
        }
    }

    /// Whether focus mode is on: the tree's diagram and list have most of the window.
    pub fn focused(&self) -> bool {
        self.focus.is_some()
    }

    /// Turns focus mode on (the tree's panes get most of the window, the render and the
    /// scene view share a strip at the left, the settings are hidden) or off (the layout and
    /// settings panel are given back exactly as they were).
    pub fn toggle_focus(&mut self) {
        match self.focus.take() {
            Some(saved) => {
                self.prefs.layout = saved.layout;
                self.prefs.settings_panel = saved.settings_panel;
            }
            None => {
                self.focus = Some(Arrangement {
                    layout: self.prefs.layout.clone(),
                    settings_panel: self.prefs.settings_panel,
                });
                self.prefs.layout = focus_layout();
                self.prefs.settings_panel = false;
                // The tree's panes are shown in the window, not beside it.
                self.popped_out = false;
            }
        }
    }

    /// The tree's panes in their own window, or back in the workspace.
    pub fn set_popped_out(&mut self, out: bool) {
        if out && self.focused() {
            self.toggle_focus();
        }
        self.popped_out = out;
    }

    /// The preferences to keep between runs: those before focus mode when it is on.
    pub fn prefs_to_save(&self) -> Prefs {
        let mut prefs = self.prefs.clone();
        if let Some(saved) = &self.focus {
            prefs.layout = saved.layout.clone();
            prefs.settings_panel = saved.settings_panel;
        } else if self.settings_auto_hidden {
            prefs.settings_panel = true;
        }
        prefs
    }

    /// Fits the settings panel to the window's width, each frame. When the window is (or
    /// becomes) narrower than [`SETTINGS_MIN_WIDTH`] points, a shown panel is hidden, saying
    /// how it comes back; when it is wide again, a panel hidden that way comes back. A choice
    /// the user makes (Ctrl+B, the « hide and » buttons, the View menu) stands until the
    /// window's width next crosses the threshold. Focus mode keeps its own arrangement.
    pub fn settle_settings_panel(&mut self, window_width: f32, messages: &mut Messages) {
        let narrow = window_width < SETTINGS_MIN_WIDTH;
        // The first frame counts as a crossing unless a choice was made before it.
        let crossed = match self.was_narrow {
            None => !self.settings_settled,
            Some(was) => was != narrow,
        };
        self.was_narrow = Some(narrow);
        self.settings_settled = true;
        if !crossed || self.focused() {
            return;
        }
        if narrow && self.prefs.settings_panel {
            self.prefs.settings_panel = false;
            self.settings_auto_hidden = true;
            messages.notice(
                "settings hidden in this narrow window: Ctrl+B or View > Settings panel shows them",
            );
        } else if !narrow && self.settings_auto_hidden {
            self.prefs.settings_panel = true;
            self.settings_auto_hidden = false;
        }
    }
}

/// One pane of the workspace.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Pane {
    Render,
    SceneView,
    Diagram,
    TreeList,
    /// The lecture's procedure, the line the selected node's call ran highlighted
    /// (pseudocode_pane.rs).
    Pseudocode,
}

impl Pane {
    pub const ALL: [Pane; 5] = [
        Pane::Render,
        Pane::SceneView,
        Pane::Diagram,
        Pane::TreeList,
        Pane::Pseudocode,
    ];

    /// The tree's panes: shown when a pixel's tree is, hidden when none is.
    pub const TREE: [Pane; 3] = [Pane::Diagram, Pane::TreeList, Pane::Pseudocode];

    pub fn title(self) -> &'static str {
        match self {
            Pane::Render => "Render",
            Pane::SceneView => "Scene view",
            Pane::Diagram => "Diagram",
            Pane::TreeList => "Tree list",
            Pane::Pseudocode => "Pseudocode",
        }
    }
}

pub type Layout = egui_tiles::Tree<Pane>;

/// The version of [`default_layout`]: a saved layout of another version is replaced.
pub const LAYOUT_VERSION: u32 = 4;

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
/// above and the tree's diagram, list and pseudocode below, as tabs of one pane (the diagram in
/// front).
pub fn default_layout() -> Layout {
    let mut tiles = egui_tiles::Tiles::default();
    let render = tabs(&mut tiles, Pane::Render);
    let scene = tabs(&mut tiles, Pane::SceneView);
    let diagram = tiles.insert_pane(Pane::Diagram);
    let list = tiles.insert_pane(Pane::TreeList);
    let code = tiles.insert_pane(Pane::Pseudocode);
    let tree = tiles.insert_tab_tile(vec![diagram, list, code]);
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

/// The render's share of the width in focus mode: a strip beside the tree.
pub const FOCUS_RENDER_SHARE: f32 = 0.24;

/// The diagram's share of the width in focus mode (the list has the rest).
pub const FOCUS_DIAGRAM_SHARE: f32 = 0.46;

/// Focus mode's layout: the render with the scene view as its neighbouring tab in a strip at
/// the left ([`FOCUS_RENDER_SHARE`]), then the diagram and the list (the pseudocode its
/// neighbouring tab) side by side.
pub fn focus_layout() -> Layout {
    let mut tiles = egui_tiles::Tiles::default();
    let render = tiles.insert_pane(Pane::Render);
    let scene = tiles.insert_pane(Pane::SceneView);
    let views = tiles.insert_tab_tile(vec![render, scene]);
    let diagram = tabs(&mut tiles, Pane::Diagram);
    let list = tiles.insert_pane(Pane::TreeList);
    let code = tiles.insert_pane(Pane::Pseudocode);
    let list = tiles.insert_tab_tile(vec![list, code]);
    let mut row = Linear::new(LinearDir::Horizontal, vec![views, diagram, list]);
    row.shares.set_share(views, FOCUS_RENDER_SHARE);
    row.shares.set_share(diagram, FOCUS_DIAGRAM_SHARE);
    row.shares
        .set_share(list, 1.0 - FOCUS_RENDER_SHARE - FOCUS_DIAGRAM_SHARE);
    let root = tiles.insert_container(row);
    egui_tiles::Tree::new(egui::Id::unique("raytree focus"), root, tiles)
}

/// The narrowest the column of the scene view and the tree's panes is made while the
/// workspace has room (at most [`TREE_COLUMN_MAX_SHARE`] of it): below about 300 points the
/// tree's three tabs no longer fit their bar and the pseudocode wraps its lines.
pub const TREE_COLUMN_MIN: f32 = 300.0;

/// The largest share of the workspace's width [`TREE_COLUMN_MIN`] may take from the render.
pub const TREE_COLUMN_MAX_SHARE: f32 = 0.4;

/// Widens the column holding the tree's panes to [`TREE_COLUMN_MIN`] points of `width` (the
/// workspace's), taking it from its neighbours, when it is narrower; a wider column is left as
/// it is. Only a layout whose root is a row holding that column is touched (the default one;
/// a rearranged layout is the user's).
fn make_room_for_tree(layout: &mut Layout, width: f32) {
    let Some((root, column)) = tree_column(layout) else {
        return;
    };
    let visible: Vec<TileId> = match layout.tiles.get(root) {
        Some(Tile::Container(egui_tiles::Container::Linear(row)))
            if row.dir == LinearDir::Horizontal && row.children.contains(&column) =>
        {
            row.children
                .iter()
                .copied()
                .filter(|&id| layout.tiles.is_visible(id))
                .collect()
        }
        _ => return,
    };
    if visible.len() < 2 || !visible.contains(&column) || !width.is_finite() || width <= 0.0 {
        return;
    }
    let Some(Tile::Container(egui_tiles::Container::Linear(row))) = layout.tiles.get_mut(root)
    else {
        return;
    };
    let total: f32 = visible.iter().map(|&id| row.shares[id]).sum();
    let own = row.shares[column];
    let others = total - own;
    let wanted = (TREE_COLUMN_MIN / width).min(TREE_COLUMN_MAX_SHARE);
    if others > 0.0 && own / total < wanted {
        // own' / (own' + others) = wanted
        row.shares
            .set_share(column, wanted * others / (1.0 - wanted));
    }
}

/// The root and the root's child that holds the tree's diagram.
fn tree_column(layout: &Layout) -> Option<(TileId, TileId)> {
    let root = layout.root()?;
    let mut column = tile_of(layout, Pane::Diagram)?;
    while let Some(parent) = layout.tiles.parent_of(column) {
        if parent == root {
            break;
        }
        column = parent;
    }
    Some((root, column))
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
fn follow_tree(ws: &mut Workspace, has_tree: bool) {
    // Popped out, the tree's panes are in their own window.
    let has_tree = has_tree && !ws.popped_out;
    let want = if has_tree {
        TreePanes::Open
    } else {
        TreePanes::Closed
    };
    if ws.tree_panes == Some(want) {
        return;
    }
    ws.tree_panes = Some(want);
    for pane in Pane::TREE {
        if let Some(id) = tile_of(&ws.prefs.layout, pane) {
            ws.prefs.layout.tiles.set_visible(id, has_tree);
        }
    }
}

/// Draws what a pane shows.
pub type PaneUi = fn(&mut ViewerApp, &mut Ui, Pane);

/// Draws the panes of `app`'s layout into `ui`, each by `pane_ui`.
pub fn show(app: &mut ViewerApp, ui: &mut Ui, pane_ui: PaneUi) {
    let ws = &mut app.workspace;
    if !usable(&ws.prefs.layout) {
        ws.prefs.layout = default_layout();
        ws.tree_panes = None;
        ws.room_width = None;
    }
    follow_tree(ws, app.selection.tree.is_some());
    // On the first frame and whenever the workspace's width changes (the window, the lesson
    // or settings panel): between those the splitter stays where the user drags it.
    let width = ui.available_width();
    if !ws.focused() && ws.room_width.is_none_or(|w| (w - width).abs() > 0.5) {
        make_room_for_tree(&mut ws.prefs.layout, width);
        ws.room_width = Some(width);
    }
    let mut layout = std::mem::replace(
        &mut app.workspace.prefs.layout,
        egui_tiles::Tree::empty(egui::Id::unique("none")),
    );
    layout.ui(&mut Panes { app, pane_ui }, ui);
    app.workspace.prefs.layout = layout;
}

/// A checkbox per pane, to hide or show it (View menu).
pub fn pane_toggles(ws: &mut Workspace, messages: &mut Messages, ui: &mut Ui) {
    for pane in Pane::ALL {
        if let Some(id) = tile_of(&ws.prefs.layout, pane) {
            let mut visible = ws.prefs.layout.tiles.is_visible(id);
            if ui.checkbox(&mut visible, pane.title()).changed() {
                ws.prefs.layout.tiles.set_visible(id, visible);
            }
        }
    }
    let mut settings = ws.prefs.settings_panel;
    if ui
        .checkbox(&mut settings, "Settings panel (Ctrl+B)")
        .changed()
    {
        ws.toggle_settings_panel(messages);
    }
    let mut focus = ws.focused();
    if ui
        .checkbox(&mut focus, "Focus on the ray tree (F)")
        .changed()
    {
        ws.toggle_focus();
    }
    if ui.button("Reset layout").clicked() {
        ws.focus = None;
        ws.prefs.layout = default_layout();
        ws.prefs.settings_panel = true;
        ws.tree_panes = None;
        ws.room_width = None;
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
    fn preferences_saved_before_layout_versions_get_the_new_layout() {
        let old: Prefs = serde_json::from_str(r#"{"exposure": 2.0}"#).expect("old prefs");
        assert_eq!(old.layout_version, 0);
        assert_eq!(old.exposure, 2.0);
        assert_eq!(old.viewer_samples, VIEWER_SAMPLES);
        assert!(old.pane_size);
        let now = Prefs::default();
        assert_eq!(now.layout_version, LAYOUT_VERSION);
        assert_eq!(old.checked().layout_version, LAYOUT_VERSION);
    }

    #[test]
    fn the_tonemap_is_saved_as_the_number_the_shader_reads() {
        let prefs: Prefs = serde_json::from_str(r#"{"tonemap": 2}"#).expect("prefs");
        assert_eq!(prefs.tonemap, Tonemap::Aces);
        let json = serde_json::to_value(&prefs).expect("serialises");
        assert_eq!(json["tonemap"], 2);
    }

    #[test]
    fn focus_gives_the_tree_the_window_and_gives_the_layout_back() {
        let mut ws = Workspace::default();
        ws.prefs.settings_panel = true;
        let before = serde_json::to_string(&ws.prefs.layout).expect("serialises");
        ws.toggle_focus();
        assert!(ws.focused());
        assert!(usable(&ws.prefs.layout));
        assert!(!ws.prefs.settings_panel);
        // What is saved meanwhile is the layout to come back to.
        let saved = ws.prefs_to_save();
        assert_eq!(serde_json::to_string(&saved.layout).expect("json"), before);
        assert!(saved.settings_panel);
        ws.toggle_focus();
        assert!(!ws.focused());
        assert_eq!(
            serde_json::to_string(&ws.prefs.layout).expect("json"),
            before
        );
        assert!(ws.prefs.settings_panel);
        // Popping the panes out ends focus.
        ws.toggle_focus();
        ws.set_popped_out(true);
        assert!(!ws.focused() && ws.popped_out);
        assert_eq!(
            serde_json::to_string(&ws.prefs.layout).expect("json"),
            before
        );
    }

    #[test]
    fn the_default_layout_is_usable_and_survives_a_round_trip() {
        let layout = default_layout();
        assert!(usable(&layout));
        let json = serde_json::to_string(&layout).expect("serialises");
        let back: Layout = serde_json::from_str(&json).expect("deserialises");
        assert!(usable(&back));
        assert!(!usable(&egui_tiles::Tree::empty(egui::Id::unique("x"))));
    }

    #[test]
    fn a_settings_panel_saved_in_a_wide_window_is_hidden_in_a_small_one() {
        let mut messages = Messages::default();
        let mut ws = Workspace::new(Prefs::default());
        assert!(ws.prefs.settings_panel, "saved shown");
        ws.settle_settings_panel(1024.0, &mut messages);
        assert!(!ws.prefs.settings_panel, "hidden at 1024 px");
        // Hidden by choice in a wide window: it stays hidden there.
        let prefs = Prefs {
            settings_panel: false,
            ..Prefs::default()
        };
        let mut ws = Workspace::new(prefs);
        ws.settle_settings_panel(1600.0, &mut messages);
        assert!(!ws.prefs.settings_panel);
    }

    #[test]
    fn the_settings_panel_follows_the_window_across_the_width_and_a_choice_stands_between() {
        let mut messages = Messages::default();
        let mut ws = Workspace::new(Prefs::default());
        ws.settle_settings_panel(1600.0, &mut messages);
        assert!(ws.prefs.settings_panel && messages.is_empty());
        // Made narrow: hidden, once, saying how it comes back; saved as shown.
        ws.settle_settings_panel(1024.0, &mut messages);
        ws.settle_settings_panel(1000.0, &mut messages);
        assert!(!ws.prefs.settings_panel);
        assert_eq!(messages.len(), 1);
        assert!(messages.log()[0].mentions("Ctrl+B"));
        assert!(
            ws.prefs_to_save().settings_panel,
            "saved as the user left it"
        );
        // Wide again: back.
        ws.settle_settings_panel(1400.0, &mut messages);
        assert!(ws.prefs.settings_panel);
        // Shown by the user in a narrow window: it stays while the window stays narrow.
        ws.settle_settings_panel(1024.0, &mut messages);
        assert!(!ws.prefs.settings_panel);
        ws.toggle_settings_panel(&mut messages);
        ws.settle_settings_panel(1100.0, &mut messages);
        assert!(ws.prefs.settings_panel, "the user's choice stands");
        // Hidden by the user in a wide window: widening does not bring it back.
        ws.settle_settings_panel(1400.0, &mut messages);
        ws.toggle_settings_panel(&mut messages);
        ws.settle_settings_panel(1200.0, &mut messages);
        ws.settle_settings_panel(1500.0, &mut messages);
        assert!(!ws.prefs.settings_panel, "hidden by choice stays hidden");
        assert!(!ws.prefs_to_save().settings_panel);
        // Focus mode keeps its own arrangement through a resize.
        let mut ws = Workspace::new(Prefs::default());
        ws.settle_settings_panel(1600.0, &mut messages);
        ws.toggle_focus();
        ws.settle_settings_panel(1024.0, &mut messages);
        ws.toggle_focus();
        assert!(ws.prefs.settings_panel, "focus gave back what it took");
    }

    #[test]
    fn opening_starts_in_the_scene_folder_and_exports_where_the_last_file_went() {
        let mut ws = Workspace::new(Prefs {
            last_dir: Some("/shots".into()),
            ..Prefs::default()
        });
        ws.scene_dir = Some("/models/kitchen".into());
        assert_eq!(
            ws.start_dir(BrowseFor::Open),
            PathBuf::from("/models/kitchen")
        );
        assert_eq!(
            ws.start_dir(BrowseFor::SaveScene),
            PathBuf::from("/models/kitchen")
        );
        assert_eq!(ws.start_dir(BrowseFor::Export), PathBuf::from("/shots"));
        ws.prefs.last_dir = None;
        assert_eq!(
            ws.start_dir(BrowseFor::Export),
            PathBuf::from("/models/kitchen")
        );
    }

    /// The share of the workspace's width the column holding the tree's panes gets.
    fn tree_column_share(layout: &Layout) -> f32 {
        let (root, column) = tree_column(layout).expect("a tree column");
        let Some(Tile::Container(egui_tiles::Container::Linear(row))) = layout.tiles.get(root)
        else {
            panic!("the root is a row");
        };
        let total: f32 = row.children.iter().map(|&c| row.shares[c]).sum();
        row.shares[column] / total
    }

    #[test]
    fn a_narrow_workspace_gives_the_tree_column_its_room_from_the_render() {
        let wide = {
            let mut l = default_layout();
            make_room_for_tree(&mut l, 2000.0);
            tree_column_share(&l)
        };
        assert!(
            (wide - (1.0 - RENDER_SHARE)).abs() < 1e-6,
            "left alone when wide: {wide}"
        );
        // 1024×640 with the lesson panel open: about 756 points of workspace.
        let mut l = default_layout();
        make_room_for_tree(&mut l, 756.0);
        let got = tree_column_share(&l) * 756.0;
        assert!((got - TREE_COLUMN_MIN).abs() < 0.01, "column {got} points");
        // Very narrow: the render keeps the larger part.
        let mut l = default_layout();
        make_room_for_tree(&mut l, 500.0);
        let share = tree_column_share(&l);
        assert!(
            (share - TREE_COLUMN_MAX_SHARE).abs() < 1e-6,
            "share {share}"
        );
        // A column the user made wider stays as it is.
        let mut l = default_layout();
        make_room_for_tree(&mut l, 500.0);
        make_room_for_tree(&mut l, 756.0);
        assert!((tree_column_share(&l) - TREE_COLUMN_MAX_SHARE).abs() < 1e-6);
        // A rearranged layout (the tree's tabs beside the render in the root row's first
        // child) is the user's: untouched.
        let mut l = focus_layout();
        let before = serde_json::to_string(&l).expect("serialises");
        let root = l.root().expect("root");
        if let Some(Tile::Container(egui_tiles::Container::Linear(row))) = l.tiles.get_mut(root) {
            row.dir = LinearDir::Vertical;
        }
        let vertical = serde_json::to_string(&l).expect("serialises");
        make_room_for_tree(&mut l, 756.0);
        assert_eq!(serde_json::to_string(&l).expect("serialises"), vertical);
        assert_ne!(before, vertical);
    }
}
