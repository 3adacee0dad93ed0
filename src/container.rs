//! The file container every binary file of radiosity is written in: the saved solution
//! (`solve --save`, [`crate::export::solution`]) and the checkpoint (`solve --checkpoint`,
//! [`crate::solve::checkpoint`]). It owns what the two share and nothing of what they hold.
//!
//! **Header** (little-endian): an 8-byte magic naming the kind of file, the format version
//! (u32), then — in a [`Container`] with reserved words — a reserved u32 (flags, 0), the
//! payload's length (u64), its CRC-32 (u32) and — with reserved words — another reserved u32
//! (0). So 32 bytes for the saved solution, 24 for the checkpoint. Then the payload.
//!
//! **Reading** checks the header before anything is parsed, in an order that gives each
//! refusal its own reason: the magic (a foreign file), the header's length (a short file), the
//! version (left to the format: [`Header::version`]), the payload's length (a truncated file)
//! and its checksum (a damaged one). Then the payload is read through a [`Cursor`], whose reads
//! past the end return [`Short`], never panic.

/// What a kind of file's header looks like.
#[derive(Clone, Copy, Debug)]
pub struct Container {
    /// The first eight bytes of every file of the kind.
    pub magic: [u8; 8],
    /// Whether the header has the two reserved u32 words (32 bytes), or not (24 bytes).
    pub reserved_words: bool,
}

/// A header as read, before the payload is checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub version: u32,
    /// The payload's length (bytes) and CRC-32, as the header states them.
    pub len: u64,
    pub crc: u32,
}

/// Why a file's container is refused; each format words the message for its own kind of file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// The bytes there are do not begin with the magic.
    Foreign,
    /// Shorter than the header (`have` bytes in all; an empty file is this one).
    ShortHeader { have: usize },
    /// The payload is shorter than the header says (`have` of `want` payload bytes).
    Truncated { have: u64, want: u64 },
    /// The payload's CRC-32 differs from the header's.
    Checksum,
}

impl Container {
    /// Bytes before the payload.
    pub const fn header_len(&self) -> usize {
        if self.reserved_words {
            32
        } else {
            24
        }
    }

    /// The file's bytes: the header for `payload` written as format `version`, then `payload`.
    pub fn wrap(&self, version: u32, payload: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.header_len() + payload.len());
        out.extend_from_slice(&self.magic);
        out.extend_from_slice(&version.to_le_bytes());
        if self.reserved_words {
            out.extend_from_slice(&0u32.to_le_bytes());
        }
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
        if self.reserved_words {
            out.extend_from_slice(&0u32.to_le_bytes());
        }
        out.extend_from_slice(payload);
        out
    }

    /// Reads the header: the magic first (so a foreign file is named as such even when it is
    /// short), then the rest of the header's length.
    pub fn header(&self, bytes: &[u8]) -> Result<Header, Refusal> {
        let n = bytes.len().min(self.magic.len());
        if bytes[..n] != self.magic[..n] {
            return Err(Refusal::Foreign);
        }
        if bytes.len() < self.header_len() {
            return Err(Refusal::ShortHeader { have: bytes.len() });
        }
        let mut c = Cursor::new(&bytes[8..self.header_len()]);
        let short = |_| Refusal::ShortHeader { have: bytes.len() };
        let version = c.u32().map_err(short)?;
        if self.reserved_words {
            c.u32().map_err(short)?;
        }
        Ok(Header {
            version,
            len: c.u64().map_err(short)?,
            crc: c.u32().map_err(short)?,
        })
    }

    /// The payload `header` describes, its checksum checked, and the bytes after it (a file
    /// written by radiosity has none; a format decides whether to refuse them).
    pub fn payload<'a>(
        &self,
        bytes: &'a [u8],
        header: &Header,
    ) -> Result<(&'a [u8], &'a [u8]), Refusal> {
        let after = bytes.get(self.header_len()..).unwrap_or_default();
        let have = after.len() as u64;
        if have < header.len {
            return Err(Refusal::Truncated {
                have,
                want: header.len,
            });
        }
        // `header.len <= have`, which is a usize.
        let (payload, rest) = after.split_at(header.len as usize);
        if crc32fast::hash(payload) != header.crc {
            return Err(Refusal::Checksum);
        }
        Ok((payload, rest))
    }
}

/// A read past the end of the bytes a [`Cursor`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Short;

/// A bounds-checked little-endian reader: every read past the end gives [`Short`], and leaves
/// the cursor where it was.
#[derive(Clone, Copy, Debug)]
pub struct Cursor<'a> {
    b: &'a [u8],
}

impl<'a> Cursor<'a> {
    pub fn new(b: &'a [u8]) -> Self {
        Cursor { b }
    }
    /// The bytes not read yet.
    pub fn rest(&self) -> &'a [u8] {
        self.b
    }
    pub fn is_empty(&self) -> bool {
        self.b.is_empty()
    }
    pub fn take(&mut self, n: usize) -> Result<&'a [u8], Short> {
        if n > self.b.len() {
            return Err(Short);
        }
        let (a, rest) = self.b.split_at(n);
        self.b = rest;
        Ok(a)
    }
    pub fn arr<const N: usize>(&mut self) -> Result<[u8; N], Short> {
        self.take(N).map(|s| s.try_into().expect("took N bytes"))
    }
    pub fn u8(&mut self) -> Result<u8, Short> {
        self.arr::<1>().map(|a| a[0])
    }
    pub fn u32(&mut self) -> Result<u32, Short> {
        self.arr().map(u32::from_le_bytes)
    }
    pub fn u64(&mut self) -> Result<u64, Short> {
        self.arr().map(u64::from_le_bytes)
    }
    pub fn f32(&mut self) -> Result<f32, Short> {
        self.arr().map(f32::from_le_bytes)
    }
    pub fn f64(&mut self) -> Result<f64, Short> {
        self.arr().map(f64::from_le_bytes)
    }
    pub fn f32x3(&mut self) -> Result<[f32; 3], Short> {
        Ok([self.f32()?, self.f32()?, self.f32()?])
    }
    pub fn f64x3(&mut self) -> Result<[f64; 3], Short> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }
    /// `count` triples of f64 (`count × 24` bytes; [`Short`] if they are not all there).
    pub fn f64x3s(&mut self, count: usize) -> Result<Vec<[f64; 3]>, Short> {
        let bytes = self.take(count.checked_mul(24).ok_or(Short)?)?;
        let mut c = Cursor::new(bytes);
        (0..count).map(|_| c.f64x3()).collect()
    }
    /// `count` f64 (`count × 8` bytes).
    pub fn f64s(&mut self, count: usize) -> Result<Vec<f64>, Short> {
        let bytes = self.take(count.checked_mul(8).ok_or(Short)?)?;
        let mut c = Cursor::new(bytes);
        (0..count).map(|_| c.f64()).collect()
    }
}

/// Little-endian writes onto a payload being built.
pub trait Put {
    fn put_u32(&mut self, v: u32);
    fn put_u64(&mut self, v: u64);
    fn put_f32s(&mut self, v: &[f32]);
    fn put_f64s(&mut self, v: &[f64]);
    /// Triples of f64, one after the other.
    fn put_f64x3s(&mut self, v: &[[f64; 3]]) {
        v.iter().for_each(|x| self.put_f64s(x));
    }
}

impl Put for Vec<u8> {
    fn put_u32(&mut self, v: u32) {
        self.extend_from_slice(&v.to_le_bytes());
    }
    fn put_u64(&mut self, v: u64) {
        self.extend_from_slice(&v.to_le_bytes());
    }
    fn put_f32s(&mut self, v: &[f32]) {
        v.iter()
            .for_each(|x| self.extend_from_slice(&x.to_le_bytes()));
    }
    fn put_f64s(&mut self, v: &[f64]) {
        v.iter()
            .for_each(|x| self.extend_from_slice(&x.to_le_bytes()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOTH: [Container; 2] = [
        Container {
            magic: *b"TESTFMT\0",
            reserved_words: false,
        },
        Container {
            magic: *b"TESTFMT\x1a",
            reserved_words: true,
        },
    ];

    #[test]
    fn wraps_and_opens() {
        for c in BOTH {
            let b = c.wrap(3, b"payload");
            assert_eq!(b.len(), c.header_len() + 7);
            let h = c.header(&b).unwrap();
            assert_eq!((h.version, h.len), (3, 7));
            assert_eq!(c.payload(&b, &h).unwrap(), (&b"payload"[..], &b""[..]));
        }
    }

    #[test]
    fn every_cut_and_flip_is_refused_without_panic() {
        for c in BOTH {
            let b = c.wrap(1, b"some payload bytes");
            let open = |b: &[u8]| c.header(b).and_then(|h| c.payload(b, &h).map(|_| h));
            for k in 0..b.len() {
                assert!(open(&b[..k]).is_err(), "cut at {k}");
                let mut f = b.clone();
                f[k] ^= 0x5a;
                // The version and the reserved words are the format's to check.
                let free = (8..12).contains(&k)
                    || (c.reserved_words && ((12..16).contains(&k) || (28..32).contains(&k)));
                assert_eq!(open(&f).is_ok(), free, "flip at {k}");
            }
            assert_eq!(open(b"other file"), Err(Refusal::Foreign));
            assert_eq!(open(b""), Err(Refusal::ShortHeader { have: 0 }));
        }
    }

    #[test]
    fn cursor_reads_past_the_end_are_errors() {
        let mut c = Cursor::new(&[1, 0, 0, 0, 2]);
        assert_eq!(c.u32(), Ok(1));
        assert_eq!(c.u32(), Err(Short));
        assert_eq!(c.u8(), Ok(2));
        assert!(c.is_empty());
        assert_eq!(Cursor::new(&[0; 8]).f64x3s(usize::MAX), Err(Short));
    }
}
