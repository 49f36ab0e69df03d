//! The file dialog for opening scenes and choosing where to save: `egui_file`'s dialog (an
//! egui window, so it works without a desktop portal, under Xvfb and in CI), told what the file
//! is for, which extensions it lists and where it starts.

use std::path::{Path, PathBuf};

use eframe::egui;
use egui_file::{FileDialog, State};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrowseFor {
    Open,
    /// A lesson file (docs/lessons.md).
    Lesson,
    SaveScene,
    Export,
    ExportFull,
    ExportOverlay,
    ExportSceneView,
    ExportTree,
    ExportDiagram,
}

impl BrowseFor {
    pub fn title(self) -> &'static str {
        match self {
            BrowseFor::Open => "Open scene or OBJ",
            BrowseFor::Lesson => "Open lesson (.toml)",
            BrowseFor::SaveScene => "Save scene as TOML",
            BrowseFor::Export => "Export the render as shown (.png or .exr)",
            BrowseFor::ExportFull => {
                "Export the render at the scene's size and samples (.png or .exr)"
            }
            BrowseFor::ExportOverlay => "Export render with the rays drawn over it (.png)",
            BrowseFor::ExportSceneView => "Export the scene view at the scene's size (.png)",
            BrowseFor::ExportTree => "Export ray tree (.json)",
            BrowseFor::ExportDiagram => "Export ray tree diagram (.svg)",
        }
    }

    /// The extensions the dialog lists (folders are always listed).
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            BrowseFor::Open => &["toml", "obj"],
            BrowseFor::SaveScene | BrowseFor::Lesson => &["toml"],
            BrowseFor::Export | BrowseFor::ExportFull => &["png", "exr"],
            BrowseFor::ExportOverlay | BrowseFor::ExportSceneView => &["png"],
            BrowseFor::ExportTree => &["json"],
            BrowseFor::ExportDiagram => &["svg"],
        }
    }

    /// Whether the dialog lists `path` (a file of one of [`Self::extensions`]).
    pub fn lists(self, path: &Path) -> bool {
        path.extension()
            .and_then(|x| x.to_str())
            .is_some_and(|x| self.extensions().contains(&x.to_ascii_lowercase().as_str()))
    }
}

pub enum Outcome {
    Open,
    Cancel,
    Chose(BrowseFor, PathBuf),
}

/// An open file dialog and what its file is for.
pub struct FileBrowser {
    purpose: BrowseFor,
    dialog: FileDialog,
}

impl FileBrowser {
    /// A dialog for `purpose` in `dir`, the file name field holding `name`.
    pub fn new(purpose: BrowseFor, dir: PathBuf, name: &str) -> Self {
        let dialog = if matches!(purpose, BrowseFor::Open | BrowseFor::Lesson) {
            FileDialog::open_file()
        } else {
            FileDialog::save_file()
        };
        let mut dialog = dialog
            .title(purpose.title())
            .initial_path(dir)
            .default_size([520.0, 420.0])
            .show_rename(false)
            .show_files_filter(Box::new(move |p: &Path| purpose.lists(p)));
        if !name.is_empty() {
            dialog = dialog.default_filename(name);
        }
        dialog.open();
        Self { purpose, dialog }
    }

    /// Draws the dialog; says whether it is still open, was cancelled or chose a file.
    pub fn show(&mut self, ctx: &egui::Context) -> Outcome {
        self.dialog.show(ctx);
        match self.dialog.state() {
            State::Open => Outcome::Open,
            State::Selected => match self.dialog.path() {
                Some(path) => Outcome::Chose(self.purpose, path.to_path_buf()),
                None => Outcome::Cancel,
            },
            State::Closed | State::Cancelled => Outcome::Cancel,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_purpose_lists_its_own_files() {
        assert!(BrowseFor::Open.lists(Path::new("a/teapot.OBJ")));
        assert!(BrowseFor::Open.lists(Path::new("scene.toml")));
        assert!(!BrowseFor::Open.lists(Path::new("shot.png")));
        assert!(BrowseFor::Export.lists(Path::new("shot.exr")));
        assert!(!BrowseFor::ExportTree.lists(Path::new("tree.svg")));
        assert!(!BrowseFor::ExportDiagram.lists(Path::new("noext")));
    }
}
