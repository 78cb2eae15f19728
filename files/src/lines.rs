//! BoundedLines from any `BufRead` with a hard length limit: an over-long line is skipped
//! without ever being held in memory whole (G-code files, `settle plan`'s input).

use std::io::{self, BufRead, Read};

/// What [`BoundedLines::next_line`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineStatus {
    /// The line is in [`BoundedLines::bytes`] (without its `\n` and a trailing `\r`).
    Complete,
    /// The line was longer than the limit; its bytes were discarded.
    TooLong,
}

/// A line splitter with a bounded buffer.
#[derive(Debug)]
pub struct BoundedLines<R> {
    input: R,
    buf: Vec<u8>,
    line_no: u64,
    max_bytes: usize,
    bytes_read: u64,
}

impl<R: BufRead> BoundedLines<R> {
    /// Lines of `input`, each at most `max_bytes` long (without its line end).
    pub fn new(input: R, max_bytes: usize) -> Self {
        BoundedLines {
            input,
            buf: Vec::new(),
            line_no: 0,
            max_bytes,
            bytes_read: 0,
        }
    }

    /// Reads the next line; `Ok(None)` at the end of the input.
    pub fn next_line(&mut self) -> io::Result<Option<LineStatus>> {
        self.buf.clear();
        // Two bytes more than the limit hold a `\r\n`; a line that fills them without a
        // newline is too long.
        let cap = self.max_bytes as u64 + 2;
        let n = (&mut self.input)
            .take(cap)
            .read_until(b'\n', &mut self.buf)?;
        if n == 0 {
            return Ok(None);
        }
        self.line_no += 1;
        self.bytes_read += n as u64;
        let complete = self.buf.last() == Some(&b'\n');
        if complete {
            self.buf.pop();
        } else if n as u64 == cap {
            // Hit the cap without a newline: discard the rest of the line unread.
            let skipped = self.input.skip_until(b'\n')?;
            self.bytes_read += skipped as u64;
            self.buf.clear();
            return Ok(Some(LineStatus::TooLong));
        }
        if self.buf.last() == Some(&b'\r') {
            self.buf.pop();
        }
        if self.buf.len() > self.max_bytes {
            self.buf.clear();
            return Ok(Some(LineStatus::TooLong));
        }
        Ok(Some(LineStatus::Complete))
    }

    /// The bytes of the last complete line.
    pub fn bytes(&self) -> &[u8] {
        &self.buf
    }

    /// The 1-based number of the last line read.
    pub fn line_no(&self) -> u64 {
        self.line_no
    }

    /// The input, to look at what it has buffered.
    pub fn get_ref(&self) -> &R {
        &self.input
    }

    /// Total bytes consumed from the input so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_and_limits() {
        let text = b"G1 X1\r\n\nabcdefghijk\nG1 X2";
        let mut l = BoundedLines::new(&text[..], 5);
        assert_eq!(
            l.next_line().expect("test input"),
            Some(LineStatus::Complete)
        );
        assert_eq!(l.bytes(), b"G1 X1");
        assert_eq!(
            l.next_line().expect("test input"),
            Some(LineStatus::Complete)
        );
        assert_eq!(l.bytes(), b"");
        assert_eq!(
            l.next_line().expect("test input"),
            Some(LineStatus::TooLong)
        );
        assert_eq!(l.line_no(), 3);
        assert_eq!(
            l.next_line().expect("test input"),
            Some(LineStatus::Complete)
        );
        assert_eq!(l.bytes(), b"G1 X2");
        assert_eq!(l.line_no(), 4);
        assert_eq!(l.next_line().expect("test input"), None);
        assert_eq!(l.bytes_read(), text.len() as u64);
    }
}
