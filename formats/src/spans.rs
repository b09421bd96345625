//! Where each value of a RON file is written. serde (through ron) decides what the values mean;
//! this tree only answers "where is `objects[3].params`, and what is its exact text?", which
//! serde cannot. `scanner` builds it.

use std::path::PathBuf;
use std::sync::Arc;

use crate::origin::Origin;

/// One value: its byte range in the source and its children.
#[derive(Debug)]
pub(crate) struct Node {
    pub start: usize,
    pub end: usize,
    pub kind: Kind,
}

#[derive(Debug)]
pub(crate) enum Kind {
    /// `Name(field: value, ...)` or `(field: value, ...)`.
    Struct(Vec<(String, Node)>),
    /// `Name(a, b)`, `(a, b)` or `()`; the name is kept to see through `Some(...)`.
    Tuple(Option<String>, Vec<Node>),
    List(Vec<Node>),
    Map(Vec<(Node, Node)>),
    /// Any number literal, including `inf` and `NaN`.
    Number,
    Str,
    Char,
    /// `true`, `false`, unit variants and unit structs.
    Ident,
}

impl Node {
    /// The value of struct field `name`, looking through `Some(...)` (implicit_some is on).
    pub fn field(&self, name: &str) -> Option<&Node> {
        self.raw_field(name).map(Node::unwrap_some)
    }

    /// The value of struct field `name` exactly as written.
    pub fn raw_field(&self, name: &str) -> Option<&Node> {
        match &self.unwrap_some().kind {
            Kind::Struct(fields) => fields.iter().find(|(n, _)| n == name).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Element `i` of a list or tuple.
    pub fn item(&self, i: usize) -> Option<&Node> {
        match &self.unwrap_some().kind {
            Kind::List(items) | Kind::Tuple(_, items) => items.get(i).map(Node::unwrap_some),
            _ => None,
        }
    }

    /// Entry `i` of a map, as (key, value).
    pub fn entry(&self, i: usize) -> Option<(&Node, &Node)> {
        match &self.unwrap_some().kind {
            Kind::Map(entries) => entries.get(i).map(|(k, v)| (k, v.unwrap_some())),
            _ => None,
        }
    }

    /// The value whose last character (its closing bracket) is at byte `at`.
    pub fn closed_at(&self, at: usize) -> Option<&Node> {
        if self.end == at + 1 {
            return Some(self);
        }
        if !(self.start..self.end).contains(&at) {
            return None;
        }
        match &self.kind {
            Kind::Struct(fields) => fields.iter().find_map(|(_, v)| v.closed_at(at)),
            Kind::Tuple(_, items) | Kind::List(items) => items.iter().find_map(|v| v.closed_at(at)),
            Kind::Map(entries) => entries
                .iter()
                .find_map(|(k, v)| k.closed_at(at).or_else(|| v.closed_at(at))),
            _ => None,
        }
    }

    pub fn unwrap_some(&self) -> &Node {
        match &self.kind {
            Kind::Tuple(Some(name), items) if name == "Some" && items.len() == 1 => {
                items[0].unwrap_some()
            }
            _ => self,
        }
    }

    /// Calls `f` on every number literal in this subtree, in source order.
    pub fn each_number<E>(&self, f: &mut impl FnMut(&Node) -> Result<(), E>) -> Result<(), E> {
        match &self.kind {
            Kind::Number => f(self),
            Kind::Struct(fields) => fields.iter().try_for_each(|(_, v)| v.each_number(f)),
            Kind::Tuple(_, items) | Kind::List(items) => {
                items.iter().try_for_each(|v| v.each_number(f))
            }
            Kind::Map(entries) => entries.iter().try_for_each(|(k, v)| {
                k.each_number(f)?;
                v.each_number(f)
            }),
            Kind::Str | Kind::Char | Kind::Ident => Ok(()),
        }
    }
}

/// A file's text with a line index, to turn byte offsets into `Origin`s.
pub(crate) struct SourceMap {
    pub file: Arc<PathBuf>,
    pub text: String,
    line_starts: Vec<usize>,
}

impl SourceMap {
    pub fn new(file: PathBuf, text: String) -> Self {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        SourceMap {
            file: Arc::new(file),
            text,
            line_starts,
        }
    }

    /// 1-based line and column (in characters, as ron counts them) of a byte offset.
    pub fn origin(&self, byte: usize) -> Origin {
        let line = self.line_starts.partition_point(|&s| s <= byte) - 1;
        let start = self.line_starts[line];
        let col = self.text[start..byte].chars().count() + 1;
        self.origin_at(line + 1, col)
    }

    pub fn origin_at(&self, line: usize, col: usize) -> Origin {
        Origin {
            file: self.file.clone(),
            line: u32::try_from(line).unwrap_or(u32::MAX),
            col: u32::try_from(col).unwrap_or(u32::MAX),
        }
    }

    /// The byte offset of a 1-based line and character column (clamped to the text).
    pub fn byte(&self, line: usize, col: usize) -> usize {
        let Some(&start) = self.line_starts.get(line.saturating_sub(1)) else {
            return self.text.len();
        };
        self.text[start..]
            .char_indices()
            .nth(col.saturating_sub(1))
            .map_or(self.text.len(), |(i, _)| start + i)
    }

    pub fn slice(&self, node: &Node) -> &str {
        &self.text[node.start..node.end]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters() {
        let map = SourceMap::new("x.ron".into(), "(\n  é: 1, ü: 2)".into());
        let at = map.origin(map.text.find('ü').unwrap());
        assert_eq!((at.line, at.col), (2, 9));
    }
}
