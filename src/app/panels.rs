//! The panels: each edits the working copy of the scene or settings and queues commands; none
//! applies anything itself.

use std::sync::atomic::Ordering;

use eframe::egui::{self, DragValue, RichText, Ui};
use glam::Vec3;

use super::dialog::BrowseFor;
use super::messages::Messages;
use super::modes::ImageMode;
use super::render_view::RenderView;
use super::scene_files::SceneFiles;
use super::selection::TreeSelection;
use super::undo::WorkingCopy;
use super::viewport::Tonemap;
use super::workspace::{self, Prefs, Workspace};
use super::{Command, tree_view};
use crate::choice::Choice;
use crate::plural::count;
use crate::scene::{Light, Material, builtin, names, rules};
use crate::trace::Tracer;

// ---- what each setting does, in the lecture's words ---------------------------------------

/// Tooltips: what each setting does to the ray tracing tree and the illumination model.
pub mod tips {
    pub const MAX_DEPTH: &str = "Termination condition: the deepest ray traced. The primary ray from the eye is depth 0; every reflected (R) or refracted (T) ray is one deeper. A ray at max depth gets no children: its reflected and refracted parts are left out.";
    pub const SAMPLES: &str = "Rays per pixel, spread over the pixel and averaged: more samples smooth the edges (anti-aliasing) and soft shadows, and cost that many times the work.";
    pub const SIZE: &str = "Image size in pixels: one primary ray per pixel and sample (1024x768 shoots 786 432 primary rays per sample).";
    pub const SHADING: &str = "The local illumination model at each hit: I = ka·Ia + Σ over lights (kd·(N·L) + ks·(specular)^n)·light colour. Phong: R·V; Blinn-Phong: N·H with the halfway vector H = normalize(L + V).";
    pub const BACKGROUND: &str = "The colour a ray gets when it meets nothing (termination condition: no intersection), including the primary ray of an empty pixel.";
    pub const AMBIENT_LIGHT: &str = "Ia: light that reaches every point from everywhere; multiplied by each material's ka. A point whose shadow rays are all blocked gets only this: I = ka·Ia.";
    pub const SPHERE: &str =
        "How a ray is intersected with a sphere (solving the quadratic for t).";
    pub const TRIANGLE: &str =
        "How a ray is intersected with a triangle (plane, then inside test).";
    pub const OFFSET: &str = "Secondary rays (shadow, reflected, refracted) start a little off the surface they leave, so they do not hit it again at t ≈ 0 (\"shadow acne\"). This picks how far.";
    pub const SHADING_NORMALS: &str = "Meshes with vertex normals are shaded as if smooth while their triangles stay flat. Robust keeps the flat geometry from darkening the terminator (shadow rays start on the smooth surface), bends reflected and refracted rays back out of the surface, and lets no light through from behind; naive shows those failures.";
    pub const ACCEL: &str = "The structure that finds which objects a ray can hit without testing them all. Changes the speed, never the image.";
    pub const CUTOFF: &str = "Adaptive depth: a ray whose weight (the product of kr and kt down the tree) is below this is not traced, as it could barely change the pixel. 0 traces every ray down to max depth.";
    pub const THREADS: &str = "CPU threads rendering the image (0: all cores).";
    pub const EXPOSURE: &str = "Multiplies the image's colours before display (a display setting: the render does not change).";
    pub const TONEMAP: &str =
        "How colours above 1 are shown: clamp cuts them, Reinhard and ACES roll them off smoothly.";
    pub const IMAGE_MODE: &str = "What the picture shows: the render, or per pixel what its ray tracing tree did (depth reached, how its rays ended, rays traced, the normal). A colour scale beside the image says what each colour means.";
    pub const POSITION: &str = "The eye: where primary rays start.";
    pub const LOOK_AT: &str = "The point at the centre of the image; the camera orbits about it.";
    pub const UP: &str = "Which way is up in the image.";
    pub const FOV: &str = "Vertical field of view: the angle the image spans from top to bottom.";
    pub const ORBIT: &str = "Degrees a drag across the whole width of the image turns the camera (the same rate up and down).";
    pub const LIGHT_POSITION: &str = "Where the point light is: shadow rays are shot from each hit towards it. Drag the light's marker in the scene view to move it.";
    pub const LIGHT_FOLLOW: &str = "A headlight: the light stands at the render camera's eye and moves with it, so what the camera sees is lit (saved as `follow_camera = true`).";
    pub const LIGHT_COLOUR: &str = "The light's colour and intensity: multiplies the diffuse and specular terms of every point it lights.";
    pub const LIGHT_RADIUS: &str = "0: a point light with hard shadows; larger: an area light whose shadow rays go to random points on it (soft shadows, needs more samples).";
    pub const KA: &str = "ka, ambient coefficient: the share of the ambient light Ia the surface returns (I_ambient = ka·Ia), shown even in shadow.";
    pub const KD: &str = "kd, diffuse coefficient: the surface's own colour under a light, kd·(N·L); only where the shadow ray reaches the light.";
    pub const KS: &str = "ks, specular coefficient: the strength of the highlight, ks·(R·V)^n or ks·(N·H)^n; only where the shadow ray reaches the light.";
    pub const KR: &str = "kr, reflectivity: how much of the reflected ray R's colour is added (local + kr·R). 0: no reflected ray is traced.";
    pub const KT: &str = "kt, transparency: how much of the refracted (transmitted) ray T's colour is added (local + kt·T). 0: no refracted ray is traced.";
    pub const SHININESS: &str =
        "n, the specular exponent: larger makes a smaller, sharper highlight.";
    pub const IOR: &str = "Index of refraction η of the material (air 1, water 1.33, glass 1.5): bends the refracted ray T by Snell's law, η_i·sin θ_i = η_r·sin θ_r.";
    pub const SCALAR: &str = "One number for all three channels (a grey coefficient): an edit changes R, G and B together. Off: R, G and B apart.";
}

// ---- small widgets ------------------------------------------------------------------------

/// A label and a drag value named by it (for screen readers and UI tests), both with `tip`.
fn drag(ui: &mut Ui, label: &str, value: DragValue<'_>, tip: &str) -> bool {
    let l = ui.label(label).on_hover_text(tip);
    ui.add(value).labelled_by(l.id).on_hover_text(tip).changed()
}

fn vec3_edit(ui: &mut Ui, label: &str, v: &mut Vec3, speed: f32, tip: &str) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        let l = ui.label(label).on_hover_text(tip);
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui
                .add(DragValue::new(c).speed(speed).max_decimals(4))
                .labelled_by(l.id)
                .on_hover_text(tip)
                .changed();
        }
    });
    changed
}

/// The colour a picker shows for `v`: `v` itself, or scaled into 0..=1 by its largest channel
/// (a light of colour (5, 4, 3) shows as (1, 0.8, 0.6)); and that scale.
pub fn picker_rgb(v: Vec3) -> ([f32; 3], f32) {
    let k = v.max_element().max(1.0);
    let c = v / k;
    ([c.x, c.y, c.z], k)
}

/// An RGB coefficient: a colour picker (its pick keeps the intensity of colours above 1) and
/// either one number for all three channels (scalar mode, the default when they are equal) or
/// R, G and B; the "=" toggle switches. Every edit is one change of the whole colour.
fn color_edit(ui: &mut Ui, label: &str, v: &mut Vec3, tip: &str) -> bool {
    let mut changed = false;
    let id = ui.scope_id().with(("rgb mode", label));
    let mut scalar = ui
        .data(|d| d.get_temp::<bool>(id))
        .unwrap_or(v.x == v.y && v.y == v.z);
    ui.horizontal(|ui| {
        // Tighter than the default so that a swatch, three channels and "=" fit the
        // settings panel at its default width inside a material's header.
        ui.spacing_mut().item_spacing.x = 3.0;
        ui.spacing_mut().interact_size.x = 24.0;
        let l = ui.label(label).on_hover_text(tip);
        let (mut rgb, k) = picker_rgb(*v);
        if ui
            .color_edit_button_rgb(&mut rgb)
            .labelled_by(l.id)
            .on_hover_text(tip)
            .changed()
        {
            *v = Vec3::from(rgb) * k;
            changed = true;
            if v.x != v.y || v.y != v.z {
                scalar = false;
            }
        }
        if scalar {
            let mut x = v.max_element();
            if ui
                .add(
                    DragValue::new(&mut x)
                        .speed(0.01)
                        .range(0.0..=100.0)
                        .max_decimals(3),
                )
                .labelled_by(l.id)
                .on_hover_text(tip)
                .changed()
            {
                *v = Vec3::splat(x);
                changed = true;
            }
        } else {
            for c in [&mut v.x, &mut v.y, &mut v.z] {
                changed |= ui
                    .add(
                        DragValue::new(c)
                            .speed(0.01)
                            .range(0.0..=100.0)
                            .max_decimals(3),
                    )
                    .labelled_by(l.id)
                    .on_hover_text(tip)
                    .changed();
            }
        }
        ui.toggle_value(&mut scalar, "=")
            .on_hover_text(tips::SCALAR);
    });
    ui.data_mut(|d| d.insert_temp(id, scalar));
    changed
}

/// A menu of every variant of a [`Choice`], each with its help line as a tooltip.
fn combo<T: Choice>(ui: &mut Ui, label: &str, value: &mut T, tip: &str) -> bool {
    let mut changed = false;
    egui::ComboBox::from_label(label)
        .selected_text(format!("{value:?}"))
        .show_ui(ui, |ui| {
            for &o in T::ALL {
                changed |= ui
                    .selectable_value(value, o, format!("{o:?}"))
                    .on_hover_text(o.help())
                    .changed();
            }
        })
        .response
        .on_hover_text(format!("{tip}\n{:?}: {}", value, value.help()));
    changed
}

// ---- panels -------------------------------------------------------------------------------

/// The menu bar: Scene, Edit, View, Lessons, the sweep, help, and the scene's name.
pub fn top_bar(
    ui: &mut Ui,
    ws: &mut Workspace,
    working: &mut WorkingCopy,
    files: &SceneFiles,
    messages: &mut Messages,
    lessons: &mut super::lesson_panel::LessonState,
    pending: &mut Vec<Command>,
) {
    egui::Panel::top("menu").show(ui, |ui| {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("Scene", |ui| {
                if ui.button("Open... (Ctrl+O)").clicked() {
                    ws.browse(BrowseFor::Open, "");
                }
                ui.menu_button("Built-in", |ui| {
                    for name in builtin::NAMES {
                        if ui.button(*name).clicked() {
                            pending.push(Command::OpenBuiltin(name.to_string()));
                        }
                    }
                });
                if ui.button("Save scene as...").clicked() {
                    ws.browse(BrowseFor::SaveScene, &format!("{}.toml", files.file_stem()));
                }
                if ui.button("Export... (Ctrl+S)").clicked() {
                    ws.export_choice = true;
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui
                    .add_enabled(
                        working.history.can_undo(),
                        egui::Button::new("Undo (Ctrl+Z)"),
                    )
                    .clicked()
                {
                    working.undo(pending);
                }
                if ui
                    .add_enabled(
                        working.history.can_redo(),
                        egui::Button::new("Redo (Ctrl+Shift+Z, Ctrl+Y)"),
                    )
                    .clicked()
                {
                    working.redo(pending);
                }
                ui.separator();
                if ui.button("Reset camera to the scene's (Home)").clicked() {
                    working.reset_camera(pending);
                }
            });
            ui.menu_button("View", |ui| {
                for mode in ImageMode::ALL {
                    ui.radio_value(&mut ws.prefs.mode, mode, mode.label());
                }
                ui.separator();
                workspace::pane_toggles(ws, messages, ui);
                ui.separator();
                let n = crate::plural::count(messages.len(), "message");
                if ui
                    .button(format!("Messages ({n})"))
                    .on_hover_text("every notice and error so far, with their details")
                    .clicked()
                {
                    messages.window = true;
                }
            });
            ui.menu_button("Lessons", |ui| {
                super::lesson_panel::menu(ui, lessons, ws, pending)
            });
            if ui.button("Speed vs accuracy").clicked() {
                ws.sweep.open = true;
            }
            if ui.button("Help (F1)").clicked() {
                ws.show_help = true;
            }
            ui.separator();
            ui.label(RichText::new(&files.label).strong());
        });
    });
}

/// The status bar: the open under way, the render's progress and rates, and the pixel under
/// the pointer.
pub fn status_bar(
    ui: &mut Ui,
    render: &RenderView,
    files: &mut SceneFiles,
    selection: &TreeSelection,
    target: u32,
    finished: bool,
    pending: &mut Vec<Command>,
) {
    egui::Panel::bottom("status").show(ui, |ui| {
        if let Some(job) = render.export_job() {
            ui.horizontal(|ui| {
                ui.add(
                    egui::ProgressBar::new(job.done())
                        .desired_width(220.0)
                        .show_percentage(),
                );
                ui.strong(format!("exporting {} at the scene's size", job.file));
                if ui
                    .button("Cancel")
                    .on_hover_text("stop the export; no file is written")
                    .clicked()
                {
                    pending.push(Command::CancelExport);
                }
            });
        }
        if let Some((label, percent)) = files.status() {
            // The open runs in the background; the scene shown stays usable meanwhile.
            ui.horizontal(|ui| {
                ui.add(egui::ProgressBar::new(percent / 100.0).desired_width(220.0));
                ui.strong(label);
                ui.weak("(the scene shown stays until the new one is ready)");
            });
        }
        let stats = render.session.stats().counts();
        let elapsed = render.progress.elapsed();
        let mrays = |n: u64| n as f64 / elapsed.max(1e-6) / 1e6;
        let (w, h) = render.size();
        let pixels_done = render.session.stats().pixels_done.load(Ordering::Relaxed);
        let pass_fraction = pixels_done as f32 / (w as u64 * h as u64).max(1) as f32;
        let done = render.progress.samples_done as f32 / target.max(1) as f32;
        let fraction = if finished {
            1.0
        } else {
            // Passes double the samples, so the last pass is half the work.
            (done + pass_fraction.min(1.0) * (1.0 - done) * 0.5).min(0.999)
        };
        ui.horizontal(|ui| {
            ui.add(
                egui::ProgressBar::new(fraction)
                    .desired_width(220.0)
                    .text(format!("{}/{} spp", render.progress.samples_done, target)),
            );
            ui.label(format!(
                "{} · {:.2} s · {:.2} Mrays/s (primary {:.2}, reflected {:.2}, refracted {:.2}, shadow {:.2}) · {} threads",
                if finished { "done" } else { &render.progress.pass_label },
                elapsed,
                mrays(stats.total()),
                mrays(stats.primary),
                mrays(stats.reflected),
                mrays(stats.refracted),
                mrays(stats.shadow),
                render.session.threads(),
            ));
        });
        ui.horizontal(|ui| {
            if let Some((x, y)) = selection.hover {
                let (c, a) = render.film.pixel(x, y);
                ui.monospace(format!(
                    "pixel ({x}, {y})  rgb ({:.4}, {:.4}, {:.4})  depth {}  rays {}  normal ({:.2}, {:.2}, {:.2})",
                    c.x, c.y, c.z, a.depth_reached, a.rays, a.normal.x, a.normal.y, a.normal.z
                ));
            } else if selection.tree_state.drawn.diagram_hovered {
                ui.monospace(format!("ray tree: {}", tree_view::DIAGRAM_HINT));
            } else {
                ui.monospace("move over the image for pixel values; click a pixel for its ray tree");
            }
        });
    });
}

/// The viewer's own settings, in the render panel: the sample target and the pane size.
fn view_settings(
    ui: &mut Ui,
    prefs: &mut Prefs,
    render: &mut RenderView,
    pending: &mut Vec<Command>,
) {
    let mut target = prefs.viewer_samples;
    let mut pane = prefs.pane_size;
    let changed_target = ui
        .add(
            egui::Slider::new(&mut target, 1..=4096)
                .logarithmic(true)
                .text("viewer samples"),
        )
        .on_hover_text(
            "samples per pixel the viewer refines to, then it idles; the scene's `samples` \
             is for export and `raytree render`",
        )
        .changed();
    let changed_pane = ui
        .checkbox(&mut pane, "render at pane size")
        .on_hover_text(
            "render as many pixels as the render pane has (sharp at any window size); the \
             scene's width and height stay for export and saving",
        )
        .changed();
    if changed_target || changed_pane {
        render.set_view(prefs, pending, target, pane);
    }
}

/// The settings panel: render settings, display, camera, lights, materials and the scene.
pub fn side_panel(
    ui: &mut Ui,
    working: &mut WorkingCopy,
    prefs: &mut Prefs,
    render: &mut RenderView,
    selection: &TreeSelection,
    pending: &mut Vec<Command>,
) {
    let mut restart = false;
    let mut rebuild = false;
    egui::CollapsingHeader::new("Render settings")
        .default_open(true)
        .show(ui, |ui| {
            view_settings(ui, prefs, render, pending);
            let r = &mut working.scene.render;
            restart |= ui
                .add(egui::Slider::new(&mut r.max_depth, rules::DEPTH).text("max depth"))
                .on_hover_text(tips::MAX_DEPTH)
                .changed();
            restart |= ui
                .add(
                    egui::Slider::new(&mut r.samples, rules::SAMPLES)
                        .logarithmic(true)
                        .text("samples"),
                )
                .on_hover_text(tips::SAMPLES)
                .changed();
            ui.horizontal(|ui| {
                restart |= drag(
                    ui,
                    "width",
                    DragValue::new(&mut r.width).range(rules::IMAGE_SIZE),
                    tips::SIZE,
                );
                restart |= drag(
                    ui,
                    "height",
                    DragValue::new(&mut r.height).range(rules::IMAGE_SIZE),
                    tips::SIZE,
                );
            });
            restart |= combo(ui, "shading", &mut r.shading, tips::SHADING);
            restart |= color_edit(ui, "background", &mut r.background, tips::BACKGROUND);
            restart |= color_edit(
                ui,
                "ambient light",
                &mut r.ambient_light,
                tips::AMBIENT_LIGHT,
            );
            let t = &mut working.settings.trace;
            restart |= combo(ui, "sphere", &mut t.methods.sphere, tips::SPHERE);
            restart |= combo(ui, "triangle", &mut t.methods.triangle, tips::TRIANGLE);
            restart |= combo(ui, "offset", &mut t.methods.offset, tips::OFFSET);
            restart |= combo(
                ui,
                "shading normals",
                &mut t.methods.shading_normals,
                tips::SHADING_NORMALS,
            );
            rebuild |= combo(ui, "accelerator", &mut t.accel, tips::ACCEL);
            ui.horizontal(|ui| {
                restart |= drag(
                    ui,
                    "weight cutoff",
                    DragValue::new(&mut t.cutoff)
                        .speed(0.001)
                        // rules::CUTOFF: at least 0, below 1.
                        .range(0.0..=0.999),
                    tips::CUTOFF,
                );
            });
            ui.horizontal(|ui| {
                restart |= drag(
                    ui,
                    "threads (0 = all)",
                    DragValue::new(&mut working.settings.threads).range(0..=rules::MAX_THREADS),
                    tips::THREADS,
                );
            });
            ui.label(format!("accelerator in use: {:?}", render.accel().kind()));
        });
    egui::CollapsingHeader::new("Display")
        .default_open(true)
        .show(ui, |ui| {
            egui::ComboBox::from_label("image")
                .selected_text(prefs.mode.label())
                .show_ui(ui, |ui| {
                    for m in ImageMode::ALL {
                        ui.selectable_value(&mut prefs.mode, m, m.label());
                    }
                })
                .response
                .on_hover_text(tips::IMAGE_MODE);
            ui.add(
                egui::Slider::new(&mut prefs.exposure, 0.01..=16.0)
                    .logarithmic(true)
                    .text("exposure"),
            )
            .on_hover_text(tips::EXPOSURE);
            ui.horizontal(|ui| {
                ui.label("tonemap").on_hover_text(tips::TONEMAP);
                for t in Tonemap::ALL {
                    ui.radio_value(&mut prefs.tonemap, t, t.label());
                }
            });
        });
    egui::CollapsingHeader::new("Camera")
        .default_open(true)
        .show(ui, |ui| {
            let c = &mut working.scene.camera;
            restart |= vec3_edit(ui, "position", &mut c.position, 0.05, tips::POSITION);
            restart |= vec3_edit(ui, "look at ", &mut c.look_at, 0.05, tips::LOOK_AT);
            restart |= vec3_edit(ui, "up      ", &mut c.up, 0.01, tips::UP);
            restart |= ui
                .add(egui::Slider::new(&mut c.fov_y_deg, 1.0..=170.0).text("fov y (°)"))
                .on_hover_text(tips::FOV)
                .changed();
            ui.horizontal(|ui| {
                if ui
                    .button("Frame all")
                    .on_hover_text("move the camera back until every object is in view")
                    .clicked()
                {
                    pending.push(Command::FrameAll);
                }
                if ui
                    .button("Reset to the scene's")
                    .on_hover_text(
                        "the camera as the scene file placed it (Home); undo with Ctrl+Z",
                    )
                    .clicked()
                {
                    working.reset_camera(pending);
                }
            });
            ui.add(
                egui::Slider::new(&mut prefs.orbit_degrees, 30.0..=720.0)
                    .text("orbit °/width")
                    .max_decimals(0),
            )
            .on_hover_text(tips::ORBIT);
            ui.small("drag: orbit · right/middle drag: pan · wheel: zoom · Home: reset");
        });
    let edit = &mut working.scene;
    egui::CollapsingHeader::new(format!("Lights ({})", edit.lights.len()))
        .default_open(true)
        .show(ui, |ui| {
            let mut remove = None;
            for (i, l) in edit.lights.iter_mut().enumerate() {
                let selected = selection.selected_light == Some(i);
                egui::CollapsingHeader::new(&l.name)
                    .id_salt(("light", i))
                    .default_open(selected)
                    .show(ui, |ui| {
                        if ui
                            .checkbox(&mut l.follow_camera, "follows the camera")
                            .on_hover_text(tips::LIGHT_FOLLOW)
                            .changed()
                        {
                            // A headlight is a point light (a ball around the eye would hide
                            // the scene).
                            if l.follow_camera {
                                l.radius = 0.0;
                            }
                            restart = true;
                        }
                        if l.follow_camera {
                            ui.label(format!(
                                "at the camera's eye ({:.2}, {:.2}, {:.2})",
                                l.position.x, l.position.y, l.position.z
                            ));
                        } else {
                            restart |= vec3_edit(
                                ui,
                                "position",
                                &mut l.position,
                                0.05,
                                tips::LIGHT_POSITION,
                            );
                        }
                        restart |= color_edit(ui, "colour", &mut l.color, tips::LIGHT_COLOUR);
                        ui.horizontal(|ui| {
                            if l.follow_camera {
                                ui.disable();
                            }
                            restart |= drag(
                                ui,
                                "radius",
                                DragValue::new(&mut l.radius).speed(0.01).range(0.0..=1e6),
                                tips::LIGHT_RADIUS,
                            );
                        });
                        if ui.button("Remove").clicked() {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove {
                edit.lights.remove(i);
                restart = true;
            }
            if ui.button("Add light").clicked() {
                // A name no light has (after a removal, `light {len + 1}` may be taken).
                let mut n = edit.lights.len() + 1;
                while edit.lights.iter().any(|l| l.name == format!("light {n}")) {
                    n += 1;
                }
                let pos = edit.camera.position + Vec3::Y;
                edit.lights.push(Light {
                    name: format!("light {n}"),
                    position: pos,
                    color: Vec3::ONE,
                    radius: 0.0,
                    follow_camera: false,
                });
                restart = true;
            }
        });
    egui::CollapsingHeader::new(format!("Materials ({})", edit.materials.len()))
        .default_open(true)
        .show(ui, |ui| {
            // Each material's fields sit one indent in: a shallow one leaves them the width.
            ui.spacing_mut().indent = 10.0;
            ui.small("click an object in the image to select its material");
            let titles = names::material_titles(edit);
            // A click on an object opens its material and brings it into view, once per
            // selection: afterwards the header folds and the panel scrolls as the user likes.
            let scrolled = egui::Id::unique("raytree material scrolled to");
            let arrived = selection
                .selected_material
                .filter(|&i| ui.data(|d| d.get_temp::<usize>(scrolled)) != Some(i));
            for (i, m) in edit.materials.iter_mut().enumerate() {
                let selected = selection.selected_material == Some(i);
                let named = titles.get(i).cloned().unwrap_or_default();
                let title = if selected {
                    RichText::new(format!("> {}", named.title)).strong()
                } else {
                    RichText::new(named.title)
                };
                let header = egui::CollapsingHeader::new(title).id_salt(("material", i));
                let header = if arrived == Some(i) {
                    header.open(Some(true))
                } else {
                    header
                };
                let shown = header.show(ui, |ui| {
                    if named.users.len() > names::NAMED_USERS {
                        ui.small(format!("used by {}", named.users.join(", ")));
                    }
                    restart |= material_editor(ui, m)
                });
                if arrived == Some(i) {
                    // Vertically only: the header is indented, and aligning both axes would
                    // also slide the whole panel sideways by that indent.
                    let rise = ui.clip_rect().top() - shown.header_response.rect.top();
                    ui.scroll_with_delta(egui::vec2(0.0, rise));
                    ui.data_mut(|d| d.insert_temp(scrolled, i));
                }
            }
            if selection.selected_material.is_none() {
                ui.data_mut(|d| d.remove::<usize>(scrolled));
            }
        });
    egui::CollapsingHeader::new("Scene")
        .default_open(false)
        .show(ui, |ui| {
            let s = render.scene();
            ui.label(format!(
                "{}, {}, {}, {}",
                count(s.spheres.len(), "sphere"),
                count(s.triangles.len(), "triangle"),
                count(s.lights.len(), "light"),
                count(s.materials.len(), "material")
            ));
            for name in builtin::NAMES {
                if ui.button(format!("Open built-in \"{name}\"")).clicked() {
                    pending.push(Command::OpenBuiltin(name.to_string()));
                }
            }
        });
    if rebuild {
        pending.push(Command::Rebuild);
    } else if restart {
        pending.push(Command::Restart);
    }
}

fn material_editor(ui: &mut Ui, m: &mut Material) -> bool {
    let mut changed = false;
    changed |= color_edit(ui, "ambient ka", &mut m.ambient, tips::KA);
    changed |= color_edit(ui, "diffuse kd", &mut m.diffuse, tips::KD);
    changed |= color_edit(ui, "specular ks", &mut m.specular, tips::KS);
    changed |= color_edit(ui, "reflect kr", &mut m.reflectivity, tips::KR);
    changed |= color_edit(ui, "transmit kt", &mut m.transparency, tips::KT);
    ui.horizontal(|ui| {
        changed |= drag(
            ui,
            "shininess",
            DragValue::new(&mut m.shininess)
                .speed(0.5)
                .range(0.0..=10000.0),
            tips::SHININESS,
        );
        changed |= drag(
            ui,
            "ior",
            DragValue::new(&mut m.ior).speed(0.01).range(0.01..=10.0),
            tips::IOR,
        );
    });
    changed
}

// ---- the ray tree -------------------------------------------------------------------------

/// The clicked pixel's tree: the list (or the pinned and current trees, side by side or in a
/// narrow pane one above the other, changed nodes marked), and below it the numbers of the
/// selected node.
pub fn tree_panel(ui: &mut Ui, selection: &mut TreeSelection, ws: &mut Workspace, tracer: &Tracer) {
    let Some(tree) = selection.tree.clone() else {
        return;
    };
    // The title, the pixel's colour (a swatch, its numbers on hover and in the root's row) and
    // the count on one row, the buttons on the next: the table below gets the room.
    ui.horizontal(|ui| {
        ui.label(
            RichText::new(format!(
                "Ray tree of ({}, {})",
                tree.pixel[0], tree.pixel[1]
            ))
            .strong()
            .size(15.0),
        );
        let numbers = format!(
            "colour ({:.4}, {:.4}, {:.4})",
            tree.color.x, tree.color.y, tree.color.z,
        );
        let side = ui.text_style_height(&egui::TextStyle::Body);
        let (swatch, response) =
            ui.allocate_exact_size(egui::vec2(side, side), egui::Sense::hover());
        let c = tree.color.clamp(Vec3::ZERO, Vec3::ONE);
        // Outlined, so a black or background-coloured pixel still shows a swatch.
        ui.painter().rect(
            swatch,
            2.0,
            egui::Rgba::from_rgb(c.x, c.y, c.z),
            egui::Stroke::new(1.0, egui::Color32::from_gray(140)),
            egui::StrokeKind::Inside,
        );
        response.on_hover_text(numbers);
        ui.weak(format!(
            "{}{}",
            count(tree.nodes, "node"),
            if tree.truncated { " (truncated)" } else { "" }
        ));
        if ui
            .small_button("x")
            .on_hover_text("close this tree")
            .clicked()
        {
            selection.tree = None;
        }
    });
    ui.horizontal_wrapped(|ui| {
        if selection.tree_state.pinned.is_some() {
            if ui.button("Unpin").clicked() {
                selection.tree_state.pinned = None;
            }
        } else if ui
            .button("Pin for comparison")
            .on_hover_text("keep this tree, then change a setting to compare")
            .clicked()
        {
            selection.tree_state.pinned = Some(tree.clone());
        }
        if ui.button("Export tree as JSON...").clicked() {
            let name = format!("tree-{}-{}.json", tree.pixel[0], tree.pixel[1]);
            ws.browse(BrowseFor::ExportTree, &name);
        }
    });
    ui.separator();
    let state = &mut selection.tree_state;
    let selected = state.selected.clone().unwrap_or_default();
    // The selected node's numbers below, the table above: the table keeps at least
    // TABLE_LEAST of the pane and the detail starts at DETAIL_SHARE of it; the divider
    // between them drags (and is remembered).
    let room = ui.available_height();
    let detail_most = (room - TABLE_LEAST).max(DETAIL_LEAST);
    // When the pane's height changes by more than a tenth (a resized window), the divider
    // starts again from its share: a new panel id, so its height kept in points is not
    // carried from a small pane to a large one.
    let generation = tree_view::resize_generation(ui, "tree detail split", room);
    egui::Panel::bottom(("tree detail pane", generation))
        .resizable(true)
        .frame(egui::Frame::NONE.inner_margin(egui::Margin {
            top: 4,
            ..Default::default()
        }))
        .default_size((room * DETAIL_SHARE).clamp(DETAIL_LEAST, detail_most))
        .size_range(DETAIL_LEAST..=detail_most)
        .show(ui, |ui| {
            // A scroll area of any height: its default least height would push the panel
            // past the pane's bottom.
            egui::ScrollArea::both()
                .id_salt("tree detail")
                .auto_shrink(false)
                .min_scrolled_height(0.0)
                .show(ui, |ui| {
                    tree_view::detail(ui, &tree, &selected);
                    accelerator_line(ui, tracer, &tree, &selected);
                });
        });
    let rest = egui::CentralPanel::default().frame(egui::Frame::NONE);
    rest.show(ui, |ui| {
        egui::ScrollArea::both()
            .id_salt("tree list")
            .auto_shrink(false)
            .min_scrolled_height(0.0)
            .show(ui, |ui| match state.pinned.clone() {
                Some(pinned) => {
                    let changes = crate::diagram::changes(&pinned, &tree);
                    tree_view::say_changes(ui, state, &changes);
                    if !changes.is_empty() {
                        ui.weak("changed nodes are marked *");
                    }
                    let titles = [
                        format!(
                            "pinned: ({}, {}), max depth {}",
                            pinned.pixel[0], pinned.pixel[1], pinned.settings.max_depth
                        ),
                        format!("current: max depth {}", tree.settings.max_depth),
                    ];
                    let title = |ui: &mut Ui, text: &str| {
                        ui.add(egui::Label::new(RichText::new(text).strong()).truncate());
                    };
                    if ui.available_width() >= SIDE_BY_SIDE {
                        ui.columns(2, |cols| {
                            title(&mut cols[0], &titles[0]);
                            tree_view::tree_list(
                                &mut cols[0],
                                &pinned,
                                state,
                                Some(&tree),
                                "pinned",
                            );
                            title(&mut cols[1], &titles[1]);
                            tree_view::tree_list(
                                &mut cols[1],
                                &tree,
                                state,
                                Some(&pinned),
                                "current",
                            );
                        });
                    } else {
                        // A narrow pane: one above the other, each with the pane's width.
                        title(ui, &titles[0]);
                        tree_view::tree_list(ui, &pinned, state, Some(&tree), "pinned");
                        ui.add_space(4.0);
                        title(ui, &titles[1]);
                        tree_view::tree_list(ui, &tree, state, Some(&pinned), "current");
                    }
                }
                None => tree_view::tree_list(ui, &tree, state, None, "current"),
            });
    });
}

/// What the accelerator did for the selected ray (replayed: one query, cheap).
fn accelerator_line(
    ui: &mut Ui,
    tracer: &Tracer,
    tree: &crate::ray_tree::RayTree,
    selected: &[usize],
) {
    if let Some((_, visits)) = crate::scene_view::visit_segments(tracer, tree, selected) {
        let mut prims = visits.prims.clone();
        prims.sort_unstable();
        prims.dedup();
        ui.label(format!(
            "accelerator ({}): this ray entered {} and tested {} ({})",
            crate::choice::Choice::name(tracer.accel.kind()),
            count(visits.boxes.len(), "box"),
            count(prims.len(), "primitive"),
            count(visits.prims.len(), "test"),
        ))
        .on_hover_text("drawn as cyan boxes in the scene view (\"visits\")");
    }
}

/// The least width of the tree list's pane that shows the pinned and current trees side by
/// side (each table's three columns need about half of it); a narrower one stacks them.
const SIDE_BY_SIDE: f32 = 560.0;

/// The least height of the tree list's table (its header and about four rows), in points.
const TABLE_LEAST: f32 = 110.0;
/// The least height of the selected node's detail below it (the accelerator's line and a row).
const DETAIL_LEAST: f32 = 48.0;
/// The detail's first share of the pane's height below the header.
const DETAIL_SHARE: f32 = 0.38;

/// What each choice of the Export window gives, for its descriptions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExportSizes {
    /// The render as shown: its size and the samples reached of the viewer's target.
    pub shown: (u32, u32),
    pub done: u32,
    pub target: u32,
    /// The scene's own size and samples.
    pub scene: (u32, u32),
    pub samples: u32,
}

/// The Export window (Ctrl+S): the render as shown (the default: Enter takes it), the render at
/// the scene's size and samples (in the background), the render with the trees drawn over it,
/// the scene view; each says the size it gives.
pub fn export_window(
    ctx: &egui::Context,
    ws: &mut Workspace,
    has_tree: bool,
    stem: &str,
    sizes: ExportSizes,
) {
    let mut open = ws.export_choice;
    let mut chosen = None;
    let (sw, sh) = sizes.shown;
    let (fw, fh) = sizes.scene;
    let same = sizes.shown == sizes.scene && sizes.done == sizes.samples;
    let choices = [
        (
            BrowseFor::Export,
            "Render as shown",
            true,
            format!(
                "{sw}x{sh}, {} of {}, the camera as it is; PNG in the display's colours \
                 (exposure, tonemap, image mode), EXR linear",
                count(sizes.done, "sample"),
                sizes.target
            ),
        ),
        (
            BrowseFor::ExportFull,
            "Render at the scene's size",
            true,
            if same {
                format!(
                    "{fw}x{fh}, {}: the same picture as shown",
                    count(sizes.samples, "sample")
                )
            } else {
                format!(
                    "{fw}x{fh}, {}, rendered again in the background (progress and Cancel in \
                     the status bar); exposure 1, clamped",
                    count(sizes.samples, "sample")
                )
            },
        ),
        (
            BrowseFor::ExportOverlay,
            "Render with rays (PNG)",
            has_tree,
            format!("{sw}x{sh}: the render with the trees drawn over it, as in the render view"),
        ),
        (
            BrowseFor::ExportSceneView,
            "Scene view (PNG)",
            has_tree,
            format!("{fw}x{fh}: the scene view's camera, with the render camera, lights and trees"),
        ),
    ];
    egui::Window::new("Export")
        .open(&mut open)
        .collapsible(false)
        .resizable(false)
        .default_width(420.0)
        .show(ctx, |ui| {
            ui.set_max_width(440.0);
            for (i, (what, label, enabled, says)) in choices.iter().enumerate() {
                let button = ui.add_enabled(*enabled, egui::Button::new(*label));
                if i == 0 && ui.memory(|m| m.focused().is_none()) {
                    button.request_focus();
                }
                if button.clicked() {
                    chosen = Some(*what);
                }
                ui.add(egui::Label::new(egui::RichText::new(says).weak()).wrap());
                ui.add_space(4.0);
            }
            if !has_tree {
                ui.weak("click a pixel for a ray tree to export the rays");
            }
        });
    ws.export_choice = open && chosen.is_none();
    if let Some(what) = chosen {
        let suffix = match what {
            BrowseFor::ExportOverlay => "-rays",
            BrowseFor::ExportSceneView => "-scene-view",
            BrowseFor::ExportFull => "-full",
            _ => "",
        };
        ws.browse(what, &format!("{stem}{suffix}.png"));
    }
}

pub fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Help")
        .open(open)
        .default_height(560.0)
        .show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading("Controls");
                egui::Grid::new("keys").striped(true).show(ui, |ui| {
                    for (k, v) in [
                        ("Left drag", "orbit the camera about its target (180° across the image; see Camera)"),
                        ("Right or middle drag", "pan"),
                        ("Wheel", "zoom"),
                        ("Click", "ray tree of that pixel; selects its material"),
                        ("Shift+click", "add that pixel's tree to the trees shown"),
                        ("Ctrl+drag", "trees of a grid of pixels in the rectangle"),
                        ("Drag a light (scene view)", "move the light, facing the view"),
                        ("Shift+drag a sphere (scene view)", "move the sphere, facing the view"),
                        ("Ctrl+Z", "undo the last edit (a whole drag is one edit)"),
                        ("Ctrl+Shift+Z, Ctrl+Y", "redo"),
                        ("Home", "reset the camera to the scene's"),
                        ("Ctrl+S", "export the render (PNG or EXR, full resolution)"),
                        (
                            "Ctrl+O",
                            "open a scene or OBJ (or drop the file on the window)",
                        ),
                        ("Esc", "stop rendering"),
                        ("F1", "this help"),
                    ] {
                        ui.strong(k);
                        ui.label(v);
                        ui.end_row();
                    }
                });
                ui.add_space(6.0);
                ui.label("Colour fields: the swatch opens a colour picker; \"=\" edits one number for all three channels.");
                ui.label("Hover any setting for what it does.");
                ui.separator();
                ui.heading("Rays and diagram glyphs");
                ui.label("The same colours in the render view's overlay, the scene view, the tree list and the diagram:");
                super::legend::ray_legend_ui(ui);
                ui.separator();
                ui.heading("Built-in scenes");
                ui.label(format!(
                    "Scene > Built-in opens: {}.",
                    builtin::NAMES.join(", ")
                ));
            });
        });
}
