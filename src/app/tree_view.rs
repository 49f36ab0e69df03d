//! The clicked pixel's ray tree in three linked views — a collapsible list, a diagram like the
//! lecture's "Ray Tracing Tree" figure, and ray segments over the image (see `viewport.rs`) —
//! plus a detail pane with every number behind the selected node's colour, and a pinned tree
//! to compare against. Hovering or selecting a node in one view highlights it in the others.
//! The list and the detail are tables (egui_extras) with resizable columns whose text is
//! elided with the full value on hover, never silently cut; the diagram's labels never go
//! below a readable size, a large tree scrolls instead.

use eframe::egui::{self, Color32, Pos2, Rect, Response, RichText, Sense, Stroke, Ui, Vec2};
use egui_extras::{Column, TableBuilder};
use glam::Vec3;

use super::undo::Edits;
pub use crate::diagram::end_text as end_label;
use crate::diagram::{self, Glyph, Mark, descendants, end_text};
use crate::plural::count;
use crate::ray_tree::{Node, RayTree};
use crate::scene::Shading;
use crate::scene_view::{NodePath, Style, kind_rgb, node_at, style_rgba};
use crate::trace::RayKind;

/// Which node is hovered and selected, and the pinned tree; shared by the views.
#[derive(Clone, Debug, Default)]
pub struct TreeState {
    pub selected: Option<NodePath>,
    pub hovered: Option<NodePath>,
    pub pinned: Option<RayTree>,
    /// The viewer's edits when the tree was pinned, and what the user changed since, one
    /// phrase each (named as a scene file names them, app/changes.rs): the cause the compare
    /// view names.
    pub pinned_edits: Option<Edits>,
    pub edited_since_pin: Vec<String>,
    /// The step-through: show generations `0..=n` only (`None`: all).
    pub reveal: Option<u32>,
    /// Nodes whose subtrees are folded in the list and the diagram (each shows "+N").
    pub folded: Vec<NodePath>,
    /// The tree `folded` belongs to (pixel, nodes): another tree starts unfolded.
    folded_for: Option<([u32; 2], usize)>,
    /// What the views drew last frame, for the layout tests.
    pub drawn: Drawn,
}

/// Sizes the tree's views drew in the last frame: the least text size of the diagram's labels
/// and each list or detail cell's text against its column.
#[derive(Clone, Debug, Default)]
pub struct Drawn {
    /// Points of the diagram's node labels (`None`: no diagram drawn).
    pub diagram_label: Option<f32>,
    /// The pointer is over the diagram: the status line then says how to move about it.
    pub diagram_hovered: bool,
    /// Every table cell drawn: text width unelided, width shown, the column's width, whether
    /// it was elided (the full text then shows on hover).
    pub cells: Vec<Cell>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    pub full: f32,
    pub shown: f32,
    pub column: f32,
    pub elided: bool,
}

impl Cell {
    /// The text fits its column, or is elided with its full value on hover: never cut.
    pub fn readable(&self) -> bool {
        self.shown <= self.column + 1.0 && (self.full <= self.column + 1.0 || self.elided)
    }
}

impl TreeState {
    /// Forgets the folds of another tree.
    pub fn folds_for(&mut self, tree: &RayTree) {
        let key = Some((tree.pixel, tree.nodes));
        if self.folded_for != key {
            self.folded_for = key;
            self.folded.clear();
        }
    }

    pub fn is_folded(&self, path: &[usize]) -> bool {
        self.folded.iter().any(|p| p.as_slice() == path)
    }

    /// Folds the subtree at `path`, or unfolds it.
    pub fn toggle_fold(&mut self, path: &[usize]) {
        if self.is_folded(path) {
            self.folded.retain(|p| p.as_slice() != path);
        } else {
            self.folded.push(path.to_vec());
        }
    }
}

fn color(rgb: [u8; 3]) -> Color32 {
    Color32::from_rgb(rgb[0], rgb[1], rgb[2])
}

pub fn kind_color(kind: RayKind) -> Color32 {
    color(kind_rgb(kind))
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

// ---- the diagram --------------------------------------------------------------------------

fn rgba32([r, g, b, a]: [u8; 4]) -> Color32 {
    Color32::from_rgba_unmultiplied(r, g, b, a)
}

/// The diagram's zoom and pan, kept in egui's memory: `screen = canvas.min + offset + zoom·p`
/// for a point `p` of the layout.
#[derive(Clone, Debug)]
struct DiagramView {
    zoom: f32,
    offset: Vec2,
    /// Fit the whole tree to the pane every frame (so also after a resize) until the user
    /// zooms or pans; a new tree or the "Fit" button sets it again.
    fit: bool,
    /// The tree (pixel, nodes, max depth) and generations the view was made for.
    key: Option<([u32; 2], usize, u32, Option<u32>)>,
    /// Whether the legend is shown.
    legend: Legend,
    /// Whether the legend fitted beside the tree in the last frame.
    legend_fits: bool,
    /// Whether the user folded the overview away (it can cover nodes in its corner).
    overview_folded: bool,
    /// The overview sits in the bottom-right corner (else the bottom-left): whichever covers
    /// less of the nodes shown ([`overview_corner`]).
    overview_right: bool,
}

/// Whether the diagram's legend is shown: as the user set it with its toggle, or, before that,
/// when it fits beside the tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Legend {
    WhenItFits,
    Shown,
    Hidden,
}

impl Legend {
    fn shown(self, fits: bool) -> bool {
        match self {
            Legend::WhenItFits => fits,
            Legend::Shown => true,
            Legend::Hidden => false,
        }
    }
}

impl Default for DiagramView {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            offset: Vec2::ZERO,
            fit: true,
            key: None,
            legend: Legend::WhenItFits,
            legend_fits: true,
            overview_folded: false,
            overview_right: false,
        }
    }
}

/// Gap kept round the fitted tree, and the largest zoom a fit picks.
const FIT_MARGIN: f32 = 12.0;
const FIT_MAX_ZOOM: f32 = 1.5;
const LEGEND_ROW: f32 = 15.0;
const LEGEND_COLUMN: f32 = 300.0;
const LEGEND_TOP: f32 = 24.0;

/// One shadow glyph (or a legend's mark for it), `s` pixels across.
fn paint_glyph(painter: &egui::Painter, glyph: Glyph, at: Pos2, s: f32) {
    let c = rgba32(glyph.rgba());
    match glyph {
        Glyph::Lit | Glyph::FacingAway => {
            painter.circle_filled(at, s * 0.5, c);
        }
        Glyph::NoContribution => {
            painter.circle_stroke(at, s * 0.4, Stroke::new((s * 0.2).max(1.0), c));
        }
        Glyph::Blocked => {
            let d = s * 0.5;
            let stroke = Stroke::new((s * 0.25).max(1.0), c);
            painter.line_segment([at - Vec2::splat(d), at + Vec2::splat(d)], stroke);
            painter.line_segment([at + Vec2::new(-d, d), at + Vec2::new(d, -d)], stroke);
        }
    }
}

/// The legend's size in `rows` rows per column.
fn legend_size(rows: usize) -> Vec2 {
    let n = diagram::legend().len();
    let columns = n.div_ceil(rows.max(1));
    Vec2::new(
        columns as f32 * LEGEND_COLUMN,
        LEGEND_TOP + 6.0 + n.min(rows) as f32 * LEGEND_ROW,
    )
}

/// The legend, from [`diagram::legend`], in `rect`, `rows` entries per column.
fn paint_legend(painter: &egui::Painter, rect: Rect, rows: usize) {
    painter.rect_filled(rect, 6.0, Color32::from_rgba_unmultiplied(35, 35, 35, 235));
    painter.rect_stroke(
        rect,
        6.0,
        Stroke::new(1.0, Color32::from_gray(85)),
        egui::StrokeKind::Inside,
    );
    let text = color(diagram::TEXT_RGB);
    let font = egui::FontId::proportional(11.5);
    painter.text(
        rect.min + Vec2::new(10.0, 12.0),
        egui::Align2::LEFT_CENTER,
        "Legend",
        egui::FontId::proportional(13.0),
        text,
    );
    for (i, e) in diagram::legend().iter().enumerate() {
        let column = rect.min.x + (i / rows.max(1)) as f32 * LEGEND_COLUMN;
        let y = rect.min.y + LEGEND_TOP + 8.0 + (i % rows.max(1)) as f32 * LEGEND_ROW;
        let at = Pos2::new(column + 22.0, y);
        paint_mark(painter, e, at);
        painter.text(
            Pos2::new(column + 44.0, y),
            egui::Align2::LEFT_CENTER,
            e.text,
            font.clone(),
            text,
        );
    }
}

/// The mark of legend entry `e` (a ray's line and letter, a glyph, a swatch...) centred at
/// `at`, about 24 × 12 points: the diagram's legend, the help's and the views' use it.
pub fn paint_mark(painter: &egui::Painter, e: &diagram::LegendEntry, at: Pos2) {
    let c = rgba32(e.rgba);
    match e.mark {
        Mark::Ray(kind) => {
            painter.line_segment(
                [at - Vec2::new(12.0, 0.0), at + Vec2::new(12.0, 0.0)],
                Stroke::new(2.0, c),
            );
            painter.text(
                at - Vec2::new(0.0, 6.0),
                egui::Align2::CENTER_CENTER,
                diagram::edge_label(kind),
                egui::FontId::proportional(10.0),
                c,
            );
        }
        Mark::Glyph(g) => paint_glyph(painter, g, at, 8.0),
        Mark::Swatch => {
            painter.rect_filled(
                Rect::from_center_size(at, Vec2::splat(diagram::SWATCH)),
                0.0,
                Color32::from_rgb(192, 128, 64),
            );
        }
        Mark::NotTraced => {
            painter.add(egui::Shape::dashed_line(
                &rect_loop(Rect::from_center_size(at, Vec2::new(24.0, 12.0))),
                Stroke::new(1.5, c),
                4.0,
                3.0,
            ));
        }
        Mark::Tir => {
            painter.text(
                at,
                egui::Align2::CENTER_CENTER,
                "TIR",
                egui::FontId::proportional(10.0),
                c,
            );
        }
        Mark::Highlight => {
            painter.rect_stroke(
                Rect::from_center_size(at, Vec2::new(24.0, 12.0)),
                3.0,
                Stroke::new(3.0, c),
                egui::StrokeKind::Middle,
            );
        }
    }
}

/// The corners of `r`, closed, for a dashed outline.
fn rect_loop(r: Rect) -> [Pos2; 5] {
    [
        r.left_top(),
        r.right_top(),
        r.right_bottom(),
        r.left_bottom(),
        r.left_top(),
    ]
}

/// The lecture's "Ray Tracing Tree" drawn from the core's layout ([`diagram::layout_folded`]):
/// boxes with the node's colour and what its ray met, R and T edges, shadow glyphs per light,
/// the rays not traced dashed, and a collapsible legend. Labels are never smaller than
/// [`diagram::MIN_LABEL_PX`]: a tree larger than the pane at that size is scrolled (wheel,
/// drag, or the overview in the corner) instead of shrunk. Fits the pane when a tree arrives
/// (and on "Fit"); Ctrl+wheel zooms about the pointer; a double-click folds a node's subtree
/// into "+N". Generations deeper than [`TreeState::reveal`] are hidden. Returns whether
/// "Export SVG" was clicked. `tools` adds the window's buttons to the toolbar.
pub fn diagram(
    ui: &mut Ui,
    tree: &RayTree,
    state: &mut TreeState,
    tools: &mut dyn FnMut(&mut Ui),
) -> bool {
    diagram_with(ui, tree, state, None, "diagram view", tools)
}

/// [`diagram()`], the nodes that differ from `other`'s at the same place outlined in the
/// compare colour; `salt` keeps two diagrams' views apart.
pub fn diagram_with(
    ui: &mut Ui,
    tree: &RayTree,
    state: &mut TreeState,
    other: Option<&RayTree>,
    salt: &str,
    tools: &mut dyn FnMut(&mut Ui),
) -> bool {
    // Two trees compared share the folds of the current one.
    if other.is_none() {
        state.folds_for(tree);
    }
    let options = diagram::Options {
        max_generation: state.reveal.unwrap_or(u32::MAX),
    };
    let lay = diagram::layout_folded(tree, &options, &state.folded);
    let id = ui.make_persistent_id(salt);
    let mut view: DiagramView = ui.data(|d| d.get_temp(id)).unwrap_or_default();
    let key = (
        tree.pixel,
        tree.nodes,
        tree.settings.max_depth,
        state.reveal,
    );
    if view.key != Some(key) {
        view.key = Some(key);
        view.fit = true;
    }
    let mut export = false;
    // Wrapped: a toolbar wider than a narrow pane must not widen the pane's space, or the
    // fitted tree would be centred in a part of it that is not shown.
    ui.horizontal_wrapped(|ui| {
        tools(ui);
        if ui
            .button("Fit")
            .on_hover_text("show as much of the tree as fits with readable labels")
            .clicked()
        {
            view.fit = true;
        }
        let mut legend = view.legend.shown(view.legend_fits);
        if ui.toggle_value(&mut legend, "Legend").changed() {
            view.legend = if legend {
                Legend::Shown
            } else {
                Legend::Hidden
            };
        }
        if other.is_none()
            && ui
                .button("Export SVG...")
                .on_hover_text("the figure for slides, with its legend")
                .clicked()
        {
            export = true;
        }
        ui.label(format!("{:.0}%", view.zoom * 100.0))
            .on_hover_text(DIAGRAM_HINT);
        if lay.hidden > 0 {
            ui.label(format!("{} folded or hidden", count(lay.hidden, "node")));
        }
        // The hint where the row has room for it; otherwise it is in the zoom's hover text
        // and the status line rather than on a toolbar row of its own. (In a wrapping row
        // the available width is the next row's, so this measures from the cursor.)
        if ui.max_rect().right() - ui.cursor().min.x >= HINT_WIDTH {
            ui.weak(DIAGRAM_HINT);
        }
    });
    // The space left that is shown (never wider than the pane's clip rectangle).
    let shown = ui.available_rect_before_wrap().intersect(ui.clip_rect());
    let size = shown.size().max(Vec2::new(120.0, 80.0));
    let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
    response.widget_info(|| {
        egui::WidgetInfo::labeled(
            egui::Role::Image,
            true,
            format!("ray tree diagram of ({}, {})", tree.pixel[0], tree.pixel[1]),
        )
    });
    state.drawn.diagram_hovered |= ui.rect_contains_pointer(rect);
    // As many columns as the pane's height needs.
    let legend_rows = ((rect.height() - 12.0 - LEGEND_TOP - 6.0) / LEGEND_ROW).floor() as usize;
    let legend_box = legend_size(legend_rows);
    let legend_rect = Rect::from_min_size(
        Pos2::new(rect.max.x - legend_box.x - 6.0, rect.min.y + 6.0),
        legend_box,
    );
    // The tree fits beside the open legend, unless that leaves it too little room.
    view.legend_fits = legend_rect.min.x - rect.min.x > 240.0;
    let legend_on = view.legend.shown(view.legend_fits);
    let area = if legend_on && view.legend_fits {
        Rect::from_min_max(rect.min, Pos2::new(legend_rect.min.x - 6.0, rect.max.y))
    } else {
        rect
    };
    let [w, h] = lay.size;
    if view.fit {
        let room = area.size() - Vec2::splat(2.0 * FIT_MARGIN);
        view.zoom = (room.x / w.max(1.0))
            .min(room.y / h.max(1.0))
            .clamp(diagram::MIN_ZOOM, FIT_MAX_ZOOM);
        let figure = Vec2::new(w, h) * view.zoom;
        // What does not fit starts at the root: centred over it, from the top.
        let root_x = lay.nodes.first().map_or(w / 2.0, |n| n.center[0]) * view.zoom;
        view.offset = Vec2::new(
            if figure.x <= room.x {
                area.center().x - rect.min.x - figure.x * 0.5
            } else {
                area.center().x - rect.min.x - root_x
            },
            if figure.y <= room.y {
                area.center().y - rect.min.y - figure.y * 0.5
            } else {
                area.min.y - rect.min.y + FIT_MARGIN
            },
        );
    }
    if response.dragged() {
        view.offset += response.drag_delta();
        view.fit = false;
    }
    let pointer = ui
        .input(|i| i.pointer.hover_pos())
        .filter(|p| rect.contains(*p));
    if let Some(p) = pointer {
        let (zoom, scroll) = ui.input(|i| (i.zoom_delta(), i.smooth_scroll_delta));
        if zoom != 1.0 {
            // The layout point under the pointer stays under it.
            let under = (p - rect.min - view.offset) / view.zoom;
            view.zoom = (view.zoom * zoom).clamp(diagram::MIN_ZOOM, 8.0);
            view.offset = p - rect.min - under * view.zoom;
            view.fit = false;
        } else if scroll != Vec2::ZERO {
            view.offset += scroll;
            view.fit = false;
        }
    }
    view.offset = keep_in_view(view.offset, Vec2::new(w, h) * view.zoom, area, rect.min);
    let (zoom, origin) = (view.zoom, rect.min + view.offset);
    let at = |[x, y]: [f32; 2]| origin + Vec2::new(x, y) * zoom;
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, color(diagram::BACKGROUND_RGB));
    let font = diagram::FONT * zoom;
    let small = (10.0 * zoom).max(diagram::MIN_LABEL_PX);
    state.drawn.diagram_label = Some(
        state
            .drawn
            .diagram_label
            .map_or(font.min(small), |f| f.min(font).min(small)),
    );
    let line = (2.0 * zoom).clamp(1.0, 3.0);
    for e in &lay.edges {
        let style = if e.not_traced {
            Style::NotTraced(e.kind)
        } else {
            Style::Ray(e.kind)
        };
        let c = rgba32(style_rgba(style));
        let (a, b) = (at(e.from), at(e.to));
        if e.not_traced {
            painter.add(egui::Shape::dashed_line(
                &[a, b],
                Stroke::new(line, c),
                4.0 * zoom,
                3.0 * zoom,
            ));
        } else {
            painter.line_segment([a, b], Stroke::new(line, c));
        }
        // The label sits on its own edge over a patch of background: it crosses no line.
        let mid = at(e.label_at);
        painter.rect_filled(
            Rect::from_center_size(mid, Vec2::new(14.0, 16.0) * zoom),
            3.0 * zoom,
            color(diagram::BACKGROUND_RGB),
        );
        painter.text(
            mid,
            egui::Align2::CENTER_CENTER,
            e.label,
            egui::FontId::proportional(font),
            c,
        );
    }
    for n in &lay.nodes {
        let [x0, y0, x1, y1] = n.rect();
        let node_rect = Rect::from_min_max(at([x0, y0]), at([x1, y1]));
        let Some(node) = node_at(&tree.root, &n.path) else {
            continue;
        };
        let differs = other.map(|o| match node_at(&o.root, &n.path) {
            Some(theirs) => node_differs(node, theirs),
            None => true,
        }) == Some(true);
        if !node_rect.intersects(rect) {
            continue;
        }
        let r = ui.interact(
            node_rect.intersect(area),
            id.with(("node", &n.path)),
            Sense::click(),
        );
        r.widget_info(|| {
            egui::WidgetInfo::labeled(
                egui::Role::Button,
                true,
                format!("tree node {}: {}", kind_letter(node.kind), n.label),
            )
        });
        if r.hovered() {
            state.hovered = Some(n.path.clone());
        }
        if r.clicked() {
            state.selected = Some(n.path.clone());
        }
        if r.double_clicked() && !node.children.is_empty() {
            state.toggle_fold(&n.path);
        }
        let r = r.on_hover_ui(|ui| {
            ui.label(node_summary(node));
            for g in &n.glyphs {
                ui.label(&g.note);
            }
            if n.hidden_children > 0 {
                ui.label(format!(
                    "{} below folded (double-click unfolds)",
                    count(n.hidden_children, "node")
                ));
            }
        });
        let _ = r;
        let selected = state.selected.as_deref() == Some(n.path.as_slice());
        let hovered = state.hovered.as_deref() == Some(n.path.as_slice());
        let outline = if n.not_traced {
            Style::NotTraced(n.kind)
        } else {
            Style::Ray(n.kind)
        };
        painter.rect_filled(node_rect, 5.0 * zoom, Color32::from_gray(42));
        if selected || hovered {
            // Thicker than any outline and in the highlight colour, so the selected primary
            // ray is not white on white.
            painter.rect_stroke(
                node_rect.expand(2.0),
                5.0 * zoom,
                Stroke::new(
                    if selected { 4.0 } else { 2.5 },
                    color(crate::scene_view::HIGHLIGHT_RGB),
                ),
                egui::StrokeKind::Outside,
            );
        } else if differs {
            painter.rect_stroke(
                node_rect.expand(1.0),
                5.0 * zoom,
                Stroke::new(3.0, CHANGED),
                egui::StrokeKind::Outside,
            );
        } else if n.not_traced {
            painter.add(egui::Shape::dashed_line(
                &rect_loop(node_rect),
                Stroke::new(1.5, rgba32(style_rgba(outline))),
                4.0 * zoom,
                3.0 * zoom,
            ));
        } else {
            painter.rect_stroke(
                node_rect,
                5.0 * zoom,
                Stroke::new(
                    if n.depth == 0 { 2.5 } else { 1.5 },
                    rgba32(style_rgba(outline)),
                ),
                egui::StrokeKind::Inside,
            );
        }
        let pad = diagram::PAD * zoom;
        let swatch = diagram::SWATCH * zoom;
        let line1 = node_rect.min.y + pad + swatch / 2.0;
        painter.rect_filled(
            Rect::from_min_size(
                Pos2::new(node_rect.min.x + pad, line1 - swatch / 2.0),
                Vec2::splat(swatch),
            ),
            0.0,
            color(n.swatch),
        );
        for g in &n.glyphs {
            paint_glyph(&painter, g.glyph, at(g.at), 8.0 * zoom);
        }
        // Clipped to the box, so a label never reaches an edge or a neighbour.
        painter.with_clip_rect(node_rect.intersect(rect)).text(
            Pos2::new(node_rect.min.x + 2.0 * pad + swatch, line1),
            egui::Align2::LEFT_CENTER,
            &n.label,
            egui::FontId::proportional(font),
            if n.not_traced {
                rgba32(style_rgba(outline))
            } else {
                color(diagram::TEXT_RGB)
            },
        );
        let line2 = node_rect.min.y + node_rect.height() * 0.75;
        if n.total_internal_reflection {
            painter.text(
                Pos2::new(
                    node_rect.min.x
                        + pad
                        + (n.glyphs.len() as f32 * diagram::GLYPH_PITCH + diagram::PAD) * zoom,
                    line2,
                ),
                egui::Align2::LEFT_CENTER,
                "TIR",
                egui::FontId::proportional(small),
                color(diagram::TIR_RGB),
            );
        }
        if n.hidden_children > 0 {
            painter.text(
                Pos2::new(node_rect.center().x, node_rect.max.y + 4.0),
                egui::Align2::CENTER_TOP,
                format!("+{}", n.hidden_children),
                egui::FontId::proportional(small),
                color(diagram::TEXT_RGB),
            );
        }
    }
    if legend_on {
        paint_legend(&painter, legend_rect, legend_rows);
    }
    if w * zoom > area.width() + 1.0 || h * zoom > area.height() + 1.0 {
        overview(ui, &painter, &lay, area, rect.min, &mut view, id);
    }
    ui.data_mut(|d| d.insert_temp(id, view));
    export
}

/// The pinned tree and the current one side by side, the nodes that differ outlined, above
/// them what changed between the two ([`diagram::changes`]). Returns whether "Export SVG"
/// was clicked (it exports the current tree).
pub fn compare(
    ui: &mut Ui,
    tree: &RayTree,
    pinned: &RayTree,
    state: &mut TreeState,
    tools: &mut dyn FnMut(&mut Ui),
) -> bool {
    let changes = diagram::changes(pinned, tree);
    let mut export = false;
    ui.horizontal_wrapped(|ui| {
        tools(ui);
        if ui
            .button("Unpin")
            .on_hover_text("stop comparing: the current tree alone")
            .clicked()
        {
            state.pinned = None;
        }
        if ui.button("Export SVG...").clicked() {
            export = true;
        }
    });
    say_changes(ui, state, &changes);
    let mut none = |_: &mut Ui| {};
    ui.columns(2, |cols| {
        cols[0].label(format!(
            "pinned: ({}, {}) · {}",
            pinned.pixel[0],
            pinned.pixel[1],
            count(pinned.nodes, "node")
        ));
        diagram_with(
            &mut cols[0],
            pinned,
            state,
            Some(tree),
            "pinned diagram",
            &mut none,
        );
        cols[1].label(format!(
            "current: ({}, {}) · {}",
            tree.pixel[0],
            tree.pixel[1],
            count(tree.nodes, "node")
        ));
        diagram_with(
            &mut cols[1],
            tree,
            state,
            Some(pinned),
            "current diagram",
            &mut none,
        );
    });
    export
}

/// What the user changed since the pin (the cause), then what changed in the tree (the
/// effect), each wrapped to the pane.
pub fn say_changes(ui: &mut Ui, state: &TreeState, in_tree: &[String]) {
    if !state.edited_since_pin.is_empty() {
        let text = format!("you changed: {}", state.edited_since_pin.join("; "));
        ui.add(egui::Label::new(egui::RichText::new(text).strong()).wrap());
    }
    let text = if in_tree.is_empty() {
        "no change between the pinned tree and the current one".to_string()
    } else {
        format!("in the tree: {}", in_tree.join("; "))
    };
    ui.add(egui::Label::new(egui::RichText::new(text).color(CHANGED)).wrap());
}

/// Outline of the nodes that differ from the other tree's.
const CHANGED: Color32 = Color32::from_rgb(255, 150, 50);

/// `offset` moved the least so that at least a corner of a figure of `size` stays in `area`
/// (the canvas starts at `min`): the tree cannot be panned out of sight.
fn keep_in_view(offset: Vec2, size: Vec2, area: Rect, min: Pos2) -> Vec2 {
    let keep = 48.0_f32;
    let lo = area.min - min - size + Vec2::splat(keep.min(size.min_elem()));
    let hi = area.max - min - Vec2::splat(keep);
    Vec2::new(
        offset.x.clamp(lo.x.min(hi.x), hi.x.max(lo.x)),
        offset.y.clamp(lo.y.min(hi.y), hi.y.max(lo.y)),
    )
}

/// How to move about the diagram, and the width the toolbar needs left to show it.
pub const DIAGRAM_HINT: &str = "drag or wheel pans, Ctrl+wheel zooms, double-click folds";
const HINT_WIDTH: f32 = 330.0;

/// Largest size of the overview in the diagram's corner.
const OVERVIEW: Vec2 = Vec2::new(170.0, 110.0);
/// The overview's largest share of the pane, each way.
const OVERVIEW_SHARE: f32 = 0.34;
/// Below this room (its share of the pane) there is no overview.
const OVERVIEW_LEAST: Vec2 = Vec2::new(60.0, 40.0);

/// Whether the overview, of `size` (its frame), goes in the bottom-right corner of `area`
/// rather than the bottom-left: the corner whose rectangle covers less of the nodes as drawn
/// (`nodes`, screen rectangles). It moves only when the other corner covers less than half as
/// much, so that panning does not make it jump back and forth.
fn overview_corner(area: Rect, size: Vec2, nodes: &[Rect], right_now: bool) -> bool {
    let corner = |right: bool| {
        let x = if right {
            area.max.x - size.x - 4.0
        } else {
            area.min.x + 4.0
        };
        Rect::from_min_size(Pos2::new(x, area.max.y - size.y - 4.0), size)
    };
    let covered = |r: Rect| -> f32 {
        nodes
            .iter()
            .map(|n| n.intersect(r))
            .filter(|i| i.is_positive())
            .map(|i| i.area())
            .sum()
    };
    let (now, other) = (covered(corner(right_now)), covered(corner(!right_now)));
    if other < 0.5 * now {
        !right_now
    } else {
        right_now
    }
}

/// The whole tree in small, in a bottom corner of `area` (the one over fewer nodes), with the
/// part the pane shows outlined; a click or drag on it moves the view there.
fn overview(
    ui: &mut Ui,
    painter: &egui::Painter,
    lay: &diagram::Layout,
    area: Rect,
    min: Pos2,
    view: &mut DiagramView,
    id: egui::Id,
) {
    let [w, h] = lay.size;
    // At most a third of the pane each way, so that a small pane still shows where it is.
    let most = OVERVIEW.min(area.size() * OVERVIEW_SHARE);
    if most.x < OVERVIEW_LEAST.x || most.y < OVERVIEW_LEAST.y {
        return; // a pane this small is all view
    }
    let scale = (most.x / w.max(1.0)).min(most.y / h.max(1.0));
    let size = Vec2::new(w, h) * scale;
    // The corner is kept while the overview itself is dragged.
    if ui.ctx().dragged_id() != Some(id.with("overview")) {
        let at = |[x, y]: [f32; 2]| min + view.offset + Vec2::new(x, y) * view.zoom;
        let nodes: Vec<Rect> = lay
            .nodes
            .iter()
            .map(|n| {
                let [x0, y0, x1, y1] = n.rect();
                Rect::from_min_max(at([x0, y0]), at([x1, y1]))
            })
            .collect();
        view.overview_right =
            overview_corner(area, size + Vec2::splat(8.0), &nodes, view.overview_right);
    }
    let left = if view.overview_right {
        area.max.x - size.x - 8.0
    } else {
        area.min.x + 8.0
    };
    let frame = Rect::from_min_size(Pos2::new(left, area.max.y - size.y - 8.0), size).expand(4.0);
    if view.overview_folded {
        let x = if view.overview_right {
            area.max.x - 54.0
        } else {
            area.min.x + 8.0
        };
        let at = Rect::from_min_size(Pos2::new(x, area.max.y - 26.0), Vec2::new(46.0, 18.0));
        if ui
            .put(at, egui::Button::new("map").small())
            .on_hover_text("show the overview of the whole tree")
            .clicked()
        {
            view.overview_folded = false;
        }
        return;
    }
    let inner = frame.shrink(4.0);
    painter.rect_filled(frame, 4.0, Color32::from_rgba_unmultiplied(20, 20, 20, 230));
    painter.rect_stroke(
        frame,
        4.0,
        Stroke::new(1.0, Color32::from_gray(110)),
        egui::StrokeKind::Inside,
    );
    let map = |[x, y]: [f32; 2]| inner.min + Vec2::new(x, y) * scale;
    for e in &lay.edges {
        painter.line_segment(
            [map(e.from), map(e.to)],
            Stroke::new(1.0, rgba32(style_rgba(Style::Ray(e.kind)))),
        );
    }
    for n in &lay.nodes {
        let [x0, y0, x1, y1] = n.rect();
        painter.rect_filled(
            Rect::from_min_max(map([x0, y0]), map([x1, y1])),
            0.0,
            kind_color(n.kind),
        );
    }
    // The part shown, in layout coordinates.
    let to_layout = |p: Pos2| (p - min - view.offset) / view.zoom;
    let a = to_layout(area.min);
    let b = to_layout(area.max);
    let shown = Rect::from_min_max(map([a.x, a.y]), map([b.x, b.y])).intersect(inner);
    painter.rect_stroke(
        shown,
        0.0,
        Stroke::new(1.5, color(crate::scene_view::HIGHLIGHT_RGB)),
        egui::StrokeKind::Middle,
    );
    let r = ui.interact(frame, id.with("overview"), Sense::click_and_drag());
    r.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "ray tree overview"));
    if let Some(p) = r.interact_pointer_pos()
        && (r.clicked() || r.dragged())
    {
        // The point under the pointer becomes the centre of the view.
        let target = (p - inner.min) / scale;
        view.offset = area.center() - min - target * view.zoom;
        view.fit = false;
    }
    let _ = r.on_hover_text("the whole tree: the outline is the part shown; click or drag to move");
    // Folds the overview away, for the nodes under it.
    let fold = Rect::from_min_size(
        frame.right_top() + Vec2::new(-25.0, 1.0),
        Vec2::new(24.0, 18.0),
    );
    if ui
        .put(fold, egui::Button::new("×").small())
        .on_hover_text("hide the overview (\"map\" brings it back)")
        .clicked()
    {
        view.overview_folded = true;
    }
}

// ---- the numbers --------------------------------------------------------------------------

/// Every number behind the selected node's colour (a table of names and values).
pub fn detail(ui: &mut Ui, tree: &RayTree, path: &[usize]) {
    detail_table(ui, tree, path);
}

// ---- the tables ---------------------------------------------------------------------------

/// Height of a table row: one line of body text.
const ROW_H: f32 = 20.0;
/// Points a row is indented per generation in the list's first column, when the deepest row
/// leaves its label room; a deep tree in a narrow column is indented less, down to
/// [`MIN_INDENT`], so that its labels stay whole.
const INDENT: f32 = 10.0;
/// The least indentation per generation: the generations still apart.
const MIN_INDENT: f32 = 3.0;
/// Width kept in the first column for the fold toggle (or the space in its place).
const TOGGLE_W: f32 = 16.0;

/// Indentation per generation in a first column `column` points wide whose deepest row is
/// `deepest` generations down and whose widest label is `label` points.
fn list_indent(column: f32, deepest: u32, label: f32) -> f32 {
    if deepest == 0 {
        return INDENT;
    }
    ((column - TOGGLE_W - label) / deepest as f32).clamp(MIN_INDENT, INDENT)
}

/// The colour of rows and values that differ from the other tree.
const LIST_CHANGED: Color32 = Color32::from_rgb(255, 150, 50);

fn kind_name(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Primary => "primary",
        RayKind::Reflected => "R",
        RayKind::Refracted => "T",
        RayKind::Shadow => "S",
    }
}

/// Width in points of `text` on one line in the body style.
fn text_width(ui: &Ui, text: impl Into<egui::WidgetText>) -> f32 {
    text.into()
        .into_galley(
            ui,
            Some(egui::TextWrapMode::Extend),
            f32::INFINITY,
            egui::TextStyle::Body,
        )
        .size()
        .x
}

/// One cell's text, elided to its column with the full text on hover; recorded in `cells`.
fn cell(ui: &mut Ui, text: RichText, cells: &mut Vec<Cell>) -> Response {
    let column = ui.available_width();
    let full = text_width(ui, text.clone());
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
fn rows<'a>(
    node: &'a Node,
    path: &mut NodePath,
    state: &TreeState,
    out: &mut Vec<(NodePath, &'a Node)>,
) {
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

/// A count that goes up each time `size` (a pane's width or height) has moved more than a
/// tenth away from where it was when the count last went up. Part of a widget's id, it makes
/// a widget that keeps its sizes in points (a table's columns, a panel's height) start again
/// from its shares of the new size.
pub(super) fn resize_generation(ui: &Ui, salt: impl egui::AsIdSalt, size: f32) -> u32 {
    let id = ui.scope_id().with(salt);
    let (mut base, mut generation): (f32, u32) = ui.data(|d| d.get_temp(id)).unwrap_or((size, 0));
    if (size - base).abs() > 0.1 * base.max(1.0) {
        (base, generation) = (size, generation + 1);
    }
    ui.data_mut(|d| d.insert_temp(id, (base, generation)));
    generation
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
    // The first two columns take their share of the pane, so the colours fit beside them in
    // a narrow one (the user can drag the dividers after).
    let width = ui.available_width();
    // When the pane's width changes by more than a tenth (a resized window, a moved
    // splitter), the columns start again from their shares of it: widths kept from a wider
    // pane would push the colours out of a narrow one.
    let generation = resize_generation(ui, ("tree list width", salt), width);
    // The deepest row and the widest label it can have set how far each generation is
    // indented.
    let deepest = list.iter().map(|(_, n)| n.depth).max().unwrap_or(0);
    let label_w = [RayKind::Reflected, RayKind::Refracted, RayKind::Shadow]
        .map(|k| format!("* {} d{deepest}", kind_name(k)))
        .into_iter()
        .map(|text| text_width(ui, text))
        .fold(0.0, f32::max);
    TableBuilder::new(ui)
        .id_salt(("tree list", salt, generation))
        .striped(true)
        .resizable(true)
        .vscroll(false)
        .sense(Sense::click())
        .cell_layout(egui::Layout::left_to_right(egui::Align::Center))
        .column(
            Column::initial((width * 0.3).clamp(50.0, 110.0))
                .at_least(50.0)
                .clip(true),
        )
        .column(
            Column::initial((width * 0.38).clamp(60.0, 170.0))
                .at_least(60.0)
                .clip(true),
        )
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
                    LIST_CHANGED
                } else {
                    kind_color(node.kind)
                };
                body.row(ROW_H, |mut row| {
                    row.set_selected(state.selected.as_ref() == Some(path));
                    row.set_hovered(state.hovered.as_ref() == Some(path));
                    row.col(|ui| {
                        let indent = list_indent(ui.available_width(), deepest, label_w);
                        ui.add_space(node.depth as f32 * indent);
                        if node.children.is_empty() {
                            ui.add_space(TOGGLE_W);
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

fn style_color(style: Style) -> Color32 {
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
            push(
                r,
                if hit.uv.is_some() {
                    "texel (× kd)"
                } else {
                    "vertex colour (× kd)"
                },
                fmt3(t),
            );
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
                style_color(Style::ShadowBlocked)
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
fn detail_table(ui: &mut Ui, tree: &RayTree, path: &[usize]) {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_overview_takes_the_bottom_corner_over_fewer_nodes_and_keeps_it_on_a_near_tie() {
        let area = Rect::from_min_size(Pos2::ZERO, Vec2::new(400.0, 300.0));
        let size = Vec2::new(120.0, 80.0);
        let node = |x: f32, y: f32| Rect::from_min_size(Pos2::new(x, y), Vec2::new(80.0, 30.0));
        // A tree leaning left: the right corner.
        let left_leaning = [node(150.0, 10.0), node(40.0, 150.0), node(10.0, 250.0)];
        assert!(overview_corner(area, size, &left_leaning, false));
        assert!(overview_corner(area, size, &left_leaning, true));
        // Leaning right: the left corner.
        let right_leaning = [node(150.0, 10.0), node(280.0, 150.0), node(310.0, 250.0)];
        assert!(!overview_corner(area, size, &right_leaning, true));
        // Nodes under both corners, about as much: it stays where it is.
        let both = [node(10.0, 250.0), node(300.0, 255.0)];
        assert!(overview_corner(area, size, &both, true));
        assert!(!overview_corner(area, size, &both, false));
        // No nodes under either: it stays too.
        assert!(!overview_corner(area, size, &[node(150.0, 10.0)], false));
    }
}
