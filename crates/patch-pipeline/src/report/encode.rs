//! Binary encodings the page inlines: base64 (RFC 4648 §4) and 8-bit RGB PNG.

/// The PNG file signature.
pub const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 with `=` padding (RFC 4648 §4), no line breaks.
pub fn base64(data: &[u8]) -> String {
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [chunk[0], chunk.get(1).copied().unwrap_or(0), chunk.get(2).copied().unwrap_or(0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Does `data` start with the PNG signature?
pub fn is_png(data: &[u8]) -> bool {
    data.starts_with(&PNG_SIGNATURE)
}

/// `data` as a `data:image/png;base64,` URI.
pub fn png_data_uri(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64(png))
}

/// An RGB image, 8 bits per channel, row-major from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgb {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// `3 * width * height` bytes.
    pub data: Vec<u8>,
}

impl Rgb {
    /// A `width` × `height` image filled with `colour`.
    pub fn filled(width: u32, height: u32, colour: [u8; 3]) -> Rgb {
        let n = width as usize * height as usize;
        Rgb { width, height, data: colour.repeat(n) }
    }

    /// Sets pixel (`x`, `y`); outside the image it does nothing.
    pub fn set(&mut self, x: u32, y: u32, colour: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            self.data[i..i + 3].copy_from_slice(&colour);
        }
    }

    /// Each pixel repeated `factor` × `factor` times (nearest neighbour).
    pub fn scaled(&self, factor: u32) -> Rgb {
        let factor = factor.max(1);
        let (w, h) = (self.width * factor, self.height * factor);
        let mut data = Vec::with_capacity(3 * w as usize * h as usize);
        for y in 0..self.height as usize {
            let row = &self.data[3 * y * self.width as usize..3 * (y + 1) * self.width as usize];
            let mut wide = Vec::with_capacity(3 * w as usize);
            for px in row.chunks_exact(3) {
                for _ in 0..factor {
                    wide.extend_from_slice(px);
                }
            }
            for _ in 0..factor {
                data.extend_from_slice(&wide);
            }
        }
        Rgb { width: w, height: h, data }
    }

    /// The image as a PNG file.
    pub fn to_png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&self.data)?;
        writer.finish()?;
        Ok(out)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Decodes standard padded base64 (the test oracle); `None` on a malformed input.
    pub(crate) fn decode_base64(text: &str) -> Option<Vec<u8>> {
        let t = text.as_bytes();
        if !t.len().is_multiple_of(4) {
            return None;
        }
        let mut out = Vec::with_capacity(t.len() / 4 * 3);
        for (ci, chunk) in t.chunks(4).enumerate() {
            let last = ci + 1 == t.len() / 4;
            let mut n = 0u32;
            let mut pad = 0;
            for (i, &c) in chunk.iter().enumerate() {
                let v = if c == b'=' && last && i >= 2 {
                    pad += 1;
                    0
                } else if pad > 0 {
                    return None;
                } else {
                    ALPHABET.iter().position(|&a| a == c)? as u32
                };
                n = (n << 6) | v;
            }
            let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
            out.extend_from_slice(&bytes[..3 - pad]);
        }
        Some(out)
    }

    #[test]
    fn base64_matches_rfc4648_vectors() {
        let vectors = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, coded) in vectors {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain:?}");
            assert_eq!(decode_base64(coded).unwrap(), plain.as_bytes());
        }
        assert_eq!(base64(&[0xFB, 0xFF, 0xBF]), "+/+/");
        assert_eq!(base64(&[0, 0, 0]), "AAAA");
    }

    #[test]
    fn base64_round_trips_every_length_and_byte() {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        for len in 0..200usize {
            let data: Vec<u8> = (0..len)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state >> 32) as u8
                })
                .collect();
            let coded = base64(&data);
            assert_eq!(coded.len(), len.div_ceil(3) * 4);
            assert_eq!(decode_base64(&coded).unwrap(), data, "length {len}");
        }
        let all: Vec<u8> = (0..=255).collect();
        assert_eq!(decode_base64(&base64(&all)).unwrap(), all);
    }

    #[test]
    fn png_round_trips_through_the_decoder() {
        let mut img = Rgb::filled(3, 2, [10, 20, 30]);
        img.set(2, 1, [200, 0, 100]);
        img.set(5, 5, [1, 1, 1]);
        let big = img.scaled(3);
        assert_eq!((big.width, big.height), (9, 6));
        let png_bytes = big.to_png().unwrap();
        assert!(is_png(&png_bytes));
        let decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (9, 6));
        let px = |x: usize, y: usize| buf[3 * (y * 9 + x)..3 * (y * 9 + x) + 3].to_vec();
        assert_eq!(px(8, 5), vec![200, 0, 100]);
        assert_eq!(px(6, 3), vec![200, 0, 100]);
        assert_eq!(px(5, 5), vec![10, 20, 30]);
    }
}
