//! The messages between the host and the child process that holds a
//! plugin library ([`super::remote`], [`super::server`]): frames of a
//! kind (`u32`) and a length (`u64`), little-endian, then the bytes.
//!
//! The child says [`HELLO`] before it opens the library (so that a crash
//! while loading is told apart from a server that never started), then how
//! loading went ([`LOADED`] and the table's header, or why not). Each
//! request is one frame ([`DESCRIBE`], [`INVERSE`], ...), each answer one
//! frame whose kind is the plugin's status (`STATUS_*` of the ABI) and whose
//! bytes are the result, or on failure the failed row (`u64`) and the
//! message. Hand-written: the format is four kinds of frame of plain
//! numbers, and the child must depend on nothing a plugin could disturb.

use std::io::{Read, Write};

/// What the child writes first, before it opens the library.
pub const HELLO: &[u8; 8] = b"PLGSRV01";

/// The library is loaded: the table's header follows ([`TableHeader`]).
pub const LOADED: u32 = 100;
/// The library cannot be opened: the system's message follows.
pub const OPEN_FAILED: u32 = 101;
/// The entry symbol is missing: its name follows.
pub const NO_ENTRY: u32 = 102;
/// The entry returned a null table.
pub const NULL_TABLE: u32 = 103;

/// Request: the descriptor (no bytes).
pub const DESCRIBE: u32 = 1;
/// Request: inverse kinematics (`count`, `width`, tool, poses).
pub const INVERSE: u32 = 2;
/// Request: forward kinematics (`count`, `width`, tool, axis rows).
pub const FORWARD: u32 = 3;
/// Request: a program's text (the JSON post request).
pub const POST: u32 = 4;

/// The most bytes of an error message sent (the host quotes less).
pub const MAX_MESSAGE: usize = 64 << 10;
/// The most bytes of any frame.
pub const MAX_FRAME: u64 = crate::files::MAX_DATA_BYTES;

/// A plugin table's header, as the child read it: ABI version, declared
/// size, capabilities, and which entries are there (describe, inverse,
/// forward, post, last_error, free_buffer), each only if its field lies
/// below the declared size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableHeader {
    /// The ABI major.
    pub major: u32,
    /// The ABI minor.
    pub minor: u32,
    /// The table's declared size.
    pub size: u32,
    /// Its capabilities (`CAP_*`).
    pub capabilities: u32,
    /// Which entries are present, in the table's order.
    pub present: [bool; 6],
}

impl TableHeader {
    /// The header as bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(22);
        for v in [self.major, self.minor, self.size, self.capabilities] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend(self.present.iter().map(|&p| u8::from(p)));
        b
    }

    /// The header from bytes.
    pub fn decode(b: &[u8]) -> Option<Self> {
        if b.len() != 22 {
            return None;
        }
        let u = |i: usize| u32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap_or_default());
        let mut present = [false; 6];
        for (p, &v) in present.iter_mut().zip(&b[16..]) {
            *p = v != 0;
        }
        Some(Self {
            major: u(0),
            minor: u(1),
            size: u(2),
            capabilities: u(3),
            present,
        })
    }
}

/// Writes one frame.
pub fn write_frame(w: &mut impl Write, kind: u32, parts: &[&[u8]]) -> std::io::Result<()> {
    let len: usize = parts.iter().map(|p| p.len()).sum();
    let mut head = [0u8; 12];
    head[..4].copy_from_slice(&kind.to_le_bytes());
    head[4..].copy_from_slice(&(len as u64).to_le_bytes());
    w.write_all(&head)?;
    for p in parts {
        w.write_all(p)?;
    }
    w.flush()
}

/// A frame's header: kind and length.
pub fn header(head: &[u8; 12]) -> (u32, u64) {
    let mut k = [0u8; 4];
    let mut l = [0u8; 8];
    k.copy_from_slice(&head[..4]);
    l.copy_from_slice(&head[4..]);
    (u32::from_le_bytes(k), u64::from_le_bytes(l))
}

/// Reads one frame (blocking: the child's side); `None` at the end of the
/// stream.
pub fn read_frame(r: &mut impl Read) -> std::io::Result<Option<(u32, Vec<u8>)>> {
    let mut head = [0u8; 12];
    match r.read_exact(&mut head) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
        Err(e) => return Err(e),
    }
    let (kind, len) = header(&head);
    if len > MAX_FRAME {
        return Err(std::io::Error::other(format!("a frame of {len} bytes")));
    }
    let mut bytes = vec![0u8; len as usize];
    r.read_exact(&mut bytes)?;
    Ok(Some((kind, bytes)))
}

/// `f64`s as bytes.
pub fn floats_to_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// Bytes as `f64`s (a length not a multiple of 8 is `None`).
pub fn bytes_to_floats(b: &[u8]) -> Option<Vec<f64>> {
    if !b.len().is_multiple_of(8) {
        return None;
    }
    Some(
        b.chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
            .collect(),
    )
}

/// A batch request's bytes: `count`, `width`, the tool's six values, the rows.
pub fn batch_request(count: usize, width: usize, tool: &[f64; 6], rows: &[f64]) -> Vec<u8> {
    let mut b = Vec::with_capacity(16 + 48 + 8 * rows.len());
    b.extend_from_slice(&(count as u64).to_le_bytes());
    b.extend_from_slice(&(width as u64).to_le_bytes());
    b.extend(floats_to_bytes(tool));
    b.extend(floats_to_bytes(rows));
    b
}

/// A batch request from bytes: `count`, `width`, tool, rows (the rows'
/// length checked against `count` rows of `per_row(width)` values).
pub fn parse_batch(
    b: &[u8],
    per_row: impl Fn(usize) -> usize,
) -> Option<(usize, usize, [f64; 6], Vec<f64>)> {
    if b.len() < 64 {
        return None;
    }
    let count = usize::try_from(u64::from_le_bytes(b[..8].try_into().ok()?)).ok()?;
    let width = usize::try_from(u64::from_le_bytes(b[8..16].try_into().ok()?)).ok()?;
    let tool: [f64; 6] = bytes_to_floats(&b[16..64])?.try_into().ok()?;
    let rows = bytes_to_floats(&b[64..])?;
    (count.checked_mul(per_row(width)) == Some(rows.len())).then_some((count, width, tool, rows))
}

/// A failure's bytes: the row (or `NO_ROW`) and the message, cut to
/// [`MAX_MESSAGE`].
pub fn failure(row: usize, message: &str) -> Vec<u8> {
    let mut end = message.len().min(MAX_MESSAGE);
    while !message.is_char_boundary(end) {
        end -= 1;
    }
    let mut b = (row as u64).to_le_bytes().to_vec();
    b.extend_from_slice(&message.as_bytes()[..end]);
    b
}

/// A failure from bytes: the row and the message.
pub fn parse_failure(b: &[u8]) -> (u64, String) {
    if b.len() < 8 {
        return (u64::MAX, String::from_utf8_lossy(b).into_owned());
    }
    let row = u64::from_le_bytes(b[..8].try_into().unwrap_or_default());
    (row, String::from_utf8_lossy(&b[8..]).into_owned())
}
