//! Shared helpers of the text formats: UTF-8 check, tokens with line numbers, numbers.

use super::{IoError, Syntax, Want};

/// The file as text, or a parse error naming the line of the first byte that is not text
/// (binary garbage with a text extension).
pub(crate) fn as_text<'a>(
    bytes: &'a [u8],
    path: &str,
    format: &'static str,
) -> Result<&'a str, IoError> {
    let bad_at = match std::str::from_utf8(bytes) {
        Ok(s) => match s.find('\0') {
            // A UTF-8 byte-order mark is not part of the first keyword.
            None => return Ok(s.strip_prefix('\u{feff}').unwrap_or(s)),
            Some(i) => i,
        },
        Err(e) => e.valid_up_to(),
    };
    let line = 1 + bytes[..bad_at].iter().filter(|&&b| b == b'\n').count();
    Err(IoError::Parse {
        path: path.to_string(),
        format,
        line,
        defect: Syntax::Binary { byte: bad_at },
    })
}

/// The file as text where names and comments may hold any bytes: like [`as_text`], except
/// that a line whose first word is one of `name_keywords` (OBJ's `g`, `usemtl`, …), or whose
/// first byte that is not UTF-8 follows a `#`, has such bytes replaced by U+FFFD. Names and
/// comments carry nothing a mesh needs, and exporters write them in the user's code page (a
/// Latin-1 material name). Anywhere else, and a NUL byte anywhere, the file is binary data,
/// as with [`as_text`]; numbers are read from the same bytes either way.
pub(crate) fn as_text_with_names<'a>(
    bytes: &'a [u8],
    path: &str,
    format: &'static str,
    name_keywords: &[&str],
) -> Result<std::borrow::Cow<'a, str>, IoError> {
    let strict = as_text(bytes, path, format);
    if strict.is_ok() || bytes.contains(&0) {
        return strict.map(std::borrow::Cow::Borrowed);
    }
    let all = bytes.len();
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut text = String::with_capacity(bytes.len());
    let mut start = all - bytes.len();
    for (line_index, line) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        match std::str::from_utf8(line) {
            Ok(s) => text.push_str(s),
            Err(e) => {
                let bad = e.valid_up_to();
                let word = line
                    .split(|b| b.is_ascii_whitespace())
                    .find(|w| !w.is_empty())
                    .unwrap_or(&[]);
                let named = name_keywords.iter().any(|k| k.as_bytes() == word);
                let commented = line[..bad].contains(&b'#');
                if !(named || commented) {
                    return Err(IoError::Parse {
                        path: path.to_string(),
                        format,
                        line: line_index + 1,
                        defect: Syntax::BinaryOutsideNames { byte: start + bad },
                    });
                }
                text.push_str(&String::from_utf8_lossy(line));
            }
        }
        start += line.len();
    }
    Ok(std::borrow::Cow::Owned(text))
}

/// The lines of `text`, ended by `\n`, `\r\n` or a lone `\r` (classic Mac OS files:
/// `str::lines` would read such a file as one line), without their line ends.
pub(crate) fn lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = Some(text);
    std::iter::from_fn(move || {
        let s = rest?;
        match s.find(['\n', '\r']) {
            Some(i) => {
                let skip = if s[i..].starts_with("\r\n") { 2 } else { 1 };
                rest = Some(&s[i + skip..]).filter(|r| !r.is_empty());
                Some(&s[..i])
            }
            None => {
                rest = None;
                Some(s)
            }
        }
    })
}

/// A UTF-8 byte-order mark at the start of `bytes` when `magic` follows it (so a binary
/// file that happens to start with those bytes is left alone): the bytes after it.
pub(crate) fn strip_bom_before<'a>(bytes: &'a [u8], magic: &[u8]) -> &'a [u8] {
    match bytes.strip_prefix(b"\xEF\xBB\xBF") {
        Some(rest) if rest.starts_with(magic) => rest,
        _ => bytes,
    }
}

/// Whitespace-separated tokens with their 1-based line, `#` comments removed.
pub(crate) struct Tokens<'a> {
    lines: Box<dyn Iterator<Item = (usize, &'a str)> + 'a>,
    cur: std::str::SplitAsciiWhitespace<'a>,
    line: usize,
    /// Line of the last token returned (or of the end of the file).
    pub(crate) last_line: usize,
    first: usize,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        Self::starting_at(text, 1)
    }

    /// Tokens of `text` whose first line is line `first` of the file.
    pub(crate) fn starting_at(text: &'a str, first: usize) -> Self {
        Tokens {
            lines: Box::new(lines(text).enumerate()),
            cur: "".split_ascii_whitespace(),
            line: first.saturating_sub(1),
            last_line: first.saturating_sub(1),
            first,
        }
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = (usize, &'a str);
    fn next(&mut self) -> Option<(usize, &'a str)> {
        loop {
            if let Some(t) = self.cur.next() {
                self.last_line = self.line;
                return Some((self.line, t));
            }
            let (i, l) = self.lines.next()?;
            self.line = i + self.first;
            self.last_line = self.line;
            let l = l.split('#').next().unwrap_or("");
            self.cur = l.split_ascii_whitespace();
        }
    }
}

/// Parse a float token (NaN and infinities parse; the caller rejects them by vertex).
pub(crate) fn float(
    tok: &str,
    line: usize,
    path: &str,
    format: &'static str,
) -> Result<f64, IoError> {
    tok.parse::<f64>().map_err(|_| IoError::Parse {
        path: path.to_string(),
        format,
        line,
        defect: Syntax::Expected {
            expected: Want::Number,
            found: short(tok),
        },
    })
}

/// Parse an integer token.
pub(crate) fn int(
    tok: &str,
    line: usize,
    path: &str,
    format: &'static str,
) -> Result<i64, IoError> {
    tok.parse::<i64>().map_err(|_| IoError::Parse {
        path: path.to_string(),
        format,
        line,
        defect: Syntax::Expected {
            expected: Want::Integer,
            found: short(tok),
        },
    })
}

/// Parse a non-negative count token.
pub(crate) fn count(
    tok: &str,
    line: usize,
    path: &str,
    format: &'static str,
) -> Result<u64, IoError> {
    tok.parse::<u64>().map_err(|_| IoError::Parse {
        path: path.to_string(),
        format,
        line,
        defect: Syntax::Expected {
            expected: Want::Count,
            found: short(tok),
        },
    })
}

/// A token shortened for a message.
pub(crate) fn short(tok: &str) -> String {
    if tok.chars().count() > 24 {
        format!("{}…", tok.chars().take(24).collect::<String>())
    } else {
        tok.to_string()
    }
}
