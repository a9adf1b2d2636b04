//! LZF compression in liblzf's stream format (as decoded by liblzf's `lzf_decompress`), as used
//! by PCD `binary_compressed` data.
//!
//! The stream is a sequence of runs, each starting with a control byte `c`:
//!
//! * `c < 32`: a literal run; the next `c + 1` bytes are copied to the output.
//! * `c >= 32`: a back-reference. Its length field is `c >> 5` (1 to 7); the value 7 means one
//!   more byte follows and is added to it. Then one byte `b` follows. The run copies
//!   `length field + 2` bytes (3 to 264) starting `((c & 0x1f) << 8 | b) + 1` bytes (1 to 8192)
//!   before the current end of the output; source and destination may overlap, in which case
//!   the bytes being written are read again (run-length repetition).
//!
//! There is no header and no checksum: the caller knows both lengths (PCD stores them in front
//! of the stream). The decompressor checks every run against the input and the expected output
//! length, so corrupt input gives an [`LzfError`], never a panic or an allocation larger than the
//! input could possibly expand to.

use std::fmt;

/// The most output one input byte can produce: a 3-byte back-reference copies at most 264 bytes.
const MAX_EXPANSION: usize = 88;
/// Longest back-reference distance.
const MAX_DISTANCE: usize = 1 << 13;
/// Longest back-reference.
const MAX_MATCH: usize = 264;
/// Longest literal run.
const MAX_LITERALS: usize = 32;
/// log2 of the compressor's hash-table size.
const HASH_LOG: u32 = 14;

/// Why an LZF stream could not be decompressed. `offset` is the input offset of the run at
/// fault.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum LzfError {
    /// The expected output is larger than any stream of this length can produce.
    ImpossibleLength {
        /// The expected output length.
        expected: usize,
        /// The input length.
        input: usize,
    },
    /// The stream ends inside a run.
    Truncated {
        /// Input offset of the run.
        offset: usize,
    },
    /// A back-reference points before the start of the output.
    BadReference {
        /// Input offset of the run.
        offset: usize,
    },
    /// A run would write past the expected output length.
    Overrun {
        /// Input offset of the run.
        offset: usize,
    },
    /// The stream ends before producing the expected output length.
    Short {
        /// Bytes produced.
        produced: usize,
        /// Bytes expected.
        expected: usize,
    },
}

impl LzfError {
    /// The input offset the error refers to (the end of the input for a short stream).
    pub(crate) fn offset(&self, input_len: usize) -> usize {
        match *self {
            LzfError::Truncated { offset }
            | LzfError::BadReference { offset }
            | LzfError::Overrun { offset } => offset,
            LzfError::ImpossibleLength { .. } => 0,
            LzfError::Short { .. } => input_len,
        }
    }
}

impl fmt::Display for LzfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LzfError::ImpossibleLength { expected, input } => write!(
                f,
                "{input} bytes of LZF data cannot expand to the declared {expected} bytes"
            ),
            LzfError::Truncated { .. } => f.write_str("LZF data end inside a run"),
            LzfError::BadReference { .. } => {
                f.write_str("LZF back-reference points before the start of the output")
            }
            LzfError::Overrun { .. } => {
                f.write_str("LZF data expand past the declared uncompressed size")
            }
            LzfError::Short { produced, expected } => {
                write!(f, "LZF data expand to {produced} bytes, {expected} declared")
            }
        }
    }
}

impl std::error::Error for LzfError {}

/// Decompresses `input`, which must expand to exactly `expected_len` bytes.
pub(crate) fn decompress(input: &[u8], expected_len: usize) -> Result<Vec<u8>, LzfError> {
    if expected_len > input.len().saturating_mul(MAX_EXPANSION) {
        return Err(LzfError::ImpossibleLength { expected: expected_len, input: input.len() });
    }
    let mut out = Vec::with_capacity(expected_len);
    let mut ip = 0;
    while let Some(&ctrl) = input.get(ip) {
        let run_start = ip;
        let ctrl = usize::from(ctrl);
        ip += 1;
        if ctrl < MAX_LITERALS {
            let len = ctrl + 1;
            let literal =
                input.get(ip..ip + len).ok_or(LzfError::Truncated { offset: run_start })?;
            if out.len() + len > expected_len {
                return Err(LzfError::Overrun { offset: run_start });
            }
            out.extend_from_slice(literal);
            ip += len;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len +=
                    usize::from(*input.get(ip).ok_or(LzfError::Truncated { offset: run_start })?);
                ip += 1;
            }
            let low = usize::from(*input.get(ip).ok_or(LzfError::Truncated { offset: run_start })?);
            ip += 1;
            let len = len + 2;
            let distance = ((ctrl & 0x1f) << 8 | low) + 1;
            if distance > out.len() {
                return Err(LzfError::BadReference { offset: run_start });
            }
            if out.len() + len > expected_len {
                return Err(LzfError::Overrun { offset: run_start });
            }
            copy_back(&mut out, distance, len);
        }
    }
    if out.len() != expected_len {
        return Err(LzfError::Short { produced: out.len(), expected: expected_len });
    }
    Ok(out)
}

/// Appends `len` bytes copied from `distance` bytes before the end of `out` (which is at least
/// `distance` long), byte by byte where the source overlaps the bytes being written.
fn copy_back(out: &mut Vec<u8>, distance: usize, len: usize) {
    let from = out.len() - distance;
    if distance >= len {
        out.extend_from_within(from..from + len);
    } else {
        for k in 0..len {
            let byte = out[from + k];
            out.push(byte);
        }
    }
}

/// Compresses `input` into a liblzf-compatible stream (greedy matching over a hash of the next
/// three bytes). Incompressible input grows by one byte per 32.
pub(crate) fn compress(input: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(input.len() + input.len() / MAX_LITERALS + 1);
    // Per hash bucket: 1 + the last input position with that hash, 0 for none.
    let mut table = vec![0usize; 1 << HASH_LOG];
    let mut literal_start = 0;
    let mut ip = 0;
    while ip + 2 < input.len() {
        let bucket = hash(&input[ip..ip + 3]);
        let candidate = table[bucket];
        table[bucket] = ip + 1;
        if let Some(reference) = candidate.checked_sub(1)
            && ip - reference <= MAX_DISTANCE
            && input[reference..reference + 3] == input[ip..ip + 3]
        {
            let max_len = MAX_MATCH.min(input.len() - ip);
            let mut len = 3;
            while len < max_len && input[reference + len] == input[ip + len] {
                len += 1;
            }
            push_literals(&mut out, &input[literal_start..ip]);
            push_reference(&mut out, ip - reference - 1, len);
            ip += len;
            literal_start = ip;
        } else {
            ip += 1;
        }
    }
    push_literals(&mut out, &input[literal_start..]);
    out
}

fn hash(bytes: &[u8]) -> usize {
    let v = u32::from(bytes[0]) << 16 | u32::from(bytes[1]) << 8 | u32::from(bytes[2]);
    (v.wrapping_mul(2_654_435_761) >> (32 - HASH_LOG)) as usize
}

fn push_literals(out: &mut Vec<u8>, literals: &[u8]) {
    for chunk in literals.chunks(MAX_LITERALS) {
        out.push((chunk.len() - 1) as u8);
        out.extend_from_slice(chunk);
    }
}

/// A back-reference of `len` (3..=264) bytes at `offset + 1` (1..=8192) bytes back.
fn push_reference(out: &mut Vec<u8>, offset: usize, len: usize) {
    let high = (offset >> 8) as u8;
    let field = len - 2;
    if field < 7 {
        out.push((field as u8) << 5 | high);
    } else {
        out.push(7 << 5 | high);
        out.push((field - 7) as u8);
    }
    out.push(offset as u8);
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_made_stream_decodes() {
        // literal "a", then 9 bytes from 1 back (long form: field 7 + 0), then literal "bc".
        let stream = [0x00, b'a', 0xE0, 0x00, 0x00, 0x01, b'b', b'c'];
        assert_eq!(decompress(&stream, 12).unwrap(), b"aaaaaaaaaabc");
        // short form: "abc" then 3 bytes from 3 back.
        let stream = [0x02, b'a', b'b', b'c', 0x20, 0x02];
        assert_eq!(decompress(&stream, 6).unwrap(), b"abcabc");
    }

    #[test]
    fn empty_stream() {
        assert_eq!(decompress(&[], 0).unwrap(), Vec::<u8>::new());
        assert!(compress(&[]).is_empty());
        assert_eq!(decompress(&[], 1), Err(LzfError::ImpossibleLength { expected: 1, input: 0 }));
    }

    #[test]
    fn corrupt_streams_are_errors() {
        // Literal run claims 6 bytes, 2 present.
        assert_eq!(decompress(&[0x05, 1, 2], 6), Err(LzfError::Truncated { offset: 0 }));
        // Back-reference with its offset byte missing.
        assert_eq!(decompress(&[0x00, 1, 0x20], 4), Err(LzfError::Truncated { offset: 2 }));
        // Long back-reference with its length byte missing.
        assert_eq!(decompress(&[0x00, 1, 0xE0], 20), Err(LzfError::Truncated { offset: 2 }));
        // Back-reference before the start of the output.
        assert_eq!(
            decompress(&[0x00, 1, 0x20, 0x05], 4),
            Err(LzfError::BadReference { offset: 2 })
        );
        assert_eq!(decompress(&[0x20, 0x00], 3), Err(LzfError::BadReference { offset: 0 }));
        // Output overrun, by a literal and by a reference.
        assert_eq!(decompress(&[0x02, 1, 2, 3], 2), Err(LzfError::Overrun { offset: 0 }));
        assert_eq!(decompress(&[0x00, 1, 0x20, 0x00], 3), Err(LzfError::Overrun { offset: 2 }));
        // Too little output.
        assert_eq!(decompress(&[0x01, 1, 2], 3), Err(LzfError::Short { produced: 2, expected: 3 }));
        // A declared size no stream of this length can reach is refused before allocating.
        assert!(matches!(
            decompress(&[0x00, 1], usize::MAX),
            Err(LzfError::ImpossibleLength { .. })
        ));
    }

    #[test]
    fn long_runs_and_far_references() {
        let mut data = vec![7u8; 10_000];
        data.extend((0..20_000u32).map(|i| (i * 7919 % 251) as u8));
        data.extend_from_within(100..9_000);
        let packed = compress(&data);
        assert!(packed.len() < data.len());
        assert_eq!(decompress(&packed, data.len()).unwrap(), data);
    }

    proptest! {
        #[test]
        fn round_trip(data in proptest::collection::vec(prop_oneof![Just(0u8), Just(1u8), any::<u8>()], 0..3000)) {
            let packed = compress(&data);
            prop_assert_eq!(decompress(&packed, data.len()).unwrap(), data);
        }

        #[test]
        fn garbage_never_panics(data in proptest::collection::vec(any::<u8>(), 0..200), len in 0usize..5000) {
            let _ = decompress(&data, len);
        }
    }
}
