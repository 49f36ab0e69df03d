//! The scene view (docs/design.md, "The viewer"): the scene seen from a camera of its own, independent of the render
//! camera, with the render camera (frustum, image plane, clicked pixel), the lights and the ray
//! trees drawn over it, parts behind surfaces dimmed.
//!
//! The scene is shaded by raytree's own tracer, progressively: a second
//! [`Session`] renders a copy of the scene whose camera is the scene view's and whose size
//! follows the pane (at most [`MAX_SIDE`] pixels on the long side, for speed). Why our tracer
//! rather than a wgpu raster pass: the picture follows the same model as the render (the same
//! materials, shadows, reflections and refraction, the same accelerator), so there is no second
//! renderer to keep equal to the first, and the render's depth of each pixel comes with it for
//! free. The cost: after an orbit the view refines progressively (a coarse preview first)
//! instead of appearing at once as a raster would.
//!
//! Orbiting, panning or zooming restarts only this session; the trees are never re-traced.
//!
//! Inside a closed model (a room around the render camera) the view cuts away the walls
//! between its eye and the render camera ([`crate::scene_view::cutaway`]): the session then
//! renders a copy of the scene with those walls left out, rebuilt only when the walls cut
//! change (and not during a drag, which keeps the last cut until the pointer lets go). The cut
//! follows the render camera: a move of it restarts this view when the walls cut change.

use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

use eframe::egui::containers::menu::{self, MenuButton, MenuConfig};
use eframe::egui::{self, Color32, Sense, Ui};

use super::film::Film;
use super::modes::ImageMode;
use super::paint3d::{self, Drawn, Look, ScreenView};
use super::selection::TreeSelection;
use super::viewport::{DisplayCallback, DisplayId, DisplayState, SharedDisplay, Tonemap};
use super::workspace::Prefs;
use super::{Command, tree_view};
use crate::accel::Accel;
use crate::render::session::{Session, SessionEvent, View};
use crate::scene::{Camera, CameraFrame, Scene};
use crate::scene_view::cutaway::{Cutaway, cut_triangles, with_cut};
use crate::scene_view::overview::{self, overview};
use crate::scene_view::{self, Filter, LevelSegments, Segment, Style};
use crate::trace::{EndReason, Tracer};

/// The longest side of the scene view's image, in pixels.
pub const MAX_SIDE: u32 = 640;
/// Samples per pixel of the scene view: enough to read the scene, few enough to follow an orbit.
const SAMPLES: u32 = 2;

/// The scene view's camera, its render and what it shows.
pub struct SceneView {
    pub camera: Camera,
    session: Session,
    generation: u64,
    /// The image size the session renders (follows the pane).
    size: (u32, u32),
    film: Film,
    display: SharedDisplay,
    /// Which rays are shown (the step-through sets the generation).
    pub filter: Filter,
    /// The step-through's playback: when the last generation was revealed, and generations
    /// revealed per second.
    pub playing: Option<Instant>,
    pub speed: f32,
    /// Segments drawn in the last frame, for picking.
    drawn: Vec<Drawn>,
    /// Whether the camera has been framed on a scene yet.
    framed: bool,
    /// The image size the camera was framed for, and that camera: while the camera is still
    /// the framed one, a new size (a pane resized, the first real layout) frames it again.
    framed_view: Option<((u32, u32), Camera)>,
    /// Whether the current render reached its samples.
    finished: bool,
    /// Draw the boxes the selected ray's traversal entered.
    pub show_visits: bool,
    /// Draw every box of this BVH level (or the grid's cells).
    pub bvh_level: Option<u32>,
    /// The boxes of the level last drawn, and the accelerator and level they are of: worked
    /// out once, not every frame (a camera edit keeps the accelerator).
    level_cache: Option<(Weak<Accel>, u32, Arc<LevelSegments>)>,
    /// When walls are cut away.
    pub cutaway: Cutaway,
    /// The tracer of the scene with walls cut, the accelerator of the geometry it was cut
    /// from and which triangles were cut: kept while the same walls of the same geometry are
    /// cut (most camera moves, and edits of lights or materials, which take the cut geometry
    /// and its accelerator into a tracer of the edited scene).
    cut_cache: Option<(Weak<Accel>, Vec<u32>, Arc<Tracer>)>,
    /// The triangles cut away in the picture shown (none when nothing is cut).
    shown_cut: Vec<u32>,
    /// Whether the camera is being dragged: the cut then keeps its last walls.
    moving: bool,
}

impl SceneView {
    pub fn new(threads: usize) -> Result<Self, String> {
        Ok(Self {
            camera: Camera::default(),
            session: Session::new(threads)?,
            generation: 0,
            size: (320, 200),
            film: Film::outlined(320, 200),
            display: Arc::new(Mutex::new(DisplayState::new(320, 200))),
            filter: Filter::default(),
            playing: None,
            speed: 1.5,
            drawn: Vec::new(),
            framed: false,
            framed_view: None,
            finished: false,
            show_visits: false,
            bvh_level: None,
            level_cache: None,
            cutaway: Cutaway::Auto,
            cut_cache: None,
            shown_cut: Vec::new(),
            moving: false,
        })
    }

    /// The boxes of the BVH level shown, `None` when none is; worked out once per accelerator
    /// and level.
    pub fn level_segments(&mut self, accel: &Arc<Accel>) -> Option<Arc<LevelSegments>> {
        let level = self.bvh_level?;
        if let Some((of, l, segments)) = &self.level_cache
            && *l == level
            && std::ptr::eq(of.as_ptr(), Arc::as_ptr(accel))
        {
            return Some(segments.clone());
        }
        let segments = Arc::new(scene_view::level_segments(accel, level));
        self.level_cache = Some((Arc::downgrade(accel), level, segments.clone()));
        Some(segments)
    }

    /// Frames the camera on the scene's bounds and the render camera's eye, from the render
    /// camera's side where that sees what it sees ([`overview()`]), so the frustum and the rays
    /// are seen across.
    pub fn frame(&mut self, tracer: &Tracer) {
        let (w, h) = self.size;
        let aspect = w as f32 / h.max(1) as f32;
        self.camera = overview(tracer, aspect, overview::FOV_Y_DEG, self.cutaway);
        self.framed = true;
        self.framed_view = Some((self.size, self.camera.clone()));
    }

    /// Frames the next scene when it is rendered (another scene was opened).
    pub fn unframe(&mut self) {
        self.framed = false;
    }

    /// Changes the worker count (takes effect at the next start).
    pub fn set_threads(&mut self, threads: usize) -> Result<(), String> {
        self.session.set_threads(threads)
    }

    /// The current image's size.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Renders the scene of `tracer` from this view's camera, sharing the scene and its
    /// accelerator: the session renders it through this view's camera and size, so nothing is
    /// copied on the UI thread (a million-triangle scene took 215 ms to copy).
    pub fn restart(&mut self, tracer: &Arc<Tracer>) {
        let resized = matches!(&self.framed_view,
            Some((size, camera)) if *size != self.size && *camera == self.camera);
        if !self.framed || resized {
            self.frame(tracer);
        }
        let (w, h) = self.size;
        let view = View {
            camera: self.camera.clone(),
            width: w,
            height: h,
        };
        let samples = tracer.scene.render.samples.clamp(1, SAMPLES);
        self.film.resize(w, h);
        crate::sync::lock(&self.display).resize(w, h);
        self.finished = false;
        let seen = self.view_tracer(tracer);
        self.generation = self.session.start_view(seen, view, samples);
    }

    /// Whether walls are cut away from the current camera.
    pub fn cuts(&self, scene: &Scene) -> bool {
        self.cutaway.active(scene, self.camera.position)
    }

    /// Whether the picture shown would change with the render camera of `scene`: a
    /// headlight moves with it, and so do the walls cut away when it steps into or about a
    /// room. A move of the render camera alone restarts the view only then.
    pub fn follows_render_camera(&self, scene: &Scene) -> bool {
        if scene.lights.iter().any(|l| l.follow_camera) {
            return true;
        }
        let walls = if self.cuts(scene) {
            cut_triangles(scene, self.camera.position)
        } else {
            Vec::new()
        };
        walls != self.shown_cut
    }

    /// The tracer the view renders: `tracer` itself, or one of its scene with the walls
    /// between this view's eye and the render camera cut away when the cut-away is active.
    fn view_tracer(&mut self, tracer: &Arc<Tracer>) -> Arc<Tracer> {
        let (seen, walls) = self.cut_tracer(tracer);
        self.shown_cut = walls;
        seen
    }

    /// The tracer [`Self::view_tracer`] gives and the triangles it leaves out.
    fn cut_tracer(&mut self, tracer: &Arc<Tracer>) -> (Arc<Tracer>, Vec<u32>) {
        if !self.cuts(&tracer.scene) {
            return (tracer.clone(), Vec::new());
        }
        let same_source = |of: &Weak<Accel>| std::ptr::eq(of.as_ptr(), Arc::as_ptr(&tracer.accel));
        let walls = match &self.cut_cache {
            // A drag keeps the last walls cut.
            Some((of, was, _)) if self.moving && same_source(of) => was.clone(),
            _ => cut_triangles(&tracer.scene, self.camera.position),
        };
        if walls.is_empty() {
            return (tracer.clone(), walls);
        }
        if let Some((of, was, cut)) = &mut self.cut_cache
            && same_source(of)
            && *was == walls
        {
            // The same geometry, perhaps in an edited scene (camera, lights, materials): the
            // cut triangles and their accelerator go into a tracer of it.
            let scene = Scene {
                triangles: cut.scene.triangles.clone(),
                ..(*tracer.scene).clone()
            };
            *cut = Arc::new(Tracer::with_accel(
                Arc::new(scene),
                tracer.settings,
                cut.accel.clone(),
            ));
            return (cut.clone(), walls);
        }
        let scene = Arc::new(with_cut(&tracer.scene, &walls));
        let cut = Arc::new(Tracer::new(scene, tracer.settings));
        self.cut_cache = Some((Arc::downgrade(&tracer.accel), walls.clone(), cut.clone()));
        (cut, walls)
    }

    /// Takes the tiles that arrived, within a time budget.
    pub fn poll(&mut self) {
        let budget = Instant::now();
        let mut display = crate::sync::lock(&self.display);
        while let Some(event) =
            self.session
                .next_within(self.generation, budget, Duration::from_millis(4))
        {
            match event {
                SessionEvent::Tile(tile) => {
                    self.film
                        .write_tile(&tile, ImageMode::Render, 0, &mut display);
                }
                SessionEvent::Finished { .. } | SessionEvent::Failed { .. } => {
                    self.finished = true;
                }
                SessionEvent::PassDone { .. } => {}
            }
        }
    }

    /// Matches the display's exposure and tonemap to the render view's.
    fn set_params(&self, exposure: f32, tonemap: Tonemap) {
        let mut d = crate::sync::lock(&self.display);
        if d.params.exposure != exposure || d.params.tonemap != tonemap {
            d.params.exposure = exposure;
            d.params.tonemap = tonemap;
            d.mark_all();
        }
    }

    /// The image size for a pane of `rect`: its aspect, at most [`MAX_SIDE`] on the long side.
    fn size_for(rect: egui::Rect) -> (u32, u32) {
        let k = (MAX_SIDE as f32 / rect.width().max(rect.height())).min(1.0);
        (
            ((rect.width() * k).round() as u32).max(1),
            ((rect.height() * k).round() as u32).max(1),
        )
    }
}

/// The deepest generation among `trees`.
pub fn deepest<'a>(trees: impl IntoIterator<Item = &'a crate::ray_tree::RayTree>) -> u32 {
    fn walk(n: &crate::ray_tree::Node) -> u32 {
        n.children.iter().map(walk).max().unwrap_or(0).max(n.depth)
    }
    trees.into_iter().map(|t| walk(&t.root)).max().unwrap_or(0)
}

/// Advances the step-through's playback: one more generation every `1 / speed` seconds, stopping
/// at the deepest.
pub fn advance_playback(view: &mut SceneView, selection: &mut TreeSelection, ctx: &egui::Context) {
    let Some(since) = view.playing else {
        return;
    };
    let deepest = deepest(selection.trees());
    let step = 1.0 / view.speed.max(0.05);
    if since.elapsed().as_secs_f32() >= step {
        let reveal = &mut selection.tree_state.reveal;
        let next = reveal.map_or(0, |g| g + 1);
        if next > deepest {
            view.playing = None;
            *reveal = None;
        } else {
            *reveal = Some(next);
            view.playing = Some(Instant::now());
        }
    }
    ctx.request_repaint();
}

/// Width (points) from which the scene view's filters sit in the toolbar as checkboxes; a
/// narrower pane keeps them in its "Show" menu, so the toolbar stays two rows and the
/// view below keeps its height (at 1024×640 the checkboxes wrapped into five rows and left the
/// 3D view a strip about 50 points tall once a pixel was clicked).
pub const FILTERS_INLINE_WIDTH: f32 = 560.0;

/// The smallest 3D view (points) that shows the key of ray colours.
const KEY_MIN_VIEW: (f32, f32) = (360.0, 320.0);

/// The toolbar: the step-through (play, depth slider, speed), "Frame", and the filters, inline
/// in a wide pane and in the "Show" menu otherwise (two rows either way).
fn toolbar(ui: &mut Ui, view: &mut SceneView, selection: &mut TreeSelection, tracer: &Arc<Tracer>) {
    let inline = ui.available_width() >= FILTERS_INLINE_WIDTH;
    if inline {
        ui.horizontal_wrapped(|ui| {
            step_through(ui, view, selection);
            speed_and_frame(ui, view, tracer, true);
        });
        ui.horizontal_wrapped(|ui| filters(ui, view, tracer));
    } else {
        // "Show" leads the first row, whose slider takes what is left: two rows in all.
        ui.horizontal(|ui| {
            MenuButton::new("Show")
                .config(stays_open())
                .ui(ui, |ui| filters(ui, view, tracer))
                .0
                .on_hover_text("ray kinds, normals, visits, BVH level and end reasons shown");
            step_through(ui, view, selection)
        });
        ui.horizontal_wrapped(|ui| speed_and_frame(ui, view, tracer, false));
    }
}

/// Play (or Pause) and the depth slider, which takes the row's remaining width.
fn step_through(ui: &mut Ui, view: &mut SceneView, selection: &mut TreeSelection) {
    let deepest = deepest(selection.trees());
    let reveal = &mut selection.tree_state.reveal;
    let playing = view.playing.is_some();
    if ui
        .button(if playing { "Pause" } else { "Play" })
        .on_hover_text("reveal the tree generation by generation")
        .clicked()
    {
        if playing {
            view.playing = None;
        } else {
            *reveal = Some(0);
            view.playing = Some(Instant::now());
        }
    }
    let mut depth = reveal.unwrap_or(deepest).min(deepest);
    let l = ui.label("depth");
    // What the slider's value box and the spacing before it take.
    const VALUE_BOX: f32 = 48.0;
    ui.spacing_mut().slider_width = (ui.available_width() - VALUE_BOX).clamp(30.0, 160.0);
    let r = ui
        .add(egui::Slider::new(&mut depth, 0..=deepest.max(1)))
        .labelled_by(l.id)
        .on_hover_text("show the tree down to this generation");
    if r.changed() {
        *reveal = (depth < deepest).then_some(depth);
        view.playing = None;
    }
}

/// The playback speed (labelled where there is room) and "Frame".
fn speed_and_frame(ui: &mut Ui, view: &mut SceneView, tracer: &Arc<Tracer>, labelled: bool) {
    let speed = egui::DragValue::new(&mut view.speed)
        .range(0.25..=8.0)
        .speed(0.05)
        .suffix(" gen/s");
    if labelled {
        let l = ui.label("speed");
        ui.add(speed).labelled_by(l.id);
    } else {
        ui.add(speed).on_hover_text("playback speed");
    }
    if ui
        .button("Frame")
        .on_hover_text("frame the scene and the render camera")
        .clicked()
    {
        view.frame(tracer);
        view.restart(tracer);
    }
    cutaway_choice(ui, view, tracer);
}

/// The cut-away's choice, saying whether "auto" cuts from the current camera.
fn cutaway_choice(ui: &mut Ui, view: &mut SceneView, tracer: &Arc<Tracer>) {
    let text = match view.cutaway {
        Cutaway::Auto if view.cuts(&tracer.scene) => "cut-away: auto (on)",
        Cutaway::Auto => "cut-away: auto (off)",
        Cutaway::On => "cut-away: on",
        Cutaway::Off => "cut-away: off",
    };
    let before = view.cutaway;
    egui::ComboBox::from_id_salt("scene view cut-away")
        .selected_text(text)
        .show_ui(ui, |ui| {
            for (choice, what) in [
                (Cutaway::Auto, "auto: on when the render camera is inside the model"),
                (Cutaway::On, "on: leave out the walls facing this view"),
                (Cutaway::Off, "off: the model whole"),
            ] {
                ui.selectable_value(&mut view.cutaway, choice, what);
            }
        })
        .response
        .on_hover_text(
            "see inside a closed model: the walls between this view's eye and the render camera are left out",
        );
    if view.cutaway != before {
        view.restart(tracer);
    }
}

/// A menu of checkboxes that stays open while they are clicked (egui closes a menu on any click
/// by default), so several filters change in one visit and the BVH level's box can be dragged.
fn stays_open() -> MenuConfig {
    MenuConfig::new().close_behavior(egui::PopupCloseBehavior::CloseOnClickOutside)
}

/// The scene view's filters: ray kinds, normals, the selected ray's visits, one BVH level, and
/// the end reasons (a menu of its own).
fn filters(ui: &mut Ui, view: &mut SceneView, tracer: &Arc<Tracer>) {
    let f = &mut view.filter;
    ui.checkbox(&mut f.primary, "primary");
    ui.checkbox(&mut f.reflected, "reflected");
    ui.checkbox(&mut f.refracted, "refracted");
    ui.checkbox(&mut f.shadow, "shadow");
    ui.checkbox(&mut f.normals, "normals");
    ui.checkbox(&mut view.show_visits, "visits")
        .on_hover_text("cyan boxes: the BVH nodes (or grid cells) the selected ray entered");
    let levels = tracer.accel.levels();
    let mut on = view.bvh_level.is_some();
    ui.horizontal(|ui| {
        if ui
            .checkbox(&mut on, "BVH level")
            .on_hover_text("every box of one level of the accelerator")
            .changed()
        {
            view.bvh_level = on.then_some(0);
        }
        if let Some(level) = &mut view.bvh_level {
            ui.add(egui::DragValue::new(level).range(0..=levels.saturating_sub(1)));
        }
    });
    if let Some(level) = view.level_segments(&tracer.accel) {
        let text = match (level.drawn, level.total) {
            (_, 1) => "1 box".to_owned(),
            (drawn, total) if drawn < total => format!("the largest {drawn} of {total} boxes"),
            (_, total) => format!("{total} boxes"),
        };
        ui.label(egui::RichText::new(text).small()).on_hover_text(format!(
            "a level's boxes are drawn up to {} at a time, the largest first (each costs its edges cut against the view's depth every frame)",
            scene_view::MAX_LEVEL_BOXES
        ));
    }
    let f = &mut view.filter;
    let ends = |ui: &mut Ui| {
        for end in [
            EndReason::NoHit,
            EndReason::HitLight,
            EndReason::MaxDepth,
            EndReason::Cutoff,
            EndReason::Budget,
        ] {
            let mut shown = !f.hidden_ends.contains(&end);
            if ui.checkbox(&mut shown, tree_view::end_label(end)).changed() {
                f.hidden_ends.retain(|e| *e != end);
                if !shown {
                    f.hidden_ends.push(end);
                }
            }
        }
    };
    // Inside the Show menu a submenu (which keeps that menu's behaviour), a menu of its own in
    // the toolbar.
    if menu::is_in_menu(ui) {
        ui.menu_button("ends", ends);
    } else {
        MenuButton::new("ends").config(stays_open()).ui(ui, ends);
    }
}

/// Every segment the scene view and the overlay draw for `tree`, shown by `filter`.
pub fn shown_segments(
    tree: &crate::ray_tree::RayTree,
    extent: f32,
    filter: &Filter,
) -> Vec<Segment> {
    scene_view::tree_segments(tree, extent)
        .into_iter()
        .filter(|s| filter.shows(s))
        .collect()
}

/// Draws the trees through `view` (the current tree, the extra trees, the pinned tree in its
/// own style) and returns what was drawn, tree 0 being the current tree, 1.. the extra trees.
pub(super) fn draw_trees(
    selection: &TreeSelection,
    scene: &Scene,
    painter: &egui::Painter,
    view: &ScreenView,
    depth: &crate::scene_view::occlusion::DepthImage,
    filter: &Filter,
) -> Vec<Drawn> {
    let extent = scene_view::extent(scene);
    let state = &selection.tree_state;
    let active: Vec<&[usize]> = [state.selected.as_deref(), state.hovered.as_deref()]
        .into_iter()
        .flatten()
        .collect();
    // Back to front: the pinned tree (dashed, fainter, not pickable), the other trees faint
    // in their tints (numbered 1..), the current tree (0) strong with its hovered and selected
    // nodes.
    let pinned = Look {
        alpha: 0.55,
        dashed: true,
        tree: None,
    };
    let mut drawn = Vec::new();
    if let Some(tree) = &state.pinned {
        let segments = shown_segments(tree, extent, filter);
        let out = &mut Vec::new();
        paint3d::draw_segments(
            painter,
            view,
            depth,
            &segments,
            usize::MAX,
            &[],
            pinned,
            out,
        );
    }
    for (tree, number, tree_look, to_depth) in selection.layers() {
        let filter = Filter {
            max_generation: to_depth
                .map_or(filter.max_generation, |d| d.min(filter.max_generation)),
            ..filter.clone()
        };
        let segments = shown_segments(tree, extent, &filter);
        let lit = if number == 0 {
            active.as_slice()
        } else {
            &[][..]
        };
        let look = Look {
            tree: Some(tree_look),
            ..Look::default()
        };
        paint3d::draw_segments(
            painter, view, depth, &segments, number, lit, look, &mut drawn,
        );
    }
    drawn
}

/// The scene view pane: toolbar, the image, the camera, lights and trees over it; drag to
/// orbit, right/middle drag to pan, wheel to zoom, click a ray to select its node.
/// `edit` is the working copy, whose lights and spheres can be dragged in the view.
pub fn scene_view_ui(
    ui: &mut Ui,
    view: &mut SceneView,
    tracer: &Arc<Tracer>,
    selection: &mut TreeSelection,
    edit: &mut Scene,
    prefs: &Prefs,
    pending: &mut Vec<Command>,
) {
    toolbar(ui, view, selection, tracer);
    let rect = ui.available_rect_before_wrap();
    if rect.width() < 8.0 || rect.height() < 8.0 {
        return;
    }
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "scene view"));
    let size = SceneView::size_for(rect);
    let mut restart = size != view.size;
    view.size = size;
    // Camera moves: only this view's render restarts.
    let delta = response.drag_delta();
    // A drag that starts on a light moves the light instead.
    let camera = view.camera.clone();
    let light = &mut selection.selected_light;
    let light_drag = super::gesture::drag_light(edit, light, pending, ui, &response, &camera, rect)
        || super::gesture::drag_sphere(edit, pending, ui, &response, &camera, rect);
    if delta != egui::Vec2::ZERO && !light_drag {
        if response.dragged_by(egui::PointerButton::Primary) {
            let (yaw, pitch) =
                super::gesture::orbit_angles(delta, rect.width(), prefs.orbit_degrees);
            view.camera.orbit(yaw, pitch);
            restart = true;
        } else if response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
        {
            view.camera
                .pan(delta.x / rect.height(), delta.y / rect.height());
            restart = true;
        }
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            view.camera.zoom((-scroll * 0.002).exp());
            restart = true;
        }
    }
    if restart {
        view.moving = response.dragged();
        view.restart(tracer);
        view.moving = false;
    } else if response.drag_stopped() && view.cuts(&tracer.scene) {
        // The cut kept during the drag, brought up to the camera's new place.
        view.restart(tracer);
    }
    view.set_params(prefs.exposure, prefs.tonemap);
    ui.painter()
        .add(eframe::egui_wgpu::Callback::new_paint_callback(
            rect,
            DisplayCallback {
                id: DisplayId::SceneView,
                shared: view.display.clone(),
            },
        ));
    let (w, h) = view.size;
    let screen = ScreenView {
        rect,
        frame: CameraFrame::new(&view.camera, w, h),
        width: w,
        height: h,
    };
    let depth = view.film.depth();
    let scene = &tracer.scene;
    let painter = ui.painter_at(rect);
    // The render camera with its image plane where the headless scene view puts it.
    let (plane, pixel) = match &selection.tree {
        Some(t) => (
            scene_view::headless::image_plane_distance(scene, t),
            Some(t.pixel),
        ),
        None => (0.15 * scene_view::extent(scene), None),
    };
    let mut camera = scene_view::camera_segments(scene, plane.max(1e-6), pixel);
    // The accelerator made visible: the boxes the selected ray's traversal entered, and all
    // boxes of one BVH level.
    let mut visits = None;
    if view.show_visits
        && let (Some(tree), Some(path)) = (&selection.tree, &selection.tree_state.selected)
        && let Some((boxes, counts)) = scene_view::visit_segments(tracer, tree, path)
    {
        camera.extend(boxes);
        visits = Some(counts.boxes.len());
    }
    let level = view.level_segments(&tracer.accel);
    paint3d::draw_segments(
        &painter,
        &screen,
        &depth,
        camera.iter().chain(level.iter().flat_map(|l| &l.segments)),
        usize::MAX,
        &[],
        Look::default(),
        &mut Vec::new(),
    );
    paint3d::draw_lights(&painter, &screen, &scene.lights);
    let filter = Filter {
        max_generation: selection.max_generation(),
        ..view.filter.clone()
    };
    let drawn = draw_trees(selection, scene, &painter, &screen, &depth, &filter);
    // The key of ray colours, where it leaves most of the view free (the render pane shows
    // the same key over the image); a row of swatches in a smaller view.
    if selection.tree.is_some() {
        if rect.width() >= KEY_MIN_VIEW.0 && rect.height() >= KEY_MIN_VIEW.1 {
            super::legend::ray_key(&painter, rect);
        } else if let Some(area) = compact_key(&painter, rect)
            && response.hover_pos().is_some_and(|p| area.contains(p))
        {
            response.clone().on_hover_text_at_pointer(COMPACT_KEY_HOVER);
        }
    }
    if view.show_visits {
        visits_caption(&painter, rect, visits, tracer.accel.kind());
    }
    pick_and_hover(selection, &response, &drawn);
    view.drawn = drawn;
    if selection.tree.is_none() {
        // Wrapped to the pane: a narrow pane must not cut the hint off.
        let hint = painter.layout(
            "click a pixel in the render view to see its rays here".to_owned(),
            egui::FontId::proportional(14.0),
            Color32::from_gray(220),
            (rect.width() - 16.0).max(40.0),
        );
        painter.galley(
            rect.left_top() + egui::vec2(8.0, 8.0),
            hint,
            Color32::PLACEHOLDER,
        );
    }
}

/// Hover on drawn rays: the current tree's node under the pointer lights up everywhere.
pub(super) fn pick_and_hover_only(
    selection: &mut TreeSelection,
    response: &egui::Response,
    drawn: &[Drawn],
) {
    if let Some(pos) = response.hover_pos()
        && let Some(d) = paint3d::pick(drawn, pos)
        && d.tree == 0
    {
        selection.tree_state.hovered = Some(d.path.clone());
    }
}

/// Hover and click on drawn rays: the node lights up everywhere, a click selects it (a ray of
/// an extra tree makes that tree the current one).
pub(super) fn pick_and_hover(
    selection: &mut TreeSelection,
    response: &egui::Response,
    drawn: &[Drawn],
) {
    pick_and_hover_only(selection, response, drawn);
    if response.clicked()
        && let Some(pos) = response.interact_pointer_pos()
        && let Some(d) = paint3d::pick(drawn, pos)
    {
        if d.tree > 0 {
            selection.make_current(d.tree - 1);
        }
        selection.tree_state.selected = Some(d.path.clone());
    }
}

impl SceneView {
    /// Pieces of rays drawn in the last frame (for tests: how many the view shows).
    pub fn drawn_count(&self) -> usize {
        self.drawn.len()
    }

    /// Whether the view's render reached its samples (or stopped).
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// How many triangles the picture shown leaves out (walls cut away).
    pub fn walls_cut(&self) -> usize {
        self.shown_cut.len()
    }

    /// The view's render generation: it grows with every restart.
    pub fn generation(&self) -> u64 {
        self.generation
    }
}

/// The compact key's entries: a short label and the style whose colour it shows.
const COMPACT_KEY: [(&str, Style); 5] = [
    ("pri", Style::Ray(crate::trace::RayKind::Primary)),
    ("refl", Style::Ray(crate::trace::RayKind::Reflected)),
    ("refr", Style::Ray(crate::trace::RayKind::Refracted)),
    ("lit", Style::ShadowLit),
    ("blk", Style::ShadowBlocked),
];

/// What the compact key's short labels stand for, shown when the pointer is over it.
const COMPACT_KEY_HOVER: &str = "pri: primary ray\nrefl: reflected ray\nrefr: refracted ray\nlit: shadow ray that reached its light\nblk: shadow ray blocked (faded past its blocker)";

/// The width (points) of one entry of the compact key: a swatch and a short label.
const COMPACT_ENTRY: f32 = 44.0;

/// The places of the compact key's entries in a view `rect`: a row along its bottom left,
/// wrapped to the view's width; `None` when the view is too small to spare it.
pub fn compact_key_layout(rect: egui::Rect) -> Option<Vec<egui::Rect>> {
    let row = 16.0;
    let per_row = (((rect.width() - 12.0) / COMPACT_ENTRY).floor() as usize).min(COMPACT_KEY.len());
    if per_row < 2 {
        return None;
    }
    let rows = COMPACT_KEY.len().div_ceil(per_row);
    if rect.height() < 4.0 * row * rows as f32 {
        return None;
    }
    let top = rect.max.y - 6.0 - row * rows as f32;
    Some(
        (0..COMPACT_KEY.len())
            .map(|i| {
                let (r, c) = (i / per_row, i % per_row);
                egui::Rect::from_min_size(
                    egui::pos2(
                        rect.min.x + 6.0 + c as f32 * COMPACT_ENTRY,
                        top + r as f32 * row,
                    ),
                    egui::vec2(COMPACT_ENTRY, row),
                )
            })
            .collect(),
    )
}

/// Draws the compact key in `rect` and returns the area it covers (for its hover).
fn compact_key(painter: &egui::Painter, rect: egui::Rect) -> Option<egui::Rect> {
    let places = compact_key_layout(rect)?;
    let area = places
        .iter()
        .fold(places[0], |a, p| a.union(*p))
        .expand(2.0);
    painter.rect_filled(area, 4.0, Color32::from_rgba_unmultiplied(25, 25, 25, 200));
    let font = egui::FontId::proportional(11.0);
    for (place, (label, style)) in places.iter().zip(COMPACT_KEY) {
        let [r, g, b, _] = scene_view::style_rgba(style);
        let y = place.center().y;
        painter.line_segment(
            [
                egui::pos2(place.min.x + 3.0, y),
                egui::pos2(place.min.x + 15.0, y),
            ],
            egui::Stroke::new(3.0, Color32::from_rgb(r, g, b)),
        );
        painter.text(
            egui::pos2(place.min.x + 18.0, y),
            egui::Align2::LEFT_CENTER,
            label,
            font.clone(),
            Color32::from_gray(225),
        );
    }
    Some(area)
}

/// What the cyan boxes are, at the top of the view while they are shown: `boxes` is how many
/// the selected ray entered (`None`: no ray is selected).
fn visits_caption(
    painter: &egui::Painter,
    rect: egui::Rect,
    boxes: Option<usize>,
    kind: crate::accel::AccelKind,
) {
    let what = if kind == crate::accel::AccelKind::Grid {
        "grid cells"
    } else {
        "BVH nodes"
    };
    let text = match boxes {
        Some(n) => format!("cyan: the {n} {what} the selected ray entered"),
        None => format!("visits: select a ray to see the {what} it entered"),
    };
    let galley = painter.layout(
        text,
        egui::FontId::proportional(12.0),
        Color32::from_rgb(0, 230, 230),
        (rect.width() - 20.0).max(40.0),
    );
    let at = rect.left_top() + egui::vec2(8.0, 8.0);
    painter.rect_filled(
        egui::Rect::from_min_size(at, galley.size()).expand(3.0),
        3.0,
        Color32::from_rgba_unmultiplied(20, 20, 20, 190),
    );
    painter.galley(at, galley, Color32::PLACEHOLDER);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The level's boxes are worked out once for an accelerator and level, and again for
    /// another level or another accelerator (a rebuild).
    #[test]
    fn level_boxes_are_worked_out_once_per_accelerator_and_level() {
        let scene = Arc::new(crate::scene::load_builtin("default").expect("built-in"));
        let settings = crate::trace::TraceSettings {
            accel: crate::accel::AccelKind::Bvh,
            ..Default::default()
        };
        let tracer = Tracer::new(scene.clone(), settings);
        let mut view = SceneView::new(1).expect("a scene view");
        assert!(view.level_segments(&tracer.accel).is_none());
        let deepest = tracer.accel.levels() - 1;
        view.bvh_level = Some(deepest);
        let first = view.level_segments(&tracer.accel).expect("boxes");
        assert!(first.total > 1);
        let again = view.level_segments(&tracer.accel).expect("boxes");
        assert!(Arc::ptr_eq(&first, &again));
        view.bvh_level = Some(0);
        let root = view.level_segments(&tracer.accel).expect("boxes");
        assert_eq!((root.drawn, root.total), (1, 1));
        let rebuilt = Tracer::new(scene, settings);
        view.bvh_level = Some(deepest);
        let other = view.level_segments(&rebuilt.accel).expect("boxes");
        assert!(!Arc::ptr_eq(&first, &other));
        assert_eq!(other.total, first.total);
    }

    /// A new view shows no visits (they say nothing until asked for) and cuts walls only
    /// when the model encloses the render camera.
    #[test]
    fn visits_are_off_and_the_cut_away_automatic_by_default() {
        let view = SceneView::new(1).expect("a scene view");
        assert!(!view.show_visits);
        assert_eq!(view.cutaway, Cutaway::Auto);
    }

    /// The compact key stays inside the view, its entries apart, in a narrow pane and a
    /// narrower ones (two and three rows); a view too small for it gets none.
    #[test]
    fn the_compact_key_fits_the_view() {
        for (w, rows) in [(250.0, 1), (160.0, 2), (110.0, 3)] {
            let rect = egui::Rect::from_min_size(egui::pos2(10.0, 20.0), egui::vec2(w, 200.0));
            let places = compact_key_layout(rect).expect("a key");
            assert_eq!(places.len(), COMPACT_KEY.len());
            assert!(places.iter().all(|p| rect.contains_rect(*p)), "{places:?}");
            for (i, a) in places.iter().enumerate() {
                for b in &places[i + 1..] {
                    assert!(!a.shrink(0.5).intersects(*b), "{a:?} over {b:?}");
                }
            }
            let tops: std::collections::BTreeSet<i32> =
                places.iter().map(|p| p.min.y as i32).collect();
            assert_eq!(tops.len(), rows);
        }
        let tiny = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(80.0, 30.0));
        assert!(compact_key_layout(tiny).is_none());
    }
}
