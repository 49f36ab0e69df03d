//! The viewer's input: keyboard shortcuts and dropped files, and the viewport's pointer
//! (drag to orbit or pan, scroll to zoom, click for a pixel's ray tree, shift-click for one
//! more, Ctrl or Alt drag for a grid of a rectangle's pixels, hover for its values),
//! each turned into an edit of the working copy or a [`Command`].

use std::path::PathBuf;

use eframe::egui;

use super::dialog::BrowseFor;
use super::paint3d::ScreenView;
use super::render_view::RenderView;
use super::selection::TreeSelection;
use super::undo::WorkingCopy;
use super::viewport::{DisplayCallback, DisplayId};
use super::workspace::{Prefs, Workspace};
use super::{Command, gesture, legend, paint3d, picker, scene_pane};
use crate::scene::{Camera, CameraFrame};
use crate::scene_view::Filter;

/// Export (Ctrl+S), open (Ctrl+O), help (F1), stop (Escape), undo (Ctrl+Z), redo
/// (Ctrl+Shift+Z, Ctrl+Y), reset the camera (Home) and a file dropped on the window.
pub(super) fn shortcuts(
    ctx: &egui::Context,
    ws: &mut Workspace,
    working: &mut WorkingCopy,
    pending: &mut Vec<Command>,
) {
    use egui::{Key, KeyboardShortcut, Modifiers};
    let save = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
    let open = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
    let (do_save, do_open, help, stop) = ctx.input_mut(|i| {
        (
            i.consume_shortcut(&save),
            i.consume_shortcut(&open),
            i.consume_key(Modifiers::NONE, Key::F1),
            i.consume_key(Modifiers::NONE, Key::Escape),
        )
    });
    // A text field being typed in keeps its own Ctrl+Z and Home.
    if !ctx.egui_wants_keyboard_input() {
        let redo_shift = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        // Ctrl+Shift+Z first: the plain Ctrl+Z pattern would match it too.
        let (redo, undo, home) = ctx.input_mut(|i| {
            let redo = i.consume_shortcut(&redo_shift) | i.consume_shortcut(&redo_y);
            (
                redo,
                i.consume_shortcut(&undo),
                i.consume_key(Modifiers::NONE, Key::Home),
            )
        });
        if redo {
            working.redo(pending);
        }
        if undo {
            working.undo(pending);
        }
        if home {
            working.reset_camera(pending);
        }
    }
    if do_save {
        ws.export_choice = true;
    }
    if do_open {
        ws.browse(BrowseFor::Open, "");
    }
    if help {
        ws.show_help = !ws.show_help;
    }
    if stop {
        pending.push(Command::Stop);
    }
    let dropped: Vec<PathBuf> = ctx.input(|i| {
        i.raw
            .dropped_files
            .iter()
            .map(|f| f.path().to_path_buf())
            .collect()
    });
    if let Some(path) = dropped.into_iter().next() {
        pending.push(Command::OpenFile(path));
    }
}

/// The render pane: draws the render fitted into `ui`'s space, the trees over it (by
/// `filter`), and handles orbit, pan and zoom of the render `camera`, click and hover. While
/// `hold` (focus on the ray tree) the render keeps its size and is drawn scaled into the strip
/// it has: entering and leaving focus restart nothing and every tree keeps its pixel.
#[allow(clippy::too_many_arguments)]
pub(super) fn render_pane(
    ui: &mut egui::Ui,
    render: &mut RenderView,
    selection: &mut TreeSelection,
    camera: &mut Camera,
    prefs: &Prefs,
    filter: &Filter,
    hold: bool,
    pending: &mut Vec<Command>,
) {
    let mut avail = ui.available_rect_before_wrap();
    if avail.width() < 1.0 || avail.height() < 1.0 {
        return; // a zero-area window: nothing to draw
    }
    // A mode that maps values to colours gets its scale in a strip beside (or under) the image.
    let scene = render.scene().clone();
    let scale = super::modes::colour_scale(prefs.mode, scene.render.max_depth);
    if let Some(scale) = &scale
        && avail.width() > 2.0 * legend::SCALE_WIDTH
        && avail.height() > 2.0 * legend::SCALE_HEIGHT
    {
        let (rw, rh) = render.size();
        let (image, strip, below) = legend::place_scale(avail, rw as f32, rh as f32);
        avail = image;
        let length = if below {
            strip.width() * 0.8
        } else {
            strip.height() * 0.6
        };
        ui.scope_builder(
            egui::UiBuilder::new().max_rect(strip.shrink2(egui::vec2(4.0, 6.0))),
            |ui| legend::colour_scale_ui(ui, scale, length, below),
        );
    }
    // The render follows the image area's size (when set); it is drawn fitted, on whole pixels.
    if !hold && render.observe_pane(ui.ctx(), avail, prefs) {
        pending.push(Command::MoveCamera);
    }
    let (w, h) = (scene.render.width as f32, scene.render.height as f32);
    let rect = render.image_rect(ui.ctx(), avail);
    let size = rect.size();
    let scale = size.x / w;
    let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "render viewport"));
    ui.painter()
        .add(eframe::egui_wgpu::Callback::new_paint_callback(
            rect,
            DisplayCallback {
                id: DisplayId::Render,
                shared: render.display.clone(),
            },
        ));
    // The trees' rays over the image, by the scene view's rules and widths, seen from the
    // render camera; parts behind surfaces (the render's own depth) dimmed.
    selection.sync();
    picker::step_keys(ui.ctx(), selection);
    let mut drawn = Vec::new();
    if selection.tree.is_some() || !selection.extra_trees.is_empty() {
        let (sw, sh) = (scene.render.width, scene.render.height);
        let view = ScreenView {
            rect,
            frame: CameraFrame::new(&scene.camera, sw, sh),
            width: sw,
            height: sh,
        };
        let filter = Filter {
            max_generation: selection.max_generation(),
            ..filter.clone()
        };
        let depth = render.film.depth();
        let painter = ui.painter_at(rect);
        drawn = scene_pane::draw_trees(selection, &scene, &painter, &view, &depth, &filter);
        pixel_rings(selection, &painter, rect, scale);
        legend::ray_key(&painter, rect);
    }
    let to_pixel = |p: egui::Pos2| {
        let x = ((p.x - rect.min.x) / scale).floor();
        let y = ((p.y - rect.min.y) / scale).floor();
        (x >= 0.0 && y >= 0.0 && x < w && y < h).then_some((x as u32, y as u32))
    };
    selection.hover = response.hover_pos().and_then(to_pixel);
    let modifiers = ui.input(|i| i.modifiers);
    // A plain click near a drawn ray selects that ray's node (every tree stays); elsewhere it
    // picks the pixel. Shift-click always adds a pixel.
    let at = response.interact_pointer_pos();
    let on_ray = !modifiers.shift && at.is_some_and(|p| paint3d::pick(&drawn, p).is_some());
    if on_ray {
        scene_pane::pick_and_hover(selection, &response, &drawn);
    } else {
        scene_pane::pick_and_hover_only(selection, &response, &drawn);
    }
    if response.clicked()
        && !on_ray
        && let Some((x, y)) = at.and_then(to_pixel)
    {
        pending.push(if modifiers.shift {
            Command::PickMore(x, y)
        } else {
            Command::Pick(x, y)
        });
    }
    // Ctrl (or Alt) and drag: a rectangle of pixels whose trees are traced on release.
    let selecting = modifiers.command || modifiers.alt;
    if selecting && response.dragged_by(egui::PointerButton::Primary) {
        if let (Some(origin), Some(now)) = (
            ui.input(|i| i.pointer.press_origin()),
            response.interact_pointer_pos(),
        ) {
            selection.rect_select = Some((origin, now));
            ui.painter_at(rect).rect_stroke(
                egui::Rect::from_two_pos(origin, now),
                0.0,
                egui::Stroke::new(2.0, egui::Color32::from_rgb(255, 120, 255)),
                egui::StrokeKind::Middle,
            );
        }
        return;
    }
    if let Some((origin, end)) = selection.rect_select.take()
        && selecting
        && response.drag_stopped()
    {
        let inside = |p: egui::Pos2| to_pixel(rect.shrink(0.01).clamp(p));
        if let (Some(a), Some(b)) = (inside(origin), inside(end)) {
            pending.push(Command::PickRect([a.0, a.1], [b.0, b.1]));
        }
        return;
    }
    let delta = response.drag_delta();
    if delta != egui::Vec2::ZERO {
        if response.dragged_by(egui::PointerButton::Primary) {
            let (yaw, pitch) = gesture::orbit_angles(delta, size.x, prefs.orbit_degrees);
            camera.orbit(yaw, pitch);
            pending.push(Command::MoveCamera);
        } else if response.dragged_by(egui::PointerButton::Secondary)
            || response.dragged_by(egui::PointerButton::Middle)
        {
            camera.pan(delta.x / size.y, delta.y / size.y);
            pending.push(Command::MoveCamera);
        }
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom((-scroll * 0.002).exp());
            pending.push(Command::MoveCamera);
        }
    }
}

/// A ring in its tree's tint around each picked pixel (the selected one larger), so the
/// picker's rows are found on the image; `scale` is screen points per image pixel.
fn pixel_rings(selection: &TreeSelection, painter: &egui::Painter, rect: egui::Rect, scale: f32) {
    let current = selection.tree.as_ref().map(|t| t.pixel);
    for e in &selection.picker.entries {
        let at = rect.min + egui::vec2(e.pixel[0] as f32 + 0.5, e.pixel[1] as f32 + 0.5) * scale;
        let [r, g, b] = crate::scene_view::tree_tint(e.tint);
        let (radius, width) = if current == Some(e.pixel) {
            (7.0, 2.5)
        } else {
            (4.5, 1.5)
        };
        painter.circle_stroke(
            at,
            radius,
            egui::Stroke::new(width, egui::Color32::from_rgb(r, g, b)),
        );
    }
}
