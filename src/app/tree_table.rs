//! The ray tree's list and the selected node's numbers as tables (egui_extras): resizable
//! columns whose text is elided with the full value on hover, never silently cut. The list
//! folds subtrees as the diagram does (shared [`TreeState::folded`]), a folded row saying how
//! many nodes it holds.

use eframe::egui::{self, Color32, Response, RichText, Sense, Ui};
use egui_extras::{Column, TableBuilder};
use glam::Vec3;

use super::tree_view::{Cell, TreeState, kind_color, node_differs, node_summary};
use crate::diagram::{descendants, end_text};
use crate::ray_tree::{Node, RayTree};
use crate::scene::Shading;
use crate::scene_view::{NodePath, Style, kind_rgb, node_at, style_rgba};
use crate::trace::RayKind;

/// Height of a table row: one line of body text.
const ROW_H: f32 = 20.0;
/// Points a row is indented per generation in the list's first column.
const INDENT: f32 = 10.0;
/// The colour of rows and values that differ from the other tree.
const CHANGED: Color32 = Color32::from_rgb(255, 150, 50);

fn fmt3(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn kind_name(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Primary => "primary",
        RayKind::Reflected => "R",
        RayKind::Refracted => "T",
        RayKind::Shadow => "S",
    }
}

/// One cell's text, elided to its column with the full text on hover; recorded in `cells`.
fn cell(ui: &mut Ui, text: RichText, cells: &mut Vec<Cell>) -> Response {
    let column = ui.available_width();
    let full = egui::WidgetText::from(text.clone())
        .into_galley(
            ui,
            Some(egui::TextWrapMode::Extend),
            f32::INFINITY,
            egui::TextStyle::Body,
        )
        .size()
        .x;
    let r = ui.add(egui::Label::new(text).truncate().selectable(false));
    cells.push(Cell {
        full,
        shown: r.rect.width(),
        column,
        elided: full > column,
    });
    r
}

/// The rows the list shows: every node in pre-order, below a folded one left out.
fn rows<'a>(node: &'a Node, path: &mut NodePath, state: &TreeState, out: &mut Vec<(NodePath, &'a Node)>) {
    out.push((path.clone(), node));
    if state.is_folded(path) {
        return;
    }
    for (i, child) in node.children.iter().enumerate() {
        path.push(i);
        rows(child, path, state, out);
        path.pop();
    }
}

/// What a node's ray met, for the list's second column.
fn met(node: &Node) -> String {
    match (&node.end, &node.hit) {
        (Some(end), _) => end_text(*end).to_string(),
        (None, Some(hit)) => format!("{} ({})", hit.object, hit.material),
        _ => String::new(),
    }
}

/// The tree as a table of rows (ray, what it met, colour); `other` marks the rows that differ
/// from another tree. A row's toggle folds its subtree, here and in the diagram.
pub fn tree_list(
    ui: &mut Ui,
    tree: &RayTree,
    state: &mut TreeState,
    other: Option<&RayTree>,
    salt: &str,
) {
    state.folds_for(tree);
    let mut list = Vec::new();
    rows(&tree.root, &mut Vec::new(), state, &mut list);
    let mut cells = Vec::new();
    let mut fold = None;
    let mut select = None;
    let mut hover = None;
    TableBuilder::new(ui)
        .id_salt(("tree list", salt))
        .striped(true)
        .resizable(true)
        .vscroll(false)
        .sense(Sense::click())
        .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
        .column(Column::initial(110.0).at_least(50.0).clip(true))
        .column(Column::initial(170.0).at_least(60.0).clip(true))
        .column(Column::remainder().at_least(60.0).clip(true))
        .header(ROW_H, |mut header| {
            for name in ["ray", "met", "colour"] {
                header.col(|ui| {
                    ui.strong(name);
                });
            }
        })
        .body(|mut body| {
            for (path, node) in &list {
                let differs = other.map(|o| match node_at(&o.root, path) {
                    Some(theirs) => node_differs(node, theirs),
                    None => true,
                }) == Some(true);
                let tint = if differs {
                    CHANGED
                } else {
                    kind_color(node.kind)
                };
                body.row(ROW_H, |mut row| {
                    row.set_selected(state.selected.as_ref() == Some(path));
                    row.set_hovered(state.hovered.as_ref() == Some(path));
                    row.col(|ui| {
                        ui.add_space(node.depth as f32 * INDENT);
                        if node.children.is_empty() {
                            ui.add_space(16.0);
                        } else {
                            let folded = state.is_folded(path);
                            let toggle = ui
                                .add(
                                    egui::Button::new(if folded { "⏵" } else { "⏷" })
                                        .small()
                                        .frame(false),
                                )
                                .on_hover_text(if folded { "unfold" } else { "fold" });
                            if toggle.clicked() {
                                fold = Some(path.clone());
                            }
                        }
                        let text = format!(
                            "{}{} d{}",
                            if differs { "* " } else { "" },
                            kind_name(node.kind),
                            node.depth
                        );
                        cell(ui, RichText::new(text).color(tint), &mut cells);
                    });
                    row.col(|ui| {
                        let mut text = met(node);
                        if state.is_folded(path) {
                            text = format!("{text} · +{} below", descendants(node));
                        }
                        cell(ui, RichText::new(text).color(tint), &mut cells);
                    });
                    row.col(|ui| {
                        cell(ui, RichText::new(fmt3(node.color)).monospace(), &mut cells);
                    });
                    let r = row.response();
                    if r.hovered() {
                        hover = Some(path.clone());
                    }
                    if r.clicked() {
                        select = Some(path.clone());
                    }
                    let _ = r.on_hover_text(node_summary(node));
                });
            }
        });
    if let Some(path) = fold {
        state.toggle_fold(&path);
    }
    if hover.is_some() {
        state.hovered = hover;
    }
    if select.is_some() {
        state.selected = select;
    }
    state.drawn.cells.extend(cells);
}

/// A row of the detail table: a name, its value and the value's colour.
struct Row {
    name: String,
    value: String,
    tint: Option<Color32>,
}

fn push(rows: &mut Vec<Row>, name: &str, value: String) {
    rows.push(Row {
        name: name.to_string(),
        value,
        tint: None,
    });
}

fn rgb(style: Style) -> Color32 {
    let [r, g, b, _] = style_rgba(style);
    Color32::from_rgb(r, g, b)
}

/// The numbers of `node`, as rows.
fn detail_rows(node: &Node, phong: bool) -> Vec<Row> {
    let mut rows = Vec::new();
    let r = &mut rows;
    push(r, "weight", fmt3(node.weight));
    push(r, "origin", fmt3(node.origin));
    push(r, "direction", fmt3(node.direction));
    if let Some(end) = node.end {
        push(
            r,
            "ended",
            format!("{} -> colour {}", end_text(end), fmt3(node.color)),
        );
    }
    if let Some(hit) = &node.hit {
        push(r, "object", format!("{} ({})", hit.object, hit.material));
        push(r, "t", format!("{:.6}", hit.t));
        push(r, "P", fmt3(hit.point));
        push(
            r,
            "N",
            format!(
                "{}{}",
                fmt3(hit.normal),
                if hit.front_face { "" } else { " (inside)" }
            ),
        );
        if let Some(b) = hit.barycentric {
            push(
                r,
                "barycentric",
                format!("({:.4}, {:.4}, {:.4})", b[0], b[1], b[2]),
            );
        }
        if let Some(ng) = hit.geometric_normal {
            push(r, "N geometric", fmt3(ng));
        }
        if let Some([u, v]) = hit.uv {
            push(r, "UV", format!("({u:.4}, {v:.4})"));
        }
        if let Some(t) = hit.texel {
            push(r, "texel (× kd)", fmt3(t));
        }
    }
    if node.direction_corrected {
        push(
            r,
            "direction",
            "corrected: mirrored back across the geometric plane".into(),
        );
    }
    if let Some(v) = node.view {
        push(r, "V", fmt3(v));
    }
    for s in &node.shadow_rays {
        let verdict = if s.facing_away {
            "facing away (N·L <= 0): adds nothing".to_string()
        } else if s.behind_surface {
            "behind the geometric surface: adds nothing".to_string()
        } else if s.contributes_nothing {
            "not traced: contributes nothing (kd and ks give zero)".to_string()
        } else if let Some(b) = &s.blocked_by {
            format!(
                "blocked by {b}{}",
                s.blocked_at
                    .map(|d| format!(" at {d:.4}"))
                    .unwrap_or_default()
            )
        } else {
            "lit".to_string()
        };
        r.push(Row {
            name: format!("light {}", s.light),
            value: verdict,
            tint: Some(if s.blocked_by.is_some() {
                rgb(Style::ShadowBlocked)
            } else {
                let [cr, cg, cb] = kind_rgb(RayKind::Shadow);
                Color32::from_rgb(cr, cg, cb)
            }),
        });
        push(r, "  L", fmt3(s.to_light));
        push(r, "  distance", format!("{:.4}", s.distance));
        push(r, "  N·L", format!("{:.6}", s.n_dot_l));
        if phong {
            push(r, "  R (Phong)", fmt3(s.mirror));
            push(r, "  R·V", format!("{:.6}", s.r_dot_v));
        } else {
            push(r, "  H (Blinn)", fmt3(s.halfway));
            push(r, "  N·H", format!("{:.6}", s.n_dot_h));
        }
        push(r, "  diffuse", fmt3(s.diffuse));
        push(r, "  specular", fmt3(s.specular));
    }
    if let Some(local) = &node.local {
        push(r, "ambient ka·A", fmt3(local.ambient));
        push(r, "diffuse (all lights)", fmt3(local.diffuse));
        push(r, "specular (all lights)", fmt3(local.specular));
        push(r, "local", fmt3(local.total));
        let mut sum = local.total;
        for child in &node.children {
            let (name, w) = match child.kind {
                RayKind::Reflected => ("kr · reflected", node.kr.unwrap_or(Vec3::ZERO)),
                _ => ("kt · refracted", node.kt.unwrap_or(Vec3::ZERO)),
            };
            let term = w * child.color;
            sum += term;
            push(
                r,
                name,
                format!("{} · {} = {}", fmt3(w), fmt3(child.color), fmt3(term)),
            );
        }
        if node.total_internal_reflection {
            push(r, "TIR", "total internal reflection: kt moved to R".into());
        }
        let ok = (sum - node.color).abs().max_element()
            <= 1e-5 * node.color.abs().max_element().max(1.0);
        push(
            r,
            "sum = colour",
            format!(
                "{} {}",
                fmt3(sum),
                if ok {
                    "(equals the node colour)"
                } else {
                    "(DIFFERS from the node colour)"
                }
            ),
        );
    }
    rows
}

/// Every number behind the selected node's colour, as a table of names and values.
pub fn detail(ui: &mut Ui, tree: &RayTree, path: &[usize]) {
    let Some(node) = node_at(&tree.root, path) else {
        return;
    };
    let mut cells = Vec::new();
    cell(
        ui,
        RichText::new(node_summary(node))
            .strong()
            .color(kind_color(node.kind)),
        &mut cells,
    );
    let rows = detail_rows(node, tree.settings.shading == Shading::Phong);
    TableBuilder::new(ui)
        .id_salt("tree detail table")
        .striped(true)
        .resizable(true)
        .vscroll(false)
        .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
        .column(Column::initial(140.0).at_least(50.0).clip(true))
        .column(Column::remainder().at_least(80.0).clip(true))
        .body(|mut body| {
            for r in &rows {
                body.row(ROW_H, |mut row| {
                    row.col(|ui| {
                        cell(ui, RichText::new(&r.name), &mut cells);
                    });
                    row.col(|ui| {
                        let text = RichText::new(&r.value).monospace();
                        let text = match r.tint {
                            Some(c) => text.color(c),
                            None => text,
                        };
                        cell(ui, text, &mut cells);
                    });
                });
            }
        });
}
