//! The ray tree's panes stay readable at common window sizes, through the real viewer: the
//! diagram's labels are never below the readable floor (a large tree scrolls instead), every
//! list cell fits its column or is elided with its full text on hover, and focus mode gives the
//! tree the window and gives the layout back exactly.

#[path = "common/viewer.rs"]
mod viewer;

use std::time::{Duration, Instant};

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use raytree::diagram::MIN_LABEL_PX;
use viewer::{Window, small, window};

/// Steps until the render follows its pane, so a click lands on the pixel under it.
fn follow_pane(h: &mut Window) {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        h.step();
        let image = h.get_by_label("render viewport").rect();
        let (w, hh) = h.state().render_size();
        let app = h.state();
        // The pane's pixels are the render's, and the image fills it 1:1.
        if app.render.pane_seen(&app.workspace.prefs) == Some((w, hh))
            && (image.width() - w as f32).abs() <= 1.0
            && (image.height() - hh as f32).abs() <= 1.0
        {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "the render never followed its pane"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Clicks the glass sphere of the default scene and lets the tree's panes open.
fn click_glass(h: &mut Window) {
    let image = h.get_by_label("render viewport").rect();
    let at = image.lerp_inside(egui::vec2(0.378, 0.58));
    h.hover_at(at);
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        h.step();
    }
    h.run_steps(3);
    assert!(h.state().selection.tree.is_some(), "a tree after the click");
}

/// Where the root's detail starts (its summary, "primary d0 · …"): the one of the nodes so
/// labelled that is laid out.
fn root_detail(h: &Window) -> egui::Rect {
    h.query_all_by_label_contains("primary d0 · ")
        .map(|n| n.rect())
        .find(|r| r.is_finite())
        .expect("the root's detail is shown")
}

/// Opens the default scene in a `size` window with the glass sphere's tree in the list.
fn list_of_glass(size: [f32; 2]) -> Window {
    let mut h = window(small("default"), size);
    follow_pane(&mut h);
    click_glass(&mut h);
    show_tab(&mut h, "Tree list");
    h
}

fn show_tab(h: &mut Window, title: &str) {
    h.get_by_role_and_label(Role::Button, title).click();
    h.run_steps(3);
}

#[test]
fn the_diagram_and_the_list_are_readable_at_common_sizes() {
    for size in [[1024.0, 640.0], [1600.0, 1000.0]] {
        let mut h = window(small("default"), size);
        follow_pane(&mut h);
        click_glass(&mut h);
        let tree = h.state().selection.tree.clone().expect("a tree");
        show_tab(&mut h, "Diagram");
        let label = h.state().selection.tree_state.drawn.diagram_label;
        let label = label.expect("the diagram was drawn");
        assert!(
            label >= MIN_LABEL_PX,
            "{size:?}: diagram labels at {label:.1} pt, below {MIN_LABEL_PX}"
        );
        // The root's box is in the pane, however large the tree.
        let pane = h
            .get_by_label(&format!(
                "ray tree diagram of ({}, {})",
                tree.pixel[0], tree.pixel[1]
            ))
            .rect();
        let root = h.get_by_label_contains("tree node primary:").rect();
        assert!(pane.intersects(root), "{size:?}: the root is out of view");

        show_tab(&mut h, "Tree list");
        let cells = h.state().selection.tree_state.drawn.cells.clone();
        assert!(
            cells.len() >= 3,
            "{size:?}: {} list cells drawn",
            cells.len()
        );
        for c in &cells {
            assert!(c.readable(), "{size:?}: a list cell is cut: {c:?}");
        }
        // The table has the room: at least four of its rows above the selected node's
        // detail (which starts with the root's summary, "primary d0 · …").
        let detail = root_detail(&h);
        let rows = h
            .query_all_by(|n| {
                let label = n.value().unwrap_or_default();
                let mut words = label.split(' ');
                matches!(words.next(), Some("primary" | "R" | "T"))
                    && words.next().is_some_and(|d| d.starts_with('d'))
                    && words.next().is_none()
            })
            .filter(|n| n.rect().max.y <= detail.min.y + 0.5)
            .count();
        assert!(
            rows >= 4,
            "{size:?}: {rows} rows of the tree list above its detail at {detail:?}"
        );
    }
}

/// A deep tree in the narrow list of a small window keeps every ray label whole: the rows are
/// indented less, not elided.
#[test]
fn a_deep_tree_keeps_its_ray_labels_whole_in_a_narrow_list() {
    let mut scene = small("default");
    scene.render.max_depth = 12;
    let mut h = window(scene, [1024.0, 640.0]);
    follow_pane(&mut h);
    click_glass(&mut h);
    show_tab(&mut h, "Tree list");
    let tree = h.state().selection.tree.clone().expect("a tree");
    let depth = raytree::app::scene_pane::deepest([&tree]);
    assert!(depth >= 8, "the glass sphere's tree is only {depth} deep");
    let cells = h.state().selection.tree_state.drawn.cells.clone();
    assert!(
        !cells.is_empty() && cells.len() % 3 == 0,
        "{} list cells, not rows of three",
        cells.len()
    );
    // Each row's first cell is its ray label ("T d9").
    for (row, c) in cells.chunks(3).enumerate() {
        let ray = &c[0];
        assert!(
            !ray.elided && ray.shown + 0.5 >= ray.full,
            "row {row}'s ray label is cut to {:.0} of {:.0} pt in a {:.0} pt column",
            ray.shown,
            ray.full,
            ray.column
        );
    }
}

/// Columns sized in a wide pane start again from their shares when the pane narrows, so the
/// colour column stays in view.
#[test]
fn the_list_columns_follow_a_narrowed_pane() {
    let mut h = list_of_glass([1600.0, 1000.0]);
    // Where the colour column starts, as a share of the pane (the list is the rightmost pane;
    // its "ray" header starts at the pane's left edge).
    let share = |h: &Window| {
        let header = |name: &str| {
            h.query_all_by_value(name)
                .map(|n| n.rect())
                .find(|r| r.is_finite())
                .unwrap_or_else(|| panic!("the list's {name} header"))
        };
        let (ray, colour) = (header("ray"), header("colour"));
        (colour.min.x - ray.min.x) / (h.ctx.content_rect().max.x - ray.min.x)
    };
    let wide = share(&h);
    h.set_size(egui::vec2(1024.0, 640.0));
    h.run_steps(4);
    let narrow = share(&h);
    assert!(
        narrow <= 0.76,
        "the colour column starts {:.0} % into the narrowed pane ({:.0} % in the wide one)",
        narrow * 100.0,
        wide * 100.0
    );
}

/// The detail below the list keeps its share of the pane when the window grows.
#[test]
fn the_detail_keeps_its_share_when_the_window_grows() {
    let mut h = list_of_glass([1024.0, 640.0]);
    let detail_height = |h: &Window| {
        let top = root_detail(h).min.y;
        let bottom = h.get_by_label_contains("spp").rect().min.y;
        bottom - top
    };
    let small_detail = detail_height(&h);
    h.set_size(egui::vec2(1600.0, 1000.0));
    h.run_steps(4);
    let large_detail = detail_height(&h);
    assert!(
        large_detail >= 1.3 * small_detail,
        "the detail is {large_detail:.0} points tall at 1600x1000, {small_detail:.0} at 1024x640"
    );
}

fn layout_json(h: &Window) -> String {
    serde_json::to_string(&h.state().workspace.prefs.layout).expect("the layout serialises")
}

#[test]
fn focus_gives_the_tree_most_of_the_window_and_leaving_restores_the_layout() {
    let mut h = window(small("default"), [1024.0, 640.0]);
    follow_pane(&mut h);
    click_glass(&mut h);
    show_tab(&mut h, "Diagram");
    let before = layout_json(&h);
    let render_before = h.get_by_label("render viewport").rect();
    let label = "ray tree diagram of (";
    let diagram_before = h.get_by_label_contains(label).rect();
    let pixel = |h: &Window| h.state().selection.tree.as_ref().map(|t| t.pixel);
    let (pixel_before, size_before) = (pixel(&h), h.state().render_size());
    let generation = h.state().render.generation();
    h.key_press(egui::Key::F);
    h.run_steps(4);
    assert!(h.state().workspace.focused(), "F turns focus on");
    // The render keeps its size and its samples (drawn scaled into the strip it has), so the
    // tree is the pixel that was clicked (waited past the pane's debounce).
    for _ in 0..12 {
        h.step();
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(pixel(&h), pixel_before, "focus keeps the tree's pixel");
    assert_eq!(
        h.state().render_size(),
        size_before,
        "focus keeps the render's size"
    );
    assert_eq!(
        h.state().render.generation(),
        generation,
        "focus restarts no render"
    );
    let diagram = h.get_by_label_contains(label).rect();
    let window_area = h.ctx.content_rect().area();
    // The diagram and the list (beside it) hold most of the window.
    assert!(
        diagram.area() > diagram_before.area() * 1.5,
        "{diagram_before:?} -> {diagram:?}"
    );
    assert!(
        diagram.area() > 0.3 * window_area,
        "the diagram has {:.2} of the window",
        diagram.area() / window_area
    );
    let render = h.get_by_label("render viewport").rect();
    assert!(render.width() < 0.3 * h.ctx.content_rect().width());
    if let Ok(path) = std::env::var("RAYTREE_FOCUS_PNG") {
        h.run_steps(20);
        h.render().expect("render").save(path).expect("saved");
    }
    h.key_press(egui::Key::F);
    h.run_steps(4);
    assert!(!h.state().workspace.focused());
    assert_eq!(layout_json(&h), before, "the layout is given back exactly");
    // The render follows its pane back to its old size.
    follow_pane(&mut h);
    let render_after = h.get_by_label("render viewport").rect();
    assert_eq!(
        render_before, render_after,
        "the render is back in its place"
    );
    // The button does the same.
    h.get_by_role_and_label(Role::Button, "Focus").click();
    h.run_steps(3);
    assert!(
        h.state().workspace.focused(),
        "the Focus button turns focus on"
    );
}
