//! The viewer's autosave under X (Xvfb in `make test`) with lavapipe and the validation layer
//! required, where it is hard: a scene directory that cannot take the autosave (a read-only
//! bind mount in a private mount namespace, where `unshare -m` is permitted, and an autosave
//! name taken by a directory, which needs no privileges), a state directory that cannot either,
//! and sessions that never recover their predecessors' edits. Every run has a time limit and a
//! scratch directory of its own, which is also its working directory and (`state/`) its
//! XDG_STATE_HOME. Skipped (with a note) when DISPLAY is not set or the mount namespace is not
//! permitted, except under `make test` and CI, where that fails.

mod common;

use common::Scratch;
use prespline::model::Model;
use prespline::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

/// Longest a scripted viewer run may take (a few seconds normally).
const LIMIT: Duration = Duration::from_secs(180);

/// Mounts "$1" read-only on itself (in the private mount namespace `unshare -m` made), then
/// runs the rest of the arguments.
const MOUNT_READ_ONLY: &str =
    r#"mount --bind "$1" "$1" && mount -o remount,bind,ro "$1" && shift && exec "$@""#;

/// `prespline` on lavapipe with the validation layer required, in `dir`, with `dir/state` as
/// XDG_STATE_HOME (never the user's own).
fn prespline(dir: &Scratch) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_prespline"));
    configure(&mut c, dir);
    c
}

fn configure(c: &mut Command, dir: &Scratch) {
    let icd = prespline::gpu::LAVAPIPE_ICD;
    c.env("VK_DRIVER_FILES", icd)
        .env("VK_ICD_FILENAMES", icd)
        .env("PRESPLINE_VALIDATION", "required")
        .env("XDG_STATE_HOME", dir.join("state"))
        .current_dir(dir.path());
}

fn run(command: &mut Command) -> (Output, String) {
    let out = common::output_with_timeout(command, LIMIT);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, err)
}

/// The lines of `err` that mention `what`.
fn lines_with<'a>(err: &'a str, what: &str) -> Vec<&'a str> {
    err.lines().filter(|l| l.contains(what)).collect()
}

/// examples/bspline_surface.json copied to `dir/NAME`.
fn surface_scene(dir: &Path, name: &str) -> PathBuf {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bspline_surface.json");
    let scene = dir.join(name);
    std::fs::create_dir_all(scene.parent().unwrap()).unwrap();
    std::fs::copy(example, &scene).unwrap();
    scene
}

/// z of the surface "bumps"' control point (3, 3), the one the scripts move.
fn bump_z(scene: &Scene) -> f64 {
    let i = scene.find("bumps").expect("the example has bumps");
    match &scene.objects[i].model {
        Model::Surface(s) => s.surface().point(3, 3).z,
        _ => panic!("bumps is a surface"),
    }
}

fn load_z(path: &Path) -> f64 {
    bump_z(
        &prespline::formats::read_json(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    )
}

/// Selects bumps' point (3, 3), moves it by exactly `dz` along z (G Z, typed), then `end`
/// (script events after frame 9).
fn move_script(dz: &str, end: &str) -> String {
    format!(
        r#"[{{"frame": 3, "move_to": {{"object": "bumps", "point": [3, 3]}}}},
            {{"frame": 4, "press": "left"}}, {{"frame": 5, "release": "left"}},
            {{"frame": 6, "key": "g"}}, {{"frame": 7, "key": "z"}}, {{"frame": 8, "type": "{dz}"}},
            {{"frame": 9, "key": "enter"}}, {end}]"#
    )
}

const QUIT_SOON: &str = r#"{"frame": 11, "quit": true}"#;
const SAVE_AND_QUIT: &str =
    r#"[{"frame": 2, "key": "s", "ctrl": true}, {"frame": 4, "quit": true}]"#;

/// How a test makes the scene's directory refuse the autosave.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Refusal {
    /// `NAME.autosave.json` is taken by a directory: renaming the written file onto it fails
    /// (EISDIR). Needs no privileges.
    Occupied,
    /// The directory is bind-mounted read-only onto itself in a private mount namespace
    /// (`unshare -m`, or `unshare -rm` for a user without privileges): writes fail with EROFS,
    /// as on a read-only file system. Root cannot write there either, unlike `chmod`.
    ReadOnlyMount(&'static str),
}

/// The ways available here: `Occupied` always; the read-only mount where this process may
/// make mount namespaces (else skipped with a note, or a failure under PRESPLINE_STRICT / CI).
fn refusals(scratch: &Scratch) -> Vec<Refusal> {
    let probe_dir = scratch.join("probe");
    std::fs::create_dir_all(&probe_dir).unwrap();
    let works = |flags: &str| {
        Command::new("unshare")
            .args([flags, "sh", "-c"])
            .arg(format!(
                r#"{} && ! touch "$1/written" 2>/dev/null"#,
                MOUNT_READ_ONLY.split(" && shift").next().unwrap()
            ))
            .arg("sh")
            .arg(&probe_dir)
            .output()
            .is_ok_and(|o| o.status.success())
            && !probe_dir.join("written").exists()
    };
    let mount = ["-m", "-rm"].into_iter().find(|f| works(f));
    let mut ways = vec![Refusal::Occupied];
    if common::precondition(
        mount.is_some(),
        "cannot make a read-only bind mount in a private mount namespace (`unshare -m` / `unshare -rm` not permitted here)",
    ) {
        ways.push(Refusal::ReadOnlyMount(mount.unwrap()));
    }
    ways
}

/// The viewer on `scene` in `scratch`, its directory refusing the autosave as `refusal` says,
/// with `state` as XDG_STATE_HOME.
fn refused_viewer(
    scratch: &Scratch,
    refusal: Refusal,
    scene: &Path,
    state: &Path,
    script: &Path,
) -> Command {
    let mut c = match refusal {
        Refusal::Occupied => {
            std::fs::create_dir_all(
                prespline::view::autosave::autosave_path(Some(scene)).join("occupied"),
            )
            .unwrap();
            Command::new(env!("CARGO_BIN_EXE_prespline"))
        }
        Refusal::ReadOnlyMount(flags) => {
            let mut c = Command::new("unshare");
            c.args([flags, "sh", "-c", MOUNT_READ_ONLY, "sh"])
                .arg(scene.parent().unwrap())
                .arg(env!("CARGO_BIN_EXE_prespline"));
            c
        }
    };
    configure(&mut c, scratch);
    c.env("XDG_STATE_HOME", state)
        .arg("view")
        .arg(scene)
        .args(["--size", "320x240", "--script"])
        .arg(script);
    c
}

/// Where the state directory keeps the scene's autosave, by the documented naming: the
/// absolute path (directory symlinks resolved) without `.json`, `%` → `%25`, `/` → `%2F`.
fn state_autosave(state: &Path, scene: &Path) -> PathBuf {
    let dir = std::fs::canonicalize(scene.parent().unwrap()).unwrap();
    let stem = dir.join(scene.file_stem().unwrap());
    let name = stem
        .to_str()
        .unwrap()
        .replace('%', "%25")
        .replace('/', "%2F");
    state
        .join("prespline")
        .join(format!("{name}.autosave.json"))
}

/// Item 4: when the scene's directory cannot take the autosave, the state directory does, the
/// viewer says so once and names it on the way out (with the real `--recover` command), and
/// `--recover` finds it there; a clean save then removes it.
#[test]
fn a_refused_autosave_goes_to_the_state_directory_and_is_recovered_from_there() {
    if !common::display() {
        return;
    }
    let probe = Scratch::new("view-autosave");
    for refusal in refusals(&probe) {
        let dir = Scratch::new("view-autosave");
        let scene = surface_scene(dir.path(), "scenes/surface.json");
        let z0 = load_z(&scene);
        let state = dir.join("state");
        let expected = state_autosave(&state, &scene);
        let script = dir.file("move.json", &move_script("0.5", QUIT_SOON));
        let (out, err) = run(&mut refused_viewer(&dir, refusal, &scene, &state, &script));
        assert!(out.status.success(), "{refusal:?}: {err}");
        let said = lines_with(&err, "cannot autosave beside the scene");
        assert_eq!(said.len(), 1, "{refusal:?}: said once: {err}");
        assert!(
            said[0].contains(&expected.display().to_string()),
            "{refusal:?}: {err}"
        );
        assert!(
            lines_with(&err, "autosave failed").is_empty(),
            "{refusal:?}: {err}"
        );
        assert!(
            err.contains(&format!(
                "unsaved edits kept in {} (`prespline view {} --recover` opens them)",
                expected.display(),
                scene.display()
            )),
            "{refusal:?}: {err}"
        );
        assert_eq!(load_z(&expected), z0 + 0.5, "{refusal:?}: the edit is kept");
        assert_eq!(load_z(&scene), z0, "{refusal:?}: the scene is untouched");

        // Writable again (outside the namespace; the occupying directory stays): --recover
        // finds the autosave in the state directory, Ctrl+S saves it and removes it.
        let (out, err) = run(prespline(&dir)
            .env("XDG_STATE_HOME", &state)
            .arg("view")
            .arg(&scene)
            .arg("--recover")
            .args(["--size", "320x240", "--script"])
            .arg(dir.file("save.json", SAVE_AND_QUIT)));
        assert!(out.status.success(), "{refusal:?}: {err}");
        assert_eq!(load_z(&scene), z0 + 0.5, "{refusal:?}: recovered and saved");
        assert!(
            !expected.exists(),
            "{refusal:?}: a clean save removes it: {err}"
        );
    }
}

/// Item 4: when neither the scene's directory nor the state directory can take the autosave,
/// the viewer does not spin: one note when the failures begin, write attempts on the backed-off
/// schedule (counted with strace where it is installed), and the way out fails with one line
/// naming the scene, the lost revisions and both places tried.
#[test]
fn nowhere_to_autosave_backs_off_and_the_exit_names_the_loss() {
    if !common::display() {
        return;
    }
    let probe = Scratch::new("view-autosave");
    for refusal in refusals(&probe) {
        let dir = Scratch::new("view-autosave");
        let scene = surface_scene(dir.path(), "scenes/surface.json");
        let z0 = load_z(&scene);
        let state = match refusal {
            // Inside the read-only mount.
            Refusal::ReadOnlyMount(_) => dir.join("scenes/state"),
            // Below a regular file.
            Refusal::Occupied => {
                dir.file("file", "");
                dir.join("file/state")
            }
        };
        // The edit at frame 9, then six seconds of idling before the quit: retries are due
        // 1 s, 2 s and 4 s after the first failure, at most.
        let script = dir.file(
            "move.json",
            &move_script("0.5", r#"{"t": 6.0, "quit": true}"#),
        );
        let mut viewer = refused_viewer(&dir, refusal, &scene, &state, &script);
        let trace = dir.join("strace.log");
        let strace = refusal == Refusal::Occupied && has_strace();
        if strace {
            viewer = traced(&viewer, &trace);
        }
        let (out, err) = run(&mut viewer);
        assert!(
            !out.status.success(),
            "{refusal:?}: lost edits must fail the run: {err}"
        );
        let autosave_lines = lines_with(&err, "autosave");
        assert_eq!(
            autosave_lines.len(),
            2,
            "{refusal:?}: one note and one error line, no storm: {} lines, first {:?}",
            autosave_lines.len(),
            &autosave_lines[..autosave_lines.len().min(3)]
        );
        assert!(
            autosave_lines[0].starts_with("autosave failed (")
                && autosave_lines[0].contains("retrying in 1 s"),
            "{refusal:?}: {err}"
        );
        let last = err.lines().last().unwrap();
        let prefix = format!("error: unsaved edits of {} lost: ", scene.display());
        assert!(last.starts_with(&prefix), "{refusal:?}: {err}");
        let revisions: u64 = last[prefix.len()..]
            .split(' ')
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{refusal:?}: no revision count: {last}"));
        assert!(revisions >= 1, "{last}");
        let beside = prespline::view::autosave::autosave_path(Some(&scene));
        assert!(
            last.contains(&beside.display().to_string())
                && last.contains(&state.display().to_string()),
            "{refusal:?}: both places named: {last}"
        );
        if matches!(refusal, Refusal::ReadOnlyMount(_)) {
            assert!(last.contains("Read-only file system"), "{last}");
        }
        assert_eq!(load_z(&scene), z0);
        if strace {
            // Each try writes a temporary file beside the scene first (then the rename onto
            // the occupying directory fails): tries on the timer (1 s, then 2 s and 4 s later,
            // within six seconds) and one on the way out.
            let log = std::fs::read_to_string(&trace).unwrap();
            let tries = log
                .lines()
                .filter(|l| l.contains(".surface.autosave.json.tmp-") && l.contains("O_CREAT"))
                .count();
            assert!(
                (2..=4).contains(&tries),
                "{tries} write attempts in six seconds (1 + 3 on the timer at most):\n{log}"
            );
        }
    }
}

fn has_strace() -> bool {
    common::precondition(
        Command::new("strace")
            .arg("-V")
            .output()
            .is_ok_and(|o| o.status.success()),
        "strace is not installed (scripts/install-deps.sh installs it)",
    )
}

/// `command` under `strace -f`, tracing openat into `log` (seccomp-filtered: other system
/// calls run at full speed).
fn traced(command: &Command, log: &Path) -> Command {
    let mut c = Command::new("strace");
    c.args(["-f", "--seccomp-bpf", "-qq", "-e", "trace=openat", "-o"])
        .arg(log)
        .arg(command.get_program())
        .args(command.get_args());
    for (k, v) in command.get_envs() {
        match v {
            Some(v) => c.env(k, v),
            None => c.env_remove(k),
        };
    }
    if let Some(d) = command.get_current_dir() {
        c.current_dir(d);
    }
    c
}

/// Item 5: three sessions in a row that never recover each keep their edits (the earlier ones
/// moved aside to timestamped names, said on stderr), a fourth is told three are waiting,
/// `--recover` opens the newest and `--recover=FILE` a named one; recovering and saving removes
/// it, recovering and editing replaces it with the new session's autosave.
#[test]
fn every_sessions_autosave_is_kept_and_any_can_be_recovered() {
    if !common::display() {
        return;
    }
    let dir = Scratch::new("view-autosave");
    let scene = surface_scene(dir.path(), "surface.json");
    let z0 = load_z(&scene);
    let current = dir.join("surface.autosave.json");
    let view = |extra: &[&str], script: &str, name: &str| {
        let (out, err) = run(prespline(&dir)
            .arg("view")
            .arg(&scene)
            .args(extra)
            .args(["--size", "320x240", "--script"])
            .arg(dir.file(name, script)));
        assert!(out.status.success(), "{err}");
        err
    };
    for k in 1..=3 {
        let err = view(
            &[],
            &move_script(&k.to_string(), QUIT_SOON),
            &format!("s{k}.json"),
        );
        let moved = lines_with(&err, "kept the earlier autosave");
        assert_eq!(moved.len(), usize::from(k > 1), "session {k}: {err}");
        assert!(
            err.contains(&format!("unsaved edits kept in {}", current.display())),
            "session {k}: {err}"
        );
    }
    // The current one and two timestamped ones, each session's own edit.
    let asides: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_str().unwrap();
            name.strip_prefix("surface.autosave.")
                .and_then(|r| r.strip_suffix(".json"))
                .is_some_and(|stamp| {
                    let (t, n) = stamp.split_once('.').unwrap_or((stamp, "1"));
                    t.len() == 15
                        && t.as_bytes()[8] == b'-'
                        && t.bytes().filter(u8::is_ascii_digit).count() == 14
                        && n.bytes().all(|b| b.is_ascii_digit())
                })
        })
        .collect();
    assert_eq!(asides.len(), 2, "{asides:?}");
    assert_eq!(load_z(&current), z0 + 3.0);
    let with_z = |z: f64| {
        asides
            .iter()
            .find(|p| load_z(p) == z)
            .unwrap_or_else(|| panic!("no autosave with z = {z}: {asides:?}"))
    };
    let (first, second) = (with_z(z0 + 1.0), with_z(z0 + 2.0));

    // A session that only looks is told how many wait, in one line.
    let err = view(&[], r#"[{"frame": 2, "quit": true}]"#, "look.json");
    let note = lines_with(&err, "--recover");
    assert_eq!(note.len(), 1, "{err}");
    assert!(
        note[0].starts_with(&format!("note: 3 autosaves of {} ", scene.display()))
            && note[0].contains(&current.display().to_string())
            && note[0].contains(&first.display().to_string()),
        "{err}"
    );
    assert!(
        !err.contains("kept the earlier"),
        "looking moves nothing: {err}"
    );

    // --recover opens the newest; saving it removes it, the others stay.
    let out3 = dir.join("out3.json");
    let err = view(
        &["--recover", "--save-as", out3.to_str().unwrap()],
        SAVE_AND_QUIT,
        "r3.json",
    );
    assert_eq!(load_z(&out3), z0 + 3.0, "{err}");
    assert!(!current.exists(), "{err}");
    assert!(
        lines_with(&err, "2 more autosaves").len() == 1,
        "the others are counted: {err}"
    );

    // --recover=FILE opens the one named.
    let out1 = dir.join("out1.json");
    let err = view(
        &[
            &format!("--recover={}", first.display()),
            "--save-as",
            out1.to_str().unwrap(),
        ],
        SAVE_AND_QUIT,
        "r1.json",
    );
    assert_eq!(load_z(&out1), z0 + 1.0, "{err}");
    assert!(!first.exists(), "{err}");

    // Recovering and editing without saving: the new session's autosave replaces it.
    let err = view(
        &[&format!("--recover={}", second.display())],
        &move_script("10", QUIT_SOON),
        "r2.json",
    );
    assert!(!second.exists(), "superseded: {err}");
    assert_eq!(load_z(&current), z0 + 2.0 + 10.0, "{err}");
    assert!(
        err.contains(&format!(
            "unsaved edits kept in {} (`prespline view {} --recover` opens them)",
            current.display(),
            scene.display()
        )),
        "{err}"
    );
    assert_eq!(load_z(&scene), z0, "the scene file was never written");

    // A file that is not one of the scene's autosaves is refused in one line.
    let (out, err) = run(prespline(&dir)
        .arg("view")
        .arg(&scene)
        .arg(format!("--recover={}", scene.display())));
    assert!(!out.status.success());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("not an autosave of"), "{err}");
}
