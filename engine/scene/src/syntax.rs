//! The `.scene` text layer: lines, comments, quoted strings, numbers and `{ }` blocks,
//! before any meaning is given to object or property names.

use crate::error::{Diagnostics, Location, SceneError};
use std::path::Path;

/// One field of a property.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    /// A finite number.
    Num(f64),
    /// A quoted string.
    Str(String),
    /// An unquoted word that is not a number.
    Word(String),
}

impl Value {
    /// How the value reads in a message.
    pub(crate) fn describe(&self) -> String {
        match self {
            Value::Num(n) => n.to_string(),
            Value::Str(s) => format!("\"{s}\""),
            Value::Word(w) => format!("'{w}'"),
        }
    }
}

/// A property line inside a block: a name and its fields.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Prop {
    /// The name, with a trailing colon already removed.
    pub name: String,
    /// The 1-based line.
    pub line: usize,
    /// The fields in order.
    pub values: Vec<Value>,
}

/// An object: its type name, an optional label (`camera "front"`), and its properties in order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Block {
    /// The type name (`model`, `sunlight`, ...).
    pub kind: String,
    /// The optional label after the type name.
    pub label: Option<String>,
    /// The line of the type name.
    pub line: usize,
    /// The properties in line order.
    pub props: Vec<Prop>,
}

/// A top-level statement.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Item {
    /// An object block.
    Block(Block),
    /// `include "file"`.
    Include {
        /// The path as written.
        path: String,
        /// Its line.
        line: usize,
    },
    /// `script "file.rhai"`: a Rhai script that adds to the scene and animates it.
    Script {
        /// The path as written.
        path: String,
        /// Its line.
        line: usize,
    },
}

/// A token of one line.
#[derive(Debug, PartialEq)]
enum Token<'a> {
    Bare(&'a str),
    Quoted(&'a str),
}

/// Splits a line into tokens, stopping at a `#` comment.
fn tokenize<'a>(text: &'a str, file: &Path, line: usize) -> Result<Vec<Token<'a>>, SceneError> {
    let mut tokens = Vec::new();
    let mut rest = text.trim_start();
    while !rest.is_empty() {
        if rest.starts_with('#') {
            break;
        }
        if let Some(after) = rest.strip_prefix('"') {
            let Some(end) = after.find('"') else {
                return Err(SceneError::syntax(
                    file,
                    line,
                    "unterminated string (missing '\"')",
                ));
            };
            tokens.push(Token::Quoted(&after[..end]));
            rest = after[end + 1..].trim_start();
        } else {
            let end = rest
                .find(|c: char| c.is_whitespace() || c == '"')
                .unwrap_or(rest.len());
            tokens.push(Token::Bare(&rest[..end]));
            rest = rest[end..].trim_start();
        }
    }
    Ok(tokens)
}

/// Reads a bare token as a number when it looks like one, rejecting NaN, infinity and overflow.
fn value_of(token: &Token<'_>, file: &Path, line: usize) -> Result<Value, SceneError> {
    let text = match token {
        Token::Quoted(s) => return Ok(Value::Str((*s).to_string())),
        Token::Bare(s) => *s,
    };
    let looks_numeric = text
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.'));
    if !looks_numeric {
        return Ok(Value::Word(text.to_string()));
    }
    let parsed: f64 = text
        .parse()
        .map_err(|_| SceneError::syntax(file, line, format!("malformed number '{text}'")))?;
    if !parsed.is_finite() || parsed.abs() > f64::from(f32::MAX) {
        return Err(SceneError::syntax(
            file,
            line,
            format!("number '{text}' is not a finite 32-bit float"),
        ));
    }
    Ok(Value::Num(parsed))
}

/// A block whose `{` has not been seen yet, or whose properties are being read.
enum State {
    Top,
    AwaitOpen(Block),
    Inside(Block),
}

/// Parses `.scene` text into top-level items; warnings go to `diag`.
pub(crate) fn parse(
    text: &str,
    file: &Path,
    diag: &mut Diagnostics,
) -> Result<Vec<Item>, SceneError> {
    let mut items = Vec::new();
    let mut state = State::Top;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let tokens = tokenize(raw, file, line)?;
        if tokens.is_empty() {
            continue;
        }
        state = match state {
            State::Top => top_level(&tokens, file, line, &mut items)?,
            State::AwaitOpen(block) => {
                if tokens != [Token::Bare("{")] {
                    return Err(SceneError::syntax(
                        file,
                        line,
                        format!(
                            "expected '{{' to open '{}' (line {})",
                            block.kind, block.line
                        ),
                    ));
                }
                State::Inside(block)
            }
            State::Inside(mut block) => match tokens.first() {
                Some(Token::Bare("}")) if tokens.len() == 1 => {
                    items.push(Item::Block(block));
                    State::Top
                }
                Some(Token::Bare(closing)) if closing.starts_with('}') => {
                    return Err(SceneError::syntax(
                        file,
                        line,
                        format!(
                            "expected '}}' alone on its line to close '{}' (line {}), found '{}'",
                            block.kind,
                            block.line,
                            raw.trim()
                        ),
                    ))
                }
                Some(Token::Bare("{")) => {
                    return Err(SceneError::syntax(
                        file,
                        line,
                        format!(
                            "unexpected '{{': '{}' opened at line {} is not closed",
                            block.kind, block.line
                        ),
                    ))
                }
                _ => {
                    block.props.push(property(&tokens, file, line, diag)?);
                    State::Inside(block)
                }
            },
        };
    }
    match state {
        State::Top => Ok(items),
        State::AwaitOpen(block) | State::Inside(block) => Err(SceneError::syntax(
            file,
            block.line,
            format!(
                "'{}' is never closed (missing '}}' before the end of the file)",
                block.kind
            ),
        )),
    }
}

/// Handles a line outside any block: an object header, an include or a script.
fn top_level(
    tokens: &[Token<'_>],
    file: &Path,
    line: usize,
    items: &mut Vec<Item>,
) -> Result<State, SceneError> {
    let kind = match tokens[0] {
        Token::Bare(closing) if closing.starts_with('}') => {
            return Err(SceneError::syntax(file, line, "'}' without an open object"))
        }
        Token::Bare("{") => {
            return Err(SceneError::syntax(
                file,
                line,
                "'{' without an object name before it",
            ))
        }
        Token::Bare(word) => word,
        Token::Quoted(_) => {
            return Err(SceneError::syntax(
                file,
                line,
                "expected an object name, found a string",
            ))
        }
    };
    if kind == "include" {
        return match tokens {
            [_, Token::Quoted(path)] => {
                items.push(Item::Include {
                    path: (*path).to_string(),
                    line,
                });
                Ok(State::Top)
            }
            _ => Err(SceneError::syntax(file, line, "expected include \"FILE\"")),
        };
    }
    if kind == "script" {
        return match tokens {
            [_, Token::Quoted(path)] => {
                items.push(Item::Script {
                    path: (*path).to_string(),
                    line,
                });
                Ok(State::Top)
            }
            _ => Err(SceneError::syntax(
                file,
                line,
                "expected script \"FILE.rhai\"",
            )),
        };
    }
    let (label, opened) = match &tokens[1..] {
        [] => (None, false),
        [Token::Bare("{")] => (None, true),
        [Token::Quoted(l) | Token::Bare(l)] => (Some((*l).to_string()), false),
        [Token::Quoted(l) | Token::Bare(l), Token::Bare("{")] => (Some((*l).to_string()), true),
        _ => {
            return Err(SceneError::syntax(
                file,
                line,
                format!(
                    "expected an object name on its own line, found '{kind}' followed by {} fields",
                    tokens.len() - 1
                ),
            ))
        }
    };
    let block = Block {
        kind: kind.to_string(),
        label,
        line,
        props: Vec::new(),
    };
    Ok(if opened {
        State::Inside(block)
    } else {
        State::AwaitOpen(block)
    })
}

/// Reads a property line, accepting (with a warning) a trailing colon after the name.
fn property(
    tokens: &[Token<'_>],
    file: &Path,
    line: usize,
    diag: &mut Diagnostics,
) -> Result<Prop, SceneError> {
    let Token::Bare(raw_name) = tokens[0] else {
        return Err(SceneError::syntax(
            file,
            line,
            "expected a property name, found a string",
        ));
    };
    let name = match raw_name.strip_suffix(':') {
        Some(stripped) if !stripped.is_empty() => {
            diag.warn(
                Location::line(file, line),
                format!("property name '{raw_name}' has a trailing colon; read as '{stripped}'"),
            );
            stripped
        }
        _ => raw_name,
    };
    let values = tokens[1..]
        .iter()
        .map(|t| value_of(t, file, line))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Prop {
        name: name.to_string(),
        line,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_ok(text: &str) -> (Vec<Item>, Vec<String>) {
        let mut diag = Diagnostics::default();
        let items = parse(text, Path::new("t.scene"), &mut diag).expect("parses");
        (items, diag.warnings.iter().map(|w| w.to_string()).collect())
    }

    fn parse_err(text: &str) -> String {
        let mut diag = Diagnostics::default();
        parse(text, Path::new("t.scene"), &mut diag)
            .expect_err("fails")
            .to_string()
    }

    #[test]
    fn blocks_properties_and_comments() {
        let (items, warnings) =
            parse_ok("# c\nmodel\n{\n\tfile \"a b.obj\" # trailing\n\tscale 1 -2.5 3e1\n}\ncamera \"front\" {\n}\n");
        assert!(warnings.is_empty());
        assert_eq!(
            items,
            vec![
                Item::Block(Block {
                    kind: "model".into(),
                    label: None,
                    line: 2,
                    props: vec![
                        Prop {
                            name: "file".into(),
                            line: 4,
                            values: vec![Value::Str("a b.obj".into())]
                        },
                        Prop {
                            name: "scale".into(),
                            line: 5,
                            values: vec![Value::Num(1.0), Value::Num(-2.5), Value::Num(30.0)]
                        },
                    ],
                }),
                Item::Block(Block {
                    kind: "camera".into(),
                    label: Some("front".into()),
                    line: 7,
                    props: vec![]
                }),
            ]
        );
    }

    #[test]
    fn trailing_colon_is_a_warning() {
        let (items, warnings) = parse_ok("sunlight\n{\n\tcolor: 1 1 1\n}");
        let Item::Block(b) = &items[0] else {
            panic!("not a block")
        };
        assert_eq!(b.props[0].name, "color");
        assert_eq!(
            warnings,
            vec![
                "t.scene:3: warning: property name 'color:' has a trailing colon; read as 'color'"
            ]
        );
    }

    #[test]
    fn located_errors() {
        assert_eq!(
            parse_err("sunlight\n{\nintensity 1\n}}\n"),
            "t.scene:4: expected '}' alone on its line to close 'sunlight' (line 1), found '}}'"
        );
        assert_eq!(
            parse_err("\u{feff}sunlight\n{\n}\n}}\n"),
            "t.scene:4: '}' without an open object"
        );
        assert_eq!(
            parse_err("model\n{\nscale 1 x2 nan\n"),
            "t.scene:1: 'model' is never closed (missing '}' before the end of the file)"
        );
        assert_eq!(
            parse_err("model\n{\nscale 1 2.5.1 3\n}"),
            "t.scene:3: malformed number '2.5.1'"
        );
        assert_eq!(
            parse_err("model\n{\nscale 1 -inf 3\n}"),
            "t.scene:3: number '-inf' is not a finite 32-bit float"
        );
        assert_eq!(
            parse_err("model\n{\nscale 1e39 1 3\n}"),
            "t.scene:3: number '1e39' is not a finite 32-bit float"
        );
        assert_eq!(
            parse_err("model\nscale 1\n"),
            "t.scene:2: expected '{' to open 'model' (line 1)"
        );
        assert_eq!(parse_err("}\n"), "t.scene:1: '}' without an open object");
        assert_eq!(
            parse_err("a\n{\nfile \"x\n}"),
            "t.scene:3: unterminated string (missing '\"')"
        );
        assert_eq!(
            parse_err("a\n{\nb\n{\n}"),
            "t.scene:4: unexpected '{': 'a' opened at line 1 is not closed"
        );
        assert_eq!(
            parse_err("include x.scene"),
            "t.scene:1: expected include \"FILE\""
        );
    }
}
