//! Reading TOML files so that every error names the file, the line and the key.
//!
//! Parsing and unknown/missing keys are caught by serde (`deny_unknown_fields`); checks on values
//! (a negative radius, zero samples) run afterwards on typed data and report a key path, which
//! [`Source::locate`] turns back into a line and column using toml's spanned document.

use serde::de::DeserializeOwned;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};

/// Largest image side a file may ask for.
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most pixels a file may ask for in one image (a frame's buffers stay within a few GB).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 25;

/// Largest experiment or scene file read.
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// An error in a configuration file, located as precisely as the document allows.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigError {
    /// The file the error is in.
    pub file: PathBuf,
    /// 1-based line and column, when the file could be read and the key found.
    pub position: Option<(usize, usize)>,
    /// Dotted key path, e.g. `lights[0].radius`; empty when the error is about the whole file.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some((line, col)) = self.position {
            write!(f, ":{line}:{col}")?;
        }
        if !self.key.is_empty() {
            write!(f, ": key `{}`", self.key)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for ConfigError {}

/// A key path segment: a table key or an array index.
#[derive(Debug, Clone, PartialEq)]
pub enum Seg {
    /// A table key.
    Key(String),
    /// An array index.
    Index(usize),
}

/// Formats a key path as `a.b[2].c`.
pub fn format_path(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Builds a key path from `"lights"`, `0usize`, `"radius"`-style pieces.
#[macro_export]
macro_rules! key_path {
    ($($seg:expr),* $(,)?) => { [$($crate::config::IntoSeg::into_seg($seg)),*] };
}

/// Conversion used by [`key_path!`].
pub trait IntoSeg {
    /// The segment.
    fn into_seg(self) -> Seg;
}
impl IntoSeg for &str {
    fn into_seg(self) -> Seg {
        Seg::Key(self.to_string())
    }
}
impl IntoSeg for usize {
    fn into_seg(self) -> Seg {
        Seg::Index(self)
    }
}

/// The text of one configuration file, kept to locate errors found after deserialising.
#[derive(Debug, Clone)]
pub struct Source {
    /// Where the text came from.
    pub path: PathBuf,
    /// The text.
    pub text: String,
}

impl Source {
    /// Reads a file; a missing, unreadable, non-regular or oversized file (beyond
    /// [`MAX_CONFIG_BYTES`]: `/dev/zero` is refused, not read until memory runs out) is a
    /// [`ConfigError`] naming it.
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let fail = |message: String| ConfigError {
            file: path.to_path_buf(),
            position: None,
            key: String::new(),
            message,
        };
        let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
        if !meta.is_file() {
            return Err(fail("not a regular file".into()));
        }
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(
            &mut std::io::Read::take(
                std::fs::File::open(path).map_err(|e| fail(format!("cannot read: {e}")))?,
                MAX_CONFIG_BYTES + 1,
            ),
            &mut bytes,
        )
        .map_err(|e| fail(format!("cannot read: {e}")))?;
        if bytes.len() as u64 > MAX_CONFIG_BYTES {
            return Err(fail(format!(
                "larger than {MAX_CONFIG_BYTES} bytes: not a configuration file"
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| fail(format!("not UTF-8 text: {e}")))?;
        Ok(Source {
            path: path.to_path_buf(),
            text,
        })
    }

    /// Checks an image size given at `width_at` and `height_at`: each side in
    /// 1..=[`MAX_IMAGE_SIDE`], at most [`MAX_IMAGE_PIXELS`] in all (the one image-size rule of
    /// every file).
    pub fn image_size(&self, width_at: &[Seg], height_at: &[Seg], width: u32, height: u32) -> Result<(), ConfigError> {
        for (at, v) in [(width_at, width), (height_at, height)] {
            if !(1..=MAX_IMAGE_SIDE).contains(&v) {
                return Err(self.error(at, format!("must be in 1..={MAX_IMAGE_SIDE} pixels, got {v}")));
            }
        }
        if width as u64 * height as u64 > MAX_IMAGE_PIXELS {
            return Err(self.error(
                width_at,
                format!("{width} x {height} is more than {MAX_IMAGE_PIXELS} pixels"),
            ));
        }
        Ok(())
    }

    /// Deserialises the whole document, locating syntax errors and unknown or missing keys.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, ConfigError> {
        toml::from_str(&self.text).map_err(|e| {
            let span = e.span();
            let message = e.message().trim().to_string();
            if let (Some(field), Some(s)) = (missing_field(&message), span.as_ref()) {
                return self.missing(s, field);
            }
            let mut key = span.as_ref().map(|s| self.key_at(s)).unwrap_or_default();
            if key.is_empty() {
                key = span.as_ref().map(|s| self.key_on_line(s.start)).unwrap_or_default();
            }
            let message = if message.starts_with("duplicate key") && !key.is_empty() {
                format!("`{key}` is defined twice")
            } else {
                message
            };
            self.error_at_span(span, key, message)
        })
    }

    /// A required key absent from the table spanning `span`: named with its table's path, at the
    /// table's header line (no line for the top level, where the key would go anywhere).
    fn missing(&self, span: &Range<usize>, field: &str) -> ConfigError {
        let table = DeTable::parse(&self.text)
            .ok()
            .and_then(|doc| {
                let mut best = None;
                let mut path = Vec::new();
                enclosing_table(Node::Table(doc.get_ref()), span, &mut path, &mut best);
                best
            })
            .unwrap_or_default();
        let position = (!table.is_empty())
            .then(|| self.locate(&table))
            .flatten()
            .map(|s| line_col(&self.text, s.start));
        let mut key = table;
        key.push(Seg::Key(field.to_string()));
        let what = if key.len() == 1 { "file" } else { "table" };
        ConfigError {
            file: self.path.clone(),
            position,
            key: format_path(&key),
            message: format!("missing: the {what} needs `{field}`"),
        }
    }

    /// The bare key that starts the line holding `offset`, or the table a `[header]` line
    /// names (for syntax errors, where no document tree exists to walk).
    fn key_on_line(&self, offset: usize) -> String {
        let start = self.text[..offset.min(self.text.len())]
            .rfind('\n')
            .map_or(0, |i| i + 1);
        let line = self.text[start..].lines().next().unwrap_or("").trim();
        let plain = |k: &str| !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c));
        if let Some(header) = line.strip_prefix('[') {
            let name = header.trim_start_matches('[').split(']').next().unwrap_or("").trim();
            return if plain(name) { name.to_string() } else { String::new() };
        }
        match line.split_once('=') {
            Some((k, _))
                if !k.trim().is_empty() && k.trim().chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c)) =>
            {
                k.trim().to_string()
            }
            _ => String::new(),
        }
    }

    /// An error about the value at `path` (or, if absent, its nearest present parent).
    pub fn error(&self, path: &[Seg], message: impl Into<String>) -> ConfigError {
        let span = self.locate(path);
        self.error_at_span(span, format_path(path), message.into())
    }

    fn error_at_span(&self, span: Option<Range<usize>>, key: String, message: String) -> ConfigError {
        ConfigError {
            file: self.path.clone(),
            position: span.map(|s| line_col(&self.text, s.start)),
            key,
            message,
        }
    }

    /// Byte range of the value at `path`, falling back to the deepest parent that exists.
    pub fn locate(&self, path: &[Seg]) -> Option<Range<usize>> {
        let doc = DeTable::parse(&self.text).ok()?;
        let mut best: Option<Range<usize>> = None;
        let mut node = Node::Table(doc.get_ref());
        for seg in path {
            let next = match (seg, node) {
                (Seg::Key(k), Node::Table(t)) => t
                    .iter()
                    .find(|(key, _)| key.get_ref().as_ref() == k.as_str())
                    .map(|(key, v)| (key.span(), v)),
                (Seg::Index(i), Node::Array(a)) => a.get(*i).map(|v| (v.span(), v)),
                _ => None,
            };
            match next {
                Some((span, v)) => {
                    best = Some(span);
                    node = Node::of(v.get_ref());
                }
                None => break,
            }
        }
        best
    }

    /// The dotted key whose key or value span most tightly contains the start of `span`.
    /// Searches the whole tree: the spans of arrays of tables are not nested like the text.
    fn key_at(&self, span: &Range<usize>) -> String {
        let Ok(doc) = DeTable::parse(&self.text) else {
            return String::new();
        };
        let mut best: Option<(usize, Vec<Seg>)> = None;
        let mut path = Vec::new();
        search(Node::Table(doc.get_ref()), span.start, &mut path, &mut best);
        best.map(|(_, p)| format_path(&p)).unwrap_or_default()
    }
}

fn search(node: Node, at: usize, path: &mut Vec<Seg>, best: &mut Option<(usize, Vec<Seg>)>) {
    fn consider(r: Range<usize>, at: usize, path: &[Seg], best: &mut Option<(usize, Vec<Seg>)>) {
        let width = r.end.saturating_sub(r.start).max(1);
        if r.start <= at && at < r.start + width && best.as_ref().is_none_or(|(w, _)| width <= *w) {
            *best = Some((width, path.to_vec()));
        }
    }
    match node {
        Node::Table(t) => {
            for (k, v) in t.iter() {
                path.push(Seg::Key(k.get_ref().to_string()));
                consider(k.span(), at, path, best);
                consider(v.span(), at, path, best);
                search(Node::of(v.get_ref()), at, path, best);
                path.pop();
            }
        }
        Node::Array(a) => {
            for (i, v) in a.iter().enumerate() {
                path.push(Seg::Index(i));
                search(Node::of(v.get_ref()), at, path, best);
                path.pop();
            }
        }
        Node::Leaf => {}
    }
}

/// The field serde reports missing ("missing field `x`").
fn missing_field(message: &str) -> Option<&str> {
    message.strip_prefix("missing field `")?.split('`').next()
}

/// The path of the deepest table whose value span holds all of `span`.
fn enclosing_table(node: Node, span: &Range<usize>, path: &mut Vec<Seg>, best: &mut Option<Vec<Seg>>) {
    let Node::Table(t) = node else { return };
    for (k, v) in t.iter() {
        let r = v.span();
        if matches!(v.get_ref(), DeValue::Table(_)) && r.start <= span.start && span.end <= r.end.max(r.start + 1) {
            path.push(Seg::Key(k.get_ref().to_string()));
            *best = Some(path.clone());
            enclosing_table(Node::of(v.get_ref()), span, path, best);
            path.pop();
            return;
        }
        if let DeValue::Array(a) = v.get_ref() {
            for (i, item) in a.iter().enumerate() {
                let r = item.span();
                if matches!(item.get_ref(), DeValue::Table(_)) && r.start <= span.start && span.end <= r.end {
                    path.push(Seg::Key(k.get_ref().to_string()));
                    path.push(Seg::Index(i));
                    *best = Some(path.clone());
                    enclosing_table(Node::of(item.get_ref()), span, path, best);
                    path.truncate(path.len() - 2);
                    return;
                }
            }
        }
    }
}

/// A position in the spanned document while walking a key path.
#[derive(Clone, Copy)]
enum Node<'a, 'i> {
    Table(&'a DeTable<'i>),
    Array(&'a toml::de::DeArray<'i>),
    Leaf,
}

impl<'a, 'i> Node<'a, 'i> {
    fn of(v: &'a DeValue<'i>) -> Self {
        match v {
            DeValue::Table(t) => Node::Table(t),
            DeValue::Array(a) => Node::Array(a),
            _ => Node::Leaf,
        }
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Doc {
        name: String,
        lights: Vec<Light>,
    }
    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Light {
        radius: f64,
    }

    fn src(text: &str) -> Source {
        Source {
            path: "x.toml".into(),
            text: text.into(),
        }
    }

    #[test]
    fn unknown_key_is_located() {
        let s = src("name = \"a\"\n[[lights]]\nradius = 1.0\n[[lights]]\nradios = 2.0\n");
        let e = s.parse::<Doc>().unwrap_err();
        assert_eq!(e.position.map(|p| p.0), Some(5), "{e}");
        assert!(e.key.contains("radios") && e.message.contains("unknown field"), "{e}");
    }

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Nested {
        name: String,
        measure: Measure,
    }
    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Measure {
        width: u32,
        height: u32,
    }

    #[test]
    fn missing_keys_are_named_with_their_table() {
        let e = src("name = \"a\"\n").parse::<Nested>().unwrap_err();
        assert_eq!((e.key.as_str(), e.position), ("measure", None), "{e}");
        assert!(e.message.contains("missing"), "{e}");
        let e = src("name = \"a\"\n\n[measure]\nwidth = 3\n")
            .parse::<Nested>()
            .unwrap_err();
        assert_eq!(
            (e.key.as_str(), e.position.map(|p| p.0)),
            ("measure.height", Some(3)),
            "{e}"
        );
        let e = src("name = \"a\"\n[[lights]]\nradius = 1.0\n[[lights]]\n")
            .parse::<Doc>()
            .unwrap_err();
        assert_eq!(e.key, "lights[1].radius", "{e}");
    }

    #[test]
    fn a_table_defined_twice_is_named() {
        let e = src("name = \"a\"\n[measure]\nwidth = 1\nheight = 2\n[measure]\nwidth = 3\n")
            .parse::<Nested>()
            .unwrap_err();
        assert_eq!((e.key.as_str(), e.position.map(|p| p.0)), ("measure", Some(5)), "{e}");
        assert!(e.message.contains("`measure` is defined twice"), "{e}");
    }

    #[test]
    fn syntax_error_is_located() {
        let e = src("name = \"a\"\nlights = [\n").parse::<Doc>().unwrap_err();
        assert!(e.position.is_some(), "{e}");
    }

    #[test]
    fn value_error_is_located_by_path() {
        let s = src("name = \"a\"\n[[lights]]\nradius = 1.0\n[[lights]]\nradius = -2.0\n");
        let e = s.error(&key_path!["lights", 1usize, "radius"], "must be positive");
        assert_eq!(e.position, Some((5, 1)));
        assert_eq!(e.to_string(), "x.toml:5:1: key `lights[1].radius`: must be positive");
    }
}
