//! The pseudocode pane: the lecture's recursive procedure ([`pseudocode::LINES`]) beside the
//! ray tree, for the node selected in the tree's views. The lines its call of `trace` ran are
//! marked, the line where it returned is highlighted, and the variables of those lines (the
//! ray, the hit, N·L, kr, kt, the sum so far) are listed with their values. While the depth
//! step or Play walks the tree, the pane follows the generation revealed: the call at that
//! depth on the way to the selected node (or below it, along first children).
//!
//! Code lines too wide for the pane wrap; values too wide are elided, the whole text on
//! hover.

use eframe::egui::{self, Color32, RichText, Ui};

use super::selection::TreeSelection;
use crate::lessons::node_name;
use crate::lessons::pseudocode::{self, Executed, LINES};
use crate::ray_tree::{Node, RayTree};

/// What the pane drew last frame (for the tests and the snapshots' checks).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Drawn {
    /// The node whose call is shown, as child indices from the root.
    pub node: Option<Vec<usize>>,
    /// The id of the line highlighted.
    pub line: Option<&'static str>,
    /// The smallest text size drawn (points).
    pub least_text: Option<f32>,
}

/// The node the pane shows: the selected one, or with the step-through on, the call of the
/// generation revealed on its way.
pub fn shown_node<'t>(
    tree: &'t RayTree,
    selected: &[usize],
    reveal: Option<u32>,
) -> (Vec<usize>, &'t Node) {
    let mut node = &tree.root;
    let mut path = Vec::new();
    for &i in selected {
        if reveal.is_some_and(|g| node.depth >= g) {
            break;
        }
        let Some(child) = node.children.get(i) else {
            break;
        };
        node = child;
        path.push(i);
    }
    if let Some(g) = reveal {
        while node.depth < g && !node.children.is_empty() {
            node = &node.children[0];
            path.push(0);
        }
    }
    (path, node)
}

/// The code of a line and its comment apart (the comment goes to the hover).
fn code_and_comment(text: &str) -> (&str, Option<&str>) {
    match text.find("//") {
        Some(i) => (text[..i].trim_end(), Some(text[i + 2..].trim())),
        None => (text, None),
    }
}

/// The pane for the selected node of the current tree.
pub fn ui(ui: &mut Ui, selection: &TreeSelection, drawn: &mut Drawn) {
    let before = std::mem::take(drawn);
    let Some(tree) = &selection.tree else {
        ui.weak("click a pixel in the render view: its tree's calls of trace() are shown here");
        return;
    };
    let state = &selection.tree_state;
    let selected = state.selected.clone().unwrap_or_default();
    let (path, node) = shown_node(tree, &selected, state.reveal);
    let lines = pseudocode::node_lines(node, &path, tree.settings.max_depth);
    let current = lines.last().map(|e| e.line);
    drawn.node = Some(path.clone());
    drawn.line = current;
    // A new line to show (another node, or the step-through moved on) is scrolled to.
    let moved = (before.node.as_ref(), before.line) != (Some(&path), current);
    let body = egui::TextStyle::Body.resolve(ui.style()).size;
    let mono = egui::TextStyle::Monospace.resolve(ui.style()).size;
    drawn.least_text = Some(body.min(mono));
    let [x, y] = tree.pixel;
    let name = node_name(tree, &path);
    let mut head = format!("trace() for {name} of ({x}, {y}), step {}", node.depth);
    if let Some(g) = state.reveal {
        head.push_str(&format!(" (generation {g} revealed)"));
    }
    ui.add(egui::Label::new(RichText::new(head).strong()).truncate());
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| {
            code(ui, &lines, current, moved);
            ui.separator();
            variables(ui, &lines);
        });
}

/// The procedure, the lines run marked and the returning one highlighted.
fn code(ui: &mut Ui, lines: &[Executed], current: Option<&str>, scroll: bool) {
    let highlight = ui.visuals().selection.bg_fill;
    for line in LINES {
        let ran = lines.iter().any(|e| e.line == line.id);
        let here = current == Some(line.id);
        let (text, comment) = code_and_comment(line.text);
        let marker = if here {
            "→"
        } else if ran {
            "•"
        } else {
            " "
        };
        let indent = "  ".repeat(line.indent as usize);
        let mut rich = RichText::new(format!("{marker} {indent}{text}")).monospace();
        rich = if here {
            rich.strong()
                .background_color(highlight)
                .color(Color32::WHITE)
        } else if ran {
            rich
        } else {
            rich.weak()
        };
        // Wrapped, not cut, in a narrow pane: every line reads whole.
        let r = ui.add(egui::Label::new(rich).wrap());
        if here && scroll {
            r.scroll_to_me(Some(egui::Align::Center));
        }
        let mut hover = line.text.to_string();
        if here {
            hover.push_str("\n(the call returns here)");
        } else if !ran {
            hover.push_str("\n(not run by this call)");
        }
        if comment.is_some() || here || !ran {
            r.on_hover_text(hover);
        }
    }
}

/// The variables of the lines run, in order, each under its line's id.
fn variables(ui: &mut Ui, lines: &[Executed]) {
    ui.label(RichText::new("variables").strong());
    // The names' column: as wide as the widest name ("sum so far"), a third of the pane at most.
    let names = (ui.available_width() / 3.0).clamp(40.0, 100.0);
    let mut listed: Vec<(&str, &str)> = Vec::new();
    for e in lines {
        for (name, value) in &e.vars {
            // A variable shown again with the same value (`step` on two lines) is listed once.
            if listed.contains(&(name, value.as_str())) {
                continue;
            }
            listed.push((name, value.as_str()));
            ui.horizontal(|ui| {
                let height = ui.spacing().interact_size.y;
                ui.allocate_ui(egui::vec2(names, height), |ui| {
                    ui.set_width(names);
                    ui.add(egui::Label::new(RichText::new(*name).monospace().weak()).truncate());
                });
                ui.add(egui::Label::new(RichText::new(value).monospace()).truncate())
                    .on_hover_text(format!("{name} = {value} (line \"{}\")", e.line));
            });
        }
    }
}
