//! Unsaved edits survive quit, crash, device loss and unwritable directories; docs/autosave.md
//! is the user's description.
//!
//! While the model differs from what was last saved, it is written to `NAME.autosave.json`
//! beside the scene file `NAME.json` (`demo.autosave.json` in the working directory for the
//! demo) at most [`AUTOSAVE_DELAY`] after an edit, and again on every way out. Where the scene's
//! directory cannot take it (read-only, full, the name taken by a directory), it goes to the
//! state directory, `$XDG_STATE_HOME/prespline/` (`~/.local/state/prespline/`), under a name made
//! from the scene's absolute path ([`escape_path`]). A clean save removes it.
//!
//! An autosave this session did not write is never overwritten: it is moved aside to
//! `NAME.autosave.YYYYMMDD-HHMMSS[.N].json` (its modification time, UTC) first; at most [`KEEP`]
//! of those stay per place, and dropping the oldest says so. A write that fails everywhere is
//! retried after 1 s, 2 s, 4 s … at most [`RETRY_MAX`] apart, with one note when the failures
//! begin and one when they end.
//!
//! [`Autosave`] holds one session's bookkeeping; [`Places`] says where a scene's autosaves live
//! and which are waiting. Notes meant for the user collect in [`Autosave::take_notes`].

use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// How long after an edit its autosave is written at the latest. Edits during that second join
/// the same write, so a drag costs one write a second, not one a frame.
pub const AUTOSAVE_DELAY: Duration = Duration::from_secs(1);

/// The wait after the first write that failed everywhere; it doubles with each further failure.
pub const RETRY_FIRST: Duration = Duration::from_secs(1);

/// The longest wait between retries of a failing autosave.
pub const RETRY_MAX: Duration = Duration::from_secs(30);

/// Earlier sessions' autosaves kept per place (beside the scene, in the state directory).
pub const KEEP: usize = 10;

/// Longest escaped path used whole as a state-directory name (file names stop at 255 bytes).
const MAX_STEM: usize = 200;

/// `NAME.autosave.json` for the scene file `NAME.json` (NAME keeps its directory; a path not
/// ending in `.json` keeps its whole name), `demo.autosave.json` in the working directory for
/// the built-in demo.
#[must_use]
pub fn autosave_path(scene: Option<&Path>) -> PathBuf {
    Place::beside(scene).current()
}

/// `$XDG_STATE_HOME/prespline` (an absolute XDG_STATE_HOME only, as the XDG base directory
/// specification asks), else `$HOME/.local/state/prespline`; `None` without either.
#[must_use]
pub fn state_dir() -> Option<PathBuf> {
    let absolute = |var: &str| {
        std::env::var_os(var)
            .map(PathBuf::from)
            .filter(|p| p.is_absolute())
    };
    let base =
        absolute("XDG_STATE_HOME").or_else(|| absolute("HOME").map(|h| h.join(".local/state")))?;
    Some(base.join("prespline"))
}

/// A path as one file name that maps back to it: `%` → `%25`, `/` → `%2F`, bytes outside
/// printable ASCII as `%XX` (so `/home/ann/teapot` → `%2Fhome%2Fann%2Fteapot`). Names longer
/// than 200 bytes keep their last 160 after a 16-digit FNV-1a hash of the whole path.
#[must_use]
pub fn escape_path(path: &Path) -> String {
    let bytes = path_bytes(path);
    let mut out = String::with_capacity(bytes.len());
    for &b in bytes.iter() {
        if b == b'%' || b == b'/' || !(0x20..0x7f).contains(&b) {
            out.push_str(&format!("%{b:02X}"));
        } else {
            out.push(char::from(b));
        }
    }
    if out.len() <= MAX_STEM {
        return out;
    }
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    // All ASCII, so any byte offset is a character boundary.
    format!("{hash:016x}-{}", &out[out.len() - 160..])
}

#[cfg(unix)]
fn path_bytes(path: &Path) -> std::borrow::Cow<'_, [u8]> {
    use std::os::unix::ffi::OsStrExt;
    path.as_os_str().as_bytes().into()
}

#[cfg(not(unix))]
fn path_bytes(path: &Path) -> std::borrow::Cow<'_, [u8]> {
    path.to_string_lossy().into_owned().into_bytes().into()
}

/// `YYYYMMDD-HHMMSS` of `t` in UTC.
#[must_use]
pub fn utc_stamp(t: SystemTime) -> String {
    let secs = t
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    let s = secs % 86_400;
    format!(
        "{y:04}{m:02}{d:02}-{:02}{:02}{:02}",
        s / 3600,
        s % 3600 / 60,
        s % 60
    )
}

/// Year, month, day of the `days`-th day after 1970-01-01 (Hinnant's `civil_from_days`).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// `(timestamp, N)` of the middle of `NAME.autosave.YYYYMMDD-HHMMSS[.N].json`.
fn parse_aside(middle: &str) -> Option<(String, u32)> {
    let (stamp, n) = match middle.split_once('.') {
        Some((s, n)) if !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()) => {
            (s, n.parse().ok()?)
        }
        Some(_) => return None,
        None => (middle, 0),
    };
    let b = stamp.as_bytes();
    let shape = b.len() == 15
        && b[8] == b'-'
        && b.iter()
            .enumerate()
            .all(|(i, c)| i == 8 || c.is_ascii_digit());
    shape.then(|| (stamp.to_string(), n))
}

fn modified(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

fn is_regular_file(p: &Path) -> bool {
    std::fs::symlink_metadata(p).is_ok_and(|m| m.is_file())
}

/// Which file a path names now; a write replaces the file, so it changes with every write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct FileId(u64, u128);

fn file_id(p: &Path) -> Option<FileId> {
    let m = std::fs::symlink_metadata(p).ok().filter(|m| m.is_file())?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some(FileId(m.dev(), u128::from(m.ino())))
    }
    #[cfg(not(unix))]
    {
        let t = m
            .modified()
            .ok()?
            .duration_since(SystemTime::UNIX_EPOCH)
            .ok()?;
        Some(FileId(m.len(), t.as_nanos()))
    }
}

/// `word` as one shell word: unchanged when it needs no quoting, else in single quotes.
fn shell_word(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"/._-+,:@%=".contains(&b));
    if plain {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

/// One directory that holds a scene's autosaves: `STEM.autosave.json` (the current one) and
/// `STEM.autosave.YYYYMMDD-HHMMSS[.N].json` (earlier sessions').
#[derive(Debug, Clone, PartialEq, Eq)]
struct Place {
    /// Empty for the working directory, so printed paths stay as the user gave them.
    dir: PathBuf,
    stem: String,
    /// The state directory, created on first use.
    state: bool,
}

impl Place {
    fn beside(scene: Option<&Path>) -> Self {
        let (dir, stem) = match scene {
            None => (PathBuf::new(), "demo".to_string()),
            Some(p) => {
                let name = p.file_name().map_or_else(
                    || p.to_string_lossy().into_owned(),
                    |n| n.to_string_lossy().into_owned(),
                );
                let stem = name.strip_suffix(".json").unwrap_or(&name).to_string();
                (p.parent().map(Path::to_path_buf).unwrap_or_default(), stem)
            }
        };
        Self {
            dir,
            stem,
            state: false,
        }
    }

    /// In `state_dir`, named after the scene's absolute path (its directory's symlinks
    /// resolved) without `.json`; the demo's is the working directory's `demo`.
    fn in_state_dir(scene: Option<&Path>, state_dir: &Path) -> Self {
        let beside = Self::beside(scene);
        let dir = if beside.dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &beside.dir
        };
        let dir = std::fs::canonicalize(dir)
            .or_else(|_| std::path::absolute(dir))
            .unwrap_or_else(|_| dir.to_path_buf());
        Self {
            dir: state_dir.to_path_buf(),
            stem: escape_path(&dir.join(&beside.stem)),
            state: true,
        }
    }

    fn current(&self) -> PathBuf {
        self.dir.join(format!("{}.autosave.json", self.stem))
    }

    fn aside(&self, stamp: &str, n: u32) -> PathBuf {
        let n = if n == 0 {
            String::new()
        } else {
            format!(".{n}")
        };
        self.dir
            .join(format!("{}.autosave.{stamp}{n}.json", self.stem))
    }

    /// Earlier sessions' autosaves, oldest first.
    fn asides(&self) -> Vec<PathBuf> {
        let listed = if self.dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &self.dir
        };
        let Ok(entries) = std::fs::read_dir(listed) else {
            return Vec::new();
        };
        let prefix = format!("{}.autosave.", self.stem);
        let mut found: Vec<((String, u32), PathBuf)> = entries
            .flatten()
            .filter_map(|e| {
                let name = e.file_name().into_string().ok()?;
                let key = parse_aside(name.strip_prefix(&prefix)?.strip_suffix(".json")?)?;
                let path = self.dir.join(&name);
                is_regular_file(&path).then_some((key, path))
            })
            .collect();
        found.sort();
        found.into_iter().map(|(_, p)| p).collect()
    }

    /// Every autosave here, oldest first: one kept by viewers before timestamped names
    /// (`STEM.autosave.previous.json`), earlier sessions', then the current one.
    fn waiting(&self) -> Vec<PathBuf> {
        let legacy = self
            .dir
            .join(format!("{}.autosave.previous.json", self.stem));
        let mut all: Vec<PathBuf> = std::iter::once(legacy)
            .filter(|p| is_regular_file(p))
            .chain(self.asides())
            .collect();
        let current = self.current();
        if is_regular_file(&current) {
            all.push(current);
        }
        all
    }
}

/// Where one scene's autosaves live: beside the scene, then the state directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Places {
    scene: Option<PathBuf>,
    list: Vec<Place>,
}

impl Places {
    /// The places of `scene` (`None`: the demo); `state_dir` from [`state_dir`], `None` for
    /// none.
    #[must_use]
    pub fn new(scene: Option<&Path>, state_dir: Option<&Path>) -> Self {
        let mut list = vec![Place::beside(scene)];
        list.extend(state_dir.map(|d| Place::in_state_dir(scene, d)));
        Self {
            scene: scene.map(Path::to_path_buf),
            list,
        }
    }

    /// The current autosave beside the scene (`NAME.autosave.json`).
    #[must_use]
    pub fn beside(&self) -> PathBuf {
        self.list[0].current()
    }

    /// The current autosave in the state directory, if there is one.
    #[must_use]
    pub fn in_state_dir(&self) -> Option<PathBuf> {
        self.list.get(1).map(Place::current)
    }

    /// The scene as the user named it, or "the demo".
    #[must_use]
    pub fn scene_name(&self) -> String {
        self.scene
            .as_ref()
            .map_or("the demo".into(), |p| p.display().to_string())
    }

    /// Every autosave of the scene in both places, newest (last modified) first. Within a
    /// place, equal times (coarse file system clocks) keep the order of the names.
    #[must_use]
    pub fn waiting(&self) -> Vec<PathBuf> {
        let mut all: Vec<(SystemTime, usize, PathBuf)> = self
            .list
            .iter()
            .flat_map(|place| place.waiting().into_iter().enumerate())
            .filter_map(|(i, p)| Some((modified(&p)?, i, p)))
            .collect();
        all.sort_by(|a, b| b.cmp(a));
        all.into_iter().map(|(.., p)| p).collect()
    }

    /// The waiting autosave that `file` names (any spelling of its path).
    #[must_use]
    pub fn find(&self, file: &Path) -> Option<PathBuf> {
        let want = std::fs::canonicalize(file).ok()?;
        self.waiting()
            .into_iter()
            .find(|p| std::fs::canonicalize(p).is_ok_and(|c| c == want))
    }

    /// The command that opens the autosave `file`: `--recover` for the newest, else
    /// `--recover=FILE`.
    #[must_use]
    pub fn recover_command(&self, file: &Path) -> String {
        let mut cmd = "prespline view".to_string();
        if let Some(scene) = &self.scene {
            cmd = format!("{cmd} {}", shell_word(&scene.to_string_lossy()));
        }
        cmd.push_str(" --recover");
        if self.waiting().first().map(PathBuf::as_path) != Some(file) {
            cmd = format!("{cmd}={}", shell_word(&file.to_string_lossy()));
        }
        cmd
    }

    /// The start-up note: how many autosaves are waiting (besides `recovered`, the one this
    /// session opened), which, and how to open them. `None` when there are none.
    #[must_use]
    pub fn waiting_note(&self, recovered: Option<&Path>) -> Option<String> {
        let waiting: Vec<PathBuf> = self
            .waiting()
            .into_iter()
            .filter(|p| Some(p.as_path()) != recovered)
            .collect();
        let newest = waiting.first()?;
        let n = waiting.len();
        let mut list: Vec<String> = waiting
            .iter()
            .take(3)
            .map(|p| p.display().to_string())
            .collect();
        if n > 3 {
            list.push(format!("and {} more", n - 3));
        }
        let (s, list) = (if n == 1 { "" } else { "s" }, list.join(", "));
        let scene = self.scene_name();
        Some(match recovered {
            None => format!(
                "note: {n} autosave{s} of {scene} with unsaved edits waiting, newest first: {list} (`{}` opens the newest, `--recover=FILE` another)",
                self.recover_command(newest)
            ),
            Some(_) => format!(
                "note: {n} more autosave{s} of {scene} waiting, newest first: {list} (`--recover=FILE` opens one)"
            ),
        })
    }
}

/// Where the unsaved edits went at the end of a session.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Kept {
    pub path: PathBuf,
    /// The command that opens them again.
    pub command: String,
}

impl std::fmt::Display for Kept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Both carry the scene's file name, which may hold control characters: escaped, so
        // the line stays one line and nothing reaches the terminal as a command.
        write!(
            f,
            "unsaved edits kept in {} (`{}` opens them)",
            crate::scene::escape_controls(&self.path.display().to_string()),
            crate::scene::escape_controls(&self.command)
        )
    }
}

/// Unsaved edits that no autosave could take on the way out.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unsaved edits of {scene} lost: {revisions} revision(s) could not be autosaved ({tried}){}",
    older.as_ref().map_or(String::new(), |p| format!("; an older state is in {}", p.display()))
)]
pub struct Lost {
    pub scene: String,
    /// Revisions (frames that changed the model) since the last save or autosave.
    pub revisions: u64,
    /// Why each place refused.
    pub tried: String,
    /// An autosave of this session that holds an earlier revision.
    pub older: Option<PathBuf>,
}

/// Autosave bookkeeping of one session: edits are counted as revisions; the scene file holds
/// revision `saved`, the file `held` revision `written`.
#[derive(Debug, Clone)]
pub struct Autosave {
    places: Places,
    /// The place tried first: the last that took a write.
    active: usize,
    revision: u64,
    saved: u64,
    written: u64,
    /// The file holding revision `written` while that is not `saved`.
    held: Option<PathBuf>,
    /// The file this session wrote last, as it was then: it may replace that one, no other.
    own: Option<(PathBuf, FileId)>,
    /// The autosave this session opened (`--recover`); the first write supersedes it.
    recovered_from: Option<PathBuf>,
    /// When the oldest edit not yet in the autosave file was applied.
    pending_since: Option<Instant>,
    /// Writes in a row that failed everywhere, and when to try again.
    failures: u32,
    retry_at: Option<Instant>,
    /// Why each place refused the last write that failed.
    refused: Vec<String>,
    notes: Vec<String>,
}

impl Autosave {
    /// Autosave for a session that opened the saved scene.
    #[must_use]
    pub fn new(places: Places) -> Self {
        Self {
            places,
            active: 0,
            revision: 0,
            saved: 0,
            written: 0,
            held: None,
            own: None,
            recovered_from: None,
            pending_since: None,
            failures: 0,
            retry_at: None,
            refused: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// A session that opened the autosave `from` (one of `places.waiting()`): unsaved from
    /// the start, and `from` holds it until this session writes its own or saves.
    #[must_use]
    pub fn recovered(places: Places, from: PathBuf) -> Self {
        Self {
            revision: 1,
            written: 1,
            held: Some(from.clone()),
            recovered_from: Some(from),
            ..Self::new(places)
        }
    }

    #[must_use]
    pub fn places(&self) -> &Places {
        &self.places
    }

    /// Whether the model differs from the last save (or what was opened).
    #[must_use]
    pub fn unsaved(&self) -> bool {
        self.revision != self.saved
    }

    /// Writes in a row that failed everywhere (0 once one succeeds).
    #[must_use]
    pub fn failures(&self) -> u32 {
        self.failures
    }

    /// Queues a note for the user (the status line and stderr).
    pub fn notify(&mut self, note: String) {
        self.notes.push(note);
    }

    /// Notes for the user since the last call: where the autosave went, what was moved aside
    /// or dropped, failures and recovery from them.
    pub fn take_notes(&mut self) -> Vec<String> {
        std::mem::take(&mut self.notes)
    }

    /// Records that edits were applied at `now`.
    pub fn edited(&mut self, now: Instant) {
        self.revision += 1;
        self.pending_since.get_or_insert(now);
    }

    fn behind(&self) -> bool {
        self.unsaved() && self.written != self.revision
    }

    /// When the autosave must be written: [`AUTOSAVE_DELAY`] after the oldest edit it lacks,
    /// and not before the retry after a failure.
    #[must_use]
    pub fn deadline(&self) -> Option<Instant> {
        let due = self
            .pending_since
            .filter(|_| self.behind())
            .map(|t| t + AUTOSAVE_DELAY)?;
        Some(self.retry_at.map_or(due, |r| r.max(due)))
    }

    /// Writes `scene` when the file lacks some edits; returns whether it wrote. A failure
    /// everywhere schedules the next try ([`Autosave::deadline`]) `RETRY_FIRST` × 2^k later.
    pub fn write(&mut self, scene: &Scene, now: Instant) -> bool {
        if !self.behind() {
            self.pending_since = None;
            return false;
        }
        match self.try_write(scene) {
            Ok((place, refused)) => {
                self.wrote(place, &refused);
                true
            }
            Err(refused) => {
                self.failures += 1;
                let wait = RETRY_FIRST
                    .saturating_mul(1 << (self.failures - 1).min(16))
                    .min(RETRY_MAX);
                self.retry_at = Some(now + wait);
                if self.failures == 1 {
                    self.notes.push(format!(
                        "autosave failed ({}); retrying in {} s, then at doubling intervals up to {} s; the edits stay in memory",
                        refused.join("; "),
                        wait.as_secs(),
                        RETRY_MAX.as_secs()
                    ));
                }
                self.refused = refused;
                false
            }
        }
    }

    /// The way out: writes what the file lacks (whatever the retry schedule) and says where
    /// the unsaved edits are, or what was lost.
    pub fn finish(&mut self, scene: &Scene) -> Result<Option<Kept>, Lost> {
        if self.behind() {
            match self.try_write(scene) {
                Ok((place, refused)) => self.wrote(place, &refused),
                Err(refused) => self.refused = refused,
            }
        }
        if !self.unsaved() {
            return Ok(None);
        }
        match &self.held {
            Some(path) if !self.behind() => Ok(Some(Kept {
                command: self.places.recover_command(path),
                path: path.clone(),
            })),
            held => Err(Lost {
                scene: self.places.scene_name(),
                revisions: self.revision - self.written,
                tried: self.refused.join("; "),
                older: held.clone().filter(|p| p.exists()),
            }),
        }
    }

    /// A clean save of the current revision happened: this session's autosave, and the one
    /// it recovered, are obsolete and removed.
    pub fn saved(&mut self) {
        self.saved = self.revision;
        self.written = self.revision;
        self.pending_since = None;
        self.failures = 0;
        self.retry_at = None;
        self.held = None;
        if let Some((path, id)) = self.own.take()
            && file_id(&path) == Some(id)
        {
            let _ = std::fs::remove_file(path);
        }
        if let Some(path) = self.recovered_from.take() {
            let _ = std::fs::remove_file(path);
        }
    }

    /// Tries the active place, then the others; returns the place that took the write and why
    /// those tried before it refused, or why all refused.
    fn try_write(&mut self, scene: &Scene) -> Result<(usize, Vec<String>), Vec<String>> {
        let active = self.active;
        let order: Vec<usize> = std::iter::once(active)
            .chain((0..self.places.list.len()).filter(|&i| i != active))
            .collect();
        let mut refused = Vec::new();
        for i in order {
            match self.write_at(i, scene) {
                Ok(()) => return Ok((i, refused)),
                Err(e) => refused.push(e),
            }
        }
        Err(refused)
    }

    fn write_at(&mut self, i: usize, scene: &Scene) -> Result<(), String> {
        let place = self.places.list[i].clone();
        if place.state {
            create_private_dir(&place.dir)
                .map_err(|e| format!("cannot create {}: {e}", place.dir.display()))?;
        }
        let target = place.current();
        if self.foreign(&target) {
            self.move_aside(&place)?;
        }
        crate::formats::save_json(scene, &target)?;
        let id = file_id(&target).ok_or_else(|| format!("{} vanished", target.display()))?;
        // The file this session wrote before, elsewhere, holds an older revision now.
        if let Some((old, old_id)) = self.own.replace((target.clone(), id))
            && old != target
            && file_id(&old) == Some(old_id)
        {
            let _ = std::fs::remove_file(old);
        }
        Ok(())
    }

    /// A regular file at `target` that this session neither wrote nor opened: another
    /// session's unsaved edits.
    fn foreign(&self, target: &Path) -> bool {
        let Some(id) = file_id(target) else {
            return false;
        };
        let mine = self
            .own
            .as_ref()
            .is_some_and(|(p, own)| p == target && *own == id);
        !mine && self.recovered_from.as_deref() != Some(target)
    }

    /// Renames the place's current autosave to its timestamped name, then drops the oldest
    /// beyond [`KEEP`], saying what it did.
    fn move_aside(&mut self, place: &Place) -> Result<(), String> {
        let from = place.current();
        let stamp = utc_stamp(modified(&from).unwrap_or_else(SystemTime::now));
        let to = (0..)
            .map(|n| place.aside(&stamp, n))
            .find(|p| std::fs::symlink_metadata(p).is_err())
            .unwrap_or_else(|| place.aside(&stamp, u32::MAX));
        std::fs::rename(&from, &to).map_err(|e| {
            format!(
                "cannot move the earlier autosave {} aside: {e}",
                from.display()
            )
        })?;
        self.notes.push(format!(
            "kept the earlier autosave {} as {}",
            from.display(),
            to.display()
        ));
        let asides = place.asides();
        for old in &asides[..asides.len().saturating_sub(KEEP)] {
            if std::fs::remove_file(old).is_ok() {
                self.notes.push(format!(
                    "dropped the oldest autosave {} (at most {KEEP} earlier ones are kept)",
                    old.display()
                ));
            }
        }
        Ok(())
    }

    /// The write of the current revision to place `i` succeeded, after the places before it
    /// `refused`.
    fn wrote(&mut self, i: usize, refused: &[String]) {
        let path = self.places.list[i].current();
        if i != self.active {
            self.notes.push(if i == 0 {
                format!("autosaving beside the scene again: {}", path.display())
            } else {
                format!(
                    "cannot autosave beside the scene ({}); autosaving to {} instead",
                    refused.join("; "),
                    path.display()
                )
            });
            self.active = i;
        }
        if self.failures > 0 {
            self.notes.push(format!(
                "autosave written to {} (after {} failed tries)",
                path.display(),
                self.failures
            ));
        }
        if let Some(from) = self.recovered_from.take()
            && from != path
        {
            // Its edits are in this session's autosave now, with everything done since.
            let _ = std::fs::remove_file(from);
        }
        self.failures = 0;
        self.retry_at = None;
        self.refused.clear();
        self.written = self.revision;
        self.held = Some(path);
        self.pending_since = None;
    }
}

/// Creates `dir` and its parents, private to the user where they are new (state data).
fn create_private_dir(dir: &Path) -> std::io::Result<()> {
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::DirBuilderExt;
        builder.mode(0o700);
    }
    builder.create(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exit_line_escapes_control_characters() {
        let kept = Kept {
            path: PathBuf::from("/tmp/we\u{1b}[31mird\nname.autosave.json"),
            command: "prespline view 'we\u{1b}[31mird\nname.json' --recover".into(),
        };
        let line = kept.to_string();
        assert!(!line.chars().any(char::is_control), "{line:?}");
        assert_eq!(line.matches("\\u{1b}").count(), 2, "{line}");
        assert_eq!(line.matches("\\n").count(), 2, "{line}");
        // Negative control: the raw fields do hold control characters.
        assert!(kept.command.chars().any(char::is_control));
    }
    use crate::formats::parse_scene;

    fn scene(x: f64) -> Scene {
        parse_scene(&format!(
            r#"{{"objects": [{{"name": "c", "type": "bezier_curve", "points": [[0, 0, 0], [{x}, 1, 0], [2, 0, 0]], "samples": 8}}]}}"#
        ))
        .unwrap()
    }

    /// A fresh empty directory under the system's temporary directory.
    fn scratch(label: &str) -> PathBuf {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "prespline-autosave-{label}-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

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
        let place = Place::beside(Some(Path::new("dir/teapot.json")));
        assert_eq!(
            place.aside("20250102-030405", 0),
            PathBuf::from("dir/teapot.autosave.20250102-030405.json")
        );
        assert_eq!(
            place.aside("20250102-030405", 2),
            PathBuf::from("dir/teapot.autosave.20250102-030405.2.json")
        );
    }

    #[test]
    fn state_names_escape_the_absolute_path_and_map_back() {
        assert_eq!(
            escape_path(Path::new("/home/ann/tea%pot é")),
            "%2Fhome%2Fann%2Ftea%25pot %C3%A9"
        );
        let dir = scratch("state-name");
        let scene = dir.join("teapot.json");
        let places = Places::new(Some(&scene), Some(Path::new("/state/prespline")));
        let canonical = std::fs::canonicalize(&dir).unwrap().join("teapot");
        assert_eq!(
            places.in_state_dir().unwrap(),
            Path::new("/state/prespline")
                .join(format!("{}.autosave.json", escape_path(&canonical)))
        );
        // Unescaping gives the path back (printable ASCII here).
        let name = escape_path(&canonical);
        let back = name.replace("%2F", "/").replace("%25", "%");
        assert_eq!(Path::new(&back), canonical);
        // A path too long for one file name: hashed, bounded, still distinct.
        let long = PathBuf::from(format!("/{}", "d/".repeat(150)));
        let (a, b) = (escape_path(&long.join("a")), escape_path(&long.join("b")));
        assert!(a.len() <= MAX_STEM && a != b, "{a} {b}");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn utc_stamps_match_known_dates() {
        let at = |s: u64| utc_stamp(SystemTime::UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "19700101-000000");
        assert_eq!(at(951_782_400), "20000229-000000");
        assert_eq!(at(1_700_000_000), "20231114-221320");
        assert_eq!(at(4_102_444_799), "20991231-235959");
        assert_eq!(
            parse_aside("20231114-221320"),
            Some(("20231114-221320".into(), 0))
        );
        assert_eq!(
            parse_aside("20231114-221320.12"),
            Some(("20231114-221320".into(), 12))
        );
        assert_eq!(parse_aside("20231114-22132"), None);
        assert_eq!(parse_aside("previous"), None);
        assert_eq!(parse_aside("20231114-221320.x"), None);
    }

    #[test]
    fn the_deadline_follows_the_oldest_unwritten_edit() {
        let mut a = Autosave::new(Places::new(Some(Path::new("/nonexistent/x.json")), None));
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

    /// Neither place can take the file (the scene's directory is a regular file's child, and
    /// so is the state directory): retries wait 1, 2, 4 … 30 s, one note says so, and the way
    /// out reports what was lost.
    #[test]
    fn failing_writes_back_off_and_say_so_once() {
        let dir = scratch("backoff");
        std::fs::write(dir.join("file"), "").unwrap();
        let scene_path = dir.join("file/scene.json");
        let state = dir.join("file/state");
        let mut a = Autosave::new(Places::new(Some(&scene_path), Some(&state)));
        let t0 = Instant::now();
        a.edited(t0);
        let mut now = a.deadline().unwrap();
        let mut waits = Vec::new();
        for _ in 0..8 {
            assert!(!a.write(&scene(1.0), now));
            let next = a.deadline().unwrap();
            waits.push((next - now).as_secs());
            // Asking again before the retry is due changes nothing.
            assert_eq!(a.deadline(), Some(next));
            now = next;
        }
        assert_eq!(waits, [1, 2, 4, 8, 16, 30, 30, 30]);
        assert_eq!(a.failures(), 8);
        let notes = a.take_notes();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].starts_with("autosave failed ("), "{notes:?}");
        assert!(notes[0].contains("Not a directory"), "{notes:?}");
        let lost = a.finish(&scene(1.0)).unwrap_err();
        assert_eq!(lost.revisions, 1);
        assert_eq!(lost.older, None);
        let line = lost.to_string();
        assert!(!line.contains('\n'));
        assert!(line.contains(&scene_path.display().to_string()), "{line}");
        assert!(line.contains(&state.display().to_string()), "{line}");
        assert!(a.take_notes().is_empty(), "the way out reports in one line");
        std::fs::remove_dir_all(dir).unwrap();
    }

    /// The scene's directory refuses (its autosave name is taken by a directory): the state
    /// directory takes it, said once; a later failure there falls back, and success again
    /// says so.
    #[test]
    fn the_state_directory_takes_what_the_scene_directory_refuses() {
        let dir = scratch("fallback");
        let scene_path = dir.join("scene.json");
        std::fs::create_dir(dir.join("scene.autosave.json")).unwrap();
        std::fs::write(dir.join("scene.autosave.json/x"), "").unwrap();
        let state = dir.join("state/prespline");
        let places = Places::new(Some(&scene_path), Some(&state));
        let target = places.in_state_dir().unwrap();
        let mut a = Autosave::new(places);
        let t0 = Instant::now();
        a.edited(t0);
        assert!(a.write(&scene(1.0), t0 + AUTOSAVE_DELAY));
        assert_eq!(crate::formats::read_json(&target).unwrap(), scene(1.0));
        let notes = a.take_notes();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("cannot autosave beside the scene")
                && notes[0].contains(&target.display().to_string()),
            "{notes:?}"
        );
        a.edited(t0);
        assert!(a.write(&scene(2.0), t0 + AUTOSAVE_DELAY));
        assert!(a.take_notes().is_empty(), "said once");
        assert_eq!(
            a.finish(&scene(2.0)).unwrap().unwrap().path,
            target,
            "kept in the state directory"
        );
        assert_eq!(a.places().waiting(), vec![target.clone()]);
        a.saved();
        assert!(!target.exists(), "a clean save removes it");
        std::fs::remove_dir_all(dir).unwrap();
    }

    /// Eleven sessions in a row that never recover: each earlier autosave is moved aside, the
    /// oldest beyond ten dropped with a note, none overwritten.
    #[test]
    fn earlier_autosaves_are_moved_aside_and_bounded() {
        let dir = scratch("aside");
        let scene_path = dir.join("scene.json");
        let places = Places::new(Some(&scene_path), None);
        let mut dropped = Vec::new();
        for k in 0..=KEEP + 1 {
            let mut a = Autosave::new(places.clone());
            a.edited(Instant::now());
            a.finish(&scene(k as f64)).unwrap().unwrap();
            for note in a.take_notes() {
                if note.starts_with("dropped the oldest autosave") {
                    dropped.push(note);
                } else {
                    assert!(note.starts_with("kept the earlier autosave"), "{note}");
                }
            }
        }
        let waiting = places.waiting();
        assert_eq!(waiting.len(), KEEP + 1, "{waiting:?}");
        assert_eq!(dropped.len(), 1, "{dropped:?}");
        // Newest first: this session's, then the earlier ones in order; session 0's dropped.
        let xs: Vec<f64> = waiting
            .iter()
            .map(
                |p| match &crate::formats::read_json(p).unwrap().objects[0].model {
                    crate::model::Model::Curve(c) => c.curve().points()[1].x,
                    _ => unreachable!(),
                },
            )
            .collect();
        let expected: Vec<f64> = (1..=KEEP + 1).rev().map(|k| k as f64).collect();
        assert_eq!(xs, expected);

        // One kept by viewers before timestamped names waits too, and is never dropped.
        let legacy = dir.join("scene.autosave.previous.json");
        crate::formats::save_json(&scene(0.5), &legacy).unwrap();
        let mut a = Autosave::new(places.clone());
        a.edited(Instant::now());
        a.finish(&scene(9.0)).unwrap().unwrap();
        assert!(legacy.exists());
        let waiting = places.waiting();
        assert_eq!(waiting.len(), KEEP + 2, "{waiting:?}");
        assert_eq!(places.find(&legacy), Some(legacy));
        std::fs::remove_dir_all(dir).unwrap();
    }
}
