//! The clicked pixel's ray tree in three linked views — a collapsible list, a diagram like the
//! lecture's "Ray Tracing Tree" figure, and ray segments over the image (see `viewport.rs`) —
//! plus a detail pane with every number behind the selected node's colour, and a pinned tree
//! to compare against. Hovering or selecting a node in one view highlights it in the others.

use eframe::egui::{self, Color32, Pos2, Rect, RichText, Sense, Stroke, Ui, Vec2};
use glam::Vec3;

use crate::ray_tree::{Node, RayTree};
use crate::scene::Shading;
use crate::trace::{EndReason, RayKind};

/// A node's place: the child indices from the root.
pub type NodePath = Vec<usize>;

/// Which node is hovered and selected, and the pinned tree; shared by the views.
#[derive(Clone, Debug, Default)]
pub struct TreeState {
    pub selected: Option<NodePath>,
    pub hovered: Option<NodePath>,
    pub pinned: Option<RayTree>,
    /// The step-through: show generations `0..=reveal` only (`None`: all).
    pub reveal: Option<u32>,
}

/// The one palette of ray kinds, shared by every view of the tree and by the overlay (sRGB).
pub fn kind_rgb(kind: RayKind) -> [u8; 3] {
    match kind {
        RayKind::Primary => [235, 235, 235],
        RayKind::Reflected => [80, 170, 255],
        RayKind::Refracted => [90, 220, 120],
        RayKind::Shadow => [255, 200, 60],
    }
}

/// Shadow rays that are blocked, up to the blocker; past it they are drawn darker.
pub const SHADOW_BLOCKED_RGB: [u8; 3] = [220, 60, 60];
pub const SHADOW_PAST_BLOCKER_RGB: [u8; 3] = [90, 30, 30];
/// Normals at hits.
pub const NORMAL_RGB: [u8; 3] = [255, 0, 255];
/// The hovered or selected node.
pub const HIGHLIGHT_RGB: [u8; 3] = [255, 255, 255];

fn color(rgb: [u8; 3]) -> Color32 {
    Color32::from_rgb(rgb[0], rgb[1], rgb[2])
}

pub fn kind_color(kind: RayKind) -> Color32 {
    color(kind_rgb(kind))
}

pub fn node_at<'a>(root: &'a Node, path: &[usize]) -> Option<&'a Node> {
    let mut node = root;
    for &i in path {
        node = node.children.get(i)?;
    }
    Some(node)
}

fn fmt3(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn kind_letter(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Primary => "primary",
        RayKind::Reflected => "R",
        RayKind::Refracted => "T",
        RayKind::Shadow => "S",
    }
}

pub fn end_label(end: EndReason) -> &'static str {
    match end {
        EndReason::NoHit => "no hit",
        EndReason::HitLight => "hit light",
        EndReason::MaxDepth => "max depth",
        EndReason::Cutoff => "cutoff",
        EndReason::Budget => "ray budget",
    }
}

/// One line naming what a node's ray met.
pub fn node_summary(node: &Node) -> String {
    let what = match (&node.end, &node.hit) {
        (Some(end), _) => end_label(*end).to_string(),
        (None, Some(hit)) => format!("{} ({})", hit.object, hit.material),
        _ => String::new(),
    };
    format!(
        "{} d{} · {what} · {}",
        kind_letter(node.kind),
        node.depth,
        fmt3(node.color)
    )
}

/// Whether two nodes at the same place differ in what they show.
pub fn node_differs(a: &Node, b: &Node) -> bool {
    let close = |x: Vec3, y: Vec3| (x - y).abs().max_element() <= 1e-6;
    a.kind != b.kind
        || a.end != b.end
        || a.hit.as_ref().map(|h| (&h.object, &h.material))
            != b.hit.as_ref().map(|h| (&h.object, &h.material))
        || !close(a.color, b.color)
        || a.children.len() != b.children.len()
        || a.shadow_rays
            .iter()
            .map(|s| s.blocked_by.as_deref())
            .ne(b.shadow_rays.iter().map(|s| s.blocked_by.as_deref()))
}

// ---- the list -----------------------------------------------------------------------------

/// The tree as collapsible rows; `other` marks the rows that differ from another tree.
pub fn tree_list(
    ui: &mut Ui,
    tree: &RayTree,
    state: &mut TreeState,
    other: Option<&RayTree>,
    salt: &str,
) {
    let mut path = Vec::new();
    let compare = other.is_some();
    list_node(
        ui,
        &tree.root,
        other.map(|o| &o.root),
        compare,
        &mut path,
        state,
        salt,
    );
}

fn list_node(
    ui: &mut Ui,
    node: &Node,
    other: Option<&Node>,
    compare: bool,
    path: &mut NodePath,
    state: &mut TreeState,
    salt: &str,
) {
    let differs = match other {
        Some(o) => node_differs(node, o),
        // A node the other tree does not have at all.
        None => compare,
    };
    let selected = state.selected.as_deref() == Some(path.as_slice());
    let hovered = state.hovered.as_deref() == Some(path.as_slice());
    let mut text = RichText::new(format!(
        "{}{}",
        if differs { "* " } else { "" },
        node_summary(node)
    ))
    .color(if differs {
        Color32::from_rgb(255, 150, 50)
    } else {
        kind_color(node.kind)
    });
    if selected || hovered {
        text = text.strong().background_color(Color32::from_gray(60));
    }
    let id = ui.make_persistent_id((salt, path.clone()));
    let header = egui::collapsing_header::CollapsingState::load_with_default_open(
        ui.ctx(),
        id,
        node.depth < 3,
    );
    let (_, header_response, _) = header
        .show_header(ui, |ui| {
            let label = egui::Label::new(text).sense(Sense::click());
            // Side by side, rows are cut to their column rather than overlapping.
            let label = if compare { label.truncate() } else { label };
            let r = ui.add(label).on_hover_text(node_summary(node));
            if r.hovered() {
                state.hovered = Some(path.clone());
            }
            if r.clicked() {
                state.selected = Some(path.clone());
            }
        })
        .body(|ui| {
            for (i, child) in node.children.iter().enumerate() {
                path.push(i);
                let other_child = other.and_then(|o| o.children.get(i));
                list_node(ui, child, other_child, compare, path, state, salt);
                path.pop();
            }
        });
    let _ = header_response;
}

// ---- the diagram --------------------------------------------------------------------------

const LEVEL: f32 = 74.0;
const COLUMN: f32 = 92.0;
const RADIUS: f32 = 11.0;

/// Horizontal slot of every node: leaves get consecutive columns, parents sit over the middle
/// of their children.
fn layout(
    node: &Node,
    next_leaf: &mut f32,
    out: &mut Vec<(NodePath, f32, u32)>,
    path: &mut NodePath,
) -> f32 {
    let x = if node.children.is_empty() {
        let x = *next_leaf;
        *next_leaf += 1.0;
        x
    } else {
        let mut xs = Vec::new();
        for (i, child) in node.children.iter().enumerate() {
            path.push(i);
            xs.push(layout(child, next_leaf, out, path));
            path.pop();
        }
        (xs[0] + xs[xs.len() - 1]) * 0.5
    };
    out.push((path.clone(), x, node.depth));
    x
}

/// The lecture's "Ray Tracing Tree": surface nodes, R and T edges, shadow rays to each light
/// drawn lit or blocked, leaves labelled with why they ended.
pub fn diagram(ui: &mut Ui, tree: &RayTree, state: &mut TreeState) {
    let mut slots = Vec::new();
    let mut leaves = 0.0;
    layout(&tree.root, &mut leaves, &mut slots, &mut Vec::new());
    let depth = slots.iter().map(|s| s.2).max().unwrap_or(0) as f32;
    let size = Vec2::new(
        (leaves.max(1.0)) * COLUMN + 60.0,
        (depth + 1.0) * LEVEL + 40.0,
    );
    egui::ScrollArea::both().id_salt("diagram").show(ui, |ui| {
        let (rect, response) = ui.allocate_exact_size(size, Sense::hover());
        response.widget_info(|| {
            egui::WidgetInfo::labeled(
                egui::Role::Image,
                true,
                format!("ray tree diagram of ({}, {})", tree.pixel[0], tree.pixel[1]),
            )
        });
        let painter = ui.painter_at(rect);
        let pos = |x: f32, d: u32| {
            Pos2::new(
                rect.min.x + 40.0 + x * COLUMN,
                rect.min.y + 28.0 + d as f32 * LEVEL,
            )
        };
        let place = |p: &[usize]| slots.iter().find(|s| s.0 == p).map(|s| pos(s.1, s.2));
        // Edges first, so the nodes sit on top.
        for (path, x, d) in &slots {
            let Some(node) = node_at(&tree.root, path) else {
                continue;
            };
            let here = pos(*x, *d);
            for (i, child) in node.children.iter().enumerate() {
                let mut cp = path.clone();
                cp.push(i);
                if let Some(there) = place(&cp) {
                    let c = kind_color(child.kind);
                    painter.line_segment([here, there], Stroke::new(2.0, c));
                    let mid = here + (there - here) * 0.5;
                    painter.text(
                        mid + Vec2::new(if there.x < here.x { -8.0 } else { 8.0 }, -4.0),
                        egui::Align2::CENTER_CENTER,
                        kind_letter(child.kind),
                        egui::FontId::proportional(13.0),
                        c,
                    );
                }
            }
        }
        for (path, x, d) in &slots {
            let Some(node) = node_at(&tree.root, path) else {
                continue;
            };
            let p = pos(*x, *d);
            // Shadow rays fan out to the upper right, one per light.
            for (k, s) in node.shadow_rays.iter().enumerate() {
                let angle = -0.9 + 0.45 * k as f32;
                let tip = p + Vec2::new(angle.cos(), angle.sin()) * 30.0;
                let (c, stroke) = if s.facing_away {
                    (Color32::GRAY, 1.0)
                } else if s.blocked_by.is_some() {
                    (color(SHADOW_BLOCKED_RGB), 1.5)
                } else {
                    (color(kind_rgb(RayKind::Shadow)), 1.5)
                };
                painter.line_segment([p, tip], Stroke::new(stroke, c));
                if s.blocked_by.is_some() && !s.facing_away {
                    let d = 4.0;
                    painter.line_segment(
                        [tip - Vec2::splat(d), tip + Vec2::splat(d)],
                        Stroke::new(2.0, c),
                    );
                    painter.line_segment(
                        [tip + Vec2::new(-d, d), tip + Vec2::new(d, -d)],
                        Stroke::new(2.0, c),
                    );
                } else {
                    painter.circle_filled(tip, 3.0, c);
                }
            }
            let id = ui.make_persistent_id(("diagram node", path.clone()));
            let node_rect = Rect::from_center_size(p, Vec2::splat(RADIUS * 2.0 + 4.0));
            let r = ui.interact(node_rect, id, Sense::click());
            let label = match (&node.end, &node.hit) {
                (Some(end), _) => end_label(*end).to_string(),
                (None, Some(hit)) => hit.object.clone(),
                _ => String::new(),
            };
            r.widget_info(|| {
                egui::WidgetInfo::labeled(
                    egui::Role::Button,
                    true,
                    format!("tree node {}: {label}", kind_letter(node.kind)),
                )
            });
            if r.hovered() {
                state.hovered = Some(path.clone());
            }
            if r.clicked() {
                state.selected = Some(path.clone());
            }
            let active = state.selected.as_deref() == Some(path.as_slice())
                || state.hovered.as_deref() == Some(path.as_slice());
            let fill = Color32::from_rgb(
                (node.color.x.clamp(0.0, 1.0) * 255.0) as u8,
                (node.color.y.clamp(0.0, 1.0) * 255.0) as u8,
                (node.color.z.clamp(0.0, 1.0) * 255.0) as u8,
            );
            if node.end.is_some() {
                // A leaf that was not shaded: a square with its end reason.
                painter.rect_filled(
                    Rect::from_center_size(p, Vec2::splat(RADIUS * 1.6)),
                    2.0,
                    fill,
                );
            } else {
                painter.circle_filled(p, RADIUS, fill);
            }
            painter.circle_stroke(
                p,
                RADIUS + 1.0,
                Stroke::new(
                    if active { 3.0 } else { 1.5 },
                    if active {
                        color(HIGHLIGHT_RGB)
                    } else {
                        kind_color(node.kind)
                    },
                ),
            );
            if node.total_internal_reflection {
                painter.text(
                    p + Vec2::new(RADIUS + 4.0, 0.0),
                    egui::Align2::LEFT_CENTER,
                    "TIR",
                    egui::FontId::proportional(11.0),
                    Color32::from_rgb(255, 150, 50),
                );
            }
            painter.text(
                p + Vec2::new(0.0, RADIUS + 9.0),
                egui::Align2::CENTER_CENTER,
                label,
                egui::FontId::proportional(11.0),
                ui.visuals().text_color(),
            );
        }
    });
}

// ---- the numbers --------------------------------------------------------------------------

fn row(ui: &mut Ui, name: &str, value: String) {
    ui.label(name);
    ui.monospace(value);
    ui.end_row();
}

/// Every number behind the selected node's colour.
pub fn detail(ui: &mut Ui, tree: &RayTree, path: &[usize]) {
    let Some(node) = node_at(&tree.root, path) else {
        return;
    };
    let phong = tree.settings.shading == Shading::Phong;
    ui.label(
        RichText::new(node_summary(node))
            .strong()
            .color(kind_color(node.kind)),
    );
    egui::Grid::new(("detail", path.to_vec()))
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            row(ui, "weight", fmt3(node.weight));
            row(ui, "origin", fmt3(node.origin));
            row(ui, "direction", fmt3(node.direction));
            if let Some(end) = node.end {
                row(
                    ui,
                    "ended",
                    format!("{} -> colour {}", end_label(end), fmt3(node.color)),
                );
            }
            if let Some(hit) = &node.hit {
                row(ui, "object", format!("{} ({})", hit.object, hit.material));
                row(ui, "t", format!("{:.6}", hit.t));
                row(ui, "P", fmt3(hit.point));
                row(
                    ui,
                    "N",
                    format!(
                        "{}{}",
                        fmt3(hit.normal),
                        if hit.front_face { "" } else { " (inside)" }
                    ),
                );
                if let Some(b) = hit.barycentric {
                    row(
                        ui,
                        "barycentric",
                        format!("({:.4}, {:.4}, {:.4})", b[0], b[1], b[2]),
                    );
                }
            }
            if let Some(v) = node.view {
                row(ui, "V", fmt3(v));
            }
        });
    for s in &node.shadow_rays {
        ui.separator();
        let verdict = if s.facing_away {
            "facing away (N·L <= 0): adds nothing".to_string()
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
        ui.label(
            RichText::new(format!("light {}: {verdict}", s.light)).color(
                if s.blocked_by.is_some() {
                    color(SHADOW_BLOCKED_RGB)
                } else {
                    color(kind_rgb(RayKind::Shadow))
                },
            ),
        );
        egui::Grid::new(("light", path.to_vec(), s.light.clone()))
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                row(ui, "L", fmt3(s.to_light));
                row(ui, "distance", format!("{:.4}", s.distance));
                row(ui, "N·L", format!("{:.6}", s.n_dot_l));
                if phong {
                    row(ui, "R (Phong)", fmt3(s.mirror));
                    row(ui, "R·V", format!("{:.6}", s.r_dot_v));
                } else {
                    row(ui, "H (Blinn)", fmt3(s.halfway));
                    row(ui, "N·H", format!("{:.6}", s.n_dot_h));
                }
                row(ui, "diffuse", fmt3(s.diffuse));
                row(ui, "specular", fmt3(s.specular));
            });
    }
    if let Some(local) = &node.local {
        ui.separator();
        egui::Grid::new(("sum", path.to_vec()))
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                row(ui, "ambient ka·A", fmt3(local.ambient));
                row(ui, "diffuse (all lights)", fmt3(local.diffuse));
                row(ui, "specular (all lights)", fmt3(local.specular));
                row(ui, "local", fmt3(local.total));
                let mut sum = local.total;
                for child in &node.children {
                    let (name, w) = match child.kind {
                        RayKind::Reflected => ("kr · reflected", node.kr.unwrap_or(Vec3::ZERO)),
                        _ => ("kt · refracted", node.kt.unwrap_or(Vec3::ZERO)),
                    };
                    let term = w * child.color;
                    sum += term;
                    row(
                        ui,
                        name,
                        format!("{} · {} = {}", fmt3(w), fmt3(child.color), fmt3(term)),
                    );
                }
                if node.total_internal_reflection {
                    row(
                        ui,
                        "",
                        "total internal reflection: kt moved to R".to_string(),
                    );
                }
                let ok = (sum - node.color).abs().max_element()
                    <= 1e-5 * node.color.abs().max_element().max(1.0);
                row(
                    ui,
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
            });
    }
}
