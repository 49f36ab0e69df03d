//! The tree picker on screen: [`strip`] above the tree's panes lists the picked trees (the
//! state is [`super::tree_picks::Picker`]), steps through them and sets the rectangle grid;
//! [`step_keys`] steps with the keyboard.

use eframe::egui::{self, Color32, Ui};

use super::selection::TreeSelection;
use super::tree_picks::MAX_GRID_SIDE;
use crate::ray_tree::RayTree;
use crate::scene_view::tree_tint;
use crate::trace::Tracer;

/// What a picker row says of a tree: its pixel, the first object met, the depth reached and
/// how many rays were traced.
pub fn summary(tree: &RayTree) -> String {
    let met = tree
        .root
        .hit
        .as_ref()
        .map_or("nothing".to_owned(), |h| h.object.clone());
    let [x, y] = tree.pixel;
    format!(
        "({x}, {y}) {met} · depth {} · {}",
        crate::app::scene_pane::deepest([tree]),
        crate::plural::count(tree.rays.total(), "ray")
    )
}

fn tint_color(tint: usize) -> Color32 {
    let [r, g, b] = tree_tint(tint);
    Color32::from_rgb(r, g, b)
}

/// A square of tint `tint`, the height of a line of text.
fn swatch(ui: &mut Ui, tint: usize) {
    let h = ui.text_style_height(&egui::TextStyle::Body) * 0.8;
    let (rect, _) = ui.allocate_exact_size(egui::vec2(h, h), egui::Sense::hover());
    ui.painter().rect_filled(rect, 2.0, tint_color(tint));
}

/// Up/Down (or `[` and `]`) select the previous or next tree of the picker, unless a text field
/// has the keyboard.
pub fn step_keys(ctx: &egui::Context, selection: &mut TreeSelection) {
    use egui::{Key, Modifiers};
    if ctx.egui_wants_keyboard_input() {
        return;
    }
    let (up, down) = ctx.input_mut(|i| {
        let up = i.consume_key(Modifiers::NONE, Key::ArrowUp)
            | i.consume_key(Modifiers::NONE, Key::OpenBracket);
        let down = i.consume_key(Modifiers::NONE, Key::ArrowDown)
            | i.consume_key(Modifiers::NONE, Key::CloseBracket);
        (up, down)
    });
    match (up, down) {
        (true, false) => selection.step(-1),
        (false, true) => selection.step(1),
        _ => {}
    }
}

/// The picker above a tree pane: with two trees or more, one line with the selected tree
/// (◀ ▶ step, its tint, pixel, first object, depth, rays) and a toggle for the list of every
/// tree, each row selecting its tree; the grid's density and depth beside. Returns the
/// current tree, for the pane below.
pub fn strip(ui: &mut Ui, selection: &mut TreeSelection, tracer: &Tracer) -> Option<RayTree> {
    strip_ui(ui, selection, tracer);
    selection.tree.clone()
}

fn strip_ui(ui: &mut Ui, selection: &mut TreeSelection, tracer: &Tracer) {
    selection.sync();
    step_keys(ui.ctx(), selection);
    let count = selection.picker.entries.len();
    if count < 2 {
        return;
    }
    let current = selection.tree.as_ref().map(|t| t.pixel);
    let index = current.and_then(|p| selection.picker.index_of(p));
    ui.horizontal(|ui| {
        if ui
            .small_button("◀")
            .on_hover_text("previous tree (Up or [)")
            .clicked()
        {
            selection.step(-1);
        }
        ui.label(format!("tree {} of {count}", index.map_or(0, |i| i + 1)));
        if ui
            .small_button("▶")
            .on_hover_text("next tree (Down or ])")
            .clicked()
        {
            selection.step(1);
        }
        if let (Some(i), Some(tree)) = (index, &selection.tree) {
            swatch(ui, selection.picker.entries[i].tint);
            ui.add(egui::Label::new(summary(tree)).truncate())
                .on_hover_text(summary(tree));
        }
    });
    ui.horizontal_wrapped(|ui| {
        let picker = &mut selection.picker;
        let label = if picker.expanded {
            "hide the list"
        } else {
            "list all trees"
        };
        if ui.small_button(label).clicked() {
            picker.expanded = !picker.expanded;
        }
        // Each label stays with its value when the strip wraps.
        let side = ui
            .horizontal(|ui| {
                ui.label("grid");
                ui.add(
                    egui::DragValue::new(&mut picker.grid.per_side)
                        .range(1..=MAX_GRID_SIDE)
                        .suffix(" per side"),
                )
                .on_hover_text("Ctrl+drag picks at most this many pixels across and down")
            })
            .inner;
        ui.horizontal(|ui| {
            ui.label("to depth");
            ui.add(egui::DragValue::new(&mut picker.grid.depth).range(0..=64))
                .on_hover_text(
                    "the other trees of a grid are drawn down to this generation; the selected one whole",
                );
        });
        if side.changed()
            && let Some((a, b)) = picker.last_rect
        {
            selection.regrid(tracer, a, b);
        }
    });
    if selection.picker.expanded {
        let row = ui.text_style_height(&egui::TextStyle::Body) + 4.0;
        egui::ScrollArea::vertical()
            .id_salt("tree picker")
            .max_height(row * 5.0)
            .show(ui, |ui| {
                let mut chosen = None;
                for (i, e) in selection.picker.entries.iter().enumerate() {
                    let Some(tree) = selection.trees().find(|t| t.pixel == e.pixel) else {
                        continue;
                    };
                    ui.horizontal(|ui| {
                        swatch(ui, e.tint);
                        let on = Some(i) == index;
                        let text = summary(tree);
                        if ui
                            .add(egui::Button::selectable(on, text.clone()).truncate())
                            .on_hover_text(text)
                            .clicked()
                        {
                            chosen = Some(e.pixel);
                        }
                    });
                }
                if let Some(pixel) = chosen {
                    selection.select_pixel(pixel);
                }
            });
    }
    ui.separator();
}
