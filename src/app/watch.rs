//! Reload on save: the open scene file, the meshes it names, the material libraries beside them
//! and the textures the scene uses are watched with `notify` (other images in those folders,
//! such as screenshots saved there, are not); a burst of changes (an editor writes a
//! temporary file, renames it over the old one, touches it again) settles for [`DEBOUNCE`]
//! before one reload is asked for.
//!
//! The folders are watched, not the files: an editor that saves by renaming a new file over the
//! old one would leave a watch on the file itself pointing at the deleted inode.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::{Duration, Instant};

use notify::{RecursiveMode, Watcher};

use crate::scene::{ObjectSource, Scene};

/// Quiet time after the last change before the reload.
pub const DEBOUNCE: Duration = Duration::from_millis(200);

/// Extensions of the files beside a mesh that change what it looks like, whatever their name
/// (a material library the OBJ names, or one it may name after the next save). Textures count
/// by name: the ones the scene uses are in its file list.
const COMPANIONS: &[&str] = &["mtl"];

pub struct SceneWatch {
    _watcher: notify::RecommendedWatcher,
    events: Receiver<notify::Result<notify::Event>>,
    /// The scene file, its meshes and its textures, as the watcher reports them (absolute).
    files: BTreeSet<PathBuf>,
    /// Folders of the meshes, where material libraries count too.
    mesh_folders: BTreeSet<PathBuf>,
    /// The last relevant change not yet acted upon.
    changed: Option<Instant>,
}

impl std::fmt::Debug for SceneWatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneWatch")
            .field("files", &self.files)
            .finish()
    }
}

fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| std::path::absolute(p).unwrap_or(p.to_path_buf()))
}

/// The files a scene loaded from `source` reads: itself, its meshes and the textures it uses
/// (their MTL paths are relative to the mesh's folder, or absolute).
pub fn scene_files(scene: &Scene, source: &Path) -> Vec<PathBuf> {
    let folder = source.parent().unwrap_or(Path::new(""));
    let mut out = vec![source.to_path_buf()];
    let mut mesh_folders = BTreeSet::new();
    for o in &scene.objects {
        if let ObjectSource::Mesh { file, .. } = &o.source {
            let mesh = folder.join(file);
            mesh_folders.insert(mesh.parent().unwrap_or(folder).to_path_buf());
            out.push(mesh);
        }
    }
    for texture in &scene.textures {
        out.extend(
            mesh_folders
                .iter()
                .map(|f| f.join(&texture.name))
                .filter(|p| p.is_file()),
        );
    }
    out
}

impl SceneWatch {
    /// Watches `files` (the first is the scene file) and the companions of the others.
    pub fn new(files: &[PathBuf]) -> Result<Self, String> {
        let (tx, events) = channel();
        let mut watcher = notify::recommended_watcher(move |e| {
            let _ = tx.send(e);
        })
        .map_err(|e| format!("cannot watch the scene for changes: {e}"))?;
        let files: BTreeSet<PathBuf> = files.iter().map(|f| absolute(f)).collect();
        let folders: BTreeSet<PathBuf> = files
            .iter()
            .filter_map(|f| f.parent().map(Path::to_path_buf))
            .collect();
        for folder in &folders {
            watcher
                .watch(folder, RecursiveMode::NonRecursive)
                .map_err(|e| format!("cannot watch {} for changes: {e}", folder.display()))?;
        }
        Ok(Self {
            _watcher: watcher,
            events,
            mesh_folders: folders,
            files,
            changed: None,
        })
    }

    fn relevant(&self, path: &Path) -> bool {
        if self.files.contains(path) || self.files.contains(&absolute(path)) {
            return true;
        }
        let companion = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| COMPANIONS.iter().any(|c| e.eq_ignore_ascii_case(c)));
        companion && path.parent().is_some_and(|p| self.mesh_folders.contains(p))
    }

    /// Takes the changes reported so far; true once, when the last relevant one is
    /// [`DEBOUNCE`] old.
    pub fn poll(&mut self) -> bool {
        loop {
            match self.events.try_recv() {
                Ok(Ok(event)) => {
                    let writes = !matches!(event.kind, notify::EventKind::Access(_));
                    if writes && event.paths.iter().any(|p| self.relevant(p)) {
                        self.changed = Some(Instant::now());
                    }
                }
                Ok(Err(_)) => {}
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => break,
            }
        }
        match self.changed {
            Some(t) if t.elapsed() >= DEBOUNCE => {
                self.changed = None;
                true
            }
            _ => false,
        }
    }

    /// True while a change waits out its debounce (the UI keeps polling).
    pub fn pending(&self) -> bool {
        self.changed.is_some()
    }
}
