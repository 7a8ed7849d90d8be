//! Arithmetic for buffer sizes: `"pixels * 4"`, `"(width / $tile + 1) * 64"`, `"$tile_bytes * 64"`.
//! Numbers, variables, `+ - * /` and parentheses; errors name the column.

use std::collections::BTreeMap;

/// Why an expression could not be evaluated, with the 0-based character offset.
#[derive(Debug, Clone, PartialEq)]
pub struct ExprError {
    pub offset: usize,
    pub message: String,
}

/// Evaluates `text` with the given variables (names without `$`; `$name` and `name` both resolve).
pub fn eval(text: &str, vars: &BTreeMap<String, f64>) -> Result<f64, ExprError> {
    let mut parser = Parser {
        chars: text.chars().collect(),
        at: 0,
        vars,
    };
    let value = parser.sum()?;
    parser.skip_ws();
    if parser.at < parser.chars.len() {
        return Err(parser.error(format!("unexpected '{}'", parser.chars[parser.at])));
    }
    Ok(value)
}

struct Parser<'a> {
    chars: Vec<char>,
    at: usize,
    vars: &'a BTreeMap<String, f64>,
}

impl Parser<'_> {
    fn error(&self, message: String) -> ExprError {
        ExprError {
            offset: self.at,
            message,
        }
    }

    fn skip_ws(&mut self) {
        while self.chars.get(self.at).is_some_and(|c| c.is_whitespace()) {
            self.at += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_ws();
        self.chars.get(self.at).copied()
    }

    fn sum(&mut self) -> Result<f64, ExprError> {
        let mut value = self.product()?;
        while let Some(op @ ('+' | '-')) = self.peek() {
            self.at += 1;
            let rhs = self.product()?;
            value = if op == '+' { value + rhs } else { value - rhs };
        }
        Ok(value)
    }

    fn product(&mut self) -> Result<f64, ExprError> {
        let mut value = self.atom()?;
        while let Some(op @ ('*' | '/')) = self.peek() {
            self.at += 1;
            let at = self.at;
            let rhs = self.atom()?;
            if op == '/' && rhs == 0.0 {
                return Err(ExprError {
                    offset: at,
                    message: "division by zero".into(),
                });
            }
            value = if op == '*' { value * rhs } else { value / rhs };
        }
        Ok(value)
    }

    fn atom(&mut self) -> Result<f64, ExprError> {
        match self.peek() {
            Some('(') => {
                self.at += 1;
                let value = self.sum()?;
                if self.peek() != Some(')') {
                    return Err(self.error("expected ')'".into()));
                }
                self.at += 1;
                Ok(value)
            }
            Some('-') => {
                self.at += 1;
                Ok(-self.atom()?)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => {
                let start = self.at;
                while self
                    .chars
                    .get(self.at)
                    .is_some_and(|c| c.is_ascii_digit() || *c == '.' || *c == '_')
                {
                    self.at += 1;
                }
                let text: String = self.chars[start..self.at]
                    .iter()
                    .filter(|c| **c != '_')
                    .collect();
                text.parse().map_err(|_| ExprError {
                    offset: start,
                    message: format!("malformed number \"{text}\""),
                })
            }
            Some(c) if c.is_alphabetic() || c == '_' || c == '$' => {
                let start = self.at;
                if c == '$' {
                    self.at += 1;
                }
                let name_start = self.at;
                while self
                    .chars
                    .get(self.at)
                    .is_some_and(|c| c.is_alphanumeric() || *c == '_')
                {
                    self.at += 1;
                }
                let name: String = self.chars[name_start..self.at].iter().collect();
                self.vars.get(&name).copied().ok_or(ExprError {
                    offset: start,
                    message: format!("unknown variable \"{name}\""),
                })
            }
            Some(c) => Err(self.error(format!("unexpected '{c}'"))),
            None => Err(self.error("unexpected end of expression".into())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars() -> BTreeMap<String, f64> {
        [("lights", 100.0), ("pixels", 921_600.0), ("tile", 16.0)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }

    #[test]
    fn evaluates_with_precedence_and_parentheses() {
        assert_eq!(eval("lights * 32 + 16", &vars()), Ok(3216.0));
        assert_eq!(eval("(lights + 4) * 2", &vars()), Ok(208.0));
        assert_eq!(eval("pixels / 4 - -1", &vars()), Ok(230_401.0));
        assert_eq!(eval("$tile * 1_024", &vars()), Ok(16_384.0));
    }

    #[test]
    fn errors_name_the_offset() {
        let e = eval("lights * lihgts", &vars()).unwrap_err();
        assert_eq!(
            (e.offset, e.message.as_str()),
            (9, "unknown variable \"lihgts\"")
        );
        assert_eq!(eval("(1 + 2", &vars()).unwrap_err().offset, 6);
        assert_eq!(
            eval("4 / 0", &vars()).unwrap_err().message,
            "division by zero"
        );
        assert_eq!(eval("3 3", &vars()).unwrap_err().message, "unexpected '3'");
    }
}
