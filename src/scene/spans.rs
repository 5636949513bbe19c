//! Where things are in a RON text. serde reads a scene file into values that have forgotten
//! their place; after it has accepted a file, this scanner reads the same text again into a
//! tree of byte spans, so that the checks that span several values (duplicate names, a
//! transform on a light) and the errors found after parsing (an unreadable mesh or base scene,
//! an unknown material) can point at the right line and column. It also tells which brackets
//! are still open at a point, for messages about a file that ends too early.
//!
//! The scanner never fails on text serde accepted; on anything else it gives up (`None`) and
//! the caller falls back to a coarser location.

/// A value and the bytes it spans.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Byte offset of the value's first character (the name, for `Name(...)`).
    pub start: usize,
    /// Byte offset just past the value.
    pub end: usize,
    /// What it is.
    pub kind: Kind,
}

/// The shape of a value.
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// `Name(field: value, ...)` or `(field: value, ...)`.
    Struct(Vec<Field>),
    /// `Name(value, ...)` or `(value, ...)`.
    Tuple(Vec<Node>),
    /// `[value, ...]`.
    List(Vec<Node>),
    /// `{key: value, ...}`.
    Map(Vec<(Node, Node)>),
    /// A string, number, character or lone identifier.
    Atom,
}

/// A named field of a struct.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// The field's name.
    pub name: String,
    /// Byte offset of the name.
    pub at: usize,
    /// The value.
    pub value: Node,
}

impl Node {
    /// The field `name` of a struct (the last, if written twice).
    pub fn field(&self, name: &str) -> Option<&Field> {
        match &self.kind {
            Kind::Struct(fields) => fields.iter().rev().find(|f| f.name == name),
            _ => None,
        }
    }

    /// The value of field `name`, looking through an explicit `Some(...)`.
    pub fn get(&self, name: &str, text: &str) -> Option<&Node> {
        self.field(name).map(|f| f.value.unwrap_some(text))
    }

    /// The items of a list or tuple.
    pub fn items(&self) -> &[Node] {
        match &self.kind {
            Kind::List(v) | Kind::Tuple(v) => v,
            _ => &[],
        }
    }

    /// The entries of a map.
    pub fn entries(&self) -> &[(Node, Node)] {
        match &self.kind {
            Kind::Map(v) => v,
            _ => &[],
        }
    }

    /// The value inside `Some(value)`, or this one.
    pub fn unwrap_some(&self, text: &str) -> &Node {
        match &self.kind {
            Kind::Tuple(v) if v.len() == 1 && text[self.start..].starts_with("Some") => &v[0],
            _ => self,
        }
    }

    /// The string this node spells, if it is a string literal.
    pub fn string(&self, text: &str) -> Option<String> {
        let src = text.get(self.start..self.end)?;
        if !matches!(src.as_bytes().first(), Some(b'"' | b'r')) {
            return None;
        }
        ron::from_str::<String>(src).ok()
    }
}

/// One token: its kind and span.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tok {
    /// An identifier (possibly raw, `r#name`).
    Ident,
    /// A string, character, number or other literal.
    Lit,
    /// One of `( ) [ ] { } , :`.
    Punct(u8),
}

/// The tokens of `text` with their spans; `None` where the text is not RON (an unclosed
/// string or comment, a stray character).
fn tokens(text: &str) -> Option<Vec<(Tok, usize, usize)>> {
    let mut out = Vec::new();
    scan(text, &mut out)?;
    Some(out)
}

/// Push the tokens of `text` onto `out`, stopping (`None`) where the text stops being RON.
fn scan(text: &str, out: &mut Vec<(Tok, usize, usize)>) -> Option<()> {
    let b = text.as_bytes();
    let mut i = 0;
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c >= 0x80;
    while i < b.len() {
        let c = b[i];
        let start = i;
        match c {
            b' ' | b'\t' | b'\n' | b'\r' => i += 1,
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let mut depth = 0usize;
                loop {
                    if i + 1 >= b.len() {
                        return None;
                    }
                    if b[i] == b'/' && b[i + 1] == b'*' {
                        depth += 1;
                        i += 2;
                    } else if b[i] == b'*' && b[i + 1] == b'/' {
                        depth -= 1;
                        i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
            }
            b'#' => {
                // `#![enable(...)]`: skip to the closing `]`.
                while i < b.len() && b[i] != b']' {
                    i += 1;
                }
                i = (i + 1).min(b.len());
            }
            b'(' | b')' | b'[' | b']' | b'{' | b'}' | b',' | b':' => {
                out.push((Tok::Punct(c), i, i + 1));
                i += 1;
            }
            b'"' => {
                i = quoted(b, i, b'"')?;
                out.push((Tok::Lit, start, i));
            }
            b'\'' => {
                i = quoted(b, i, b'\'')?;
                out.push((Tok::Lit, start, i));
            }
            b'b' if matches!(b.get(i + 1), Some(b'"' | b'\'')) => {
                i = quoted(b, i + 1, b[i + 1])?;
                out.push((Tok::Lit, start, i));
            }
            b'r' | b'b' if raw_string_start(b, i).is_some() => {
                i = raw_string_end(b, i)?;
                out.push((Tok::Lit, start, i));
            }
            b'r' if b.get(i + 1) == Some(&b'#') => {
                i += 2;
                while i < b.len() && (ident(b[i]) || b"+-.".contains(&b[i])) {
                    i += 1;
                }
                out.push((Tok::Ident, start, i));
            }
            b'0'..=b'9' | b'+' | b'-' | b'.' => {
                i += 1;
                while i < b.len() && (ident(b[i]) || b[i] == b'.' || b[i] == b'+' || b[i] == b'-') {
                    // An exponent sign only right after `e`.
                    if (b[i] == b'+' || b[i] == b'-') && !matches!(b[i - 1], b'e' | b'E') {
                        break;
                    }
                    i += 1;
                }
                out.push((Tok::Lit, start, i));
            }
            _ if ident(c) => {
                while i < b.len() && ident(b[i]) {
                    i += 1;
                }
                out.push((Tok::Ident, start, i));
            }
            _ => return None,
        }
    }
    Some(())
}

/// Offset just past the string or character opened by the quote at `i`.
fn quoted(b: &[u8], mut i: usize, quote: u8) -> Option<usize> {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            c if c == quote => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

/// The number of `#` of a raw string starting at `i` (`r"`, `r#"`, `br"`...).
fn raw_string_start(b: &[u8], i: usize) -> Option<usize> {
    let mut j = i + usize::from(b[i] == b'b');
    if b.get(j) != Some(&b'r') {
        return None;
    }
    j += 1;
    let hashes = b[j..].iter().take_while(|&&c| c == b'#').count();
    (b.get(j + hashes) == Some(&b'"')).then_some(hashes)
}

/// Offset just past the raw string starting at `i`.
fn raw_string_end(b: &[u8], i: usize) -> Option<usize> {
    let hashes = raw_string_start(b, i)?;
    let open = i + usize::from(b[i] == b'b') + 1 + hashes + 1;
    let mut close = vec![b'"'];
    close.extend(std::iter::repeat_n(b'#', hashes));
    let rest = b.get(open..)?;
    rest.windows(close.len())
        .position(|w| w == close.as_slice())
        .map(|p| open + p + close.len())
}

/// Deepest nesting the scanner follows (ron's own limit is lower).
const MAX_DEPTH: usize = 256;

struct Parser<'a> {
    toks: &'a [(Tok, usize, usize)],
    text: &'a str,
    pos: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<(Tok, usize, usize)> {
        self.toks.get(self.pos).copied()
    }

    fn punct(&mut self, c: u8) -> bool {
        if matches!(self.peek(), Some((Tok::Punct(p), ..)) if p == c) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    fn value(&mut self, depth: usize) -> Option<Node> {
        if depth > MAX_DEPTH {
            return None;
        }
        let (tok, start, end) = self.peek()?;
        self.pos += 1;
        match tok {
            Tok::Ident if self.punct(b'(') => self.parens(start, depth),
            Tok::Ident | Tok::Lit => Some(Node {
                start,
                end,
                kind: Kind::Atom,
            }),
            Tok::Punct(b'(') => self.parens(start, depth),
            Tok::Punct(b'[') => {
                let items = self.list(b']', depth)?;
                Some(self.node(start, Kind::List(items)))
            }
            Tok::Punct(b'{') => {
                let mut entries = Vec::new();
                loop {
                    if self.punct(b'}') {
                        break;
                    }
                    let k = self.value(depth + 1)?;
                    if !self.punct(b':') {
                        return None;
                    }
                    let v = self.value(depth + 1)?;
                    entries.push((k, v));
                    if !self.punct(b',') {
                        if self.punct(b'}') {
                            break;
                        }
                        return None;
                    }
                }
                Some(self.node(start, Kind::Map(entries)))
            }
            Tok::Punct(_) => None,
        }
    }

    /// The end of the node just closed: past the last token read.
    fn node(&self, start: usize, kind: Kind) -> Node {
        let end = self.toks[self.pos - 1].2;
        Node { start, end, kind }
    }

    /// Values separated by commas up to `close` (already past the opening bracket).
    fn list(&mut self, close: u8, depth: usize) -> Option<Vec<Node>> {
        let mut items = Vec::new();
        loop {
            if self.punct(close) {
                return Some(items);
            }
            items.push(self.value(depth + 1)?);
            if !self.punct(b',') {
                return self.punct(close).then_some(items);
            }
        }
    }

    /// The inside of `(...)`, after the `(`: fields when it starts with `name:`.
    fn parens(&mut self, start: usize, depth: usize) -> Option<Node> {
        let is_struct = matches!(
            (self.toks.get(self.pos), self.toks.get(self.pos + 1)),
            (Some((Tok::Ident, ..)), Some((Tok::Punct(b':'), ..)))
        );
        if !is_struct {
            let items = self.list(b')', depth)?;
            return Some(self.node(start, Kind::Tuple(items)));
        }
        let mut fields = Vec::new();
        loop {
            if self.punct(b')') {
                break;
            }
            let (tok, at, end) = self.peek()?;
            if tok != Tok::Ident {
                return None;
            }
            self.pos += 1;
            if !self.punct(b':') {
                return None;
            }
            let value = self.value(depth + 1)?;
            let name = self.text[at..end].trim_start_matches("r#").to_string();
            fields.push(Field { name, at, value });
            if !self.punct(b',') {
                if self.punct(b')') {
                    break;
                }
                return None;
            }
        }
        Some(self.node(start, Kind::Struct(fields)))
    }
}

/// The tree of the one value `text` holds, or `None` when the text is not RON.
pub fn parse(text: &str) -> Option<Node> {
    let toks = tokens(text)?;
    let mut p = Parser {
        toks: &toks,
        text,
        pos: 0,
    };
    let node = p.value(0)?;
    (p.pos == toks.len()).then_some(node)
}

/// The brackets still open at byte `upto` of `text`, outermost first: each bracket character
/// and its byte offset. Strings and comments are skipped; the scan stops at the first
/// character that is not RON.
pub fn open_brackets(text: &str, upto: usize) -> Vec<(char, usize)> {
    let mut end = upto.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    // An unclosed string or comment ends the scan: the brackets before it count.
    let mut toks = Vec::new();
    let _ = scan(&text[..end], &mut toks);
    let mut stack = Vec::new();
    for (tok, at, _) in toks {
        match tok {
            Tok::Punct(c @ (b'(' | b'[' | b'{')) => stack.push((c as char, at)),
            Tok::Punct(c @ (b')' | b']' | b'}')) => {
                let open = match c {
                    b')' => '(',
                    b']' => '[',
                    _ => '{',
                };
                if stack.last().map(|s| s.0) == Some(open) {
                    stack.pop();
                }
            }
            _ => {}
        }
    }
    stack
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_items_and_keys_have_their_offsets() {
        let text = r#"Scene( // c
            extends: Some("a.ron"), /* x /* y */ */
            materials: { "red": Phong(kd: (1, 0, 0)), r"blue": Mirror() },
            entities: [(name: "a", shape: Mesh(path: "m.obj")), (light: Point(position: (0, -1e-3, 0)))],
        )"#;
        let t = parse(text).unwrap();
        let ext = t.get("extends", text).unwrap();
        assert_eq!(ext.string(text).as_deref(), Some("a.ron"));
        assert_eq!(&text[ext.start..ext.end], "\"a.ron\"");
        let keys: Vec<_> = t
            .get("materials", text)
            .unwrap()
            .entries()
            .iter()
            .map(|(k, _)| k.string(text).unwrap())
            .collect();
        assert_eq!(keys, ["red", "blue"]);
        let ents = t.get("entities", text).unwrap().items();
        assert_eq!(ents.len(), 2);
        let path = ents[0]
            .get("shape", text)
            .unwrap()
            .get("path", text)
            .unwrap();
        assert_eq!(&text[path.start..path.end], "\"m.obj\"");
        assert!(ents[1].field("light").is_some());
    }

    #[test]
    fn not_ron_gives_none_and_open_brackets_are_listed() {
        assert_eq!(parse("Scene(a: \"x)"), None);
        assert_eq!(parse("Scene(a: 1"), None);
        assert_eq!(parse("(a: 1))"), None);
        let text = "Scene(entities: [(a: \"(\", b: {";
        let open: Vec<char> = open_brackets(text, text.len())
            .iter()
            .map(|o| o.0)
            .collect();
        assert_eq!(open, ['(', '[', '(', '{']);
        let text = "Scene(a: \"unclosed (";
        let open: Vec<char> = open_brackets(text, text.len())
            .iter()
            .map(|o| o.0)
            .collect();
        assert_eq!(open, ['(']);
    }
}
