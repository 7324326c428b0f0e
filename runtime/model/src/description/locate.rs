//! Source locations of TOML fields, looked up by field path (`constraint.h`, `joints[3].axis[2]`).
//!
//! The text is parsed once more into a spanned document ([`toml::de::DeTable`]); every error and
//! every validation rule then names its field by path and gets line and column from here. A path
//! that is not in the document (a missing key) resolves to its deepest existing prefix (the table
//! the key is missing from).

use super::Location;
use std::ops::Range;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// Position of byte `offset` in `text`, 1-based line and column (columns count characters).
pub(crate) fn location_of(text: &str, offset: usize) -> Location {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    Location { line, column }
}

/// One segment of a field path.
#[derive(Debug, PartialEq)]
enum Segment<'a> {
    Key(&'a str),
    Index(usize),
}

/// Splits `joints[3].xyz[1]` into `Key(joints) Index(3) Key(xyz) Index(1)`.
fn segments(path: &str) -> Vec<Segment<'_>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = match part.find('[') {
            Some(k) => (&part[..k], &part[k..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            out.push(Segment::Key(key));
        }
        while let Some(stripped) = rest.strip_prefix('[') {
            let Some(end) = stripped.find(']') else { break };
            match stripped[..end].parse() {
                Ok(k) => out.push(Segment::Index(k)),
                Err(_) => return out,
            }
            rest = &stripped[end + 1..];
        }
    }
    out
}

/// Field locations of one TOML text.
pub(crate) struct Locator<'a> {
    text: &'a str,
    root: Option<DeTable<'a>>,
    /// `false` when the text has TOML syntax errors (the document was recovered).
    pub(crate) syntax_ok: bool,
}

impl<'a> Locator<'a> {
    /// Parses `text`; a text that is not TOML gives a locator that knows nothing.
    pub(crate) fn new(text: &'a str) -> Self {
        // Recoverable: a document with a duplicate key still locates its other fields.
        let (root, errors) = DeTable::parse_recoverable(text);
        Locator {
            text,
            root: Some(root.into_inner()),
            syntax_ok: errors.is_empty(),
        }
    }

    /// Where `field` is written: the key for a key, the element for an index; a missing key
    /// resolves to its deepest existing prefix.
    pub(crate) fn locate(&self, field: &str) -> Option<Location> {
        let root = self.root.as_ref()?;
        let mut best: Option<Range<usize>> = None;
        let mut table = Some(root);
        let mut value: Option<&DeValue<'a>> = None;
        for segment in segments(field) {
            match segment {
                Segment::Key(key) => {
                    let t = match (table, value) {
                        (Some(t), None) => t,
                        (_, Some(DeValue::Table(t))) => t,
                        _ => break,
                    };
                    let Some((k, v)) = t.iter().find(|(k, _)| k.get_ref() == key) else {
                        break;
                    };
                    best = Some(k.span());
                    table = None;
                    value = Some(v.get_ref());
                }
                Segment::Index(index) => {
                    let Some(DeValue::Array(a)) = value else {
                        break;
                    };
                    let Some(item) = a.get(index) else { break };
                    best = Some(item.span());
                    value = Some(item.get_ref());
                }
            }
        }
        best.map(|span| location_of(self.text, span.start))
    }

    /// The table (`constraint`, `joints[2]`) whose header is the last one before byte `offset`;
    /// `""` for the top level.
    pub(crate) fn table_before(&self, offset: usize) -> String {
        let mut best = (0, String::new());
        let Some(root) = self.root.as_ref() else {
            return best.1;
        };
        for (k, v) in root.iter() {
            let name = k.get_ref().to_string();
            match v.get_ref() {
                DeValue::Table(_) if v.span().start <= offset && v.span().start >= best.0 => {
                    best = (v.span().start, name);
                }
                DeValue::Array(a) => {
                    for (i, item) in a.iter().enumerate() {
                        let start = item.span().start;
                        if matches!(item.get_ref(), DeValue::Table(_))
                            && start <= offset
                            && start >= best.0
                        {
                            best = (start, format!("{name}[{i}]"));
                        }
                    }
                }
                _ => {}
            }
        }
        best.1
    }

    /// For an array of scalars at `path`: the path of its first element that is neither a number
    /// nor a string.
    pub(crate) fn first_non_scalar(&self, path: &str) -> Option<String> {
        let mut value: Option<&DeValue<'a>> = None;
        let mut table = self.root.as_ref();
        for segment in segments(path) {
            match segment {
                Segment::Key(key) => {
                    let t = match value {
                        None => table?,
                        Some(DeValue::Table(t)) => t,
                        Some(_) => return None,
                    };
                    value = Some(t.iter().find(|(k, _)| k.get_ref() == key)?.1.get_ref());
                    table = None;
                }
                Segment::Index(i) => match value {
                    Some(DeValue::Array(a)) => value = Some(a.get(i)?.get_ref()),
                    _ => return None,
                },
            }
        }
        let Some(DeValue::Array(a)) = value else {
            return None;
        };
        a.iter()
            .position(|item| {
                !matches!(
                    item.get_ref(),
                    DeValue::Integer(_) | DeValue::Float(_) | DeValue::String(_)
                )
            })
            .map(|k| format!("{path}[{k}]"))
    }

    /// The most specific field whose key or value span contains byte `offset`.
    pub(crate) fn path_at(&self, offset: usize) -> Option<String> {
        let root = self.root.as_ref()?;
        let mut best: Option<(usize, String)> = None;
        visit_table(root, "", offset, &mut best);
        best.map(|(_, path)| path)
    }
}

fn consider(span: Range<usize>, path: &str, offset: usize, best: &mut Option<(usize, String)>) {
    let contains = span.start <= offset && (offset < span.end || span.is_empty());
    if contains && best.as_ref().is_none_or(|(len, _)| span.len() <= *len) {
        *best = Some((span.len(), path.to_string()));
    }
}

fn visit_table(t: &DeTable<'_>, prefix: &str, offset: usize, best: &mut Option<(usize, String)>) {
    for (k, v) in t.iter() {
        let path = if prefix.is_empty() {
            k.get_ref().to_string()
        } else {
            format!("{prefix}.{}", k.get_ref())
        };
        consider(k.span(), &path, offset, best);
        visit_value(v, &path, offset, best);
    }
}

fn visit_value(
    v: &Spanned<DeValue<'_>>,
    path: &str,
    offset: usize,
    best: &mut Option<(usize, String)>,
) {
    consider(v.span(), path, offset, best);
    match v.get_ref() {
        DeValue::Table(t) => visit_table(t, path, offset, best),
        DeValue::Array(a) => {
            for (k, item) in a.iter().enumerate() {
                visit_value(item, &format!("{path}[{k}]"), offset, best);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[c]\nlink = 3\n\n[[joints]]\nname = \"a\"\naxis = [0, 0, 1]\n[[joints]]\nname = \"b\"\naxis = [0, 0]\n";

    #[test]
    fn paths_split_into_segments() {
        assert_eq!(
            segments("joints[3].xyz[1]"),
            vec![
                Segment::Key("joints"),
                Segment::Index(3),
                Segment::Key("xyz"),
                Segment::Index(1)
            ]
        );
    }

    #[test]
    fn fields_resolve_to_lines() {
        let l = Locator::new(TEXT);
        assert_eq!(l.locate("c.link"), Some(Location { line: 2, column: 1 }));
        assert_eq!(l.locate("joints[1].axis").unwrap().line, 9);
        assert_eq!(
            l.locate("joints[0].axis[2]"),
            Some(Location {
                line: 6,
                column: 15
            })
        );
        // A missing key resolves to its table.
        assert_eq!(l.locate("joints[1].rpy").unwrap().line, 7);
        assert_eq!(l.locate("nothing"), None);
    }

    #[test]
    fn offsets_resolve_to_paths() {
        let l = Locator::new(TEXT);
        let at = TEXT.find("[0, 0]").unwrap();
        assert_eq!(l.path_at(at).as_deref(), Some("joints[1].axis"));
        assert_eq!(l.path_at(at + 1).as_deref(), Some("joints[1].axis[0]"));
        assert_eq!(
            l.path_at(TEXT.find("link").unwrap()).as_deref(),
            Some("c.link")
        );
    }
}
