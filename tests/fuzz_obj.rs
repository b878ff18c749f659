//! The OBJ reader under fuzzing: random edits of a valid file and arbitrary bytes never panic,
//! and every rejection names the file and a line.

use penumbra::mesh::obj::parse;
use proptest::prelude::*;
use std::path::Path;

const VALID: &str = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\ng floor\nf 1/1/1 2/2/2 3/3/3 4/4/4\ng roof\nf -5//1 -4//1 -1//1\no tip\nf 1 2 5\n";
const ALPHABET: &[u8] = b"vfgo/#- .\n0123456789e+xyz";

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, ..ProptestConfig::default() })]

    #[test]
    fn edited_files_parse_or_fail_with_a_line(edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..8)) {
        let mut bytes = VALID.as_bytes().to_vec();
        for (pos, op, ch) in edits {
            let at = pos % (bytes.len() + 1);
            let c = ALPHABET[ch as usize % ALPHABET.len()];
            match op % 3 {
                0 => bytes.insert(at, c),
                1 if at < bytes.len() => { bytes.remove(at); }
                _ if at < bytes.len() => bytes[at] = c,
                _ => {}
            }
        }
        let text = String::from_utf8_lossy(&bytes);
        match parse(&text, Path::new("m.obj")) {
            Ok(m) => {
                prop_assert_eq!(m.triangles.len(), m.group_of.len());
                prop_assert!(m.group_of.iter().all(|&g| (g as usize) < m.groups.len()));
            }
            Err(e) => {
                let line = e.line.expect("parse errors are on a line");
                prop_assert!(line >= 1 && line <= text.lines().count());
                let prefix = format!("m.obj:{line}:");
                prop_assert!(e.to_string().starts_with(&prefix), "{}", e);
            }
        }
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,300}") {
        let _ = parse(&text, Path::new("x.obj"));
    }
}
