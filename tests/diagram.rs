//! The ray tree's figure (`raytree::diagram`): its tidy layout never overlaps two boxes and
//! draws every edge from a parent to its child one row down, for generated deep and wide trees
//! and the glass scene's trees at max depth 8 to 12; its SVG parses as XML, names every hit's
//! object and lists every glyph in its legend; `raytree tree --diagram` writes it.

use std::sync::Arc;

use glam::Vec3;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use raytree::diagram::{self, Glyph, Layout, Mark, NODE_H, Options, ROW};
use raytree::ray_tree::{HitRecord, Node, RayTree, ShadowRecord, TreeSettings, pixel_tree};
use raytree::scene::Shading;
use raytree::scene::builtin::load_builtin;
use raytree::trace::{EndReason, RayCounts, RayKind, TraceSettings, Tracer};

fn shadow(light: usize, how: u64) -> ShadowRecord {
    ShadowRecord {
        light: format!("light{light}"),
        to_light: Vec3::Y,
        distance: 1.0,
        blocked_by: (how == 1).then(|| "blocker".to_string()),
        blocked_at: (how == 1).then_some(0.5),
        facing_away: how == 2,
        contributes_nothing: false,
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

fn node(kind: RayKind, depth: u32, end: Option<EndReason>, object: &str) -> Node {
    let mut n = Node::new(kind, depth, Vec3::ZERO, Vec3::Z, Vec3::ONE);
    n.end = end;
    n.hit = end.is_none().then(|| HitRecord {
        t: 1.0,
        point: Vec3::ZERO,
        normal: Vec3::Y,
        object: object.to_string(),
        material: "m".to_string(),
        front_face: true,
        barycentric: None,
        geometric_normal: None,
        uv: None,
        texel: None,
    });
    n.color = Vec3::new(0.2, 0.4, 0.6);
    n
}

fn tree_of(root: Node) -> RayTree {
    fn count(n: &Node) -> usize {
        1 + n.children.iter().map(count).sum::<usize>()
    }
    RayTree {
        pixel: [3, 4],
        color: root.color,
        settings: TreeSettings {
            max_depth: 64,
            shading: Shading::BlinnPhong,
            trace: TraceSettings::default(),
        },
        nodes: count(&root),
        truncated: false,
        rays: RayCounts::default(),
        root,
    }
}

/// Seeded numbers for the random trees: each call gives a number below `n` (at least 1).
struct Mix(raytree::rng::Pcg);

impl Mix {
    fn new(seed: u64) -> Self {
        Mix(raytree::rng::Pcg::new(seed))
    }

    fn next(&mut self, n: u64) -> u64 {
        self.0.below(n.max(1) as usize) as u64
    }
}

/// A random tree: each hit has no child, R, T or both (more often both when `wide`), names of
/// random length, up to 3 lights; leaves end for any reason.
fn random_node(rng: &mut Mix, kind: RayKind, depth: u32, max_depth: u32, wide: bool) -> Node {
    let ends = [
        EndReason::NoHit,
        EndReason::HitLight,
        EndReason::MaxDepth,
        EndReason::Cutoff,
        EndReason::Budget,
    ];
    if depth > max_depth || (depth > 0 && rng.next(5) == 0) {
        return node(kind, depth, Some(ends[rng.next(5) as usize]), "");
    }
    let longest = if rng.next(4) == 0 { 30 } else { 8 };
    let name = "o".repeat(1 + rng.next(longest) as usize);
    let mut n = node(kind, depth, None, &name);
    for l in 0..rng.next(4) as usize {
        n.shadow_rays.push(shadow(l, rng.next(3)));
    }
    n.total_internal_reflection = rng.next(6) == 0;
    let branches = if wide { 1 + rng.next(6) } else { rng.next(4) };
    if matches!(branches, 1 | 3..) {
        n.children.push(random_node(
            rng,
            RayKind::Reflected,
            depth + 1,
            max_depth,
            wide,
        ));
    }
    if matches!(branches, 2..) {
        n.children.push(random_node(
            rng,
            RayKind::Refracted,
            depth + 1,
            max_depth,
            wide,
        ));
    }
    n
}

/// The layout's rules, for `tree` shown to `max_generation`.
fn check_layout(tree: &RayTree, options: &Options) -> Result<Layout, String> {
    let lay = diagram::layout(tree, options);
    let mut shown = 0;
    let mut all = 0;
    let mut stack = vec![&tree.root];
    while let Some(n) = stack.pop() {
        all += 1;
        shown += usize::from(n.depth <= options.max_generation);
        stack.extend(&n.children);
    }
    if lay.nodes.len() != shown || lay.hidden != all - shown {
        return Err(format!(
            "{} laid out and {} hidden of {all}, {shown} shown",
            lay.nodes.len(),
            lay.hidden
        ));
    }
    // No two boxes overlap (boxes that only touch do not count).
    let mut rows: Vec<Vec<usize>> = Vec::new();
    for (i, n) in lay.nodes.iter().enumerate() {
        let [x0, y0, x1, y1] = n.rect();
        if x0 < -1e-3 || y0 < -1e-3 || x1 > lay.size[0] + 1e-3 || y1 > lay.size[1] + 1e-3 {
            return Err(format!("node {:?} outside the figure", n.path));
        }
        let d = n.depth as usize;
        if rows.len() <= d {
            rows.resize(d + 1, Vec::new());
        }
        rows[d].push(i);
    }
    for (i, a) in lay.nodes.iter().enumerate() {
        for b in &lay.nodes[i + 1..] {
            let (ra, rb) = (a.rect(), b.rect());
            let overlap = ra[0] < rb[2] - 1e-3
                && rb[0] < ra[2] - 1e-3
                && ra[1] < rb[3] - 1e-3
                && rb[1] < ra[3] - 1e-3;
            if overlap {
                return Err(format!("{:?} and {:?} overlap", a.path, b.path));
            }
        }
    }
    // Leaves in order: along each row, nodes go left to right in the tree's order.
    for row in &rows {
        let mut by_x = row.clone();
        by_x.sort_by(|&a, &b| lay.nodes[a].center[0].total_cmp(&lay.nodes[b].center[0]));
        let mut by_path = row.clone();
        by_path.sort_by(|&a, &b| lay.nodes[a].path.cmp(&lay.nodes[b].path));
        if by_x != by_path {
            return Err("a row is out of the tree's order".into());
        }
    }
    // Every edge goes from a parent to its child one row down, bottom to top of the boxes,
    // and every shown child has its edge.
    let shown_children = lay.nodes.iter().filter(|n| !n.path.is_empty()).count();
    if lay.edges.len() != shown_children {
        return Err(format!(
            "{} edges, {shown_children} children",
            lay.edges.len()
        ));
    }
    for e in &lay.edges {
        let (p, c) = (&lay.nodes[e.parent], &lay.nodes[e.child]);
        if c.path[..c.path.len() - 1] != p.path[..] || c.depth != p.depth + 1 {
            return Err(format!("edge {:?} -> {:?}", p.path, c.path));
        }
        let (pr, cr) = (p.rect(), c.rect());
        if (e.from[1] - pr[3]).abs() > 1e-3
            || (e.to[1] - cr[1]).abs() > 1e-3
            || (c.center[1] - p.center[1] - ROW).abs() > 1e-3
            || (e.from[0] - p.center[0]).abs() > 1e-3
            || (e.to[0] - c.center[0]).abs() > 1e-3
            || e.kind != c.kind
        {
            return Err(format!("edge {:?} -> {:?} misplaced", p.path, c.path));
        }
    }
    // Parents are centred over their children.
    for (i, p) in lay.nodes.iter().enumerate() {
        let xs: Vec<f32> = lay
            .edges
            .iter()
            .filter(|e| e.parent == i)
            .map(|e| lay.nodes[e.child].center[0])
            .collect();
        if let (Some(first), Some(last)) = (xs.first(), xs.last())
            && (p.center[0] - (first + last) / 2.0).abs() > 1e-2
        {
            return Err(format!("{:?} is not centred over its children", p.path));
        }
    }
    const { assert!(ROW > NODE_H, "rows leave room for edges") };
    Ok(lay)
}

#[test]
fn generated_trees_lay_out_tidily() {
    let config = Config {
        cases: 300,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[12; 32]));
    let strategy = (any::<u64>(), 0u32..14, any::<bool>(), 0u32..16);
    runner
        .run(&strategy, |(seed, max_depth, wide, generation)| {
            let tree = tree_of(random_node(
                &mut Mix::new(seed),
                RayKind::Primary,
                0,
                max_depth,
                wide,
            ));
            for max_generation in [u32::MAX, generation] {
                check_layout(&tree, &Options { max_generation })
                    .map_err(proptest::test_runner::TestCaseError::fail)?;
            }
            Ok(())
        })
        .expect("the layout's rules hold");
}

#[test]
fn a_full_binary_tree_and_a_long_chain_lay_out_tidily() {
    fn full(kind: RayKind, depth: u32, max: u32) -> Node {
        let mut n = node(kind, depth, None, "sphere");
        if depth < max {
            n.children = vec![
                full(RayKind::Reflected, depth + 1, max),
                full(RayKind::Refracted, depth + 1, max),
            ];
        }
        n
    }
    let wide = tree_of(full(RayKind::Primary, 0, 9));
    let lay = check_layout(&wide, &Options::default()).expect("full tree");
    assert_eq!(lay.nodes.len(), 1023);
    let mut chain = node(RayKind::Refracted, 40, Some(EndReason::MaxDepth), "");
    for depth in (0..40).rev() {
        let mut parent = node(
            if depth == 0 {
                RayKind::Primary
            } else {
                RayKind::Reflected
            },
            depth,
            None,
            "mirror",
        );
        parent.children.push(chain);
        chain = parent;
    }
    let deep = tree_of(chain);
    let lay = check_layout(&deep, &Options::default()).expect("chain");
    assert_eq!(lay.nodes.len(), 41);
    let lay = check_layout(&deep, &Options { max_generation: 3 }).expect("chain to 3");
    assert_eq!((lay.nodes.len(), lay.hidden), (4, 37));
}

/// The biggest tree of a few pixels of the glass scene at this max depth.
fn glass_tree(max_depth: u32) -> RayTree {
    let mut scene = load_builtin("glass").expect("built-in glass scene");
    scene.render.max_depth = max_depth;
    let (w, h) = (scene.render.width, scene.render.height);
    let tracer = Tracer::new(Arc::new(scene), TraceSettings::default());
    (1..8)
        .flat_map(|i| (1..8).map(move |j| (w * i / 8, h * j / 8)))
        .filter_map(|(x, y)| pixel_tree(&tracer, x, y))
        .max_by_key(|t| t.nodes)
        .expect("a tree")
}

#[test]
fn the_glass_scene_lays_out_tidily_at_max_depth_8_to_12() {
    for max_depth in 8..=12 {
        let tree = glass_tree(max_depth);
        assert!(tree.nodes > 8, "a branching tree at depth {max_depth}");
        check_layout(&tree, &Options::default()).expect("glass tree");
        check_layout(&tree, &Options { max_generation: 4 }).expect("glass tree to 4");
    }
}

/// Every `<text>` of the document, with its content.
fn texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("the SVG is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.has_tag_name("text") || n.has_tag_name("title"))
        .map(|n| n.text().unwrap_or_default().to_string())
        .collect()
}

#[test]
fn the_svg_parses_names_every_object_and_lists_every_glyph() {
    let tree = glass_tree(8);
    let svg = diagram::svg(&tree, &Options::default());
    let texts = texts(&svg);
    let mut stack = vec![&tree.root];
    while let Some(n) = stack.pop() {
        if let Some(hit) = &n.hit {
            assert!(texts.contains(&hit.object), "{} is named", hit.object);
        }
        stack.extend(&n.children);
    }
    for entry in diagram::legend() {
        if let Mark::Glyph(g) = entry.mark {
            assert!(
                texts.iter().any(|t| t == entry.text),
                "the legend lists {g:?}"
            );
        }
    }
    assert_eq!(
        diagram::legend()
            .iter()
            .filter(|e| matches!(e.mark, Mark::Glyph(_)))
            .count(),
        Glyph::ALL.len()
    );
    assert!(
        texts
            .iter()
            .any(|t| t.starts_with("Ray tracing tree of pixel ("))
    );
}

#[test]
fn svg_text_is_escaped() {
    let name = "a<b> & \"c\" 'd'";
    let mut root = node(RayKind::Primary, 0, None, name);
    root.shadow_rays.push(shadow(0, 1));
    root.children
        .push(node(RayKind::Reflected, 1, Some(EndReason::NoHit), ""));
    let svg = diagram::svg(&tree_of(root), &Options::default());
    assert!(texts(&svg).iter().any(|t| t == name));
}

#[test]
fn the_cli_writes_the_diagram() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("tree.svg");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_raytree"))
        .args(["tree", "default", "--pixel", "300,250", "--diagram"])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("raytree runs");
    assert!(status.success());
    let svg = std::fs::read_to_string(&out).expect("the diagram was written");
    let texts = texts(&svg);
    assert!(texts.iter().any(|t| t == "glass sphere"), "{texts:?}");
}

/// The viewer test harness (tests/common/viewer.rs).
#[cfg(feature = "viewer")]
#[path = "common/viewer.rs"]
mod harness;

/// The viewer's diagram pane, through egui_kittest (see tests/viewer.rs).
#[cfg(feature = "viewer")]
mod viewer {
    use eframe::egui;
    use egui_kittest::kittest::Queryable;

    use super::harness::{Window, settle_render, sized, window_with};

    /// The viewer in a `size` window with the glass sphere's tree picked (pixel (75, 62) of
    /// the 160×120 image: a 13-node tree).
    fn glass_tree(size: [f32; 2]) -> Window {
        // Few samples: the layout, not the picture, is under test.
        let mut h = window_with(sized("default", 160, 120, None), size, |app| {
            app.set_view(4, true)
        });
        settle_render(&mut h, "the render did not finish");
        h.step();
        // Pixel (75, 62) of the 160×120 image is on the glass sphere: a 13-node tree.
        let image = h.get_by_label("render viewport").rect();
        let at = image.min
            + egui::Vec2::new(75.5 / 160.0 * image.width(), 62.5 / 120.0 * image.height());
        h.hover_at(at);
        for pressed in [true, false] {
            h.event(egui::Event::PointerButton {
                pos: at,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: egui::Modifiers::NONE,
            });
        }
        for _ in 0..4 {
            h.step();
        }
        h
    }

    fn ctrl_wheel(h: &mut Window, at: egui::Pos2, delta: f32) {
        h.hover_at(at);
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::Vec2::new(0.0, delta),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers {
                ctrl: true,
                command: true,
                ..egui::Modifiers::NONE
            },
        });
        for _ in 0..4 {
            h.step();
        }
    }

    /// The overview shows in the small window's pane too (within 40 % of it each way), folds
    /// away on its × and comes back from "map".
    #[test]
    fn the_overview_folds_away_and_comes_back() {
        for size in [[1024.0, 640.0], [1600.0, 1000.0]] {
            let mut h = glass_tree(size);
            let [x, y] = h.state().selection.tree.as_ref().expect("a tree").pixel;
            let pane = h
                .get_by_label(&format!("ray tree diagram of ({x}, {y})"))
                .rect();
            // Zoomed in until the tree overflows the pane: the overview shows where the view is.
            for _ in 0..6 {
                ctrl_wheel(&mut h, pane.center(), 120.0);
                if h.query_by_label("ray tree overview").is_some() {
                    break;
                }
            }
            let map = h
                .query_by_label("ray tree overview")
                .unwrap_or_else(|| panic!("{size:?}: no overview of the zoomed tree"))
                .rect();
            assert!(
                pane.contains_rect(map)
                    && map.width() <= pane.width() * 0.34 + 9.0
                    && map.height() <= pane.height() * 0.34 + 9.0,
                "{size:?}: the overview {map:?} is not a corner of the pane {pane:?}"
            );
            // The × inside the overview (a small window has others, on its messages).
            h.query_all_by_label("×")
                .find(|n| map.contains_rect(n.rect()))
                .expect("a × inside the overview")
                .click();
            h.step();
            h.step();
            assert!(
                h.query_by_label("ray tree overview").is_none(),
                "{size:?}: the overview did not fold"
            );
            let button = h.get_by_label("map").rect();
            assert!(
                button.height() < map.height() * 0.5 && pane.contains_rect(button),
                "{size:?}: the folded overview leaves a small button in the pane: {button:?} for {map:?}"
            );
            // The messages' toasts (a small window's "settings hidden") keep off the diagram.
            for toast in h.query_all_by_label("×") {
                assert!(
                    !toast.rect().intersects(pane),
                    "{size:?}: a toast's × {:?} over the diagram {pane:?}",
                    toast.rect()
                );
            }
            h.get_by_label("map").click();
            h.step();
            h.step();
            let back = h
                .query_by_label("ray tree overview")
                .unwrap_or_else(|| panic!("{size:?}: \"map\" did not bring the overview back"));
            assert_eq!(back.rect(), map, "{size:?}");
        }
    }

    /// How to move about the diagram: in the status line while the pointer is over it, and
    /// in the toolbar only on one line where its row has room (at 1024×640 in focus mode it
    /// had wrapped into a second row of the pane).
    #[test]
    fn the_diagram_says_how_to_move_about_it_without_wrapping() {
        use raytree::app::tree_view::DIAGRAM_HINT as HINT;
        for size in [[1024.0, 640.0], [1280.0, 800.0], [1600.0, 1000.0]] {
            let mut h = glass_tree(size);
            for focus in [false, true] {
                if focus {
                    h.get_by_role_and_label(egui::accesskit::Role::Button, "Focus")
                        .click();
                    for _ in 0..4 {
                        h.step();
                    }
                    assert!(h.state().workspace.focused(), "{size:?}: focus is on");
                }
                let fit = h
                    .get_by_role_and_label(egui::accesskit::Role::Button, "Fit")
                    .rect();
                if let Some(hint) = h.query_by_label(HINT) {
                    let r = hint.rect();
                    assert!(
                        r.height() < fit.height() * 1.5
                            && (r.center().y - fit.center().y).abs() < 4.0,
                        "{size:?}, focus {focus}: the hint {r:?} is not on Fit's row {fit:?}"
                    );
                }
                let [x, y] = h.state().selection.tree.as_ref().expect("a tree").pixel;
                let pane = h
                    .get_by_label(&format!("ray tree diagram of ({x}, {y})"))
                    .rect();
                h.hover_at(pane.left_bottom() + egui::vec2(pane.width() * 0.6, -4.0));
                h.step();
                h.step();
                h.get_by_label(&format!("ray tree: {HINT}"));
            }
        }
    }

    #[test]
    fn the_glass_spheres_tree_is_readable_in_its_pane_zooms_and_pans() {
        let mut h = glass_tree([1600.0, 1000.0]);
        let tree = h
            .state()
            .selection
            .tree
            .clone()
            .expect("a tree after the click");
        assert!(
            tree.nodes >= 9,
            "the glass sphere's tree: {} nodes",
            tree.nodes
        );
        let [x, y] = tree.pixel;
        let pane = h
            .get_by_label(&format!("ray tree diagram of ({x}, {y})"))
            .rect();
        // Labels stay readable: what does not fit is scrolled to, the overview says where.
        let nodes: Vec<_> = h
            .query_all_by_label_contains("tree node ")
            .map(|n| n.rect())
            .collect();
        assert!(!nodes.is_empty() && nodes.len() <= tree.nodes);
        for r in &nodes {
            assert!(pane.intersects(*r), "node {r:?} is in the pane {pane:?}");
        }
        let label = h.state().selection.tree_state.drawn.diagram_label;
        assert!(label.expect("drawn") >= raytree::diagram::MIN_LABEL_PX);
        if nodes.len() < tree.nodes {
            h.get_by_label("ray tree overview");
        }
        // Ctrl+wheel zooms about the pointer: the root grows and stays under it.
        let root_label = "tree node primary: glass sphere";
        let before = h.get_by_label(root_label).rect();
        ctrl_wheel(&mut h, before.center(), 60.0);
        let zoomed = h.get_by_label(root_label).rect();
        assert!(
            zoomed.width() > before.width() * 1.05,
            "{before:?} -> {zoomed:?}"
        );
        assert!(
            (zoomed.center() - before.center()).length() < 2.0,
            "{before:?} -> {zoomed:?}"
        );
        // Drag pans.
        // Clear of the overview in the bottom-left corner.
        let from = pane.lerp_inside(egui::vec2(0.5, 0.6));
        let to = from + egui::Vec2::new(40.0, 30.0);
        h.drag_at(from);
        h.step();
        for k in 1..=4 {
            h.hover_at(from + (to - from) * k as f32 / 4.0);
            h.step();
        }
        h.drop_at(to);
        h.step();
        let panned = h.get_by_label(root_label).rect();
        assert!(
            (panned.center() - zoomed.center() - egui::Vec2::new(40.0, 30.0)).length() < 2.0,
            "{zoomed:?} -> {panned:?}"
        );
        // "Fit" brings the root back, at a readable size.
        h.get_by_label("Fit").click();
        h.step();
        h.step();
        assert!(pane.contains_rect(h.get_by_label(root_label).rect()));
        if let Ok(path) = std::env::var("RAYTREE_DIAGRAM_PNG") {
            h.render().expect("render").save(path).expect("saved");
        }
    }
}
