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
use std::sync::Arc;
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use notify::{RecursiveMode, Watcher};

use crate::scene::{ObjectSource, Scene};

/// Quiet time after the last change before the reload.
pub const DEBOUNCE: Duration = Duration::from_millis(200);

/// Extensions of the files beside a mesh that change what it looks like, whatever their name
/// (a material library the OBJ names, or one it may name after the next save). Textures count
/// by name: the ones the scene uses are in its file list.
const COMPANIONS: &[&str] = &["mtl"];

/// Called by the watcher's thread on a relevant change, to wake the UI (which otherwise
/// sleeps: an idle viewer requests no frame).
pub type Waker = Arc<dyn Fn() + Send + Sync>;

pub struct SceneWatch {
    _watcher: notify::RecommendedWatcher,
    /// The relevant changes, as the watcher's thread found them.
    events: Receiver<()>,
    /// The files watched, for the record.
    files: Arc<Relevant>,
    /// The last relevant change not yet acted upon.
    changed: Option<Instant>,
}

impl std::fmt::Debug for SceneWatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneWatch")
            .field("files", &self.files.files)
            .finish()
    }
}

/// Which changed paths matter: the scene's files, and material libraries beside its meshes.
struct Relevant {
    /// The scene file, its meshes and its textures, as the watcher reports them (absolute).
    files: BTreeSet<PathBuf>,
    /// Folders of the meshes, where material libraries count too.
    mesh_folders: BTreeSet<PathBuf>,
}

impl Relevant {
    fn path(&self, path: &Path) -> bool {
        if self.files.contains(path) || self.files.contains(&absolute(path)) {
            return true;
        }
        let companion = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| COMPANIONS.iter().any(|c| e.eq_ignore_ascii_case(c)));
        companion && path.parent().is_some_and(|p| self.mesh_folders.contains(p))
    }

    /// A write (not a mere read) of a relevant file.
    fn event(&self, event: &notify::Event) -> bool {
        !matches!(event.kind, notify::EventKind::Access(_))
            && event.paths.iter().any(|p| self.path(p))
    }
}

fn absolute(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| std::path::absolute(p).unwrap_or(p.to_path_buf()))
}

/// The files a scene loaded from `source` reads: itself, its meshes and the textures it uses
/// (their MTL paths are relative to the mesh's folder, or absolute; a name in another case than
/// the file's is the file on disk, as the loader found it).
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
                .map(|f| crate::scene::disk_names::ignoring_case(&f.join(&texture.name)))
                .filter(|p| p.is_file()),
        );
    }
    out
}

impl SceneWatch {
    /// Watches `files` (the first is the scene file) and the companions of the others; a
    /// relevant change calls `wake` (from the watcher's thread), nothing else does.
    pub fn new(files: &[PathBuf], wake: Option<Waker>) -> Result<Self, String> {
        let files: BTreeSet<PathBuf> = files.iter().map(|f| absolute(f)).collect();
        let folders: BTreeSet<PathBuf> = files
            .iter()
            .filter_map(|f| f.parent().map(Path::to_path_buf))
            .collect();
        let relevant = Arc::new(Relevant {
            files,
            mesh_folders: folders.clone(),
        });
        let (tx, events) = channel();
        let sees = relevant.clone();
        let mut watcher = notify::recommended_watcher(move |e: notify::Result<notify::Event>| {
            if e.is_ok_and(|e| sees.event(&e)) {
                let _ = tx.send(());
                if let Some(wake) = &wake {
                    wake();
                }
            }
        })
        .map_err(|e| format!("cannot watch the scene for changes: {e}"))?;
        for folder in &folders {
            watcher
                .watch(folder, RecursiveMode::NonRecursive)
                .map_err(|e| format!("cannot watch {} for changes: {e}", folder.display()))?;
        }
        Ok(Self {
            _watcher: watcher,
            events,
            files: relevant,
            changed: None,
        })
    }

    /// Takes the changes reported so far; true once, when the last relevant one is
    /// [`DEBOUNCE`] old.
    pub fn poll(&mut self) -> bool {
        while self.events.try_recv().is_ok() {
            self.changed = Some(Instant::now());
        }
        match self.changed {
            Some(t) if t.elapsed() >= DEBOUNCE => {
                self.changed = None;
                true
            }
            _ => false,
        }
    }

    /// How long the last change still has to settle before its reload (`None`: no change
    /// waiting): the UI asks for a frame then, and for none while nothing changes.
    pub fn settles_in(&self) -> Option<Duration> {
        self.changed.map(|t| DEBOUNCE.saturating_sub(t.elapsed()))
    }
}
