//! STL files: binary (by the `stl_io` crate, under a header of ours) or
//! ASCII, in millimetres; and reading them back.

use super::{cross, normalize, sub, MeshError, TriMesh};
use std::io::Write;

/// Which STL flavour to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StlFormat {
    /// Binary (the default: compact, exact f32).
    #[default]
    Binary,
    /// ASCII.
    Ascii,
}

/// Passes bytes through, replacing the first 80 (the STL header `stl_io`
/// leaves blank) with ours.
struct Header<'a, W: Write> {
    inner: &'a mut W,
    header: [u8; 80],
    at: usize,
}

impl<W: Write> Write for Header<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.at < 80 {
            let n = buf.len().min(80 - self.at);
            self.inner.write_all(&self.header[self.at..self.at + n])?;
            self.at += n;
            return Ok(n);
        }
        self.inner.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

fn facets(mesh: &TriMesh) -> impl ExactSizeIterator<Item = stl_io::Triangle> + '_ {
    mesh.triangles.iter().map(move |t| {
        let p = |i: u32| mesh.positions[i as usize];
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        let n = normalize(cross(sub(b, a), sub(c, a)));
        let f = |v: [f64; 3]| stl_io::Vector::new([v[0] as f32, v[1] as f32, v[2] as f32]);
        stl_io::Triangle {
            normal: f(n),
            vertices: [f(a), f(b), f(c)],
        }
    })
}

/// Writes `mesh` as STL named `name`, in millimetres. The binary header
/// reads `pilgrim <version> <name> units=mm`; the ASCII file's `solid` line
/// names the body and a comment-free unit is implied (mm).
///
/// # Failures
/// A write error.
pub fn write_stl<W: Write>(
    mesh: &TriMesh,
    name: &str,
    format: StlFormat,
    out: &mut W,
) -> Result<(), MeshError> {
    let io = |e: std::io::Error| MeshError::Io {
        file: name.to_owned(),
        message: e.to_string(),
    };
    match format {
        StlFormat::Binary => {
            let mut header = [b' '; 80];
            let text = format!("pilgrim {} {} units=mm", crate::version::VERSION, name);
            let n = text.len().min(80);
            header[..n].copy_from_slice(&text.as_bytes()[..n]);
            let mut w = Header {
                inner: out,
                header,
                at: 0,
            };
            stl_io::write_stl(&mut w, facets(mesh)).map_err(io)
        }
        StlFormat::Ascii => {
            let mut w = std::io::BufWriter::new(out);
            let solid: String = name
                .chars()
                .map(|c| if c.is_whitespace() { '_' } else { c })
                .collect();
            writeln!(w, "solid {solid}").map_err(io)?;
            for t in facets(mesh) {
                let [nx, ny, nz] = t.normal.0;
                writeln!(w, "  facet normal {nx:e} {ny:e} {nz:e}\n    outer loop").map_err(io)?;
                for v in t.vertices {
                    writeln!(w, "      vertex {:e} {:e} {:e}", v.0[0], v.0[1], v.0[2])
                        .map_err(io)?;
                }
                writeln!(w, "    endloop\n  endfacet").map_err(io)?;
            }
            writeln!(w, "endsolid {solid}").map_err(io)?;
            w.flush().map_err(io)
        }
    }
}

/// Whether `bytes` are as long as a binary STL of the triangle count in
/// its header.
fn binary_length_matches(bytes: &[u8]) -> bool {
    bytes.len() >= 84
        && bytes[80..84]
            .try_into()
            .map(u32::from_le_bytes)
            .is_ok_and(|n| bytes.len() as u64 == 84 + 50 * u64::from(n))
}

/// Reads an STL file (binary or ASCII) into a mesh, as [`read_stl_bytes`].
///
/// # Failures
/// A read error or a malformed file.
pub fn read_stl(path: &std::path::Path) -> Result<TriMesh, MeshError> {
    let bytes = crate::files::read_bytes(path, crate::files::MAX_DATA_BYTES).map_err(|e| {
        MeshError::Io {
            file: e.file,
            message: e.message,
        }
    })?;
    read_stl_bytes(&bytes, &crate::files::shown_path(path))
}

/// An STL file's bytes (binary or ASCII; `file` names it in errors) as a
/// mesh, welded by `stl_io`, with vertex normals averaged from the faces.
/// A binary file must be as long as its triangle count says before any of
/// it is read (a count of four billion in a short file would otherwise be
/// believed).
///
/// # Failures
/// A malformed file.
pub fn read_stl_bytes(bytes: &[u8], file: &str) -> Result<TriMesh, MeshError> {
    let err = |m: String| MeshError::Io {
        file: file.to_owned(),
        message: m,
    };
    let ascii = bytes.starts_with(b"solid") && !binary_length_matches(bytes);
    if !ascii && !binary_length_matches(bytes) {
        return Err(err(format!(
            "not an STL file: {} bytes, where a binary STL holds 84 + 50 per triangle of its count",
            bytes.len()
        )));
    }
    let stl = stl_io::read_stl(&mut std::io::Cursor::new(bytes)).map_err(|e| err(e.to_string()))?;
    let positions: Vec<[f64; 3]> = stl
        .vertices
        .iter()
        .map(|v| [v.0[0] as f64, v.0[1] as f64, v.0[2] as f64])
        .collect();
    let triangles: Vec<[u32; 3]> = stl
        .faces
        .iter()
        .map(|f| {
            [
                f.vertices[0] as u32,
                f.vertices[1] as u32,
                f.vertices[2] as u32,
            ]
        })
        .collect();
    let mut acc = vec![[0.0; 3]; positions.len()];
    for t in &triangles {
        let (a, b, c) = (
            positions[t[0] as usize],
            positions[t[1] as usize],
            positions[t[2] as usize],
        );
        let n = cross(sub(b, a), sub(c, a));
        for v in t {
            for k in 0..3 {
                acc[*v as usize][k] += n[k];
            }
        }
    }
    Ok(TriMesh {
        positions,
        normals: acc.into_iter().map(normalize).collect(),
        triangles,
    })
}
