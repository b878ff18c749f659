//! The mesh readers (OBJ, OFF) under fuzzing: random edits of a valid file and arbitrary bytes
//! never panic, and every rejection names the file and a line of it.

use penumbra::mesh::{obj, off, MeshFile, MeshFileError};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use std::path::Path;

type Parse = fn(&str, &Path) -> Result<MeshFile, MeshFileError>;

const OBJ: &str = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\ng floor\nf 1/1/1 2/2/2 3/3/3 4/4/4\ng roof\nf -5//1 -4//1 -1//1\no tip\nf 1 2 5\n";
const OBJ_ALPHABET: &[u8] = b"vfgo/#- .\n0123456789e+xyz";
const OFF: &str = "OFF\n# a quad and two triangles\n5 3 0\n0 0 0\n1 0 0\n1 1 0 255 0 0\n0 1 0\n0.5 0.5 1\n4 0 1 2 3\n3 0 1 4\n3 0 1 4\n";
const OFF_ALPHABET: &[u8] = b"OF#- .\n0123456789e+x";

/// Applies `edits` (insert, delete or replace one byte from `alphabet`) to `valid` and checks the
/// reader either returns a consistent mesh or an error on one of the text's lines.
fn edit_and_parse(
    parse: Parse,
    name: &str,
    valid: &str,
    alphabet: &[u8],
    edits: &[(usize, u8, u8)],
) -> Result<(), TestCaseError> {
    let mut bytes = valid.as_bytes().to_vec();
    for &(pos, op, ch) in edits {
        let at = pos % (bytes.len() + 1);
        let c = alphabet[ch as usize % alphabet.len()];
        match op % 3 {
            0 => bytes.insert(at, c),
            1 if at < bytes.len() => {
                bytes.remove(at);
            }
            _ if at < bytes.len() => bytes[at] = c,
            _ => {}
        }
    }
    let text = String::from_utf8_lossy(&bytes);
    match parse(&text, Path::new(name)) {
        Ok(m) => {
            prop_assert_eq!(m.triangles.len(), m.group_of.len());
            prop_assert!(m.group_of.iter().all(|&g| (g as usize) < m.groups.len()));
        }
        Err(e) => {
            let line = e.line.expect("parse errors are on a line");
            prop_assert!(line >= 1 && line <= text.lines().count().max(1));
            let prefix = format!("{name}:{line}:");
            prop_assert!(e.to_string().starts_with(&prefix), "{}", e);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, ..ProptestConfig::default() })]

    #[test]
    fn edited_obj_files_parse_or_fail_with_a_line(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..8)) {
        edit_and_parse(obj::parse, "m.obj", OBJ, OBJ_ALPHABET, &edits)?;
    }

    #[test]
    fn edited_off_files_parse_or_fail_with_a_line(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..8)) {
        edit_and_parse(off::parse, "m.off", OFF, OFF_ALPHABET, &edits)?;
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,300}") {
        let _ = obj::parse(&text, Path::new("x.obj"));
        let _ = off::parse(&text, Path::new("x.off"));
    }
}

#[test]
fn valid_files_give_the_same_triangles() {
    let a = obj::parse(OBJ, Path::new("m.obj")).unwrap();
    let b = off::parse(OFF, Path::new("m.off")).unwrap();
    assert_eq!(a.triangles, b.triangles);
}
