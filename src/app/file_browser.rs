//! A small file browser window for opening scenes and choosing where to save. No file-dialog
//! crate supports egui 0.37 yet, and native dialogs (rfd) need a desktop portal that Xvfb and
//! CI machines lack, so this is the one piece of UI written by hand.

use std::path::{Path, PathBuf};

use eframe::egui;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrowseFor {
    Open,
    SaveScene,
    Export,
    ExportOverlay,
    ExportSceneView,
    ExportTree,
    ExportDiagram,
}

impl BrowseFor {
    fn title(self) -> &'static str {
        match self {
            BrowseFor::Open => "Open scene or OBJ",
            BrowseFor::SaveScene => "Save scene as TOML",
            BrowseFor::Export => "Export render (.png or .exr)",
            BrowseFor::ExportOverlay => "Export render with the rays drawn over it (.png)",
            BrowseFor::ExportSceneView => "Export the scene view at the scene's size (.png)",
            BrowseFor::ExportTree => "Export ray tree (.json)",
            BrowseFor::ExportDiagram => "Export ray tree diagram (.svg)",
        }
    }

    fn extensions(self) -> &'static [&'static str] {
        match self {
            BrowseFor::Open => &["toml", "obj"],
            BrowseFor::SaveScene => &["toml"],
            BrowseFor::Export => &["png", "exr"],
            BrowseFor::ExportOverlay | BrowseFor::ExportSceneView => &["png"],
            BrowseFor::ExportTree => &["json"],
            BrowseFor::ExportDiagram => &["svg"],
        }
    }
}

pub enum Outcome {
    Open,
    Cancel,
    Chose(BrowseFor, PathBuf),
}

pub struct FileBrowser {
    purpose: BrowseFor,
    dir: PathBuf,
    name: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

impl FileBrowser {
    pub fn new(purpose: BrowseFor, dir: PathBuf, name: &str) -> Self {
        let mut b = Self {
            purpose,
            dir,
            name: name.to_string(),
            entries: Vec::new(),
            error: None,
        };
        b.read_dir();
        b
    }

    fn read_dir(&mut self) {
        self.entries.clear();
        self.error = None;
        match std::fs::read_dir(&self.dir) {
            Ok(rd) => {
                for e in rd.flatten() {
                    let name = e.file_name().to_string_lossy().to_string();
                    if name.starts_with('.') {
                        continue;
                    }
                    let is_dir = e.file_type().map(|t| t.is_dir()).unwrap_or(false);
                    let wanted = Path::new(&name)
                        .extension()
                        .and_then(|x| x.to_str())
                        .is_some_and(|x| {
                            self.purpose
                                .extensions()
                                .contains(&x.to_ascii_lowercase().as_str())
                        });
                    if is_dir || wanted {
                        self.entries.push((name, is_dir));
                    }
                }
                self.entries
                    .sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
            }
            Err(e) => self.error = Some(format!("cannot list {}: {e}", self.dir.display())),
        }
    }

    pub fn show(&mut self, ctx: &egui::Context) -> Outcome {
        let mut outcome = Outcome::Open;
        let mut open = true;
        let mut go_to: Option<PathBuf> = None;
        egui::Window::new(self.purpose.title())
            .open(&mut open)
            .default_size([460.0, 420.0])
            .collapsible(false)
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    if ui.button("Up").clicked()
                        && let Some(parent) = self.dir.parent()
                    {
                        go_to = Some(parent.to_path_buf());
                    }
                    ui.label(self.dir.display().to_string());
                });
                if let Some(e) = &self.error {
                    ui.colored_label(egui::Color32::LIGHT_RED, e);
                }
                egui::ScrollArea::vertical()
                    .max_height(280.0)
                    .show(ui, |ui| {
                        for (name, is_dir) in &self.entries {
                            let label = if *is_dir {
                                format!("{name}/")
                            } else {
                                name.clone()
                            };
                            let r = ui.selectable_label(self.name == *name, label);
                            if r.clicked() {
                                if *is_dir {
                                    go_to = Some(self.dir.join(name));
                                } else {
                                    self.name = name.clone();
                                }
                            }
                            if r.double_clicked() && !*is_dir {
                                outcome = Outcome::Chose(self.purpose, self.dir.join(name));
                            }
                        }
                    });
                ui.horizontal(|ui| {
                    ui.label("File:");
                    ui.text_edit_singleline(&mut self.name);
                });
                ui.horizontal(|ui| {
                    let verb = if self.purpose == BrowseFor::Open {
                        "Open"
                    } else {
                        "Save"
                    };
                    if ui.button(verb).clicked() && !self.name.trim().is_empty() {
                        let p = PathBuf::from(self.name.trim());
                        let path = if p.is_absolute() { p } else { self.dir.join(p) };
                        outcome = Outcome::Chose(self.purpose, path);
                    }
                    if ui.button("Cancel").clicked() {
                        outcome = Outcome::Cancel;
                    }
                });
            });
        if let Some(dir) = go_to {
            self.dir = dir;
            self.read_dir();
        }
        if !open {
            return Outcome::Cancel;
        }
        outcome
    }
}
