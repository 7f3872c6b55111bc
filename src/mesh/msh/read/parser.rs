//! The byte parser: a cursor over the file's bytes that reads ASCII tokens (a line's entry
//! at a time) and binary fields, exact integer and float parsing, and errors that name the
//! line (ASCII) or the byte offset (binary).

use crate::mesh::ReadError;
use std::path::Path;

pub(super) fn parse_u64(t: &[u8]) -> Option<u64> {
    if t.is_empty() || t.len() > 20 {
        return None;
    }
    let mut v: u64 = 0;
    for &c in t {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(u64::from(d))?;
    }
    Some(v)
}

fn parse_i64(t: &[u8]) -> Option<i64> {
    match t.split_first() {
        Some((b'-', rest)) => parse_u64(rest)
            .filter(|&v| v <= i64::MAX as u64 + 1)
            .map(|v| (v as i64).wrapping_neg()),
        Some((b'+', rest)) => parse_u64(rest).and_then(|v| i64::try_from(v).ok()),
        _ => parse_u64(t).and_then(|v| i64::try_from(v).ok()),
    }
}

fn parse_f64(t: &[u8]) -> Option<f64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// Shows a token in a message: at most 40 characters, non-printable bytes escaped.
pub(super) fn show(t: &[u8]) -> String {
    let s: String = t
        .iter()
        .take(40)
        .flat_map(|&c| std::ascii::escape_default(c))
        .map(char::from)
        .collect();
    if t.len() > 40 { format!("{s}...") } else { s }
}

#[derive(Clone)]
pub(super) struct Parser<'a> {
    pub(super) path: &'a Path,
    pub(super) b: &'a [u8],
    pub(super) pos: usize,
    pub(super) binary: bool,
    /// Inside one entry of an ASCII section (a node, an element, a header): its values are
    /// on one line, so tokens do not cross a line end (see [`Parser::entry_end`]).
    pub(super) in_line: bool,
}

pub(super) type Res<T> = Result<T, ReadError>;

impl<'a> Parser<'a> {
    pub(super) fn line_of(&self, pos: usize) -> usize {
        1 + self.b[..pos.min(self.b.len())]
            .iter()
            .filter(|&&c| c == b'\n')
            .count()
    }

    /// An error at position `pos`: its line in an ASCII file, its byte offset in a binary one
    /// (where binary data make line numbers meaningless).
    pub(super) fn err(&self, pos: usize, message: impl Into<String>) -> ReadError {
        if self.binary {
            return self.err_bin(pos, message.into());
        }
        ReadError::Syntax {
            path: self.path.to_path_buf(),
            line: self.line_of(pos),
            message: message.into(),
        }
    }

    /// An error inside binary data at byte offset `pos`.
    pub(super) fn err_bin(&self, pos: usize, message: impl std::fmt::Display) -> ReadError {
        ReadError::Io {
            path: self.path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("byte offset {pos}: {message}"),
            ),
        }
    }

    pub(super) fn skip_ws(&mut self) {
        let b = self.b;
        if self.in_line {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() && b[self.pos] != b'\n' {
                self.pos += 1;
            }
        } else {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
        }
    }

    /// From here to [`Parser::entry_end`], the values read are on the current line.
    #[inline]
    pub(super) fn entry_start(&mut self) {
        self.in_line = !self.binary;
    }

    /// Ends an entry begun with [`Parser::entry_start`]: the rest of its line must be blank
    /// (`what` names the entry). A value left over means the line holds more than its entry
    /// (Gmsh writes one entry per line), which would shift every later read.
    pub(super) fn entry_end(&mut self, what: &dyn Fn() -> String) -> Res<()> {
        if !self.in_line {
            return Ok(());
        }
        self.skip_ws();
        self.in_line = false;
        if self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            let at = self.pos;
            let t = self.token().map_or(&b""[..], |(_, t)| t);
            return Err(self.err(
                at,
                format!(
                    "unexpected `{}` after {}: the line holds more values than it should",
                    show(t),
                    what()
                ),
            ));
        }
        Ok(())
    }

    /// Next whitespace-separated token and its position, or `None` at the end of the file.
    #[inline]
    pub(super) fn token(&mut self) -> Option<(usize, &'a [u8])> {
        self.skip_ws();
        let start = self.pos;
        let b = self.b;
        let mut p = start;
        while p < b.len() && !b[p].is_ascii_whitespace() {
            p += 1;
        }
        self.pos = p;
        if p == start {
            None
        } else {
            Some((start, &b[start..p]))
        }
    }

    /// Next token, or an error saying the file ends inside `section`.
    #[inline]
    pub(super) fn need(
        &mut self,
        section: &str,
        what: &dyn Fn() -> String,
    ) -> Res<(usize, &'a [u8])> {
        match self.token() {
            Some(t) => Ok(t),
            None if self.pos < self.b.len() => Err(self.err(
                self.pos,
                format!(
                    "the line ends where {} was expected (the values of an entry are on one line)",
                    what()
                ),
            )),
            None => Err(self.err(
                self.b.len(),
                format!(
                    "file is truncated: it ends inside {section} while {} was expected (missing $End{})",
                    what(),
                    section.trim_start_matches('$')
                ),
            )),
        }
    }

    pub(super) fn bad_token(
        &self,
        pos: usize,
        tok: &[u8],
        section: &str,
        what: &dyn Fn() -> String,
    ) -> ReadError {
        if tok.first() == Some(&b'$') {
            self.err(
                pos,
                format!(
                    "found `{}` where {} was expected: {section} holds fewer entries than its header announces",
                    show(tok),
                    what()
                ),
            )
        } else {
            self.err(pos, format!("expected {}, found `{}`", what(), show(tok)))
        }
    }

    #[inline]
    pub(super) fn uint(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<u64> {
        let (p, t) = self.need(section, what)?;
        parse_u64(t).ok_or_else(|| self.bad_token(p, t, section, what))
    }

    #[inline]
    pub(super) fn int(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<i64> {
        let (p, t) = self.need(section, what)?;
        parse_i64(t).ok_or_else(|| self.bad_token(p, t, section, what))
    }

    #[inline]
    pub(super) fn float(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<(usize, f64)> {
        let (p, t) = self.need(section, what)?;
        parse_f64(t)
            .map(|v| (p, v))
            .ok_or_else(|| self.bad_token(p, t, section, what))
    }

    /// A `size_t` field of an MSH 4.1 header: 8 little-endian bytes in a binary file, an
    /// unsigned token in an ASCII one.
    pub(super) fn size_t(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<u64> {
        if self.binary {
            self.bin_u64(section, what)
        } else {
            self.uint(section, what)
        }
    }

    /// An `int` field of an MSH 4.1 header: 4 little-endian bytes in a binary file, a
    /// signed token in an ASCII one.
    pub(super) fn int_field(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<i64> {
        if self.binary {
            self.bin_i32(section, what).map(i64::from)
        } else {
            self.int(section, what)
        }
    }

    /// A `double` field: 8 little-endian bytes in a binary file, a token in an ASCII one.
    pub(super) fn double_field(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<f64> {
        if self.binary {
            let s = self.take(8, section, what)?;
            Ok(f64_at(s, 0))
        } else {
            self.float(section, what).map(|(_, v)| v)
        }
    }

    /// Skips the rest of the current line (ASCII element lines of types without a fixed
    /// number of nodes) and ends the entry.
    pub(super) fn skip_line(&mut self) {
        while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            self.pos += 1;
        }
        self.in_line = false;
    }

    /// Expects the `$End...` token closing `section`, after `count` entries.
    pub(super) fn end(&mut self, section: &str, count: &dyn Fn() -> String) -> Res<()> {
        let end = format!("$End{}", section.trim_start_matches('$'));
        match self.token() {
            Some((_, t)) if t == end.as_bytes() => Ok(()),
            Some((p, t)) => Err(self.err(
                p,
                format!(
                    "expected {end} after {}, found `{}`: {section} holds more than its header announces, or is not closed",
                    count(),
                    show(t)
                ),
            )),
            None => Err(self.err(
                self.b.len(),
                format!("file is truncated: missing {end} (the file ends inside {section})"),
            )),
        }
    }

    /// Skips a section we do not read, up to its `$End...` marker.
    pub(super) fn skip_section(&mut self, start: usize, name: &[u8]) -> Res<()> {
        let mut end = b"$End".to_vec();
        end.extend_from_slice(&name[1..]);
        let hay = &self.b[self.pos..];
        match hay.windows(end.len()).position(|w| w == end.as_slice()) {
            Some(i) => {
                self.pos += i + end.len();
                Ok(())
            }
            None => Err(self.err(
                start,
                format!(
                    "file is truncated: section {} is never closed (missing {})",
                    show(name),
                    show(&end)
                ),
            )),
        }
    }

    /// After a section header in a binary file: the single newline before the binary data
    /// (nothing in an ASCII file, where the newline is whitespace).
    pub(super) fn binary_data_start(&mut self) {
        if !self.binary {
            return;
        }
        if self.b.get(self.pos) == Some(&b'\r') {
            self.pos += 1;
        }
        if self.b.get(self.pos) == Some(&b'\n') {
            self.pos += 1;
        }
    }

    /// `n` bytes of binary data, or a truncation error naming `what`.
    #[inline]
    pub(super) fn take(
        &mut self,
        n: usize,
        section: &str,
        what: &dyn Fn() -> String,
    ) -> Res<&'a [u8]> {
        let left = self.b.len() - self.pos;
        if n > left {
            return Err(self.err_bin(
                self.pos,
                format!(
                    "file is truncated inside {section}: {} needs {n} bytes, {left} left",
                    what()
                ),
            ));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    pub(super) fn bin_i32(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<i32> {
        let s = self.take(4, section, what)?;
        Ok(i32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }

    fn bin_u64(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<u64> {
        let s = self.take(8, section, what)?;
        Ok(u64_at(s, 0))
    }

    /// `count * size` bytes, checked for overflow and truncation.
    pub(super) fn take_array(
        &mut self,
        count: u64,
        size: usize,
        section: &str,
        what: &dyn Fn() -> String,
    ) -> Res<&'a [u8]> {
        let n = usize::try_from(count)
            .ok()
            .and_then(|c| c.checked_mul(size))
            .ok_or_else(|| {
                self.err_bin(self.pos, format!("{}: count {count} is too large", what()))
            })?;
        self.take(n, section, what)
    }
}

#[inline]
pub(super) fn u64_at(s: &[u8], i: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&s[i..i + 8]);
    u64::from_le_bytes(a)
}

#[inline]
pub(super) fn f64_at(s: &[u8], i: usize) -> f64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&s[i..i + 8]);
    f64::from_le_bytes(a)
}

#[inline]
pub(super) fn i32_at(s: &[u8], i: usize) -> i32 {
    i32::from_le_bytes([s[i], s[i + 1], s[i + 2], s[i + 3]])
}

/// A capacity for `count` items of at least `min_bytes` each that the file can really hold.
pub(super) fn cap(count: u64, min_bytes: usize, bytes_left: usize) -> usize {
    (count.min((bytes_left / min_bytes.max(1)) as u64)) as usize
}

/// Checks that a node's coordinates are finite.
pub(super) fn check_finite(p: &Parser<'_>, at: usize, tag: u64, x: [f64; 3]) -> Res<()> {
    if x.iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    let msg = format!(
        "node {tag} has a non-finite coordinate ({}, {}, {})",
        x[0], x[1], x[2]
    );
    Err(p.err(at, msg))
}

pub(super) fn to_i32(p: &Parser<'_>, at: usize, v: i64, what: &str) -> Res<i32> {
    i32::try_from(v).map_err(|_| {
        let msg = format!("{what} {v} is out of range");
        p.err(at, msg)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_parse_exactly_or_not_at_all() {
        assert_eq!(parse_u64(b"0"), Some(0));
        assert_eq!(parse_u64(b"18446744073709551615"), Some(u64::MAX));
        assert_eq!(parse_u64(b"18446744073709551616"), None);
        assert_eq!(parse_u64(b"-1"), None);
        assert_eq!(parse_u64(b"1.0"), None);
        assert_eq!(parse_u64(b""), None);
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"-9223372036854775809"), None);
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"+5"), Some(5));
        assert_eq!(parse_i64(b"-"), None);
    }

    #[test]
    fn shown_tokens_are_short_and_printable() {
        assert_eq!(show(b"ab\x01"), "ab\\x01");
        assert!(show(&[b'x'; 100]).ends_with("..."));
    }
}
