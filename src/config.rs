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
    /// Reads a file; a missing or unreadable file is a [`ConfigError`] naming it.
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError {
            file: path.to_path_buf(),
            position: None,
            key: String::new(),
            message: format!("cannot read: {e}"),
        })?;
        Ok(Source {
            path: path.to_path_buf(),
            text,
        })
    }

    /// Deserialises the whole document, locating syntax errors and unknown or missing keys.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, ConfigError> {
        toml::from_str(&self.text).map_err(|e| {
            let span = e.span();
            let mut key = span.as_ref().map(|s| self.key_at(s)).unwrap_or_default();
            if key.is_empty() {
                key = span.as_ref().map(|s| self.key_on_line(s.start)).unwrap_or_default();
            }
            self.error_at_span(span, key, e.message().trim().to_string())
        })
    }

    /// The bare key that starts the line holding `offset` (for syntax errors, where no
    /// document tree exists to walk).
    fn key_on_line(&self, offset: usize) -> String {
        let start = self.text[..offset.min(self.text.len())]
            .rfind('\n')
            .map_or(0, |i| i + 1);
        let line = self.text[start..].lines().next().unwrap_or("");
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
