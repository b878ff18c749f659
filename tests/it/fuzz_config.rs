//! Bad input, fuzzed: random edits of valid experiment and scene files, of every kind, never
//! panic the loader, and every rejection names the file (and, when the text parses as TOML, a
//! line).

use penumbra::experiment::sweep::Spec;
use proptest::prelude::*;
use std::path::PathBuf;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// Characters that matter to TOML, plus a few digits and letters.
const ALPHABET: &[u8] = b"[]{}=\"',.-+#\n 0123456789eE_abcxyz\t\\";

fn mutate(text: &str, edits: &[(usize, u8, u8)]) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    for &(pos, op, ch) in edits {
        let at = pos % (bytes.len() + 1);
        let c = ALPHABET[ch as usize % ALPHABET.len()];
        match op % 3 {
            0 => bytes.insert(at, c),
            1 if at < bytes.len() => {
                bytes.remove(at);
            }
            _ if at < bytes.len() => bytes[at] = c,
            _ => {}
        }
    }
    bytes
}

fn load_edited(experiment: &[u8], scene: &[u8]) -> Result<Spec, String> {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("scenes")).unwrap();
    std::fs::write(dir.path().join("scenes/sphere.toml"), scene).unwrap();
    let exp = dir.path().join("exp.toml");
    std::fs::write(&exp, experiment).unwrap();
    Spec::load(&exp).map_err(|e| {
        let text = e.to_string();
        assert!(
            text.contains("exp.toml") || text.contains("sphere.toml"),
            "error names no file: {text}"
        );
        text
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn edited_experiment_files_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)) {
        let exp = std::fs::read_to_string(repo("experiments/ci.toml")).unwrap();
        let scene = std::fs::read(repo("experiments/scenes/sphere.toml")).unwrap();
        let _ = load_edited(&mutate(&exp, &edits), &scene);
    }

    #[test]
    fn edited_scene_files_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)) {
        let exp = std::fs::read(repo("experiments/ci.toml")).unwrap();
        let scene = std::fs::read_to_string(repo("experiments/scenes/sphere.toml")).unwrap();
        let _ = load_edited(&exp, &mutate(&scene, &edits));
    }

    #[test]
    fn arbitrary_bytes_are_rejected_cleanly(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let scene = std::fs::read(repo("experiments/scenes/sphere.toml")).unwrap();
        prop_assert!(load_edited(&bytes, &scene).is_err());
    }
}

/// The shipped CI-sized experiment of each other kind, its relative paths made absolute.
fn kind_file(file: &str) -> String {
    std::fs::read_to_string(repo(&format!("experiments/{file}")))
        .unwrap()
        .replace("\"../assets/", &format!("\"{}/", repo("assets").display()))
        .replace("\"scenes/", &format!("\"{}/", repo("experiments/scenes").display()))
}

/// Loads `text` as an experiment of any kind through the driver's loader; an error must name
/// the experiment file with a line (`exp.toml:LINE:`), or, for a file that is no text at all,
/// the file and why, or, for a key the file lacks (no line holds it), the file and the key.
fn load_kind(text: &[u8]) {
    let dir = tempfile::tempdir().unwrap();
    let exp = dir.path().join("exp.toml");
    std::fs::write(&exp, text).unwrap();
    if let Err(e) = penumbra::experiment::load(&exp) {
        let message = e.to_string();
        let located = message
            .split("exp.toml:")
            .skip(1)
            .any(|rest| rest.starts_with(|c: char| c.is_ascii_digit()));
        let not_text = std::str::from_utf8(text).is_err() && message.contains("exp.toml");
        let missing = message.contains("exp.toml: key `") && message.contains("missing");
        assert!(
            located || not_text || missing,
            "error names no line of the file: {message}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn edited_frame_time_experiments_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)) {
        load_kind(&mutate(&kind_file("frames-ci.toml"), &edits));
    }

    #[test]
    fn edited_ambient_occlusion_experiments_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)) {
        load_kind(&mutate(&kind_file("ao-ci.toml"), &edits));
    }

    #[test]
    fn edited_frame_rate_experiments_never_panic(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6)) {
        let text = kind_file("fps.toml").replace("scenes/body.toml", "scenes/sphere-two-lights.toml");
        load_kind(&mutate(&text, &edits));
    }
}

/// Every error that comes from parsed TOML carries a position: an unknown key at any depth.
#[test]
fn unknown_keys_at_every_depth_are_located() {
    let exp = std::fs::read_to_string(repo("experiments/ci.toml")).unwrap();
    let scene = std::fs::read(repo("experiments/scenes/sphere.toml")).unwrap();
    for (anchor, extra) in [
        ("name = \"ci\"", "colour = 1"),
        ("[measure]", "zoom = 2"),
        ("[sweep]", "shuffle = true"),
        ("[timing]", "jitter = 1"),
    ] {
        let text = exp.replacen(anchor, &format!("{anchor}\n{extra}"), 1);
        let err = load_edited(text.as_bytes(), &scene).unwrap_err();
        let key = extra.split(' ').next().unwrap();
        assert!(err.contains(key) && err.contains("exp.toml:"), "{err}");
    }
}
