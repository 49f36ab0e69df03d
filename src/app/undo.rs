//! Undo and redo of the viewer's edits (Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y, the Edit menu), and
//! "reset the camera to the scene's" (Home).
//!
//! The history keeps what the viewer can edit ([`Edits`]: render parameters, camera, lights,
//! materials, spheres (they can be dragged) and trace settings), not the triangles, so a step
//! stays small even for a mesh of millions of triangles. It is watched once a frame, after the
//! commands are applied: a change that the loader's rules refused never becomes a step, and a
//! change made while a gesture is under way (a button held: a drag of a value, an orbit, the
//! colour picker; the wheel still turning) becomes one step when the gesture ends.

use eframe::egui;

use super::Command;
use crate::render::RenderSettings;
use crate::scene::{Camera, Light, Material, RenderParams, Scene, Sphere};
use crate::trace::TraceSettings;

/// The most steps kept; older ones are dropped.
pub const MAX_STEPS: usize = 200;

/// Everything the viewer's panels and pointer edit.
#[derive(Clone, Debug, PartialEq)]
pub struct Edits {
    pub render: RenderParams,
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub spheres: Vec<Sphere>,
    pub trace: TraceSettings,
}

impl Edits {
    pub fn of(scene: &Scene, trace: TraceSettings) -> Self {
        Self {
            render: scene.render.clone(),
            camera: scene.camera.clone(),
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
            spheres: scene.spheres.clone(),
            trace,
        }
    }

    /// Writes these edits into `scene` and `trace`.
    pub fn put(self, scene: &mut Scene, trace: &mut TraceSettings) {
        scene.render = self.render;
        scene.camera = self.camera;
        scene.lights = self.lights;
        scene.materials = self.materials;
        scene.spheres = self.spheres;
        *trace = self.trace;
    }
}

/// The undo and redo stacks round the last settled state.
#[derive(Clone, Debug, Default)]
pub struct History {
    undo: Vec<Edits>,
    redo: Vec<Edits>,
    /// The state the last step ended in (`None` before the first look).
    settled: Option<Edits>,
    /// The camera of the scene as it was opened.
    pub home_camera: Option<Camera>,
}

impl History {
    /// Looks at the state `now`; a change since the settled state becomes one step unless a
    /// `gesture` is still under way. Returns whether a step was recorded.
    pub fn observe(&mut self, now: &Edits, gesture: bool) -> bool {
        match &mut self.settled {
            None => {
                self.home_camera.get_or_insert_with(|| now.camera.clone());
                self.settled = Some(now.clone());
                false
            }
            Some(s) if s == now || gesture => false,
            Some(s) => {
                let before = std::mem::replace(s, now.clone());
                self.undo.push(before);
                if self.undo.len() > MAX_STEPS {
                    self.undo.remove(0);
                }
                self.redo.clear();
                true
            }
        }
    }

    /// The state before the last step, given the state `now` (a change not yet settled is
    /// settled first, so it is the one undone).
    pub fn undo(&mut self, now: &Edits) -> Option<Edits> {
        self.observe(now, false);
        let previous = self.undo.pop()?;
        let current = self.settled.replace(previous.clone())?;
        self.redo.push(current);
        Some(previous)
    }

    /// The state the last undo left, again.
    pub fn redo(&mut self, now: &Edits) -> Option<Edits> {
        if self.observe(now, false) {
            return None; // a new edit since the undo: nothing to redo
        }
        let next = self.redo.pop()?;
        let current = self.settled.replace(next.clone())?;
        self.undo.push(current);
        Some(next)
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Steps that can be undone.
    pub fn undo_steps(&self) -> usize {
        self.undo.len()
    }
}

/// Whether a gesture is under way: a pointer button held, a widget dragged, the wheel turning.
pub fn gesture_under_way(ctx: &egui::Context) -> bool {
    ctx.dragged_id().is_some()
        || ctx.input(|i| i.pointer.any_down() || i.smooth_scroll_delta != egui::Vec2::ZERO)
}

/// The working copy the panels edit (the scene and the settings), and its undo history.
pub struct WorkingCopy {
    pub scene: Scene,
    pub settings: RenderSettings,
    /// Undo and redo of the edits.
    pub history: History,
}

impl WorkingCopy {
    pub fn new(scene: Scene, settings: RenderSettings) -> Self {
        Self {
            scene,
            settings,
            history: History::default(),
        }
    }

    /// What the viewer's edits are now.
    pub fn edits(&self) -> Edits {
        Edits::of(&self.scene, self.settings.trace)
    }

    /// Records the frame's edits in the history (called once a frame, after the commands).
    pub fn track(&mut self, ctx: &egui::Context) {
        let now = self.edits();
        self.history.observe(&now, gesture_under_way(ctx));
    }

    fn restore(&mut self, to: Edits, pending: &mut Vec<Command>) {
        // Moved spheres need the accelerator rebuilt.
        let rebuild = to.spheres != self.scene.spheres;
        to.put(&mut self.scene, &mut self.settings.trace);
        pending.push(if rebuild {
            Command::Rebuild
        } else {
            Command::Restart
        });
    }

    /// Undoes the last edit; false when there is none.
    pub fn undo(&mut self, pending: &mut Vec<Command>) -> bool {
        let now = self.edits();
        match self.history.undo(&now) {
            Some(to) => {
                self.restore(to, pending);
                true
            }
            None => false,
        }
    }

    /// Redoes the last undone edit; false when there is none.
    pub fn redo(&mut self, pending: &mut Vec<Command>) -> bool {
        let now = self.edits();
        match self.history.redo(&now) {
            Some(to) => {
                self.restore(to, pending);
                true
            }
            None => false,
        }
    }

    /// Puts the camera back where the scene placed it (one undoable step).
    pub fn reset_camera(&mut self, pending: &mut Vec<Command>) {
        if let Some(home) = self.history.home_camera.clone()
            && home != self.scene.camera
        {
            self.scene.camera = home;
            pending.push(Command::MoveCamera);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin::load_builtin;

    fn state() -> Edits {
        let scene = load_builtin("default").expect("built-in");
        Edits::of(&scene, TraceSettings::default())
    }

    #[test]
    fn undo_restores_and_redo_reapplies() {
        let mut h = History::default();
        let a = state();
        h.observe(&a, false);
        let mut b = a.clone();
        b.render.max_depth += 1;
        assert!(h.observe(&b, false));
        let mut c = b.clone();
        c.camera.position.x += 1.0;
        assert!(h.observe(&c, false));
        assert_eq!(h.undo(&c), Some(b.clone()));
        assert_eq!(h.undo(&b), Some(a.clone()));
        assert_eq!(h.undo(&a), None);
        assert_eq!(h.redo(&a), Some(b.clone()));
        assert_eq!(h.redo(&b), Some(c.clone()));
        assert_eq!(h.redo(&c), None);
        assert_eq!(h.home_camera, Some(a.camera.clone()));
    }

    #[test]
    fn a_gesture_is_one_step() {
        let mut h = History::default();
        let a = state();
        h.observe(&a, false);
        let mut s = a.clone();
        for _ in 0..10 {
            s.camera.position.y += 0.1;
            assert!(!h.observe(&s, true), "a step in the middle of a drag");
        }
        assert!(h.observe(&s, false));
        assert_eq!(h.undo_steps(), 1);
        assert_eq!(h.undo(&s), Some(a));
    }

    #[test]
    fn a_new_edit_after_undo_drops_the_redo() {
        let mut h = History::default();
        let a = state();
        h.observe(&a, false);
        let mut b = a.clone();
        b.render.samples += 1;
        h.observe(&b, false);
        assert_eq!(h.undo(&b), Some(a.clone()));
        let mut c = a.clone();
        c.render.max_depth = 0;
        // An edit not yet settled when redo is asked: it settles, and there is nothing to redo.
        assert_eq!(h.redo(&c), None);
        assert!(!h.can_redo());
        assert_eq!(h.undo(&c), Some(a));
    }

    #[test]
    fn an_unsettled_change_is_what_undo_undoes() {
        let mut h = History::default();
        let a = state();
        h.observe(&a, false);
        let mut b = a.clone();
        b.lights[0].color = glam::Vec3::splat(0.5);
        assert_eq!(h.undo(&b), Some(a));
        assert!(h.can_redo());
    }
}
