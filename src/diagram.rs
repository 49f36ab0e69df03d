//! The lecture's "Ray Tracing Tree" figure (docs/design.md, "The ray tree as data") as data and as
//! SVG: a tidy layout of a pixel's [`RayTree`] (rows by depth, leaves in order, parents centred
//! over their children, subtrees never overlapping), its node and edge labels, the shadow-ray
//! glyphs, the rays that were not traced, and one legend table. The viewer's diagram and `raytree
//! tree --diagram` both draw this layout, in the one palette of [`crate::scene_view`].

use std::fmt::Write as _;

use crate::choice::Choice;
use crate::export::to_srgb8;
use crate::ray_tree::{Node, RayTree, ShadowRecord};
use crate::scene_view::{NodePath, Style, style_rgba};
use crate::trace::{EndReason, RayKind};

/// Height of a node box.
pub const NODE_H: f32 = 38.0;
/// Vertical distance between the tops of two rows: room for the edge and its R/T label.
pub const ROW: f32 = 66.0;
/// Least horizontal gap between two boxes on a row.
pub const GAP: f32 = 14.0;
/// Font size of node labels; [`CHAR_W`] is a generous estimate of one character's width in
/// it, so that a label fits its box in any sans-serif font.
pub const FONT: f32 = 12.0;
pub const CHAR_W: f32 = 7.0;
/// The smallest text (points) the viewer's diagram draws: it never zooms out further than
/// [`FONT`] at this size, and a tree larger than its pane is scrolled instead.
pub const MIN_LABEL_PX: f32 = 11.0;
/// The least zoom of the viewer's diagram: the one at which node labels are [`MIN_LABEL_PX`].
pub const MIN_ZOOM: f32 = MIN_LABEL_PX / FONT;
/// Side of the colour swatch in a node box, and the padding around the box's content.
pub const SWATCH: f32 = 12.0;
pub const PAD: f32 = 6.0;
/// Horizontal pitch of the shadow glyphs on a box's second line.
pub const GLYPH_PITCH: f32 = 12.0;
/// Grey of a light behind the surface (`N·L ≤ 0`): no shadow ray is traced, so the 3D views
/// draw nothing for it and the palette has no style for it.
pub const FACING_AWAY_RGB: [u8; 3] = [140, 140, 140];
/// Ring of a light that was not traced because it contributes nothing (its `kd` and `ks` give
/// zero): hollow, so it never reads as the filled grey dot of a light behind the surface.
pub const NOT_TRACED_RGB: [u8; 3] = [170, 170, 200];
/// The dark ground the palette is made for (the viewer's), also the SVG's background.
pub const BACKGROUND_RGB: [u8; 3] = [27, 27, 27];
/// Text on [`BACKGROUND_RGB`].
pub const TEXT_RGB: [u8; 3] = [220, 220, 220];
/// Total internal reflection marker.
pub const TIR_RGB: [u8; 3] = [255, 150, 50];

/// What the figure shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Lay out generations `0..=max_generation` (the step-through); deeper nodes are left out.
    pub max_generation: u32,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            max_generation: u32::MAX,
        }
    }
}

/// How one light's shadow ray at a hit came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Glyph {
    /// The shadow ray reached the light: a dot in the shadow-ray colour.
    Lit,
    /// The light is behind the surface (`N·L ≤ 0`): a grey dot, no shadow ray traced.
    FacingAway,
    /// An object is in the way: a red cross.
    Blocked,
    /// The light would add nothing here (zero `kd` and `ks`), so its shadow ray was not
    /// traced: a hollow ring.
    NoContribution,
}

impl Glyph {
    pub const ALL: [Glyph; 4] = [
        Glyph::Lit,
        Glyph::FacingAway,
        Glyph::Blocked,
        Glyph::NoContribution,
    ];

    pub fn of(s: &ShadowRecord) -> Glyph {
        if s.facing_away {
            Glyph::FacingAway
        } else if s.contributes_nothing {
            Glyph::NoContribution
        } else if s.blocked_by.is_some() {
            Glyph::Blocked
        } else {
            Glyph::Lit
        }
    }

    pub fn rgba(self) -> [u8; 4] {
        match self {
            Glyph::Lit => style_rgba(Style::ShadowLit),
            Glyph::FacingAway => {
                let [r, g, b] = FACING_AWAY_RGB;
                [r, g, b, 255]
            }
            Glyph::Blocked => style_rgba(Style::ShadowBlocked),
            Glyph::NoContribution => {
                let [r, g, b] = NOT_TRACED_RGB;
                [r, g, b, 255]
            }
        }
    }
}

/// One shadow glyph of a node, with the light it stands for.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowGlyph {
    pub glyph: Glyph,
    /// Centre, in layout coordinates.
    pub at: [f32; 2],
    /// "light key: blocked by floor", for tooltips.
    pub note: String,
}

/// A node's box and what is written in it.
#[derive(Clone, Debug, PartialEq)]
pub struct LaidNode {
    pub path: NodePath,
    pub depth: u32,
    pub kind: RayKind,
    /// Centre of the box, in layout coordinates (y down, the root's row at the top).
    pub center: [f32; 2],
    pub size: [f32; 2],
    /// The object the ray hit, or why it ended.
    pub label: String,
    /// The node's colour as displayed (sRGB).
    pub swatch: [u8; 3],
    /// The ray was not traced (past max depth, below the cutoff, past the ray budget).
    pub not_traced: bool,
    pub total_internal_reflection: bool,
    pub glyphs: Vec<ShadowGlyph>,
    /// Nodes below this one left out: by [`Options::max_generation`] or because the subtree
    /// is folded (drawn as "+N").
    pub hidden_children: usize,
}

impl LaidNode {
    /// `[min_x, min_y, max_x, max_y]` of the box.
    pub fn rect(&self) -> [f32; 4] {
        let [cx, cy] = self.center;
        let [w, h] = self.size;
        [cx - w / 2.0, cy - h / 2.0, cx + w / 2.0, cy + h / 2.0]
    }
}

/// A parent-to-child edge: from the bottom of the parent's box to the top of the child's.
#[derive(Clone, Debug, PartialEq)]
pub struct Edge {
    /// Indices into [`Layout::nodes`].
    pub parent: usize,
    pub child: usize,
    pub kind: RayKind,
    /// "R" or "T".
    pub label: &'static str,
    pub from: [f32; 2],
    pub to: [f32; 2],
    /// Where the label sits: on the edge, halfway.
    pub label_at: [f32; 2],
    pub not_traced: bool,
}

/// The laid-out tree: every coordinate is at zoom 1, with the top-left of the figure at 0, 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub nodes: Vec<LaidNode>,
    pub edges: Vec<Edge>,
    /// Width and height of the figure.
    pub size: [f32; 2],
    /// Nodes left out by [`Options::max_generation`].
    pub hidden: usize,
}

/// What a legend entry shows next to its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// A ray of this kind: an edge (R, T) or, for the primary ray, the root's outline.
    Ray(RayKind),
    Glyph(Glyph),
    /// The node's colour swatch.
    Swatch,
    /// A ray that was not traced: a faint, dashed box.
    NotTraced,
    /// The total internal reflection marker.
    Tir,
    /// The selected or hovered node (the viewer only).
    Highlight,
}

/// One row of the legend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegendEntry {
    pub mark: Mark,
    pub rgba: [u8; 4],
    pub text: &'static str,
}

/// Every glyph and colour of the figure with its meaning: the one table the SVG's legend and
/// the viewer's legend are drawn from.
pub fn legend() -> Vec<LegendEntry> {
    let ray = |kind| style_rgba(Style::Ray(kind));
    vec![
        LegendEntry {
            mark: Mark::Ray(RayKind::Primary),
            rgba: ray(RayKind::Primary),
            text: "primary ray from the eye (the root)",
        },
        LegendEntry {
            mark: Mark::Ray(RayKind::Reflected),
            rgba: ray(RayKind::Reflected),
            text: "R: reflected ray",
        },
        LegendEntry {
            mark: Mark::Ray(RayKind::Refracted),
            rgba: ray(RayKind::Refracted),
            text: "T: refracted (transmitted) ray",
        },
        LegendEntry {
            mark: Mark::Glyph(Glyph::Lit),
            rgba: Glyph::Lit.rgba(),
            text: "shadow ray reaches its light: lit",
        },
        LegendEntry {
            mark: Mark::Glyph(Glyph::Blocked),
            rgba: Glyph::Blocked.rgba(),
            text: "shadow ray blocked: in shadow",
        },
        LegendEntry {
            mark: Mark::Glyph(Glyph::FacingAway),
            rgba: Glyph::FacingAway.rgba(),
            text: "light behind the surface (N\u{b7}L \u{2264} 0): no shadow ray",
        },
        LegendEntry {
            mark: Mark::Glyph(Glyph::NoContribution),
            rgba: Glyph::NoContribution.rgba(),
            text: "not traced: the light contributes nothing (kd, ks zero)",
        },
        LegendEntry {
            mark: Mark::Swatch,
            rgba: [255, 255, 255, 255],
            text: "swatch: the node's colour (local + kr\u{b7}R + kt\u{b7}T)",
        },
        LegendEntry {
            mark: Mark::NotTraced,
            rgba: style_rgba(Style::NotTraced(RayKind::Reflected)),
            text: "not traced: max depth, cutoff or ray budget",
        },
        LegendEntry {
            mark: Mark::Tir,
            rgba: {
                let [r, g, b] = TIR_RGB;
                [r, g, b, 255]
            },
            text: "TIR: total internal reflection (kt goes to R)",
        },
        LegendEntry {
            mark: Mark::Highlight,
            rgba: {
                let [r, g, b] = crate::scene_view::HIGHLIGHT_RGB;
                [r, g, b, 255]
            },
            text: "selected or hovered node",
        },
    ]
}

/// "R" or "T" for an edge to a child of this kind.
pub fn edge_label(kind: RayKind) -> &'static str {
    match kind {
        RayKind::Reflected => "R",
        RayKind::Refracted => "T",
        RayKind::Primary => "",
        RayKind::Shadow => "S",
    }
}

/// Why a branch ended, in words.
pub fn end_text(end: EndReason) -> &'static str {
    match end {
        EndReason::NoHit => "no hit",
        EndReason::HitLight => "hit light",
        EndReason::MaxDepth => "max depth",
        EndReason::Cutoff => "cutoff",
        EndReason::Budget => "ray budget",
    }
}

/// The text in a node's box: the object its ray hit, or why it ended (and which light it met).
pub fn node_label(node: &Node) -> String {
    match (&node.end, &node.hit, &node.light) {
        (Some(EndReason::HitLight), _, Some(light)) => format!("light {}", light.name),
        (Some(end), _, _) => end_text(*end).to_string(),
        (None, Some(hit), _) => hit.object.clone(),
        _ => String::new(),
    }
}

fn not_traced(node: &Node) -> bool {
    matches!(
        node.end,
        Some(EndReason::MaxDepth | EndReason::Cutoff | EndReason::Budget)
    )
}

fn text_width(text: &str) -> f32 {
    text.chars().count() as f32 * CHAR_W
}

/// Width of a node's box: its swatch and label on the first line, its glyphs (and the TIR
/// marker) on the second.
fn node_width(node: &Node, label: &str) -> f32 {
    let line1 = SWATCH + PAD + text_width(label);
    let tir = if node.total_internal_reflection {
        PAD + text_width("TIR")
    } else {
        0.0
    };
    let line2 = node.shadow_rays.len() as f32 * GLYPH_PITCH + tir;
    (line1.max(line2) + 2.0 * PAD).max(48.0)
}

/// The left and right edges of a subtree on each row below its root, relative to the root's
/// centre.
type Contour = Vec<(f32, f32)>;

/// A node during layout: its x relative to its parent's.
struct Placed<'a> {
    node: &'a Node,
    path: NodePath,
    parent: Option<usize>,
    rel_x: f32,
    width: f32,
}

/// Lays out `node`'s subtree (a simple contour-based tidy tree, after Reingold and Tilford:
/// each child subtree is pushed right just far enough to clear its left siblings on every
/// row), and returns the subtree's contour. Nodes are pushed in pre-order.
fn place<'a>(
    node: &'a Node,
    path: &mut NodePath,
    parent: Option<usize>,
    shown: &dyn Fn(&Node, &NodePath) -> bool,
    out: &mut Vec<Placed<'a>>,
) -> Contour {
    let me = out.len();
    let width = node_width(node, &node_label(node));
    out.push(Placed {
        node,
        path: path.clone(),
        parent,
        rel_x: 0.0,
        width,
    });
    let mut children: Vec<(usize, f32)> = Vec::new();
    let mut merged: Contour = Vec::new();
    if shown(node, path) {
        for (i, child) in node.children.iter().enumerate() {
            path.push(i);
            let index = out.len();
            let contour = place(child, path, Some(me), shown, out);
            path.pop();
            // How far right this subtree must go to clear everything left of it.
            let shift = if children.is_empty() {
                0.0
            } else {
                merged
                    .iter()
                    .zip(&contour)
                    .map(|(acc, next)| acc.1 + GAP - next.0)
                    .fold(f32::NEG_INFINITY, f32::max)
            };
            for (level, &(l, r)) in contour.iter().enumerate() {
                match merged.get_mut(level) {
                    // A subtree to the right: its right edge is the row's right edge.
                    Some(row) => row.1 = r + shift,
                    None => merged.push((l + shift, r + shift)),
                }
            }
            children.push((index, shift));
        }
    }
    let centre = match (children.first(), children.last()) {
        (Some(first), Some(last)) => (first.1 + last.1) / 2.0,
        _ => 0.0,
    };
    for &(index, x) in &children {
        out[index].rel_x = x - centre;
    }
    let mut contour = vec![(-width / 2.0, width / 2.0)];
    contour.extend(merged.iter().map(|&(l, r)| (l - centre, r - centre)));
    contour
}

fn count(node: &Node) -> usize {
    1 + node.children.iter().map(count).sum::<usize>()
}

/// How many nodes lie below `node` (what a folded node's "+N" says).
pub fn descendants(node: &Node) -> usize {
    count(node) - 1
}

/// Lays out `tree` for drawing: see [`Layout`].
pub fn layout(tree: &RayTree, options: &Options) -> Layout {
    layout_folded(tree, options, &[])
}

/// [`layout`] with the subtrees below the nodes at `folded` left out, each counted in its
/// node's [`LaidNode::hidden_children`].
pub fn layout_folded(tree: &RayTree, options: &Options, folded: &[NodePath]) -> Layout {
    let shown = |node: &Node, path: &NodePath| {
        node.depth < options.max_generation && !folded.contains(path)
    };
    let mut placed = Vec::new();
    place(&tree.root, &mut Vec::new(), None, &shown, &mut placed);
    // Absolute x: parents come before their children.
    let mut xs = vec![0.0_f32; placed.len()];
    for i in 0..placed.len() {
        xs[i] = placed[i].parent.map_or(0.0, |p| xs[p]) + placed[i].rel_x;
    }
    let left = placed
        .iter()
        .zip(&xs)
        .map(|(p, x)| x - p.width / 2.0)
        .fold(f32::INFINITY, f32::min);
    let mut nodes = Vec::with_capacity(placed.len());
    let mut hidden = 0;
    for (p, x) in placed.iter().zip(&xs) {
        let node = p.node;
        let center = [
            x - left,
            node.depth as f32 * ROW + NODE_H / 2.0 - tree.root.depth as f32 * ROW,
        ];
        let hidden_children = if shown(node, &p.path) {
            0
        } else {
            descendants(node)
        };
        hidden += hidden_children;
        let glyph_y = center[1] + NODE_H / 4.0;
        let glyph_x0 = center[0] - p.width / 2.0 + PAD + GLYPH_PITCH / 2.0;
        let glyphs = node
            .shadow_rays
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let glyph = Glyph::of(s);
                let verdict = match (glyph, &s.blocked_by) {
                    (Glyph::Blocked, Some(b)) => format!("blocked by {b}"),
                    (Glyph::NoContribution, _) => "not traced: contributes nothing".to_string(),
                    (Glyph::FacingAway, _) => "facing away".to_string(),
                    _ => "lit".to_string(),
                };
                ShadowGlyph {
                    glyph,
                    at: [glyph_x0 + k as f32 * GLYPH_PITCH, glyph_y],
                    note: format!("light {}: {verdict}", s.light),
                }
            })
            .collect();
        nodes.push(LaidNode {
            path: p.path.clone(),
            depth: node.depth,
            kind: node.kind,
            center,
            size: [p.width, NODE_H],
            label: node_label(node),
            swatch: to_srgb8(node.color),
            not_traced: not_traced(node),
            total_internal_reflection: node.total_internal_reflection,
            glyphs,
            hidden_children,
        });
    }
    let mut edges = Vec::new();
    for (child, p) in placed.iter().enumerate() {
        let Some(parent) = p.parent else { continue };
        let (a, b) = (&nodes[parent], &nodes[child]);
        let from = [a.center[0], a.center[1] + NODE_H / 2.0];
        let to = [b.center[0], b.center[1] - NODE_H / 2.0];
        edges.push(Edge {
            parent,
            child,
            kind: b.kind,
            label: edge_label(b.kind),
            from,
            to,
            label_at: [(from[0] + to[0]) / 2.0, (from[1] + to[1]) / 2.0],
            not_traced: b.not_traced,
        });
    }
    let width = nodes.iter().map(|n| n.rect()[2]).fold(0.0_f32, f32::max);
    let height = nodes.iter().map(|n| n.rect()[3]).fold(0.0_f32, f32::max);
    Layout {
        nodes,
        edges,
        size: [width, height],
        hidden,
    }
}

/// One value that differs between two trees, named: "max depth 3 \u{2192} 5", "kr of glass
/// (0.10, 0.10, 0.10) \u{2192} (0.30, 0.30, 0.30)". The values are those the trees record: their
/// settings and the weights (kr, kt) each material gave its rays.
pub fn changes(before: &RayTree, after: &RayTree) -> Vec<String> {
    let mut out = Vec::new();
    let mut note = |name: &str, a: String, b: String| {
        if a != b {
            out.push(format!("{name} {a} \u{2192} {b}"));
        }
    };
    let (s, t) = (&before.settings, &after.settings);
    note(
        "pixel",
        format!("{:?}", before.pixel),
        format!("{:?}", after.pixel),
    );
    note(
        "max depth",
        s.max_depth.to_string(),
        t.max_depth.to_string(),
    );
    note("shading", s.shading.name().into(), t.shading.name().into());
    note(
        "cutoff",
        s.trace.cutoff.to_string(),
        t.trace.cutoff.to_string(),
    );
    note(
        "accel",
        s.trace.accel.name().into(),
        t.trace.accel.name().into(),
    );
    if s.trace.methods != t.trace.methods {
        out.push("tracing methods changed".into());
    }
    let (mut a, mut b) = (Vec::new(), Vec::new());
    weights(&before.root, &mut a);
    weights(&after.root, &mut b);
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for (material, name, wa) in &a {
        if seen.contains(&(material.as_str(), name)) {
            continue;
        }
        seen.push((material.as_str(), name));
        let Some((_, _, wb)) = b.iter().find(|(m, n, _)| m == material && n == name) else {
            continue;
        };
        let v = |w: &glam::Vec3| format!("({:.2}, {:.2}, {:.2})", w.x, w.y, w.z);
        if (*wa - *wb).abs().max_element() > 1e-6 {
            out.push(format!("{name} of {material} {} \u{2192} {}", v(wa), v(wb)));
        }
    }
    if before.nodes != after.nodes {
        out.push(format!("nodes {} \u{2192} {}", before.nodes, after.nodes));
    }
    out
}

/// (material, "kr" or "kt", weight) of every node that recorded one.
fn weights(node: &Node, out: &mut Vec<(String, &'static str, glam::Vec3)>) {
    // On total internal reflection kr holds kt too: not the material's own value.
    if let Some(hit) = node
        .hit
        .as_ref()
        .filter(|_| !node.total_internal_reflection)
    {
        if let Some(kr) = node.kr {
            out.push((hit.material.clone(), "kr", kr));
        }
        if let Some(kt) = node.kt {
            out.push((hit.material.clone(), "kt", kt));
        }
    }
    for child in &node.children {
        weights(child, out);
    }
}

// ---- SVG ------------------------------------------------------------------------------------

/// `text` with XML's special characters escaped, for element text and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // XML 1.0 allows no other control characters, even escaped.
            c if (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

/// `stroke="#rrggbb" stroke-opacity=".."` (or fill) for a palette colour with alpha.
fn paint(attr: &str, rgba: [u8; 4]) -> String {
    let [r, g, b, a] = rgba;
    if a == 255 {
        format!("{attr}=\"{}\"", hex([r, g, b]))
    } else {
        format!(
            "{attr}=\"{}\" {attr}-opacity=\"{:.2}\"",
            hex([r, g, b]),
            a as f32 / 255.0
        )
    }
}

/// The title line: the pixel, its colour and what produced the tree.
pub fn title(tree: &RayTree) -> String {
    let [r, g, b] = tree.color.to_array();
    let s = &tree.settings;
    format!(
        "Ray tracing tree of pixel ({}, {}): colour ({r:.3}, {g:.3}, {b:.3}); {}{}; \
         max depth {}, {} shading, cutoff {}, accel {}",
        tree.pixel[0],
        tree.pixel[1],
        crate::plural::count(tree.nodes, "node"),
        if tree.truncated { " (truncated)" } else { "" },
        s.max_depth,
        s.shading.name(),
        s.trace.cutoff,
        s.trace.accel.name(),
    )
}

fn svg_glyph(out: &mut String, glyph: Glyph, [x, y]: [f32; 2], note: &str) {
    let c = glyph.rgba();
    let _ = write!(out, "<g><title>{}</title>", escape(note));
    match glyph {
        Glyph::Lit | Glyph::FacingAway => {
            let _ = write!(
                out,
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"4\" {}/>",
                paint("fill", c)
            );
        }
        Glyph::NoContribution => {
            let _ = write!(
                out,
                "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"3.5\" fill=\"none\" stroke-width=\"1.5\" {}/>",
                paint("stroke", c)
            );
        }
        Glyph::Blocked => {
            let d = 4.0;
            let _ = write!(
                out,
                "<path d=\"M{:.1} {:.1}L{:.1} {:.1}M{:.1} {:.1}L{:.1} {:.1}\" stroke-width=\"2\" {}/>",
                x - d,
                y - d,
                x + d,
                y + d,
                x - d,
                y + d,
                x + d,
                y - d,
                paint("stroke", c)
            );
        }
    }
    out.push_str("</g>");
}

/// Top margin for the title line, and the margin round the figure.
const TITLE_H: f32 = 34.0;
const MARGIN: f32 = 16.0;
const LEGEND_W: f32 = 330.0;
const LEGEND_ROW: f32 = 20.0;

/// The figure as a standalone SVG document: title line, edges with R/T labels, node boxes
/// (colour swatch, object name or end reason, shadow glyphs), and the legend on the right.
pub fn svg(tree: &RayTree, options: &Options) -> String {
    let lay = layout(tree, options);
    let entries: Vec<LegendEntry> = legend()
        .into_iter()
        .filter(|e| e.mark != Mark::Highlight)
        .collect();
    let legend_h = entries.len() as f32 * LEGEND_ROW + 28.0;
    let title = title(tree);
    let width = (MARGIN * 3.0 + lay.size[0] + LEGEND_W).max(text_width(&title) + 2.0 * MARGIN);
    let height = TITLE_H + MARGIN + lay.size[1].max(legend_h) + MARGIN;
    let (ox, oy) = (MARGIN, TITLE_H + MARGIN);
    let mut out = String::new();
    let _ = write!(
        out,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" \
         width=\"{width:.0}\" height=\"{height:.0}\" viewBox=\"0 0 {width:.0} {height:.0}\" \
         font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\" font-size=\"{FONT}\">\n"
    );
    let _ = writeln!(
        out,
        "<rect width=\"100%\" height=\"100%\" fill=\"{}\"/>",
        hex(BACKGROUND_RGB)
    );
    let _ = writeln!(
        out,
        "<text x=\"{MARGIN}\" y=\"22\" font-size=\"14\" fill=\"{}\">{}</text>",
        hex(TEXT_RGB),
        escape(&title)
    );
    let _ = writeln!(out, "<g transform=\"translate({ox} {oy})\">");
    out.push_str("<g class=\"edges\">\n");
    for e in &lay.edges {
        let rgba = if e.not_traced {
            style_rgba(Style::NotTraced(e.kind))
        } else {
            style_rgba(Style::Ray(e.kind))
        };
        let dash = if e.not_traced {
            " stroke-dasharray=\"4 3\""
        } else {
            ""
        };
        let _ = writeln!(
            out,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke-width=\"2\" {}{dash}/>",
            e.from[0],
            e.from[1],
            e.to[0],
            e.to[1],
            paint("stroke", rgba)
        );
        // The label sits on its own edge, on a patch of background, so it crosses no line.
        let [x, y] = e.label_at;
        let _ = writeln!(
            out,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"14\" height=\"16\" rx=\"3\" fill=\"{}\"/>\
             <text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\" font-weight=\"bold\" {}>{}</text>",
            x - 7.0,
            y - 8.0,
            hex(BACKGROUND_RGB),
            y + 4.5,
            paint("fill", rgba),
            e.label
        );
    }
    out.push_str("</g>\n<g class=\"nodes\">\n");
    for n in &lay.nodes {
        let [x0, y0, _, _] = n.rect();
        let outline = if n.not_traced {
            style_rgba(Style::NotTraced(n.kind))
        } else {
            style_rgba(Style::Ray(n.kind))
        };
        let _ = write!(
            out,
            "<g><title>{} d{}: {}</title>",
            escape(if n.kind == RayKind::Primary {
                "primary"
            } else {
                edge_label(n.kind)
            }),
            n.depth,
            escape(&n.label)
        );
        let _ = write!(
            out,
            "<rect x=\"{x0:.1}\" y=\"{y0:.1}\" width=\"{:.1}\" height=\"{NODE_H}\" rx=\"5\" \
             fill=\"#2a2a2a\" stroke-width=\"{}\" {}{}/>",
            n.size[0],
            if n.depth == 0 { 2.5 } else { 1.5 },
            paint("stroke", outline),
            if n.not_traced {
                " stroke-dasharray=\"4 3\""
            } else {
                ""
            }
        );
        let line1 = y0 + PAD + SWATCH / 2.0;
        let _ = write!(
            out,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{SWATCH}\" height=\"{SWATCH}\" fill=\"{}\" \
             stroke=\"#808080\" stroke-width=\"0.5\"/>",
            x0 + PAD,
            line1 - SWATCH / 2.0,
            hex(n.swatch)
        );
        let _ = write!(
            out,
            "<text x=\"{:.1}\" y=\"{:.1}\" {}>{}</text>",
            x0 + PAD + SWATCH + PAD,
            line1 + 4.0,
            paint(
                "fill",
                if n.not_traced {
                    outline
                } else {
                    let [r, g, b] = TEXT_RGB;
                    [r, g, b, 255]
                }
            ),
            escape(&n.label)
        );
        for g in &n.glyphs {
            svg_glyph(&mut out, g.glyph, g.at, &g.note);
        }
        if n.total_internal_reflection {
            let _ = write!(
                out,
                "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" fill=\"{}\">TIR</text>",
                x0 + PAD + n.glyphs.len() as f32 * GLYPH_PITCH + PAD,
                n.center[1] + NODE_H / 4.0 + 3.5,
                hex(TIR_RGB)
            );
        }
        if n.hidden_children > 0 {
            let _ = write!(
                out,
                "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"10\" text-anchor=\"middle\" fill=\"{}\">+{} below</text>",
                n.center[0],
                y0 + NODE_H + 14.0,
                hex(TEXT_RGB),
                n.hidden_children
            );
        }
        out.push_str("</g>\n");
    }
    out.push_str("</g>\n</g>\n");
    // The legend, right of the figure.
    let lx = MARGIN * 2.0 + lay.size[0];
    let _ = writeln!(
        out,
        "<g class=\"legend\" transform=\"translate({lx:.1} {oy})\">\
         <rect width=\"{LEGEND_W}\" height=\"{legend_h:.0}\" rx=\"6\" fill=\"#232323\" stroke=\"#555\"/>\
         <text x=\"10\" y=\"18\" font-weight=\"bold\" fill=\"{}\">Legend</text>",
        hex(TEXT_RGB)
    );
    for (i, e) in entries.iter().enumerate() {
        let y = 34.0 + i as f32 * LEGEND_ROW;
        let x = 22.0;
        match e.mark {
            Mark::Ray(kind) => {
                let _ = write!(
                    out,
                    "<line x1=\"{}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke-width=\"2\" {}/>\
                     <text x=\"{x}\" y=\"{:.1}\" text-anchor=\"middle\" font-weight=\"bold\" font-size=\"10\" {}>{}</text>",
                    x - 12.0,
                    x + 12.0,
                    paint("stroke", e.rgba),
                    y - 3.0,
                    paint("fill", e.rgba),
                    edge_label(kind)
                );
            }
            Mark::Glyph(g) => svg_glyph(&mut out, g, [x, y], e.text),
            Mark::Swatch => {
                let _ = write!(
                    out,
                    "<rect x=\"{}\" y=\"{}\" width=\"{SWATCH}\" height=\"{SWATCH}\" fill=\"#c08040\" stroke=\"#808080\" stroke-width=\"0.5\"/>",
                    x - SWATCH / 2.0,
                    y - SWATCH / 2.0
                );
            }
            Mark::NotTraced => {
                let _ = write!(
                    out,
                    "<rect x=\"{}\" y=\"{}\" width=\"24\" height=\"12\" rx=\"3\" fill=\"none\" stroke-dasharray=\"4 3\" {}/>",
                    x - 12.0,
                    y - 6.0,
                    paint("stroke", e.rgba)
                );
            }
            Mark::Tir => {
                let _ = write!(
                    out,
                    "<text x=\"{x}\" y=\"{:.1}\" text-anchor=\"middle\" font-size=\"10\" {}>TIR</text>",
                    y + 3.5,
                    paint("fill", e.rgba)
                );
            }
            Mark::Highlight => {}
        }
        let _ = writeln!(
            out,
            "<text x=\"44\" y=\"{:.1}\" fill=\"{}\">{}</text>",
            y + 4.0,
            hex(TEXT_RGB),
            escape(e.text)
        );
    }
    out.push_str("</g>\n</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_covers_xml_specials() {
        assert_eq!(
            escape("a<b>&\"c'\u{1}"),
            "a&lt;b&gt;&amp;&quot;c&apos;\u{fffd}"
        );
    }

    fn shadow(facing_away: bool, contributes_nothing: bool, blocked: bool) -> ShadowRecord {
        use glam::Vec3;
        ShadowRecord {
            light: "key".into(),
            to_light: Vec3::Y,
            distance: 1.0,
            blocked_by: blocked.then(|| "floor".to_string()),
            blocked_at: None,
            facing_away,
            contributes_nothing,
            behind_surface: false,
            n_dot_l: 0.5,
            n_dot_h: 0.5,
            r_dot_v: 0.5,
            halfway: Vec3::Y,
            mirror: Vec3::Y,
            diffuse: Vec3::ZERO,
            specular: Vec3::ZERO,
        }
    }

    #[test]
    fn a_light_that_contributes_nothing_has_its_own_glyph_and_legend_entry() {
        let nothing = Glyph::of(&shadow(false, true, false));
        let behind = Glyph::of(&shadow(true, false, false));
        assert_eq!(nothing, Glyph::NoContribution);
        assert_eq!(behind, Glyph::FacingAway);
        assert_ne!(nothing.rgba(), behind.rgba());
        assert_eq!(Glyph::of(&shadow(false, false, true)), Glyph::Blocked);
        assert_eq!(Glyph::of(&shadow(false, false, false)), Glyph::Lit);
        let entries = legend();
        let text = |g| {
            entries
                .iter()
                .find(|e| e.mark == Mark::Glyph(g))
                .map(|e| e.text)
                .expect("an entry")
        };
        assert!(text(Glyph::NoContribution).contains("contributes nothing"));
        assert!(!text(Glyph::FacingAway).contains("contributes nothing"));
    }

    /// The glass sphere's tree in the 160×120 default scene.
    fn glass_tree() -> RayTree {
        let mut scene = crate::scene::builtin::load_builtin("default").expect("built in");
        (scene.render.width, scene.render.height) = (160, 120);
        let tracer = crate::trace::Tracer::new(
            std::sync::Arc::new(scene),
            crate::trace::TraceSettings::default(),
        );
        crate::ray_tree::pixel_tree(&tracer, 60, 69).expect("inside the image")
    }

    #[test]
    fn changes_name_the_settings_and_weights_that_differ() {
        let before = glass_tree();
        assert!(changes(&before, &before).is_empty());
        let mut after = before.clone();
        after.settings.max_depth = before.settings.max_depth + 2;
        fn bump(node: &mut Node, first: &mut Option<String>) {
            // Every node of one material, as an edit of that material would.
            if let (Some(hit), Some(kr)) = (&node.hit, node.kr.as_mut())
                && !node.total_internal_reflection
                && first.get_or_insert(hit.material.clone()) == &hit.material
            {
                *kr += glam::Vec3::splat(0.25);
            }
            for child in &mut node.children {
                bump(child, first);
            }
        }
        let mut first = None;
        bump(&mut after.root, &mut first);
        let material = first.expect("a node with kr");
        let found = changes(&before, &after);
        let depth = format!(
            "max depth {} \u{2192} {}",
            before.settings.max_depth, after.settings.max_depth
        );
        assert!(found.contains(&depth), "{found:?}");
        assert!(
            found
                .iter()
                .any(|c| c.starts_with(&format!("kr of {material} ("))),
            "{found:?}"
        );
        assert_eq!(found.len(), 2, "{found:?}");
    }

    #[test]
    fn legend_names_every_glyph_once() {
        let entries = legend();
        for g in Glyph::ALL {
            assert_eq!(
                entries.iter().filter(|e| e.mark == Mark::Glyph(g)).count(),
                1
            );
        }
    }
}
