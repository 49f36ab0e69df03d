//! Lessons in the viewer (docs/lessons.md): the Lessons menu, the side panel with a step's
//! text, its task and the verdict, and what a step sets when it is shown.
//!
//! A lesson opens its scene through the commands any open uses, then enters its first step
//! in phases, each once the viewer is ready for it: the step's edits (max depth, offset,
//! accelerator) go into the working copy after the scene is installed, so the undo history
//! records them as one step like any edit; the step's view (the pixel selected, the pane
//! shown, the depth step or Play) once the scene's tracer renders. Answers are checked by the
//! engine's [`evaluate`] on the working copy as it is: the scene, settings and edits the
//! student sees. While a lesson is open the viewer renders at the scene's own size, so the
//! pixels a lesson names are the pixels clicked; ending the lesson gives back the pane size.

use std::path::Path;
use std::time::Instant;

use eframe::egui::{self, Color32, RichText, Ui};

pub use super::LessonArg;
use super::dialog::BrowseFor;
use super::pseudocode_pane;
use super::undo::WorkingCopy;
use super::workspace::{self, Pane, Workspace};
use super::{Command, ViewerApp, remap_pixel};
use crate::lessons::{
    Answer, Control, Lesson, SceneRef, Setup, Step, StepState, TaskKind, Verdict, View,
    choice_options, evaluate,
};

/// Where entering a step stands.
#[derive(Clone, Debug, PartialEq)]
pub enum Enter {
    /// The lesson's scene is to be opened by this command (still queued).
    Queued(Command),
    /// The open command ran; waiting for the scene to be the working copy.
    Scene,
    /// The step's edits go into the working copy next.
    Edits,
    /// The step's view (pixel, pane, depth step, Play) is set once the scene's tracer renders.
    View,
    /// The step is shown.
    Done,
}

/// The lesson under way.
pub struct Active {
    pub lesson: Lesson,
    /// The step shown, 0-based.
    pub step: usize,
    pub enter: Enter,
    /// The last answer's outcome: a verdict, or why it could not be checked.
    pub outcome: Option<Result<Verdict, String>>,
    /// The number typed for a value task.
    pub typed: String,
    /// Whether the render followed the pane's size before the lesson (given back at its end).
    pane_size_before: bool,
}

impl Active {
    /// The step shown.
    pub fn current(&self) -> Option<&Step> {
        self.lesson.steps.get(self.step)
    }

    /// "step 3 of 7".
    pub fn progress(&self) -> String {
        format!("step {} of {}", self.step + 1, self.lesson.steps.len())
    }

    fn go(&mut self, step: usize) {
        if step < self.lesson.steps.len() && step != self.step {
            self.step = step;
            self.outcome = None;
            self.typed.clear();
            self.enter = Enter::Edits;
        }
    }
}

/// The viewer's lesson state: the lesson under way (kept while its panel is closed) and the
/// pseudocode pane's last drawing.
#[derive(Default)]
pub struct LessonState {
    pub active: Option<Active>,
    /// Whether the side panel is shown.
    pub open: bool,
    /// The shipped lessons' names, titles and summaries, read once.
    shipped: Option<Vec<(String, String, String)>>,
    /// What the pseudocode pane drew last.
    pub code: pseudocode_pane::Drawn,
}

impl LessonState {
    /// Moves to the step `step` (0-based) of the lesson under way.
    pub fn go(&mut self, step: usize) {
        if let Some(a) = &mut self.active {
            a.go(step);
        }
    }

    /// What the preferences keep of the view: the pane size as it was before the lesson.
    pub fn keep_prefs(&self, prefs: &mut workspace::Prefs) {
        if let Some(a) = &self.active {
            prefs.pane_size = a.pane_size_before;
        }
    }

    fn shipped(&mut self) -> &[(String, String, String)] {
        self.shipped.get_or_insert_with(|| {
            Lesson::all_shipped()
                .into_iter()
                .flatten()
                .map(|l| (l.name, l.title, l.summary))
                .collect()
        })
    }
}

/// The Lessons menu: the lesson under way to resume, the shipped lessons one line each, and
/// a lesson file.
pub fn menu(
    ui: &mut Ui,
    lessons: &mut LessonState,
    ws: &mut Workspace,
    pending: &mut Vec<Command>,
) {
    if let Some(a) = &lessons.active {
        let text = format!("Resume \"{}\" ({})", a.lesson.title, a.progress());
        if ui
            .add_enabled(!lessons.open, egui::Button::new(text))
            .on_hover_text("show the lesson panel again, at the step you left")
            .clicked()
        {
            lessons.open = true;
            ui.close();
        }
        ui.separator();
    }
    let shipped = lessons.shipped().to_vec();
    for (i, (name, title, summary)) in shipped.iter().enumerate() {
        if ui
            .button(format!("{}. {title}", i + 1))
            .on_hover_text(summary)
            .clicked()
        {
            pending.push(Command::OpenLesson(LessonArg::Shipped(name.clone())));
            ui.close();
        }
    }
    ui.separator();
    if ui
        .button("Open lesson file...")
        .on_hover_text("a lesson of your own (.toml; the format is in docs/lessons.md)")
        .clicked()
    {
        ws.browse(BrowseFor::Lesson, "");
        ui.close();
    }
}

fn same_path(a: &Path, b: &Path) -> bool {
    a == b
        || matches!(
            (std::fs::canonicalize(a), std::fs::canonicalize(b)),
            (Ok(x), Ok(y)) if x == y
        )
}

impl ViewerApp {
    /// Opens a lesson: its scene through the usual open, then its first step. The lesson under
    /// way is resumed instead when it is the one asked for.
    pub(super) fn open_lesson(&mut self, arg: LessonArg) {
        let loaded = match &arg {
            LessonArg::Shipped(name) => Lesson::shipped(name).unwrap_or_else(|| {
                Err(crate::lessons::LessonError(format!(
                    "there is no shipped lesson `{name}`; the Lessons menu lists them"
                )))
            }),
            LessonArg::File(path) => Lesson::load(path),
        };
        let lesson = match loaded {
            Ok(l) => l,
            Err(e) => {
                self.messages.error(e.0);
                return;
            }
        };
        if let Some(a) = &self.lesson.active
            && a.lesson.file == lesson.file
            && a.lesson.name == lesson.name
        {
            self.lesson.open = true;
            return;
        }
        let open = match &lesson.scene {
            SceneRef::Builtin(name) => Command::OpenBuiltin(name.clone()),
            SceneRef::File(path) => Command::OpenFile(path.clone()),
        };
        self.pending.push(open.clone());
        let pane_size_before = match &self.lesson.active {
            Some(a) => a.pane_size_before,
            None => self.workspace.prefs.pane_size,
        };
        if self.workspace.prefs.pane_size {
            // The pixels a lesson names are the scene's: render at its size meanwhile.
            let target = self.viewer_target();
            self.set_view(target, false);
        }
        self.messages.notice(format!(
            "lesson \"{}\": rendered at the scene's own size while it is open, so the pixels it names are the pixels you click",
            lesson.title
        ));
        self.lesson.active = Some(Active {
            lesson,
            step: 0,
            enter: Enter::Queued(open),
            outcome: None,
            typed: String::new(),
            pane_size_before,
        });
        self.lesson.open = true;
    }

    /// Ends the lesson under way: the panel closes and the render follows the pane again if it
    /// did before.
    pub fn end_lesson(&mut self) {
        if let Some(a) = self.lesson.active.take()
            && a.pane_size_before
        {
            let target = self.viewer_target();
            self.set_view(target, true);
        }
        self.lesson.open = false;
    }

    /// A click on the render (pixel `x`, `y` of the render): the answer to a pixel task.
    pub(super) fn lesson_clicked(&mut self, x: u32, y: u32) {
        let Some(a) = &self.lesson.active else {
            return;
        };
        let is_pixel = matches!(
            a.current().and_then(|s| s.task.as_ref()).map(|t| &t.kind),
            Some(TaskKind::Pixel { .. })
        );
        if !self.lesson.open || a.enter != Enter::Done || !is_pixel {
            return;
        }
        let p = remap_pixel([x, y], self.render.size(), self.render.scene_size);
        self.check_answer(Answer::Pixel(p));
    }

    /// Checks `answer` to the task of the step shown, on the working copy as it is; the
    /// verdict's node is selected when the tree shown is its pixel's.
    fn check_answer(&mut self, answer: Answer) {
        let Some(a) = &mut self.lesson.active else {
            return;
        };
        let Some(step) = a.lesson.steps.get(a.step) else {
            return;
        };
        // The step's settings are already in the working copy (from when it was shown):
        // the check reads the scene as the viewer has it, edits since included.
        let mut step = step.clone();
        step.setup = Setup::default();
        let working = &self.working;
        let outcome =
            evaluate(&step, &answer, &working.scene, &working.settings.trace).map_err(|e| e.0);
        if let Ok(v) = &outcome {
            select_verdict_node(self, v.clone(), false);
        }
        if let Some(a) = &mut self.lesson.active {
            a.outcome = Some(outcome);
        }
    }

    /// The step's edits, into the working copy (the history records them as one step).
    fn enter_edits(&mut self, sets: &StepState) {
        let w = &mut self.working;
        let mut changed = false;
        let mut rebuild = false;
        if let Some(d) = sets.max_depth
            && w.scene.render.max_depth != d
        {
            w.scene.render.max_depth = d;
            changed = true;
        }
        if let Some(o) = sets.offset
            && w.settings.trace.methods.offset != o
        {
            w.settings.trace.methods.offset = o;
            changed = true;
        }
        if let Some(accel) = sets.accel
            && w.settings.trace.accel != accel
        {
            w.settings.trace.accel = accel;
            rebuild = true;
        }
        if rebuild {
            self.pending.push(Command::Rebuild);
        } else if changed {
            self.pending.push(Command::Restart);
        }
    }

    /// The step's view: the pixel selected, the pane shown, the depth step or Play.
    fn enter_view(&mut self, sets: &StepState) {
        if let Some(p) = sets.select {
            let [x, y] = remap_pixel(p, self.render.scene_size, self.render.size());
            self.selection.pick(&self.render.tracer, x, y);
        }
        if let Some(view) = sets.view {
            show_pane(&mut self.workspace, pane_of(view));
        }
        if let Some(d) = sets.depth_step {
            self.selection.tree_state.reveal = Some(d);
            self.scene_view.playing = None;
        }
        if sets.play {
            self.selection.tree_state.reveal = Some(0);
            self.scene_view.playing = Some(Instant::now());
        }
    }
}

/// The pane a lesson's `view` names.
pub fn pane_of(view: View) -> Pane {
    match view {
        View::Render => Pane::Render,
        View::Scene => Pane::SceneView,
        View::Diagram => Pane::Diagram,
        View::Tree => Pane::TreeList,
        View::Pseudocode => Pane::Pseudocode,
    }
}

/// Shows `pane`: visible, and the front tab of its group.
pub fn show_pane(ws: &mut Workspace, pane: Pane) {
    let layout = &mut ws.prefs.layout;
    if let Some(id) = workspace::tile_of(layout, pane) {
        layout.tiles.set_visible(id, true);
        layout.make_active(|t, _| t == id);
    }
}

/// Selects the verdict's node in the tree views when the tree shown is its pixel's (`pick`:
/// else pick that pixel first).
fn select_verdict_node(app: &mut ViewerApp, v: Verdict, pick: bool) {
    let (Some(p), Some(path)) = (v.pixel, v.node_path) else {
        return;
    };
    let [x, y] = remap_pixel(p, app.render.scene_size, app.render.size());
    let shown = app.selection.tree.as_ref().map(|t| t.pixel);
    if shown != Some([x, y]) {
        if !pick {
            return;
        }
        app.selection.pick(&app.render.tracer, x, y);
    }
    app.selection.tree_state.selected = Some(path);
}

/// Enters the step shown as far as the viewer is ready (called once a frame, after the
/// commands and the history): the scene opened, the edits, then the view. Asks for another
/// frame while a phase waits.
pub fn after_frame(app: &mut ViewerApp, ctx: &egui::Context) {
    loop {
        let Some(a) = &app.lesson.active else {
            return;
        };
        let sets = a.current().map(|s| s.sets.clone()).unwrap_or_default();
        let (enter, scene, title) = (
            a.enter.clone(),
            a.lesson.scene.clone(),
            a.lesson.title.clone(),
        );
        let next = match enter {
            Enter::Queued(open) => {
                if app.pending.contains(&open) {
                    break;
                }
                Enter::Scene
            }
            Enter::Scene => {
                if app.files.opening().is_some() {
                    break;
                }
                let arrived = match &scene {
                    SceneRef::Builtin(name) => app.files.label == *name,
                    SceneRef::File(path) => app
                        .working
                        .scene
                        .source
                        .as_deref()
                        .is_some_and(|s| same_path(s, path)),
                };
                if !arrived {
                    app.end_lesson();
                    app.messages.error(format!(
                        "the lesson \"{title}\" is closed: its scene did not open (the message before says why)"
                    ));
                    return;
                }
                Enter::Edits
            }
            Enter::Edits => {
                app.enter_edits(&sets);
                Enter::View
            }
            Enter::View => {
                if app.render.pending_build.is_some() || app.files.opening().is_some() {
                    break;
                }
                app.enter_view(&sets);
                Enter::Done
            }
            Enter::Done => break,
        };
        if let Some(a) = &mut app.lesson.active {
            a.enter = next;
        }
    }
    // A phase waits, or queued a command: the next frame carries on. A step shown asks for
    // nothing (the viewer idles with a lesson open).
    let waiting = app
        .lesson
        .active
        .as_ref()
        .is_some_and(|a| a.enter != Enter::Done);
    if waiting || !app.pending.is_empty() {
        ctx.request_repaint();
    }
}

/// The current value of a control task's control in the working copy, as an answer, and in
/// words; `Err` when the scene lacks the material it names.
pub fn control_value(control: &Control, working: &WorkingCopy) -> Result<(Answer, String), String> {
    let material = |m: &str| {
        working
            .scene
            .materials
            .iter()
            .find(|x| x.name == m)
            .ok_or_else(|| format!("the scene has no material \"{m}\" for this task"))
    };
    Ok(match control {
        Control::MaxDepth => {
            let d = working.scene.render.max_depth;
            (Answer::Value(f64::from(d)), format!("max depth is {d}"))
        }
        Control::Cutoff => {
            let c = working.settings.trace.cutoff;
            (Answer::Value(f64::from(c)), format!("the cutoff is {c}"))
        }
        Control::Offset => {
            let o = crate::choice::Choice::name(working.settings.trace.methods.offset);
            (Answer::Choice(o.to_string()), format!("the offset is {o}"))
        }
        Control::Reflectivity(m) | Control::Transparency(m) | Control::Ior(m) => {
            let mat = material(m)?;
            let (v, what) = match control {
                // A coefficient is checked as one number for all channels: the largest.
                Control::Reflectivity(_) => (mat.reflectivity.max_element(), "kr"),
                Control::Transparency(_) => (mat.transparency.max_element(), "kt"),
                _ => (mat.ior, "ior"),
            };
            (
                Answer::Value(f64::from(v)),
                format!("{what} of \"{m}\" is {v}"),
            )
        }
    })
}

/// Where a control task's control is in the viewer.
fn control_place(control: &Control) -> &'static str {
    match control {
        Control::MaxDepth => "Render > max depth in the settings panel",
        Control::Cutoff => "the adaptive-depth cutoff in the settings panel",
        Control::Offset => "the offset method in the settings panel",
        Control::Reflectivity(_) => "the material's kr in the settings panel's Materials",
        Control::Transparency(_) => "the material's kt in the settings panel's Materials",
        Control::Ior(_) => "the material's ior in the settings panel's Materials",
    }
}

/// The side panel of the lesson under way, when it is open.
pub fn side_panel(app: &mut ViewerApp, ui: &mut Ui) {
    if !app.lesson.open || app.lesson.active.is_none() {
        return;
    }
    // A quarter of the window, so that at 1024 points the render keeps most of the room.
    let width = (ui.ctx().content_rect().width() * 0.25).clamp(240.0, 340.0);
    egui::Panel::right("lesson")
        .resizable(true)
        .default_size(width)
        .min_size(220.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical()
                .auto_shrink([false, false])
                .show(ui, |ui| panel_body(app, ui));
        });
}

fn panel_body(app: &mut ViewerApp, ui: &mut Ui) {
    let Some(a) = &app.lesson.active else {
        return;
    };
    let (title, progress) = (a.lesson.title.clone(), a.progress());
    let (step_i, n) = (a.step, a.lesson.steps.len());
    let intro = a.lesson.intro.clone();
    let Some(step) = a.current().cloned() else {
        return;
    };
    let outcome = a.outcome.clone();
    let ready = a.enter == Enter::Done;
    let mut close = false;
    let mut end = false;
    ui.horizontal(|ui| {
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Min), |ui| {
            close = ui
                .button("Close")
                .on_hover_text("close the panel; the lesson stays: the Lessons menu resumes it")
                .clicked();
            ui.with_layout(egui::Layout::left_to_right(egui::Align::Min), |ui| {
                ui.add(egui::Label::new(RichText::new(&title).heading()).wrap());
            });
        });
    });
    ui.horizontal(|ui| {
        ui.label(&progress);
        ui.add(egui::ProgressBar::new((step_i + 1) as f32 / n.max(1) as f32).desired_width(100.0));
    });
    egui::CollapsingHeader::new("Introduction")
        .id_salt(("lesson intro", &title))
        .default_open(step_i == 0)
        .show(ui, |ui| {
            ui.add(egui::Label::new(prose(&intro)).wrap());
        });
    ui.separator();
    ui.add(egui::Label::new(prose(&step.text)).wrap());
    if !ready {
        ui.weak("setting up the step...");
    }
    if let Some(task) = &step.task {
        ui.add_space(6.0);
        if let Some(prompt) = &task.prompt {
            ui.add(egui::Label::new(RichText::new(prompt).strong()).wrap());
        }
        ui.add_enabled_ui(ready, |ui| answer_ui(app, ui, &task.kind));
    }
    if let Some(outcome) = outcome {
        ui.add_space(6.0);
        verdict_ui(app, ui, &outcome);
    }
    ui.add_space(8.0);
    ui.separator();
    let mut go = None;
    ui.horizontal(|ui| {
        if ui
            .add_enabled(step_i > 0, egui::Button::new("< Back"))
            .on_hover_text("the step before (its settings are set again)")
            .clicked()
        {
            go = Some(step_i - 1);
        }
        if ui
            .add_enabled(step_i + 1 < n, egui::Button::new("Next >"))
            .on_hover_text("the next step; a task need not be answered first")
            .clicked()
        {
            go = Some(step_i + 1);
        }
        end = ui
            .button("End lesson")
            .on_hover_text("leave the lesson; the scene stays as it is")
            .clicked();
    });
    if let Some(g) = go {
        app.lesson.go(g);
    }
    if close {
        app.lesson.open = false;
    }
    if end {
        app.end_lesson();
    }
}

/// A lesson's paragraph as one run of text (the file's line breaks are the author's, not the
/// panel's): blank lines stay paragraph breaks.
fn prose(text: &str) -> String {
    text.split("\n\n")
        .map(|p| p.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect::<Vec<_>>()
        .join("\n\n")
}

/// The answer control of a task: a click on the render, a Check of a control, a number, or
/// the options.
fn answer_ui(app: &mut ViewerApp, ui: &mut Ui, kind: &TaskKind) {
    match kind {
        TaskKind::Pixel { .. } => {
            ui.add(
                egui::Label::new("Answer by clicking a pixel in the render: its tree is checked.")
                    .wrap(),
            );
        }
        TaskKind::Control { control, .. } => {
            let now = control_value(control, &app.working);
            ui.add(
                egui::Label::new(format!(
                    "Change {}, then check. Now: {}.",
                    control_place(control),
                    now.as_ref().map_or_else(|e| e.clone(), |(_, w)| w.clone())
                ))
                .wrap(),
            );
            if ui
                .button("Check")
                .on_hover_text("checks the control's value as it is now in the viewer")
                .clicked()
            {
                match now {
                    Ok((answer, _)) => app.check_answer(answer),
                    Err(e) => {
                        if let Some(a) = &mut app.lesson.active {
                            a.outcome = Some(Err(e));
                        }
                    }
                }
            }
        }
        TaskKind::Value { tolerance, .. } => {
            let mut submit = false;
            ui.horizontal(|ui| {
                let l = ui.label("answer");
                if let Some(a) = &mut app.lesson.active {
                    let r = ui.add(
                        egui::TextEdit::singleline(&mut a.typed)
                            .desired_width(110.0)
                            .hint_text("a number"),
                    );
                    let r = r.labelled_by(l.id);
                    submit |= r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                }
                submit |= ui.button("Check").clicked();
            });
            // Written as in the file (a tolerance is read as f32).
            ui.weak(format!("checked to within ±{}", *tolerance as f32));
            if submit {
                let typed = app
                    .lesson
                    .active
                    .as_ref()
                    .map(|a| a.typed.trim().to_string())
                    .unwrap_or_default();
                match typed.replace(',', ".").parse::<f64>() {
                    Ok(v) if v.is_finite() => app.check_answer(Answer::Value(v)),
                    _ => {
                        if let Some(a) = &mut app.lesson.active {
                            a.outcome = Some(Err(format!(
                                "\"{typed}\" is not a number: type one such as 0.7071"
                            )));
                        }
                    }
                }
            }
        }
        TaskKind::Choice { question, .. } => {
            let options = choice_options(question);
            let letters = "abcdefghijklmnopqrstuvwxyz".chars();
            for (o, letter) in options.iter().zip(letters) {
                let button = egui::Button::new(format!("{letter}) {}", o.label)).wrap();
                if ui.add(button).clicked() {
                    app.check_answer(Answer::Choice(o.key.clone()));
                }
            }
        }
    }
}

/// The verdict: right or not, what the tree shows, the hint, and the node to look at.
fn verdict_ui(app: &mut ViewerApp, ui: &mut Ui, outcome: &Result<Verdict, String>) {
    let (fill, stroke) = match outcome {
        Ok(v) if v.correct => (
            Color32::from_rgb(24, 64, 32),
            Color32::from_rgb(90, 200, 110),
        ),
        Ok(_) => (
            Color32::from_rgb(72, 28, 28),
            Color32::from_rgb(230, 110, 100),
        ),
        Err(_) => (Color32::from_gray(48), Color32::from_gray(140)),
    };
    egui::Frame::group(ui.style())
        .fill(fill)
        .stroke(egui::Stroke::new(1.0, stroke))
        .show(ui, |ui| {
            ui.set_width(ui.available_width());
            match outcome {
                Err(why) => {
                    ui.add(egui::Label::new(format!("Cannot check: {why}")).wrap());
                }
                Ok(v) => {
                    let head = if v.correct { "Correct" } else { "Not yet" };
                    ui.label(RichText::new(head).strong().color(stroke));
                    ui.add(egui::Label::new(&v.message).wrap());
                    if let Some(hint) = &v.hint {
                        ui.add(egui::Label::new(format!("Hint: {hint}")).wrap());
                    }
                    if let (Some(node), Some([x, y])) = (&v.node, v.pixel)
                        && v.node_path.is_some()
                        && ui
                            .button(format!("see node {node} of ({x}, {y})"))
                            .on_hover_text("select that node in the tree's views")
                            .clicked()
                    {
                        select_verdict_node(app, v.clone(), true);
                        show_pane(&mut app.workspace, Pane::Diagram);
                    }
                }
            }
        });
}
