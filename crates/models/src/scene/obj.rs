//! Wavefront OBJ faces as an index buffer, numbered the way the file
//! numbers its vertices.
//!
//! The cost model of paper 000 (sections 2 and 4.5) depends only on the
//! index stream, and some post-transform caches depend on the index *values*
//! (a direct-mapped cache such as Mesa lavapipe's maps a vertex to the slot
//! `index mod slots`). So the loader keeps the file's numbering instead of
//! renumbering vertices in order of first use:
//!
//! - **One vertex per position** (faces give only positions `f 1 2 3`, or every
//!   position is always referenced with the same texture coordinate and
//!   normal, as in `f 1/1/1 2/2/2 3/3/3`): the index of a corner is its
//!   position's 0-based number in the file's `v` order, and the vertex buffer
//!   holds every `v` line (`vertex_count`), used or not. Unused positions
//!   are in the buffer but never fetched: [`Mesh::unique_vertices`] counts
//!   the referenced ones only.
//! - **Split vertices** (some position is referenced with two different
//!   texture-coordinate or normal indices, as at a UV seam): a GPU vertex
//!   buffer needs one vertex per distinct (position, texcoord, normal)
//!   triple; the triples are numbered in order of first use in the faces,
//!   and `vertex_count` is their number.
//!
//! Faces with more than three corners are triangulated as a fan from their
//! first corner: (0, 1, 2), (0, 2, 3), .... Negative (relative) indices count
//! back from the last element read so far. Objects, groups and materials
//! (`o`, `g`, `usemtl`) do not restart the numbering: OBJ indices are global
//! to the file, and all faces form one triangle list in file order. Lines
//! (`l`) and points (`p`) form no triangles and are ignored; so are all
//! other statements. `#` starts a comment.
//!
//! [`Mesh::unique_vertices`]: super::mesh::Mesh::unique_vertices

use std::collections::HashMap;
use std::io::BufRead;

use super::mesh::RESTART;

/// Why an OBJ file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    /// The file could not be read (or is not UTF-8).
    #[error("read error: {0}")]
    Read(#[from] std::io::Error),
    /// A `v` line without three numbers.
    #[error("position parse error: `v` needs at least three numbers")]
    Position,
    /// A `vt` line without a number.
    #[error("texcoord parse error: `vt` needs one to three numbers")]
    Texcoord,
    /// A `vn` line without three numbers.
    #[error("normal parse error: `vn` needs three numbers")]
    Normal,
    /// A face corner that is not `v`, `v/vt`, `v//vn` or `v/vt/vn` with
    /// non-zero integers.
    #[error("face parse error: bad corner `{0}` (expected v, v/vt, v//vn or v/vt/vn, non-zero integers)")]
    Face(String),
    /// A face with fewer than three corners.
    #[error("face parse error: a face needs at least three corners, found {0}")]
    FaceTooShort(usize),
    /// A corner referring to an element not defined (yet).
    #[error("face {what} index {index} out of bounds ({count} defined so far)")]
    OutOfBounds {
        /// `vertex`, `texcoord` or `normal`.
        what: &'static str,
        /// The index as written.
        index: i64,
        /// Elements of that kind defined before the face.
        count: u64,
    },
    /// A `v`, `vt` or `vn` number that is NaN or infinite (`nan`, `inf`, `1e400`).
    #[error("`{0}` is not a finite number (positions, texcoords and normals must be finite)")]
    NotFinite(String),
    /// More vertices than 32-bit indices (below the restart marker) can address.
    #[error("more vertices than 32-bit indices can address")]
    TooManyVertices,
}

/// An error and the 1-based line it was found on (`None`: not tied to a line).
#[derive(Debug)]
pub struct ObjFailure {
    /// The line, where the error belongs to one.
    pub line: Option<usize>,
    /// What went wrong.
    pub error: ObjError,
}

/// The faces of an OBJ file as a triangle list (see the module docs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjTriangles {
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    /// Size of the vertex buffer the indices address.
    pub vertex_count: u32,
    /// Whether vertices were split into (position, texcoord, normal) triples.
    pub split: bool,
}

/// "No texcoord / normal given" in a corner.
const NONE: u32 = u32::MAX;

/// A face corner: 0-based position, texcoord and normal ([`NONE`] if absent).
type Corner = [u32; 3];

/// Counts of the elements defined so far, and the triangulated corners.
#[derive(Default)]
struct Reader {
    counts: [u64; 3],
    corners: Vec<Corner>,
}

/// Reads the faces of an OBJ file.
pub fn read_obj(input: impl BufRead) -> Result<ObjTriangles, ObjFailure> {
    let mut r = Reader::default();
    for (n, line) in input.lines().enumerate() {
        let at = |error| ObjFailure {
            line: Some(n + 1),
            error,
        };
        let line = line.map_err(|e| at(ObjError::Read(e)))?;
        r.line(&line).map_err(at)?;
    }
    let unlined = |error| ObjFailure { line: None, error };
    let positions = u32::try_from(r.counts[0])
        .ok()
        .filter(|&v| v < RESTART)
        .ok_or_else(|| unlined(ObjError::TooManyVertices))?;
    number(r.corners, positions).map_err(unlined)
}

impl Reader {
    fn line(&mut self, line: &str) -> Result<(), ObjError> {
        let content = line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        match words.next() {
            Some("v") => count_numbers(words, 3, usize::MAX, ObjError::Position, &mut self.counts[0]),
            Some("vt") => count_numbers(words, 1, 3, ObjError::Texcoord, &mut self.counts[1]),
            Some("vn") => count_numbers(words, 3, 3, ObjError::Normal, &mut self.counts[2]),
            Some("f") => self.face(words),
            _ => Ok(()),
        }
    }

    /// Parses a face's corners and appends its fan triangulation.
    fn face<'a>(&mut self, words: impl Iterator<Item = &'a str>) -> Result<(), ObjError> {
        let corners = words.map(|w| self.corner(w)).collect::<Result<Vec<_>, _>>()?;
        if corners.len() < 3 {
            return Err(ObjError::FaceTooShort(corners.len()));
        }
        for k in 1..corners.len() - 1 {
            self.corners
                .extend_from_slice(&[corners[0], corners[k], corners[k + 1]]);
        }
        Ok(())
    }

    /// One corner `v`, `v/vt`, `v//vn` or `v/vt/vn`.
    fn corner(&self, word: &str) -> Result<Corner, ObjError> {
        let bad = || ObjError::Face(word.to_string());
        let parts: Vec<&str> = word.splitn(4, '/').collect();
        if parts.len() > 3 {
            return Err(bad());
        }
        let mut out = [NONE; 3];
        for (slot, (part, what)) in parts.iter().zip(["vertex", "texcoord", "normal"]).enumerate() {
            if part.is_empty() && slot > 0 {
                continue;
            }
            let i: i64 = part.parse().ok().filter(|&i| i != 0).ok_or_else(bad)?;
            out[slot] = resolve(i, self.counts[slot], what)?;
        }
        Ok(out)
    }
}

/// A non-zero 1-based (or negative, relative) OBJ index as a 0-based one,
/// checked against the `count` elements defined so far.
fn resolve(i: i64, count: u64, what: &'static str) -> Result<u32, ObjError> {
    let out = || ObjError::OutOfBounds { what, index: i, count };
    let zero_based = if i > 0 {
        i.unsigned_abs() - 1
    } else {
        count.checked_sub(i.unsigned_abs()).ok_or_else(out)?
    };
    if zero_based >= count {
        return Err(out());
    }
    u32::try_from(zero_based).map_err(|_| ObjError::TooManyVertices)
}

/// Checks that a statement has between `min` and `max` numbers and counts it.
fn count_numbers<'a>(
    words: impl Iterator<Item = &'a str>,
    min: usize,
    max: usize,
    error: ObjError,
    count: &mut u64,
) -> Result<(), ObjError> {
    let mut n = 0;
    for w in words {
        match w.parse::<f64>() {
            Err(_) => return Err(error),
            Ok(v) if !v.is_finite() => return Err(ObjError::NotFinite(w.to_string())),
            Ok(_) => {}
        }
        n += 1;
    }
    if n < min || n > max {
        return Err(error);
    }
    *count += 1;
    Ok(())
}

/// Numbers the corners: by position when every position has one
/// (texcoord, normal) pair, else by distinct triple in first-use order.
fn number(corners: Vec<Corner>, positions: u32) -> Result<ObjTriangles, ObjError> {
    if one_vertex_per_position(&corners, positions) {
        return Ok(ObjTriangles {
            indices: corners.iter().map(|c| c[0]).collect(),
            vertex_count: positions,
            split: false,
        });
    }
    let mut ids: HashMap<Corner, u32> = HashMap::new();
    let mut indices = Vec::with_capacity(corners.len());
    for c in corners {
        let next = ids.len();
        let id = *ids.entry(c).or_insert(next as u32);
        indices.push(id);
    }
    // Distinct triples are at most the corners, themselves addressable.
    let vertex_count = u32::try_from(ids.len()).map_err(|_| ObjError::TooManyVertices)?;
    Ok(ObjTriangles {
        indices,
        vertex_count,
        split: true,
    })
}

/// Whether every position is referenced with a single (texcoord, normal).
fn one_vertex_per_position(corners: &[Corner], positions: u32) -> bool {
    let mut attrs: Vec<Option<[u32; 2]>> = vec![None; positions as usize];
    for c in corners {
        let a = [c[1], c[2]];
        match &mut attrs[c[0] as usize] {
            slot @ None => *slot = Some(a),
            Some(seen) if *seen == a => {}
            Some(_) => return false,
        }
    }
    true
}

#[cfg(test)]
mod tests;
