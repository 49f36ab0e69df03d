//! Lessons in the real viewer, driven as a student would through egui_kittest on the wgpu
//! software adapter: a lesson opened from the Lessons menu opens its scene and shows its
//! panel, Next and Back set each step's pixel, the answer controls of every task kind give
//! verdicts (a pixel clicked on the render, a number typed, an option chosen, a control
//! checked after changing it), Ctrl+Z undoes a step's setting, the panel closes and resumes
//! at its step, and the pseudocode pane highlights the line of the selected node.
//!
//! Update the snapshots after a deliberate change (look at them first):
//! `UPDATE_SNAPSHOTS=1 cargo test --release --test viewer_lessons`

#[path = "common/viewer.rs"]
mod viewer;

use eframe::egui;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use raytree::app::lesson_panel::{self, Enter};
use raytree::app::workspace::Pane;
use raytree::lessons::pseudocode;
use viewer::{Window, mask_status, settle, small, steps_until, window_with};

/// The viewer in a `size` window, refining to 1 sample per pixel (the lessons' checks read
/// trees, not the image), the settings panel shown.
fn viewer(size: [f32; 2]) -> Window {
    let mut h = window_with(small("default"), size, |app| {
        app.set_view(1, true);
        app.workspace.set_settings_panel(true);
    });
    h.step();
    h
}

/// Opens the shipped lesson titled `title` from the Lessons menu and waits for its first
/// step to be set up.
fn open_from_menu(h: &mut Window, title: &str) {
    h.get_by_role_and_label(Role::Button, "Lessons").click();
    h.step();
    h.step();
    h.get_by_label_contains(title).click();
    h.step();
    step_done(h);
}

/// Steps frames until the step shown is set up (its scene opened, its settings and view set).
fn step_done(h: &mut Window) {
    steps_until(h, "the lesson's step was not set up", |app| {
        app.lesson
            .active
            .as_ref()
            .is_some_and(|a| a.enter == Enter::Done)
            && app.is_finished()
    });
    h.step();
}

fn click_button(h: &mut Window, label: &str) {
    h.get_by_role_and_label(Role::Button, label).click();
    h.step();
    h.step();
    h.step();
}

/// Brings the pseudocode pane to the front, as a step's `view = "pseudocode"` does.
fn show_pseudocode(h: &mut Window) {
    lesson_panel::show_pane(&mut h.state_mut().workspace, Pane::Pseudocode);
    h.step();
    h.step();
}

fn step_of(h: &Window) -> usize {
    h.state().lesson.active.as_ref().expect("a lesson").step
}

fn tree_pixel(h: &Window) -> Option<[u32; 2]> {
    h.state().selection.tree.as_ref().map(|t| t.pixel)
}

/// The last answer's verdict: (correct, message, hint).
fn verdict(h: &Window) -> (bool, String, Option<String>) {
    let a = h.state().lesson.active.as_ref().expect("a lesson");
    match a.outcome.clone().expect("an answer was checked") {
        Ok(v) => (v.correct, v.message, v.hint),
        Err(e) => panic!("the answer could not be checked: {e}"),
    }
}

/// Where pixel (`x`, `y`) of the render is on screen.
fn pixel_pos(h: &Window, x: u32, y: u32) -> egui::Pos2 {
    let image = h.get_by_label("render viewport").rect();
    let (w, hh) = h.state().render_size();
    egui::pos2(
        image.min.x + (x as f32 + 0.5) / w as f32 * image.width(),
        image.min.y + (y as f32 + 0.5) / hh as f32 * image.height(),
    )
}

fn click_at(h: &mut Window, pos: egui::Pos2) {
    h.hover_at(pos);
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        h.step();
    }
    h.step();
}

#[test]
fn the_menu_opens_a_lesson_and_next_and_back_set_each_steps_pixel() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    let app = h.state();
    assert_eq!(app.files.label, "default", "the lesson's scene is open");
    // Rendered at the scene's own size while the lesson is open.
    assert_eq!(app.render_size(), (640, 480));
    assert!(app.lesson.open);
    h.get_by_label("step 1 of 5");
    assert_eq!(tree_pixel(&h), Some([100, 100]), "step 1 selects the sky");
    click_button(&mut h, "Next >");
    step_done(&mut h);
    assert_eq!(step_of(&h), 1);
    h.get_by_label("step 2 of 5");
    assert_eq!(tree_pixel(&h), Some([566, 40]));
    click_button(&mut h, "< Back");
    step_done(&mut h);
    assert_eq!(step_of(&h), 0);
    assert_eq!(tree_pixel(&h), Some([100, 100]));
    // Ending the lesson gives the render back to the pane's size.
    click_button(&mut h, "End lesson");
    settle(&mut h);
    assert!(h.state().lesson.active.is_none());
    assert!(h.state().workspace.prefs.pane_size);
    assert_ne!(h.state().render_size(), (640, 480));
}

#[test]
fn a_choice_task_gives_a_verdict_per_option() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    // The sky pixel's primary ray meets nothing.
    h.get_by_label_contains("b) it hits a light source").click();
    h.step();
    h.step();
    let (correct, _, hint) = verdict(&h);
    assert!(!correct, "the sky's ray hits no light");
    assert!(hint.is_some_and(|t| t.contains("primary node")));
    h.get_by_label_contains("Not yet");
    h.get_by_label_contains("a) no intersection").click();
    h.step();
    h.step();
    let (correct, message, hint) = verdict(&h);
    assert!(correct, "{message}");
    assert!(hint.is_none());
    h.get_by_label("Correct");
}

#[test]
fn a_pixel_task_checks_the_clicked_pixels_tree_and_a_control_task_the_changed_max_depth() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    for _ in 0..3 {
        click_button(&mut h, "Next >");
        step_done(&mut h);
    }
    // Step 4: a ray stopped at the maximum depth (step 3 set it to 1).
    assert_eq!(h.state().working.scene.render.max_depth, 1);
    let sky = pixel_pos(&h, 100, 100);
    click_at(&mut h, sky);
    assert_eq!(tree_pixel(&h), Some([100, 100]), "the click picks its tree");
    let (correct, message, hint) = verdict(&h);
    assert!(!correct, "{message}");
    assert!(message.contains("(100, 100)"), "{message}");
    assert!(hint.is_some());
    let glass = pixel_pos(&h, 240, 300);
    click_at(&mut h, glass);
    let (correct, message, _) = verdict(&h);
    assert!(correct, "{message}");
    // The node that shows it is selected in the tree's views.
    let a = h.state().lesson.active.as_ref().expect("a lesson");
    let path = a
        .outcome
        .clone()
        .and_then(|o| o.ok())
        .and_then(|v| v.node_path);
    assert!(path.as_ref().is_some_and(|p| !p.is_empty()));
    assert_eq!(h.state().selection.tree_state.selected, path);
    // Step 5: max depth so that the floor shows through the glass at (230, 230).
    click_button(&mut h, "Next >");
    step_done(&mut h);
    click_button(&mut h, "Check");
    let (correct, message, _) = verdict(&h);
    assert!(!correct, "max depth 1 is too shallow: {message}");
    // The student raises max depth (as the settings panel's field does).
    h.state_mut().working.scene.render.max_depth = 6;
    h.state_mut().command(raytree::app::Command::Restart);
    settle(&mut h);
    h.get_by_label_contains("Now: max depth is 6");
    click_button(&mut h, "Check");
    let (correct, message, _) = verdict(&h);
    assert!(correct, "{message}");
}

#[test]
fn a_value_task_checks_the_number_typed() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "The quiz");
    assert_eq!(h.state().files.label, "quiz");
    assert_eq!(tree_pixel(&h), Some([100, 100]));
    let field = || Role::TextInput;
    let type_and_check = |h: &mut Window, text: &str| {
        h.get_by_role_and_label(field(), "answer")
            .set_text_value_accesskit(text);
        h.step();
        click_button(h, "Check");
    };
    type_and_check(&mut h, "0.5");
    let (correct, message, hint) = verdict(&h);
    assert!(!correct, "{message}");
    assert!(hint.is_some_and(|t| t.contains("1/√2")));
    type_and_check(&mut h, "0.7071");
    let (correct, message, _) = verdict(&h);
    assert!(correct, "{message}");
    // Not a number: said so, no verdict.
    type_and_check(&mut h, "seven");
    let a = h.state().lesson.active.as_ref().expect("a lesson");
    assert!(matches!(&a.outcome, Some(Err(e)) if e.contains("not a number")));
}

#[test]
fn ctrl_z_undoes_a_steps_max_depth() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    let before = h.state().working.scene.render.max_depth;
    assert_eq!(before, 5);
    click_button(&mut h, "Next >");
    step_done(&mut h);
    click_button(&mut h, "Next >");
    step_done(&mut h);
    assert_eq!(
        h.state().working.scene.render.max_depth,
        1,
        "step 3 sets it"
    );
    h.step();
    assert!(h.state().working.history.can_undo());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.step();
    h.step();
    assert_eq!(h.state().working.scene.render.max_depth, before);
    // The lesson stays at its step: undo is an edit like any other.
    assert_eq!(step_of(&h), 2);
}

#[test]
fn a_closed_panel_keeps_the_lesson_and_the_menu_resumes_it_at_its_step() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    click_button(&mut h, "Next >");
    step_done(&mut h);
    click_button(&mut h, "Close");
    assert!(!h.state().lesson.open);
    assert!(h.state().lesson.active.is_some());
    assert!(h.query_by_label("step 2 of 5").is_none());
    // Free exploration meanwhile: another pixel's tree.
    let at = pixel_pos(&h, 300, 400);
    click_at(&mut h, at);
    assert_eq!(tree_pixel(&h), Some([300, 400]));
    h.get_by_role_and_label(Role::Button, "Lessons").click();
    h.step();
    h.step();
    h.get_by_label_contains("Resume \"Termination").click();
    h.step();
    h.step();
    assert!(h.state().lesson.open);
    assert_eq!(step_of(&h), 1);
    h.get_by_label("step 2 of 5");
    // Resuming re-sets nothing: the tree explored stays.
    assert_eq!(tree_pixel(&h), Some([300, 400]));
}

#[test]
fn the_pseudocode_pane_highlights_the_line_of_the_selected_node() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    // Step 3: the glass sphere at max depth 1.
    click_button(&mut h, "Next >");
    step_done(&mut h);
    click_button(&mut h, "Next >");
    step_done(&mut h);
    show_pseudocode(&mut h);
    let tree = h.state().selection.tree.clone().expect("a tree");
    assert_eq!(tree.pixel, [240, 300]);
    let root_line = pseudocode::current_line(&tree, &[]).expect("the root's line");
    assert_eq!(root_line.line, "return");
    let drawn = h.state().lesson.code.clone();
    assert_eq!(drawn.node, Some(vec![]));
    assert_eq!(drawn.line, Some("return"));
    assert!(drawn.least_text.is_some_and(|s| s >= 11.0), "{drawn:?}");
    h.get_by_label_contains("→   return(local");
    // A node cut at max depth returns at the max-depth test.
    let cut = path_to(&tree.root, &mut Vec::new(), &|n| {
        n.end == Some(raytree::trace::EndReason::MaxDepth)
    })
    .expect("a node stopped at max depth 1");
    h.state_mut().selection.tree_state.selected = Some(cut.clone());
    h.step();
    h.step();
    let drawn = h.state().lesson.code.clone();
    assert_eq!(drawn.node, Some(cut.clone()));
    assert_eq!(drawn.line, Some("max_depth"));
    assert_eq!(
        pseudocode::current_line(&tree, &cut).map(|e| e.line),
        Some("max_depth")
    );
    h.get_by_label_contains("→   if (step > max)");
    // Stepping the tree to generation 0 shows the root's call on the way.
    h.state_mut().selection.tree_state.reveal = Some(0);
    h.step();
    h.step();
    assert_eq!(h.state().lesson.code.node, Some(vec![]));
}

fn path_to(
    node: &raytree::ray_tree::Node,
    path: &mut Vec<usize>,
    want: &dyn Fn(&raytree::ray_tree::Node) -> bool,
) -> Option<Vec<usize>> {
    if want(node) {
        return Some(path.clone());
    }
    for (i, c) in node.children.iter().enumerate() {
        path.push(i);
        if let Some(p) = path_to(c, path, want) {
            return Some(p);
        }
        path.pop();
    }
    None
}

/// The quiz lesson at its first step with the pseudocode pane in front, at `size`.
fn lesson_snapshot(size: [f32; 2], name: &str) {
    let mut h = window_with(small("default"), size, |app| app.set_view(4, true));
    h.step();
    open_from_menu(&mut h, "The quiz");
    show_pseudocode(&mut h);
    h.get_by_role_and_label(Role::TextInput, "answer")
        .set_text_value_accesskit("0.7071");
    h.step();
    click_button(&mut h, "Check");
    settle(&mut h);
    h.state_mut().messages.clear_toasts();
    h.step();
    let drawn = h.state().lesson.code.clone();
    assert!(drawn.least_text.is_some_and(|s| s >= 11.0), "{drawn:?}");
    mask_status(&mut h);
    h.snapshot(name);
}

#[test]
fn lesson_snapshot_1024x640() {
    lesson_snapshot([1024.0, 640.0], "lesson_1024x640");
}

#[test]
fn lesson_snapshot_1600x1000() {
    lesson_snapshot([1600.0, 1000.0], "lesson_1600x1000");
}

#[test]
fn a_viewer_with_a_lesson_open_asks_for_no_frame_once_its_step_is_shown() {
    let mut h = viewer([1280.0, 800.0]);
    open_from_menu(&mut h, "Termination conditions");
    click_button(&mut h, "Next >");
    step_done(&mut h);
    let immediate = |h: &Window| {
        h.output()
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay == std::time::Duration::ZERO)
    };
    // A layout change restarts the scene view at its new size once or twice: converge first.
    let deadline = std::time::Instant::now() + viewer::DEADLINE;
    loop {
        settle(&mut h);
        if !immediate(&h) {
            break;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "the viewer kept asking for frames with a lesson open"
        );
    }
    h.step();
    assert!(!immediate(&h), "a shown step asks for no immediate frame");
}
