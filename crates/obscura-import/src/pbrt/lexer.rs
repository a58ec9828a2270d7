//! pbrt-v4's tokens: quoted strings, numbers, bare words (directives, `true`, `false`),
//! brackets; `#` comments to the end of the line. Each token keeps its line and column.

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Kind {
    /// A quoted string, unescaped.
    Str(String),
    /// A number.
    Num(f64),
    /// A bare word: a directive name, `true` or `false`.
    Word(String),
    /// `[`
    Open,
    /// `]`
    Close,
}

/// A token and where it starts (1-based line, and 1-based column in bytes).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    pub(crate) kind: Kind,
    pub(crate) line: usize,
    pub(crate) column: usize,
}

/// Splits pbrt text into tokens; the error is (line, column, message).
pub(crate) fn tokenize(text: &str) -> Result<Vec<Token>, (usize, usize, String)> {
    let mut tokens = Vec::new();
    let mut chars = text.char_indices().peekable();
    let (mut line, mut line_start) = (1usize, 0usize);
    while let Some(&(at, c)) = chars.peek() {
        // In bytes, so a long line (pbrt exporters write whole meshes on one) costs nothing.
        let column = at - line_start + 1;
        let here = |kind| Token { kind, line, column };
        match c {
            '\n' => {
                chars.next();
                line += 1;
                line_start = at + 1;
            }
            c if c.is_whitespace() => {
                chars.next();
            }
            '#' => {
                while chars.peek().is_some_and(|&(_, c)| c != '\n') {
                    chars.next();
                }
            }
            '[' => {
                chars.next();
                tokens.push(here(Kind::Open));
            }
            ']' => {
                chars.next();
                tokens.push(here(Kind::Close));
            }
            '"' => {
                chars.next();
                let mut s = String::new();
                loop {
                    match chars.next() {
                        None => return Err((line, column, "unterminated string".into())),
                        Some((_, '"')) => break,
                        Some((_, '\n')) => {
                            return Err((
                                line,
                                column,
                                "a string runs past the end of its line".into(),
                            ));
                        }
                        Some((_, '\\')) => match chars.next() {
                            Some((_, 'n')) => s.push('\n'),
                            Some((_, 't')) => s.push('\t'),
                            Some((_, 'r')) => s.push('\r'),
                            Some((_, e @ ('\\' | '"' | '\''))) => s.push(e),
                            Some((_, 'b')) => s.push('\u{8}'),
                            Some((_, 'f')) => s.push('\u{c}'),
                            _ => return Err((line, column, "unknown escape in a string".into())),
                        },
                        Some((_, c)) => s.push(c),
                    }
                }
                tokens.push(here(Kind::Str(s)));
            }
            _ => {
                let start = at;
                let mut end = at;
                while let Some(&(i, c)) = chars.peek() {
                    if c.is_whitespace() || matches!(c, '[' | ']' | '"' | '#') {
                        break;
                    }
                    end = i + c.len_utf8();
                    chars.next();
                }
                let word = &text[start..end];
                let numeric = word
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_ascii_digit() || matches!(c, '-' | '+' | '.'));
                if numeric {
                    let v: f64 = word
                        .parse()
                        .map_err(|_| (line, column, format!("`{word}` is not a number")))?;
                    if !v.is_finite() {
                        return Err((line, column, format!("`{word}` is not a finite number")));
                    }
                    tokens.push(here(Kind::Num(v)));
                } else if word.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                    tokens.push(here(Kind::Word(word.to_string())));
                } else {
                    return Err((line, column, format!("unexpected `{word}`")));
                }
            }
        }
    }
    Ok(tokens)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn tokens_carry_lines_and_columns() {
        let t = tokenize("LookAt 0 1 -2.5e1 # comment\n  \"float fov\" [ 45 ]").unwrap();
        let kinds: Vec<_> = t.iter().map(|t| t.kind.clone()).collect();
        assert_eq!(
            kinds,
            vec![
                Kind::Word("LookAt".into()),
                Kind::Num(0.0),
                Kind::Num(1.0),
                Kind::Num(-25.0),
                Kind::Str("float fov".into()),
                Kind::Open,
                Kind::Num(45.0),
                Kind::Close,
            ]
        );
        assert_eq!((t[4].line, t[4].column), (2, 3));
        assert_eq!((t[6].line, t[6].column), (2, 17));
    }

    #[test]
    fn bad_tokens_name_their_place() {
        assert_eq!(tokenize("Shape\n  \"sphere").unwrap_err().0, 2);
        let (line, column, _) = tokenize("a 1x").unwrap_err();
        assert_eq!((line, column), (1, 3));
        assert!(tokenize("1e999").is_err());
    }

    proptest! {
        #[test]
        fn any_text_tokenizes_or_errs(s in "\\PC{0,200}") {
            let _ = tokenize(&s);
        }
    }
}
