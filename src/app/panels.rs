//! The panels: each edits the working copy of the scene or settings and queues commands; none
//! applies anything itself.

use eframe::egui::{self, Color32, DragValue, RichText, Ui};
use glam::Vec3;

use super::file_browser::{BrowseFor, FileBrowser};
use super::modes::{ImageMode, TERMINATION_LEGEND};
use super::tree_view;
use super::{Command, ViewerApp};
use crate::choice::Choice;
use crate::scene::{Light, Material, builtin, rules};

// ---- small widgets ------------------------------------------------------------------------

/// A label and a drag value named by it (for screen readers and UI tests).
fn drag(ui: &mut Ui, label: &str, value: DragValue<'_>) -> bool {
    let l = ui.label(label);
    ui.add(value).labelled_by(l.id).changed()
}

fn vec3_edit(ui: &mut Ui, label: &str, v: &mut Vec3, speed: f32) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        let l = ui.label(label);
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui
                .add(DragValue::new(c).speed(speed).max_decimals(4))
                .labelled_by(l.id)
                .changed();
        }
    });
    changed
}

fn color_edit(ui: &mut Ui, label: &str, v: &mut Vec3) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        let l = ui.label(label);
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui
                .add(
                    DragValue::new(c)
                        .speed(0.01)
                        .range(0.0..=100.0)
                        .max_decimals(3),
                )
                .labelled_by(l.id)
                .changed();
        }
        let mut rgb = [v.x.min(1.0), v.y.min(1.0), v.z.min(1.0)];
        if ui
            .color_edit_button_rgb(&mut rgb)
            .labelled_by(l.id)
            .changed()
        {
            *v = Vec3::from(rgb);
            changed = true;
        }
    });
    changed
}

/// A menu of every variant of a [`Choice`], each with its help line as a tooltip.
fn combo<T: Choice>(ui: &mut Ui, label: &str, value: &mut T) -> bool {
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
        });
    changed
}

// ---- panels -------------------------------------------------------------------------------

pub fn top_bar(app: &mut ViewerApp, ui: &mut Ui) {
    egui::Panel::top("menu").show(ui, |ui| {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("Scene", |ui| {
                if ui.button("Open... (Ctrl+O)").clicked() {
                    app.browser = Some(FileBrowser::new(BrowseFor::Open, app.start_dir(), ""));
                }
                ui.menu_button("Built-in", |ui| {
                    for name in builtin::NAMES {
                        if ui.button(*name).clicked() {
                            app.command(Command::OpenBuiltin(name.to_string()));
                        }
                    }
                });
                if ui.button("Save scene as...").clicked() {
                    let name = format!("{}.toml", app.file_stem());
                    app.browser = Some(FileBrowser::new(
                        BrowseFor::SaveScene,
                        app.start_dir(),
                        &name,
                    ));
                }
                if ui.button("Export... (Ctrl+S)").clicked() {
                    app.export_choice = true;
                }
            });
            ui.menu_button("View", |ui| {
                for mode in ImageMode::ALL {
                    ui.radio_value(&mut app.prefs.mode, mode, mode.label());
                }
                ui.separator();
                super::workspace::pane_toggles(app, ui);
            });
            if ui.button("Speed vs accuracy").clicked() {
                app.sweep.open = true;
            }
            if ui.button("Help (F1)").clicked() {
                app.show_help = true;
            }
            ui.separator();
            ui.label(RichText::new(&app.scene_label).strong());
        });
        let mut dismiss = None;
        for (i, (is_error, msg)) in app.messages.iter().enumerate().rev().take(3) {
            ui.horizontal(|ui| {
                let color = if *is_error {
                    Color32::LIGHT_RED
                } else {
                    Color32::LIGHT_YELLOW
                };
                ui.colored_label(color, msg);
                if ui.small_button("x").clicked() {
                    dismiss = Some(i);
                }
            });
        }
        if let Some(i) = dismiss {
            app.messages.remove(i);
        }
    });
}

pub fn status_bar(app: &mut ViewerApp, ui: &mut Ui) {
    egui::Panel::bottom("status").show(ui, |ui| {
        let target = app.scene.render.samples;
        let stats = app.session.stats().counts();
        let elapsed = match (app.progress.finished_secs, app.progress.started) {
            (Some(s), _) => s,
            (None, Some(t)) => t.elapsed().as_secs_f64(),
            _ => 0.0,
        };
        let mrays = |n: u64| n as f64 / elapsed.max(1e-6) / 1e6;
        let (w, h) = (app.scene.render.width as u64, app.scene.render.height as u64);
        let pass_fraction = app.session.stats().pixels_done.load(std::sync::atomic::Ordering::Relaxed) as f32 / (w * h).max(1) as f32;
        let done = app.progress.samples_done as f32 / target.max(1) as f32;
        let fraction = if app.is_finished() {
            1.0
        } else {
            // Passes double the samples, so the last pass is half the work.
            (done + pass_fraction.min(1.0) * (1.0 - done) * 0.5).min(0.999)
        };
        ui.horizontal(|ui| {
            ui.add(
                egui::ProgressBar::new(fraction)
                    .desired_width(220.0)
                    .text(format!("{}/{} spp", app.progress.samples_done, target)),
            );
            ui.label(format!(
                "{} · {:.2} s · {:.2} Mrays/s (primary {:.2}, reflected {:.2}, refracted {:.2}, shadow {:.2}) · {} threads",
                if app.is_finished() { "done" } else { &app.progress.pass_label },
                elapsed,
                mrays(stats.total()),
                mrays(stats.primary),
                mrays(stats.reflected),
                mrays(stats.refracted),
                mrays(stats.shadow),
                app.session.threads(),
            ));
        });
        ui.horizontal(|ui| {
            if let Some((x, y)) = app.hover {
                let (c, a) = app.film.pixel(x, y);
                ui.monospace(format!(
                    "pixel ({x}, {y})  rgb ({:.4}, {:.4}, {:.4})  depth {}  rays {}  normal ({:.2}, {:.2}, {:.2})",
                    c.x, c.y, c.z, a.depth_reached, a.rays, a.normal.x, a.normal.y, a.normal.z
                ));
            } else {
                ui.monospace("move over the image for pixel values; click a pixel for its ray tree");
            }
        });
    });
}

pub fn side_panel(app: &mut ViewerApp, ui: &mut Ui) {
    let mut restart = false;
    let mut rebuild = false;
    egui::CollapsingHeader::new("Render settings")
        .default_open(true)
        .show(ui, |ui| {
            let r = &mut app.edit.render;
            restart |= ui
                .add(egui::Slider::new(&mut r.max_depth, rules::DEPTH).text("max depth"))
                .changed();
            restart |= ui
                .add(
                    egui::Slider::new(&mut r.samples, rules::SAMPLES)
                        .logarithmic(true)
                        .text("samples"),
                )
                .changed();
            ui.horizontal(|ui| {
                restart |= drag(
                    ui,
                    "width",
                    DragValue::new(&mut r.width).range(rules::IMAGE_SIZE),
                );
                restart |= drag(
                    ui,
                    "height",
                    DragValue::new(&mut r.height).range(rules::IMAGE_SIZE),
                );
            });
            restart |= combo(ui, "shading", &mut r.shading);
            restart |= color_edit(ui, "background", &mut r.background);
            restart |= color_edit(ui, "ambient light", &mut r.ambient_light);
            let t = &mut app.settings.trace;
            restart |= combo(ui, "sphere", &mut t.methods.sphere);
            restart |= combo(ui, "triangle", &mut t.methods.triangle);
            restart |= combo(ui, "offset", &mut t.methods.offset);
            restart |= combo(ui, "shading normals", &mut t.methods.shading_normals);
            rebuild |= combo(ui, "accelerator", &mut t.accel);
            ui.horizontal(|ui| {
                restart |= drag(
                    ui,
                    "weight cutoff",
                    DragValue::new(&mut t.cutoff)
                        .speed(0.001)
                        // rules::CUTOFF: at least 0, below 1.
                        .range(0.0..=0.999),
                );
            });
            ui.horizontal(|ui| {
                restart |= drag(
                    ui,
                    "threads (0 = all)",
                    DragValue::new(&mut app.settings.threads).range(0..=rules::MAX_THREADS),
                );
            });
            ui.label(format!("accelerator in use: {:?}", app.tracer.accel.kind()));
        });
    egui::CollapsingHeader::new("Display")
        .default_open(true)
        .show(ui, |ui| {
            egui::ComboBox::from_label("image")
                .selected_text(app.prefs.mode.label())
                .show_ui(ui, |ui| {
                    for m in ImageMode::ALL {
                        ui.selectable_value(&mut app.prefs.mode, m, m.label());
                    }
                });
            ui.add(
                egui::Slider::new(&mut app.prefs.exposure, 0.01..=16.0)
                    .logarithmic(true)
                    .text("exposure"),
            );
            ui.horizontal(|ui| {
                ui.label("tonemap");
                ui.radio_value(&mut app.prefs.tonemap, 0, "clamp");
                ui.radio_value(&mut app.prefs.tonemap, 1, "Reinhard");
                ui.radio_value(&mut app.prefs.tonemap, 2, "ACES");
            });
            if app.prefs.mode == ImageMode::Termination {
                for (label, (r, g, b)) in TERMINATION_LEGEND {
                    ui.colored_label(Color32::from_rgb(r, g, b), format!("# {label}"));
                }
            }
        });
    egui::CollapsingHeader::new("Camera")
        .default_open(true)
        .show(ui, |ui| {
            let c = &mut app.edit.camera;
            restart |= vec3_edit(ui, "position", &mut c.position, 0.05);
            restart |= vec3_edit(ui, "look at ", &mut c.look_at, 0.05);
            restart |= vec3_edit(ui, "up      ", &mut c.up, 0.01);
            restart |= ui
                .add(egui::Slider::new(&mut c.fov_y_deg, 1.0..=170.0).text("fov y (°)"))
                .changed();
            if ui.button("Frame all").clicked() {
                app.pending.push(Command::FrameAll);
            }
            ui.small("drag: orbit · right/middle drag: pan · wheel: zoom");
        });
    egui::CollapsingHeader::new(format!("Lights ({})", app.edit.lights.len()))
        .default_open(true)
        .show(ui, |ui| {
            let mut remove = None;
            for (i, l) in app.edit.lights.iter_mut().enumerate() {
                let selected = app.selected_light == Some(i);
                egui::CollapsingHeader::new(&l.name)
                    .id_salt(("light", i))
                    .default_open(selected)
                    .show(ui, |ui| {
                        restart |= vec3_edit(ui, "position", &mut l.position, 0.05);
                        restart |= color_edit(ui, "colour", &mut l.color);
                        ui.horizontal(|ui| {
                            restart |= drag(
                                ui,
                                "radius",
                                DragValue::new(&mut l.radius).speed(0.01).range(0.0..=1e6),
                            );
                        });
                        if ui.button("Remove").clicked() {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove {
                app.edit.lights.remove(i);
                restart = true;
            }
            if ui.button("Add light").clicked() {
                let n = app.edit.lights.len() + 1;
                let pos = app.edit.camera.position + Vec3::Y;
                app.edit.lights.push(Light {
                    name: format!("light {n}"),
                    position: pos,
                    color: Vec3::ONE,
                    radius: 0.0,
                });
                restart = true;
            }
        });
    egui::CollapsingHeader::new(format!("Materials ({})", app.edit.materials.len()))
        .default_open(true)
        .show(ui, |ui| {
            ui.small("click an object in the image to select its material");
            for (i, m) in app.edit.materials.iter_mut().enumerate() {
                let selected = app.selected_material == Some(i);
                let title = if selected {
                    RichText::new(format!("> {}", m.name)).strong()
                } else {
                    RichText::new(&m.name)
                };
                let header = egui::CollapsingHeader::new(title).id_salt(("material", i));
                let header = if selected {
                    header.open(Some(true))
                } else {
                    header
                };
                header.show(ui, |ui| restart |= material_editor(ui, m));
            }
        });
    egui::CollapsingHeader::new("Scene")
        .default_open(false)
        .show(ui, |ui| {
            let s = &app.scene;
            ui.label(format!(
                "{} spheres, {} triangles, {} lights, {} materials",
                s.spheres.len(),
                s.triangles.len(),
                s.lights.len(),
                s.materials.len()
            ));
            for name in builtin::NAMES {
                if ui.button(format!("Open built-in \"{name}\"")).clicked() {
                    app.pending.push(Command::OpenBuiltin(name.to_string()));
                }
            }
        });
    if rebuild {
        app.pending.push(Command::Rebuild);
    } else if restart {
        app.pending.push(Command::Restart);
    }
}

fn material_editor(ui: &mut Ui, m: &mut Material) -> bool {
    let mut changed = false;
    changed |= color_edit(ui, "ambient ka ", &mut m.ambient);
    changed |= color_edit(ui, "diffuse kd ", &mut m.diffuse);
    changed |= color_edit(ui, "specular ks", &mut m.specular);
    changed |= color_edit(ui, "reflect kr ", &mut m.reflectivity);
    changed |= color_edit(ui, "transmit kt", &mut m.transparency);
    ui.horizontal(|ui| {
        changed |= drag(
            ui,
            "shininess",
            DragValue::new(&mut m.shininess)
                .speed(0.5)
                .range(0.0..=10000.0),
        );
        changed |= drag(
            ui,
            "ior",
            DragValue::new(&mut m.ior).speed(0.01).range(0.01..=10.0),
        );
    });
    changed
}

// ---- the ray tree -------------------------------------------------------------------------

/// The clicked pixel's tree: the list (or the pinned and current trees side by side, changed
/// nodes marked), and the numbers of the selected node.
pub fn tree_panel(app: &mut ViewerApp, ui: &mut Ui) {
    let Some(tree) = app.tree.clone() else {
        return;
    };
    ui.horizontal(|ui| {
        ui.heading(format!(
            "Ray tree of ({}, {})",
            tree.pixel[0], tree.pixel[1]
        ));
        if ui.small_button("x").clicked() {
            app.tree = None;
        }
    });
    ui.label(format!(
        "colour ({:.4}, {:.4}, {:.4}) · {} nodes{}",
        tree.color.x,
        tree.color.y,
        tree.color.z,
        tree.nodes,
        if tree.truncated { " (truncated)" } else { "" }
    ));
    ui.horizontal(|ui| {
        if app.tree_state.pinned.is_some() {
            if ui.button("Unpin").clicked() {
                app.tree_state.pinned = None;
            }
        } else if ui
            .button("Pin for comparison")
            .on_hover_text("keep this tree, then change a setting to compare")
            .clicked()
        {
            app.tree_state.pinned = Some(tree.clone());
        }
        if ui.button("Export tree as JSON...").clicked() {
            let name = format!("tree-{}-{}.json", tree.pixel[0], tree.pixel[1]);
            app.browser = Some(FileBrowser::new(
                BrowseFor::ExportTree,
                app.start_dir(),
                &name,
            ));
        }
    });
    ui.separator();
    let state = &mut app.tree_state;
    egui::ScrollArea::both()
        .id_salt("tree list")
        .max_height(ui.available_height() * 0.5)
        .show(ui, |ui| match state.pinned.clone() {
            Some(pinned) => {
                ui.label("changed nodes are marked *");
                ui.columns(2, |cols| {
                    cols[0].label(format!(
                        "pinned: ({}, {}), max depth {}",
                        pinned.pixel[0], pinned.pixel[1], pinned.settings.max_depth
                    ));
                    tree_view::tree_list(&mut cols[0], &pinned, state, Some(&tree), "pinned");
                    cols[1].label(format!("current: max depth {}", tree.settings.max_depth));
                    tree_view::tree_list(&mut cols[1], &tree, state, Some(&pinned), "current");
                });
            }
            None => tree_view::tree_list(ui, &tree, state, None, "current"),
        });
    ui.separator();
    let selected = state.selected.clone().unwrap_or_default();
    // What the accelerator did for the selected ray (replayed: one query, cheap).
    if let Some((_, visits)) = crate::scene_view::visit_segments(&app.tracer, &tree, &selected) {
        let mut prims = visits.prims.clone();
        prims.sort_unstable();
        prims.dedup();
        ui.label(format!(
            "accelerator ({}): this ray entered {} boxes and tested {} primitives ({} tests)",
            crate::choice::Choice::name(app.tracer.accel.kind()),
            visits.boxes.len(),
            prims.len(),
            visits.prims.len(),
        ))
        .on_hover_text("drawn as cyan boxes in the scene view (\"visits\")");
    }
    egui::ScrollArea::both()
        .id_salt("tree detail")
        .show(ui, |ui| {
            tree_view::detail(ui, &tree, &selected);
        });
}

/// What Ctrl+S offers: the clean render, the render with the rays drawn over it, or the scene
/// view; each then asks for a file name.
pub fn export_window(app: &mut ViewerApp, ctx: &egui::Context) {
    let mut open = app.export_choice;
    let mut chosen = None;
    egui::Window::new("Export")
        .open(&mut open)
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| {
            let has_tree = app.tree.is_some();
            for (what, label, enabled, hint) in [
                (BrowseFor::Export, "Render (PNG or EXR)", true, "the film at full resolution, as rendered"),
                (BrowseFor::ExportOverlay, "Render with rays (PNG)", has_tree, "the render with the trees drawn over it, as in the render view"),
                (BrowseFor::ExportSceneView, "Scene view (PNG)", has_tree, "the scene view's camera at the scene's size, with the render camera, lights and tree"),
            ] {
                if ui.add_enabled(enabled, egui::Button::new(label)).on_hover_text(hint).clicked() {
                    chosen = Some(what);
                }
            }
            if !has_tree {
                ui.weak("click a pixel for a ray tree to export the rays");
            }
        });
    app.export_choice = open && chosen.is_none();
    if let Some(what) = chosen {
        let suffix = match what {
            BrowseFor::ExportOverlay => "-rays",
            BrowseFor::ExportSceneView => "-scene-view",
            _ => "",
        };
        let name = format!("{}{suffix}.png", app.file_stem());
        app.browser = Some(FileBrowser::new(what, app.start_dir(), &name));
    }
}

pub fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Help").open(open).show(ctx, |ui| {
        egui::Grid::new("keys").striped(true).show(ui, |ui| {
            for (k, v) in [
                ("Left drag", "orbit the camera about its target"),
                ("Right or middle drag", "pan"),
                ("Wheel", "zoom"),
                ("Click", "ray tree of that pixel; selects its material"),
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
    });
}
