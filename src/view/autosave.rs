//! Unsaved edits survive quit, crash and device loss: while the model differs from what was last
//! saved, it is written to `NAME.autosave.json` beside the scene file (`demo.autosave.json` in
//! the working directory for the demo) at most [`AUTOSAVE_DELAY`] after an edit, and again on
//! every way out. A clean save removes it; `prespline view --recover` opens it.

use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// How long after an edit its autosave is written at the latest. Edits during that second join
/// the same write, so a drag costs one write a second, not one a frame.
pub const AUTOSAVE_DELAY: Duration = Duration::from_secs(1);

/// `NAME.autosave.json` for the scene file `NAME.json` (NAME keeps its directory; a path not
/// ending in `.json` keeps its whole name), `demo.autosave.json` in the working directory for
/// the built-in demo.
#[must_use]
pub fn autosave_path(scene: Option<&Path>) -> PathBuf {
    match scene {
        None => PathBuf::from("demo.autosave.json"),
        Some(p) => {
            let text = p.as_os_str().to_string_lossy();
            let stem = text.strip_suffix(".json").unwrap_or(&text);
            PathBuf::from(format!("{stem}.autosave.json"))
        }
    }
}

/// The autosave of `scene` when it exists and is newer than the scene file (always, for the
/// demo, which has no file): the edits of a session that ended without saving.
#[must_use]
pub fn newer_autosave(scene: Option<&Path>) -> Option<PathBuf> {
    let path = autosave_path(scene);
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let saved = modified(&path)?;
    let scene_time = scene.map_or(Some(SystemTime::UNIX_EPOCH), modified);
    (scene_time.is_none_or(|t| saved > t)).then_some(path)
}

/// Where an earlier session's autosave is kept when this session writes its own: "x.json" →
/// "x.autosave.previous.json".
#[must_use]
pub fn previous_path(autosave: &Path) -> PathBuf {
    let text = autosave.as_os_str().to_string_lossy();
    let stem = text.strip_suffix(".json").unwrap_or(&text);
    PathBuf::from(format!("{stem}.previous.json"))
}

/// Autosave bookkeeping of one session: edits are counted as revisions; the scene file holds
/// revision `saved`, the autosave file revision `written`.
#[derive(Debug, Clone)]
pub struct Autosave {
    path: PathBuf,
    revision: u64,
    saved: u64,
    written: u64,
    /// When the oldest edit not yet in the autosave file was applied.
    pending_since: Option<Instant>,
    /// An autosave this session did not write, to be set aside before the first write.
    earlier: bool,
}

impl Autosave {
    /// Autosave to `path` for a session that opened the saved scene.
    #[must_use]
    pub fn new(path: PathBuf) -> Self {
        let earlier = path.exists();
        Self {
            path,
            revision: 0,
            saved: 0,
            written: 0,
            pending_since: None,
            earlier,
        }
    }

    /// A session that opened the autosave at `path` itself (`--recover`): unsaved from the
    /// start, and the file already holds it.
    #[must_use]
    pub fn recovered(path: PathBuf) -> Self {
        Self {
            path,
            revision: 1,
            saved: 0,
            written: 1,
            pending_since: None,
            earlier: false,
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the model differs from the last save (or what was opened).
    pub fn unsaved(&self) -> bool {
        self.revision != self.saved
    }

    /// Whether an autosave file of this session holds edits not in the scene file.
    pub fn exists(&self) -> bool {
        self.unsaved() && self.written != self.saved && self.path.exists()
    }

    /// Records that edits were applied at `now`.
    pub fn edited(&mut self, now: Instant) {
        self.revision += 1;
        self.pending_since.get_or_insert(now);
    }

    /// When the autosave must be written: [`AUTOSAVE_DELAY`] after the oldest edit it lacks.
    pub fn deadline(&self) -> Option<Instant> {
        self.pending_since
            .filter(|_| self.unsaved() && self.written != self.revision)
            .map(|t| t + AUTOSAVE_DELAY)
    }

    /// Writes `scene` when edits are unsaved and the file lacks some of them; returns whether
    /// it wrote.
    pub fn write(&mut self, scene: &Scene) -> Result<bool, SceneError> {
        if !self.unsaved() || self.written == self.revision {
            self.pending_since = None;
            return Ok(false);
        }
        if std::mem::take(&mut self.earlier) && self.path.exists() {
            // Another session's unsaved edits: kept, not overwritten.
            let aside = previous_path(&self.path);
            std::fs::rename(&self.path, &aside).map_err(|e| {
                SceneError(format!(
                    "cannot move the earlier autosave {} aside: {e}",
                    self.path.display()
                ))
            })?;
        }
        scene.save(&self.path)?;
        self.written = self.revision;
        self.pending_since = None;
        Ok(true)
    }

    /// A clean save of revision `revision` happened: the autosave is obsolete and removed.
    pub fn saved(&mut self) {
        self.saved = self.revision;
        self.pending_since = None;
        if self.written != self.saved || self.path.exists() {
            let _ = std::fs::remove_file(&self.path);
        }
        self.written = self.saved;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_follow_the_scene_name() {
        assert_eq!(autosave_path(None), PathBuf::from("demo.autosave.json"));
        assert_eq!(
            autosave_path(Some(Path::new("dir/teapot.json"))),
            PathBuf::from("dir/teapot.autosave.json")
        );
        assert_eq!(
            autosave_path(Some(Path::new("scene.txt"))),
            PathBuf::from("scene.txt.autosave.json")
        );
        assert_eq!(
            previous_path(Path::new("dir/teapot.autosave.json")),
            PathBuf::from("dir/teapot.autosave.previous.json")
        );
    }

    #[test]
    fn the_deadline_follows_the_oldest_unwritten_edit() {
        let mut a = Autosave::new(PathBuf::from("/nonexistent/x.autosave.json"));
        assert_eq!(a.deadline(), None);
        let t0 = Instant::now();
        a.edited(t0);
        a.edited(t0 + Duration::from_millis(700));
        assert_eq!(
            a.deadline(),
            Some(t0 + AUTOSAVE_DELAY),
            "a drag does not postpone it"
        );
        assert!(a.unsaved());
        a.saved();
        assert!(!a.unsaved());
        assert_eq!(a.deadline(), None);
    }
}
