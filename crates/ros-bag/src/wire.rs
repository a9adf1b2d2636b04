//! The two wire encodings of ROS messages, read and written by hand.
//!
//! * **CDR** (ROS 2, `message_encoding` `cdr` in MCAP): a 4-byte encapsulation header (`00 01`
//!   little-endian, `00 00` big-endian, then two option bytes), then every primitive aligned to
//!   its size relative to the end of that header; strings are a `u32` length that counts a
//!   trailing NUL; sequences are a `u32` count.
//! * **ROS 1** serialisation (`.bag`): little-endian, no alignment, strings without NUL.
//!
//! One reader serves both, for the few message types this crate decodes. A serde CDR crate
//! would cover only ROS 2 and would not give what this reader does: the byte offset and the
//! field name in every error, and a check of every sequence length against the bytes left
//! before anything is allocated.

use std::fmt;

/// How a message's bytes are encoded.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// OMG CDR with its encapsulation header (ROS 2).
    Cdr,
    /// ROS 1 serialisation.
    Ros1,
}

impl fmt::Display for Encoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Encoding::Cdr => "cdr",
            Encoding::Ros1 => "ros1",
        })
    }
}

/// A message that cannot be decoded: where in the message and what was expected.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("byte {offset} of the message: {what}")]
pub struct WireError {
    /// Byte offset in the message's data.
    pub offset: u64,
    /// What was expected there.
    pub what: String,
}

/// Reads primitives from one message.
pub struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
    origin: usize,
    big_endian: bool,
    aligned: bool,
}

impl<'a> Reader<'a> {
    /// A reader of `data` in `encoding` (for CDR, after checking the encapsulation header).
    pub fn new(data: &'a [u8], encoding: Encoding) -> Result<Reader<'a>, WireError> {
        match encoding {
            Encoding::Ros1 => {
                Ok(Reader { data, pos: 0, origin: 0, big_endian: false, aligned: false })
            }
            Encoding::Cdr => {
                let head = data.get(..4).ok_or_else(|| WireError {
                    offset: 0,
                    what: format!(
                        "a 4-byte CDR encapsulation header, the message has {} bytes",
                        data.len()
                    ),
                })?;
                let big_endian = match (head[0], head[1]) {
                    (0, 0) => true,
                    (0, 1) => false,
                    (a, b) => {
                        return Err(WireError {
                            offset: 0,
                            what: format!(
                                "CDR encapsulation 00 00 or 00 01, found {a:02x} {b:02x}"
                            ),
                        });
                    }
                };
                Ok(Reader { data, pos: 4, origin: 4, big_endian, aligned: true })
            }
        }
    }

    /// The current byte offset.
    pub fn offset(&self) -> u64 {
        self.pos as u64
    }

    fn error(&self, what: String) -> WireError {
        WireError { offset: self.pos as u64, what }
    }

    fn align(&mut self, n: usize) {
        if self.aligned {
            let rel = self.pos - self.origin;
            self.pos += (n - rel % n) % n;
        }
    }

    fn take(&mut self, n: usize, field: &str) -> Result<&'a [u8], WireError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        match end {
            Some(end) => {
                let s = &self.data[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(self.error(format!(
                "{n} bytes of `{field}`, the message has {} bytes",
                self.data.len()
            ))),
        }
    }

    fn fixed<const N: usize>(&mut self, field: &str) -> Result<[u8; N], WireError> {
        self.align(N);
        let mut b = [0u8; N];
        b.copy_from_slice(self.take(N, field)?);
        if self.big_endian {
            b.reverse();
        }
        Ok(b)
    }

    /// A byte.
    pub fn u8(&mut self, field: &str) -> Result<u8, WireError> {
        Ok(self.take(1, field)?[0])
    }

    /// A boolean (any non-zero byte is true).
    pub fn bool(&mut self, field: &str) -> Result<bool, WireError> {
        Ok(self.u8(field)? != 0)
    }

    /// A `uint32`.
    pub fn u32(&mut self, field: &str) -> Result<u32, WireError> {
        Ok(u32::from_le_bytes(self.fixed(field)?))
    }

    /// An `int32`.
    pub fn i32(&mut self, field: &str) -> Result<i32, WireError> {
        Ok(i32::from_le_bytes(self.fixed(field)?))
    }

    /// A `float32`.
    pub fn f32(&mut self, field: &str) -> Result<f32, WireError> {
        Ok(f32::from_le_bytes(self.fixed(field)?))
    }

    /// A `float64`.
    pub fn f64(&mut self, field: &str) -> Result<f64, WireError> {
        Ok(f64::from_le_bytes(self.fixed(field)?))
    }

    /// A sequence count, checked against the bytes left (each element takes at least
    /// `min_size` bytes).
    pub fn count(&mut self, field: &str, min_size: usize) -> Result<usize, WireError> {
        let at = self.pos;
        let n = self.u32(field)? as usize;
        let left = self.data.len() - self.pos;
        if n.saturating_mul(min_size) > left {
            return Err(WireError {
                offset: at as u64,
                what: format!(
                    "`{field}` declares {n} elements of at least {min_size} bytes, {left} bytes are left"
                ),
            });
        }
        Ok(n)
    }

    /// A `uint8[]` sequence.
    pub fn bytes(&mut self, field: &str) -> Result<&'a [u8], WireError> {
        let n = self.count(field, 1)?;
        self.take(n, field)
    }

    /// A string (UTF-8; CDR's trailing NUL removed).
    pub fn string(&mut self, field: &str) -> Result<String, WireError> {
        let at = self.pos;
        let mut raw = self.bytes(field)?;
        if self.aligned {
            match raw.split_last() {
                Some((0, rest)) => raw = rest,
                _ => {
                    return Err(WireError {
                        offset: at as u64,
                        what: format!("`{field}`: a CDR string ends in NUL"),
                    });
                }
            }
        }
        String::from_utf8(raw.to_vec())
            .map_err(|_| WireError { offset: at as u64, what: format!("`{field}` is not UTF-8") })
    }
}

/// Writes primitives of one message.
pub struct Writer {
    out: Vec<u8>,
    origin: usize,
    aligned: bool,
}

impl Writer {
    /// A writer in `encoding` (CDR: little-endian, with its encapsulation header).
    pub fn new(encoding: Encoding) -> Writer {
        match encoding {
            Encoding::Ros1 => Writer { out: Vec::new(), origin: 0, aligned: false },
            Encoding::Cdr => Writer { out: vec![0, 1, 0, 0], origin: 4, aligned: true },
        }
    }

    fn align(&mut self, n: usize) {
        if self.aligned {
            let rel = self.out.len() - self.origin;
            self.out.resize(self.out.len() + (n - rel % n) % n, 0);
        }
    }

    /// A byte.
    pub fn u8(&mut self, v: u8) {
        self.out.push(v);
    }

    /// A boolean.
    pub fn bool(&mut self, v: bool) {
        self.out.push(v as u8);
    }

    /// A `uint32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.out.extend(v.to_le_bytes());
    }

    /// An `int32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.out.extend(v.to_le_bytes());
    }

    /// A `float32`.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.out.extend(v.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.out.extend(v.to_le_bytes());
    }

    /// A `uint8[]` sequence.
    pub fn bytes(&mut self, v: &[u8]) {
        self.u32(v.len() as u32);
        self.out.extend_from_slice(v);
    }

    /// A string.
    pub fn string(&mut self, v: &str) {
        if self.aligned {
            self.u32(v.len() as u32 + 1);
            self.out.extend_from_slice(v.as_bytes());
            self.out.push(0);
        } else {
            self.bytes(v.as_bytes());
        }
    }

    /// The message bytes.
    pub fn finish(self) -> Vec<u8> {
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdr_aligns_after_the_encapsulation_header() {
        let mut w = Writer::new(Encoding::Cdr);
        w.u8(7);
        w.f64(1.5);
        w.string("ab");
        let bytes = w.finish();
        assert_eq!(bytes.len(), 4 + 8 + 8 + 4 + 3);
        let mut r = Reader::new(&bytes, Encoding::Cdr).unwrap();
        assert_eq!(r.u8("a").unwrap(), 7);
        assert_eq!(r.f64("b").unwrap(), 1.5);
        assert_eq!(r.string("c").unwrap(), "ab");
    }

    #[test]
    fn big_endian_cdr_is_read() {
        let mut bytes = vec![0, 0, 0, 0];
        bytes.extend(258u32.to_be_bytes());
        let mut r = Reader::new(&bytes, Encoding::Cdr).unwrap();
        assert_eq!(r.u32("n").unwrap(), 258);
    }

    #[test]
    fn lengths_beyond_the_data_are_errors_with_offsets() {
        let mut w = Writer::new(Encoding::Ros1);
        w.u32(1_000_000_000);
        let bytes = w.finish();
        let e = Reader::new(&bytes, Encoding::Ros1).unwrap().bytes("data").unwrap_err();
        assert_eq!(e.offset, 0);
        assert!(e.what.contains("`data` declares 1000000000"), "{e}");
        let e = Reader::new(&[1, 2], Encoding::Ros1).unwrap().u32("width").unwrap_err();
        assert!(e.to_string().contains("`width`"), "{e}");
        assert!(Reader::new(&[1, 2], Encoding::Cdr).is_err());
        assert!(Reader::new(&[7, 7, 0, 0], Encoding::Cdr).is_err());
    }
}
