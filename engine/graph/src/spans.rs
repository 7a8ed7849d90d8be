//! Source positions for RON values. `ron` deserializes without keeping spans, so
//! this reads the same text into a tree of positions that validation queries by
//! path (`passes[3].color[0].image`) to point errors at the exact line and column.

pub use weft_diagnostic::Pos;

/// One step of a path into a RON value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seg<'a> {
    /// A named field of a struct.
    Field(&'a str),
    /// An element of a list or tuple.
    Index(usize),
    /// The value of a map entry whose key is this string.
    Key(&'a str),
    /// The key itself of a map entry.
    KeyOf(&'a str),
}

/// A value's position and, for compound values, its children.
#[derive(Debug, Clone, Default)]
pub struct SpanTree {
    pos: Pos,
    fields: Vec<(String, SpanTree)>,
    items: Vec<SpanTree>,
    entries: Vec<(String, SpanTree, SpanTree)>,
}

impl SpanTree {
    /// Reads the positions of `text`; text that is not valid RON yields a partial tree.
    pub fn parse(text: &str) -> SpanTree {
        let mut reader = Reader {
            chars: text.chars().collect(),
            at: 0,
            line: 1,
            col: 1,
        };
        reader.skip_trivia();
        reader.value(0)
    }

    /// The position of the value at `path`, or of its deepest ancestor that exists.
    pub fn locate(&self, path: &[Seg]) -> Pos {
        let mut node = self;
        for seg in path {
            match node.child(*seg) {
                Some(next) => node = next,
                None => break,
            }
        }
        node.pos
    }

    fn child(&self, seg: Seg) -> Option<&SpanTree> {
        let direct = match seg {
            Seg::Field(name) => self.fields.iter().find(|(n, _)| n == name).map(|(_, t)| t),
            Seg::Index(i) => self.items.get(i),
            Seg::Key(k) => self
                .entries
                .iter()
                .find(|(n, _, _)| n == k)
                .map(|(_, _, v)| v),
            Seg::KeyOf(k) => self
                .entries
                .iter()
                .find(|(n, _, _)| n == k)
                .map(|(_, k, _)| k),
        };
        // `Some(x)` and newtype wrappers: look through a single-element tuple.
        direct.or_else(|| match (seg, self.items.as_slice()) {
            (Seg::Field(_) | Seg::Key(_) | Seg::KeyOf(_), [only]) => only.child(seg),
            _ => None,
        })
    }
}

struct Reader {
    chars: Vec<char>,
    at: usize,
    line: u32,
    col: u32,
}

const MAX_DEPTH: usize = 256;

impl Reader {
    fn peek(&self) -> Option<char> {
        self.chars.get(self.at).copied()
    }

    fn peek_at(&self, offset: usize) -> Option<char> {
        self.chars.get(self.at + offset).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.at += 1;
        if c == '\n' {
            self.line += 1;
            self.col = 1;
        } else {
            self.col += 1;
        }
        Some(c)
    }

    fn pos(&self) -> Pos {
        Pos {
            line: self.line,
            col: self.col,
        }
    }

    fn skip_trivia(&mut self) {
        loop {
            match (self.peek(), self.peek_at(1)) {
                (Some(c), _) if c.is_whitespace() => {
                    self.bump();
                }
                (Some('/'), Some('/')) => {
                    while !matches!(self.peek(), None | Some('\n')) {
                        self.bump();
                    }
                }
                (Some('/'), Some('*')) => self.block_comment(),
                (Some('#'), Some('!')) => {
                    while !matches!(self.peek(), None | Some('\n')) {
                        self.bump();
                    }
                }
                _ => return,
            }
        }
    }

    fn block_comment(&mut self) {
        let mut depth = 0usize;
        while let Some(c) = self.bump() {
            match (c, self.peek()) {
                ('/', Some('*')) => {
                    self.bump();
                    depth += 1;
                }
                ('*', Some('/')) => {
                    self.bump();
                    depth -= 1;
                    if depth == 0 {
                        return;
                    }
                }
                _ => {}
            }
        }
    }

    fn ident(&mut self) -> String {
        let mut s = String::new();
        if self.peek() == Some('r') && self.peek_at(1) == Some('#') {
            self.bump();
            self.bump();
        }
        while let Some(c) = self.peek() {
            if c.is_alphanumeric() || c == '_' {
                s.push(c);
                self.bump();
            } else {
                break;
            }
        }
        s
    }

    fn value(&mut self, depth: usize) -> SpanTree {
        let pos = self.pos();
        let mut tree = SpanTree {
            pos,
            ..SpanTree::default()
        };
        if depth > MAX_DEPTH {
            return tree;
        }
        match self.peek() {
            Some('"') => {
                self.string();
            }
            Some('r')
                if matches!(self.peek_at(1), Some('"') | Some('#')) && self.is_raw_string() =>
            {
                self.raw_string();
            }
            Some('\'') => {
                self.bump();
                if self.bump() == Some('\\') {
                    self.bump();
                }
                self.bump();
            }
            Some('[') => {
                self.bump();
                tree.items = self.sequence(']', depth);
            }
            Some('{') => {
                self.bump();
                tree.entries = self.map(depth);
            }
            Some('(') => self.parenthesised(&mut tree, depth),
            Some(c) if c.is_alphabetic() || c == '_' => {
                self.ident();
                self.skip_trivia();
                if self.peek() == Some('(') {
                    self.parenthesised(&mut tree, depth);
                }
            }
            Some(_) => {
                while let Some(c) = self.peek() {
                    if c.is_alphanumeric() || matches!(c, '.' | '+' | '-' | '_') {
                        self.bump();
                    } else {
                        break;
                    }
                }
            }
            None => {}
        }
        tree
    }

    fn is_raw_string(&self) -> bool {
        let mut i = 1;
        while self.peek_at(i) == Some('#') {
            i += 1;
        }
        self.peek_at(i) == Some('"')
    }

    fn string(&mut self) -> String {
        let mut s = String::new();
        self.bump();
        while let Some(c) = self.bump() {
            match c {
                '"' => break,
                '\\' => {
                    if let Some(e) = self.bump() {
                        s.push(match e {
                            'n' => '\n',
                            't' => '\t',
                            other => other,
                        });
                    }
                }
                other => s.push(other),
            }
        }
        s
    }

    fn raw_string(&mut self) -> String {
        self.bump();
        let mut hashes = 0;
        while self.peek() == Some('#') {
            self.bump();
            hashes += 1;
        }
        self.bump();
        let mut s = String::new();
        while let Some(c) = self.bump() {
            if c == '"' && (0..hashes).all(|i| self.peek_at(i) == Some('#')) {
                for _ in 0..hashes {
                    self.bump();
                }
                break;
            }
            s.push(c);
        }
        s
    }

    fn parenthesised(&mut self, tree: &mut SpanTree, depth: usize) {
        self.bump();
        self.skip_trivia();
        if self.starts_named_field() {
            while let Some(c) = self.peek() {
                if c == ')' {
                    self.bump();
                    return;
                }
                let name = self.ident();
                if name.is_empty() {
                    self.bump();
                    self.skip_trivia();
                    continue;
                }
                self.skip_trivia();
                if self.peek() == Some(':') {
                    self.bump();
                }
                self.skip_trivia();
                let value = self.value(depth + 1);
                tree.fields.push((name, value));
                self.skip_separator();
            }
        } else {
            tree.items = self.sequence(')', depth);
        }
    }

    fn starts_named_field(&self) -> bool {
        let mut i = 0;
        while let Some(c) = self.peek_at(i) {
            if c.is_alphanumeric() || c == '_' {
                i += 1;
            } else {
                break;
            }
        }
        if i == 0 {
            return false;
        }
        while matches!(self.peek_at(i), Some(c) if c.is_whitespace()) {
            i += 1;
        }
        self.peek_at(i) == Some(':')
    }

    fn skip_separator(&mut self) {
        self.skip_trivia();
        if self.peek() == Some(',') {
            self.bump();
        }
        self.skip_trivia();
    }

    fn sequence(&mut self, close: char, depth: usize) -> Vec<SpanTree> {
        let mut items = Vec::new();
        self.skip_trivia();
        while let Some(c) = self.peek() {
            if c == close {
                self.bump();
                break;
            }
            let before = self.at;
            items.push(self.value(depth + 1));
            self.skip_separator();
            if self.at == before {
                self.bump();
            }
        }
        items
    }

    fn map(&mut self, depth: usize) -> Vec<(String, SpanTree, SpanTree)> {
        let mut entries = Vec::new();
        self.skip_trivia();
        while let Some(c) = self.peek() {
            if c == '}' {
                self.bump();
                break;
            }
            let before = self.at;
            let key_pos = self.pos();
            let key = if c == '"' {
                self.string()
            } else {
                self.value(depth + 1);
                String::new()
            };
            self.skip_trivia();
            if self.peek() == Some(':') {
                self.bump();
            }
            self.skip_trivia();
            let value = self.value(depth + 1);
            let key_tree = SpanTree {
                pos: key_pos,
                ..SpanTree::default()
            };
            entries.push((key, key_tree, value));
            self.skip_separator();
            if self.at == before {
                self.bump();
            }
        }
        entries
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"// a comment
Graph(
    params: { "bias": 0.5, "res": 2048 },
    resources: [
        Image(name: "depth", format: D32_SFLOAT),
        /* nested /* block */ comment */ Buffer(name: "lights", size: "lights * 16"),
    ],
    passes: [
        Pass(name: "a", depth: Some((image: "depth", load: Clear([0.0])))),
    ],
)"#;

    /// The text from a position to the end of its line.
    fn at(pos: Pos) -> &'static str {
        let line = TEXT
            .lines()
            .nth(pos.line as usize - 1)
            .expect("line exists");
        let start = line
            .char_indices()
            .nth(pos.col as usize - 1)
            .expect("column exists")
            .0;
        &line[start..]
    }

    #[test]
    fn locates_fields_items_and_map_entries() {
        let t = SpanTree::parse(TEXT);
        let p = |path: &[Seg]| t.locate(path);
        let res = p(&[Seg::Field("params"), Seg::Key("res")]);
        assert_eq!(res, Pos { line: 3, col: 35 });
        assert!(at(res).starts_with("2048 }"));
        assert!(at(p(&[Seg::Field("params"), Seg::KeyOf("res")])).starts_with("\"res\": 2048"));
        let format = p(&[Seg::Field("resources"), Seg::Index(0), Seg::Field("format")]);
        assert!(at(format).starts_with("D32_SFLOAT)"));
        let size = p(&[Seg::Field("resources"), Seg::Index(1), Seg::Field("size")]);
        assert!(at(size).starts_with("\"lights * 16\""));
    }

    #[test]
    fn looks_through_some_and_falls_back_to_the_deepest_ancestor() {
        let t = SpanTree::parse(TEXT);
        let depth = [
            Seg::Field("passes"),
            Seg::Index(0),
            Seg::Field("depth"),
            Seg::Field("image"),
        ];
        assert!(at(t.locate(&depth)).starts_with("\"depth\", load"));
        let missing = [Seg::Field("passes"), Seg::Index(0), Seg::Field("color")];
        assert!(at(t.locate(&missing)).starts_with("Pass(name: \"a\""));
    }

    #[test]
    fn survives_truncated_and_deeply_nested_input() {
        let deep = "[".repeat(10_000);
        assert_eq!(
            SpanTree::parse(&deep).locate(&[Seg::Index(0)]),
            Pos { line: 1, col: 2 }
        );
        for cut in 0..TEXT.len() {
            if TEXT.is_char_boundary(cut) {
                SpanTree::parse(&TEXT[..cut]);
            }
        }
    }
}
