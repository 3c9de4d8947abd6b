//! Medit `.sol` files (the Gamma Mesh Format used by Medit and MMG): per-vertex metric tensors.
//!
//! Conventions (see `paper-notes.md` § 3.1):
//! - Only `SolAtVertices` with exactly one solution field, dimension 3.
//! - Type 3 (symmetric matrix): six numbers per vertex in the order `m11 m12 m22 m13 m23 m33`
//!   (the lower triangle row by row, the order MMG reads).
//! - Type 1 (scalar): an isotropic target size `h` (MMG's convention), read as the metric
//!   `M = I / h²` (so that an edge of length `h` has metric length 1); `h` must be positive.
//! - ASCII and binary (`libMeshb` layout: a 4-byte `1` giving the byte order, the version, then
//!   keywords `code, next-keyword position, header, data`). Versions 1 (float32), 2 (float64,
//!   32-bit positions) and 3 (float64, 64-bit positions) are read; binary files are written as
//!   version 2 little-endian (version 3 above 2 GiB), ASCII files with the shortest decimal that
//!   reads back to the same `f64` (bit-exact round trip).
//!
//! The reader checks the format only (count, finiteness, layout); positive definiteness on the
//! tangent plane is checked against the mesh by [`crate::metric::MetricField::new`].

use nalgebra::Matrix3;
use std::path::Path;
use thiserror::Error;

/// Errors of reading and writing `.sol` files.
#[derive(Debug, Error)]
pub enum SolError {
    /// Operating-system error on a path.
    #[error("{path}: {source}")]
    Io {
        /// the file
        path: String,
        /// the OS error
        source: std::io::Error,
    },
    /// The file has a different number of vertices than the mesh.
    #[error("{path}: SolAtVertices has {found} entries but the mesh has {expected} vertices")]
    CountMismatch {
        /// the file
        path: String,
        /// vertices of the mesh
        expected: usize,
        /// entries in the file
        found: usize,
    },
    /// A value is NaN or infinite.
    #[error("{path}: the solution at vertex v{vertex} is NaN or infinite")]
    NaN {
        /// the file
        path: String,
        /// 0-based vertex index
        vertex: usize,
    },
    /// A scalar size that is not positive.
    #[error("{path}: the size at vertex v{vertex} is {value}, not positive")]
    InvalidSize {
        /// the file
        path: String,
        /// 0-based vertex index
        vertex: usize,
        /// the value read
        value: f64,
    },
    /// A token that does not parse, or a misplaced keyword.
    #[error("{path}:{line}: {defect}")]
    Parse {
        /// the file
        path: String,
        /// 1-based line number (ASCII) or 0 (binary)
        line: usize,
        /// what went wrong
        defect: SolSyntax,
    },
    /// Dimension, solution type, field count or binary version we do not read.
    #[error("{path}: unsupported: {what}")]
    UnsupportedType {
        /// the file
        path: String,
        /// what
        what: SolUnsupported,
    },
    /// The file ends before all the data announced by its header.
    #[error("{path}: truncated: {missing}")]
    Truncated {
        /// the file
        path: String,
        /// what was missing
        missing: SolTruncation,
    },
}

/// What does not parse in a `.sol` file ([`SolError::Parse`]).
#[derive(Debug, Error)]
pub enum SolSyntax {
    /// The bytes are neither a binary `.solb` nor UTF-8 text.
    #[error("neither binary nor UTF-8 text ({0})")]
    NotText(#[source] std::str::Utf8Error),
    /// An integer was expected.
    #[error("expected {what} (an integer), found {found:?}")]
    NotAnInteger {
        /// what the integer is
        what: &'static str,
        /// the token found
        found: String,
    },
    /// A number was expected.
    #[error("expected a number, found {found:?}")]
    NotANumber {
        /// the token found
        found: String,
    },
    /// A second `SolAtVertices` block.
    #[error("second SolAtVertices block")]
    SecondBlock,
    /// A negative vertex count.
    #[error("negative count {0}")]
    NegativeCount(i64),
    /// A field count outside 0..=64.
    #[error("{0} solution fields")]
    FieldCount(i64),
    /// A token where a keyword was expected.
    #[error("unexpected token {0:?} (expected a keyword: MeshVersionFormatted, Dimension, SolAtVertices, End)")]
    UnexpectedToken(String),
    /// A binary `SolAtVertices` header with a negative count or too many fields.
    #[error("SolAtVertices header at byte {byte}: count {count}, {fields} fields")]
    BinaryHeader {
        /// the byte offset after the header
        byte: usize,
        /// the vertex count read
        count: i64,
        /// the field count read
        fields: i64,
    },
}

/// What a `.sol` file holds that we do not read ([`SolError::UnsupportedType`]).
#[derive(Debug, Error)]
pub enum SolUnsupported {
    /// A dimension other than 3.
    #[error("dimension {0} (only 3)")]
    Dimension(i64),
    /// Solution fields other than one scalar or one symmetric matrix.
    #[error("solution types {types:?} at line {line} (only one field of type 1 or 3)")]
    Types {
        /// the types read
        types: Vec<i64>,
        /// the header's line (0 in a binary file)
        line: usize,
    },
    /// A binary version other than 1, 2 or 3.
    #[error("binary version {0} (1, 2 or 3)")]
    BinaryVersion(i64),
}

/// What a truncated `.sol` file lacks ([`SolError::Truncated`]).
#[derive(Debug, Error)]
pub enum SolTruncation {
    /// The text ends where a token was expected.
    #[error("end of file where {0} was expected")]
    Token(&'static str),
    /// The text ends inside the values.
    #[error("{need} values announced, {found} found (vertex v{vertex} incomplete)")]
    Values {
        /// values announced by the header
        need: usize,
        /// values found
        found: usize,
        /// the first incomplete vertex
        vertex: usize,
    },
    /// The bytes end inside a word.
    #[error("end of file at byte {byte} reading {what}")]
    Word {
        /// the byte offset of the word
        byte: usize,
        /// what the word is
        what: &'static str,
    },
    /// The bytes end before the values.
    #[error("{need} values announced, {left} bytes left for them")]
    Bytes {
        /// values announced by the header
        need: usize,
        /// bytes left in the file
        left: usize,
    },
    /// No `SolAtVertices` block in a text file (read up to `line`).
    #[error("no SolAtVertices block (read up to line {0})")]
    NoBlockUpTo(usize),
    /// No `SolAtVertices` block in a binary file.
    #[error("no SolAtVertices block")]
    NoBlock,
}

const KW_DIMENSION: i32 = 3;
const KW_END: i32 = 54;
const KW_SOL_AT_VERTICES: i32 = 62;
const TYPE_SCALAR: i64 = 1;
const TYPE_SYM_MATRIX: i64 = 3;

/// The raw content of the `SolAtVertices` block.
struct RawSol {
    count: usize,
    kind: i64,
    values: Vec<f64>,
}

fn values_per_vertex(kind: i64) -> usize {
    if kind == TYPE_SCALAR {
        1
    } else {
        6
    }
}

/// Read a `.sol` file of metric tensors for a mesh with `n_vertices` vertices (see the module
/// doc for the conventions). One symmetric tensor per vertex, in vertex order.
pub fn read_sol(path: &Path, n_vertices: usize) -> Result<Vec<Matrix3<f64>>, SolError> {
    let p = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| SolError::Io {
        path: p.clone(),
        source,
    })?;
    read_sol_bytes(&bytes, &p, n_vertices)
}

/// [`read_sol`] on the bytes of a file; `path` only names the source in errors.
pub fn read_sol_bytes(
    bytes: &[u8],
    path: &str,
    n_vertices: usize,
) -> Result<Vec<Matrix3<f64>>, SolError> {
    let p = path.to_string();
    let raw = if bytes.len() >= 4 && (bytes[..4] == [1, 0, 0, 0] || bytes[..4] == [0, 0, 0, 1]) {
        read_binary(&p, bytes, n_vertices)?
    } else {
        read_ascii(&p, bytes, n_vertices)?
    };
    let per = values_per_vertex(raw.kind);
    let mut out = Vec::with_capacity(raw.count);
    for v in 0..raw.count {
        let x = &raw.values[v * per..(v + 1) * per];
        if !x.iter().all(|y| y.is_finite()) {
            return Err(SolError::NaN { path: p, vertex: v });
        }
        if raw.kind == TYPE_SCALAR {
            let h = x[0];
            if h <= 0.0 {
                return Err(SolError::InvalidSize {
                    path: p,
                    vertex: v,
                    value: h,
                });
            }
            out.push(Matrix3::identity() / (h * h));
        } else {
            let (m11, m12, m22, m13, m23, m33) = (x[0], x[1], x[2], x[3], x[4], x[5]);
            out.push(Matrix3::new(m11, m12, m13, m12, m22, m23, m13, m23, m33));
        }
    }
    Ok(out)
}

fn check_header(
    p: &str,
    line: usize,
    dim: i64,
    count: usize,
    types: &[i64],
    n_vertices: usize,
) -> Result<i64, SolError> {
    if dim != 3 {
        return Err(SolError::UnsupportedType {
            path: p.to_string(),
            what: SolUnsupported::Dimension(dim),
        });
    }
    if types.len() != 1 || !(types[0] == TYPE_SCALAR || types[0] == TYPE_SYM_MATRIX) {
        return Err(SolError::UnsupportedType {
            path: p.to_string(),
            what: SolUnsupported::Types {
                types: types.to_vec(),
                line,
            },
        });
    }
    if count != n_vertices {
        return Err(SolError::CountMismatch {
            path: p.to_string(),
            expected: n_vertices,
            found: count,
        });
    }
    Ok(types[0])
}

fn read_ascii(p: &str, bytes: &[u8], n_vertices: usize) -> Result<RawSol, SolError> {
    let text = std::str::from_utf8(bytes).map_err(|e| SolError::Parse {
        path: p.to_string(),
        line: 0,
        defect: SolSyntax::NotText(e),
    })?;
    // Tokens with their 1-based line; '#' starts a comment.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut tokens = super::text::lines(text).enumerate().flat_map(|(i, l)| {
        let l = l.split('#').next().unwrap_or("");
        l.split_whitespace().map(move |t| (i + 1, t))
    });
    let mut last_line = 1usize;
    let parse_err = |line: usize, defect: SolSyntax| SolError::Parse {
        path: p.to_string(),
        line,
        defect,
    };
    let mut dim = 3i64;
    let mut sol: Option<RawSol> = None;
    macro_rules! next_int {
        ($what:expr) => {{
            match tokens.next() {
                None => {
                    return Err(SolError::Truncated {
                        path: p.to_string(),
                        missing: SolTruncation::Token($what),
                    })
                }
                Some((line, t)) => {
                    last_line = line;
                    t.parse::<i64>().map_err(|_| {
                        parse_err(
                            line,
                            SolSyntax::NotAnInteger {
                                what: $what,
                                found: t.to_string(),
                            },
                        )
                    })?
                }
            }
        }};
    }
    while let Some((line, tok)) = tokens.next() {
        last_line = line;
        if tok.eq_ignore_ascii_case("MeshVersionFormatted") {
            let _version = next_int!("the version");
        } else if tok.eq_ignore_ascii_case("Dimension") {
            dim = next_int!("the dimension");
        } else if tok.eq_ignore_ascii_case("SolAtVertices") {
            if sol.is_some() {
                return Err(parse_err(line, SolSyntax::SecondBlock));
            }
            let count = next_int!("the number of vertices");
            if count < 0 {
                return Err(parse_err(last_line, SolSyntax::NegativeCount(count)));
            }
            let ntypes = next_int!("the number of solution fields");
            if !(0..=64).contains(&ntypes) {
                return Err(parse_err(last_line, SolSyntax::FieldCount(ntypes)));
            }
            let mut types = Vec::new();
            for _ in 0..ntypes {
                types.push(next_int!("a solution type"));
            }
            let kind = check_header(p, line, dim, count as usize, &types, n_vertices)?;
            let need = count as usize * values_per_vertex(kind);
            let mut values = Vec::with_capacity(need);
            for k in 0..need {
                let Some((l, t)) = tokens.next() else {
                    return Err(SolError::Truncated {
                        path: p.to_string(),
                        missing: SolTruncation::Values {
                            need,
                            found: k,
                            vertex: k / values_per_vertex(kind),
                        },
                    });
                };
                last_line = l;
                let x = t.parse::<f64>().map_err(|_| {
                    parse_err(
                        l,
                        SolSyntax::NotANumber {
                            found: t.to_string(),
                        },
                    )
                })?;
                values.push(x);
            }
            sol = Some(RawSol {
                count: count as usize,
                kind,
                values,
            });
        } else if tok.eq_ignore_ascii_case("End") {
            break;
        } else {
            return Err(parse_err(line, SolSyntax::UnexpectedToken(tok.to_string())));
        }
    }
    sol.ok_or_else(|| SolError::Truncated {
        path: p.to_string(),
        missing: SolTruncation::NoBlockUpTo(last_line),
    })
}

/// A bounds-checked reader of binary words in the file's byte order.
struct Cursor<'a> {
    p: &'a str,
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Cursor<'_> {
    fn take<const N: usize>(&mut self, what: &'static str) -> Result<[u8; N], SolError> {
        let end = self.pos.checked_add(N).filter(|e| *e <= self.bytes.len());
        let Some(end) = end else {
            return Err(SolError::Truncated {
                path: self.p.to_string(),
                missing: SolTruncation::Word {
                    byte: self.pos,
                    what,
                },
            });
        };
        let mut b = [0u8; N];
        b.copy_from_slice(&self.bytes[self.pos..end]);
        self.pos = end;
        if self.big_endian {
            b.reverse();
        }
        Ok(b)
    }
    fn i32(&mut self, what: &'static str) -> Result<i64, SolError> {
        Ok(i32::from_le_bytes(self.take::<4>(what)?) as i64)
    }
    fn i64(&mut self, what: &'static str) -> Result<i64, SolError> {
        Ok(i64::from_le_bytes(self.take::<8>(what)?))
    }
    fn f32(&mut self, what: &'static str) -> Result<f64, SolError> {
        Ok(f32::from_le_bytes(self.take::<4>(what)?) as f64)
    }
    fn f64(&mut self, what: &'static str) -> Result<f64, SolError> {
        Ok(f64::from_le_bytes(self.take::<8>(what)?))
    }
}

fn read_binary(p: &str, bytes: &[u8], n_vertices: usize) -> Result<RawSol, SolError> {
    let mut c = Cursor {
        p,
        bytes,
        pos: 0,
        big_endian: bytes[..4] == [0, 0, 0, 1],
    };
    let _code = c.i32("the byte-order code")?;
    let version = c.i32("the version")?;
    if !(1..=3).contains(&version) {
        return Err(SolError::UnsupportedType {
            path: p.to_string(),
            what: SolUnsupported::BinaryVersion(version),
        });
    }
    let mut dim = 3i64;
    loop {
        let kw = c.i32("a keyword")? as i32;
        let next = if version >= 3 {
            c.i64("a keyword position")?
        } else {
            c.i32("a keyword position")?
        };
        match kw {
            KW_END => break,
            KW_DIMENSION => dim = c.i32("the dimension")?,
            KW_SOL_AT_VERTICES => {
                let count = c.i32("the number of vertices")?;
                let ntypes = c.i32("the number of solution fields")?;
                if count < 0 || !(0..=64).contains(&ntypes) {
                    return Err(SolError::Parse {
                        path: p.to_string(),
                        line: 0,
                        defect: SolSyntax::BinaryHeader {
                            byte: c.pos,
                            count,
                            fields: ntypes,
                        },
                    });
                }
                let mut types = Vec::new();
                for _ in 0..ntypes {
                    types.push(c.i32("a solution type")?);
                }
                let kind = check_header(p, 0, dim, count as usize, &types, n_vertices)?;
                let need = count as usize * values_per_vertex(kind);
                let width = if version == 1 { 4 } else { 8 };
                if bytes.len() - c.pos < need * width {
                    return Err(SolError::Truncated {
                        path: p.to_string(),
                        missing: SolTruncation::Bytes {
                            need,
                            left: bytes.len() - c.pos,
                        },
                    });
                }
                let mut values = Vec::with_capacity(need);
                for _ in 0..need {
                    values.push(if version == 1 {
                        c.f32("a value")?
                    } else {
                        c.f64("a value")?
                    });
                }
                return Ok(RawSol {
                    count: count as usize,
                    kind,
                    values,
                });
            }
            _ => {
                // Unknown keyword: jump over it with its next-keyword position.
                if next <= 0 || next as usize > bytes.len() || next as usize <= c.pos {
                    break;
                }
                c.pos = next as usize;
            }
        }
    }
    Err(SolError::Truncated {
        path: p.to_string(),
        missing: SolTruncation::NoBlock,
    })
}

/// The six stored numbers `m11 m12 m22 m13 m23 m33` of a tensor (its upper triangle).
fn six(m: &Matrix3<f64>) -> [f64; 6] {
    [
        m[(0, 0)],
        m[(0, 1)],
        m[(1, 1)],
        m[(0, 2)],
        m[(1, 2)],
        m[(2, 2)],
    ]
}

/// Write one symmetric tensor per vertex as a type-3 `.sol` file, ASCII or binary, atomically
/// (a temporary file in the same directory, renamed over `path`). Only the upper triangle is
/// stored; a non-finite entry is [`SolError::NaN`] and nothing is written.
pub fn write_sol(path: &Path, metrics: &[Matrix3<f64>], binary: bool) -> Result<(), SolError> {
    let bytes = sol_bytes(path, metrics, binary)?;
    let mut out = super::Outputs::new();
    let io = |e: super::IoError| match e {
        super::IoError::Os { path, error } => SolError::Io {
            path,
            source: error,
        },
        other => SolError::Io {
            path: path.display().to_string(),
            source: std::io::Error::other(other.to_string()),
        },
    };
    out.bytes(path, &bytes).map_err(io)?;
    out.commit().map_err(io)
}

/// The bytes [`write_sol`] writes to `path` (named in the error of a non-finite entry), for
/// staging with other outputs ([`super::Outputs`]).
pub fn sol_bytes(path: &Path, metrics: &[Matrix3<f64>], binary: bool) -> Result<Vec<u8>, SolError> {
    for (v, m) in metrics.iter().enumerate() {
        if !six(m).iter().all(|x| x.is_finite()) {
            return Err(SolError::NaN {
                path: path.display().to_string(),
                vertex: v,
            });
        }
    }
    Ok(if binary {
        binary_bytes(metrics)
    } else {
        ascii_bytes(metrics)
    })
}

fn ascii_bytes(metrics: &[Matrix3<f64>]) -> Vec<u8> {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(64 + metrics.len() * 120);
    s.push_str("MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n");
    let _ = writeln!(s, "{}\n1 3", metrics.len());
    for m in metrics {
        let x = six(m);
        // `{:e}` prints the shortest decimal that reads back to the same f64.
        let _ = writeln!(
            s,
            "{:e} {:e} {:e} {:e} {:e} {:e}",
            x[0], x[1], x[2], x[3], x[4], x[5]
        );
    }
    s.push_str("\nEnd\n");
    s.into_bytes()
}

fn binary_bytes(metrics: &[Matrix3<f64>]) -> Vec<u8> {
    let data = metrics.len() * 48;
    // Version 2 has 32-bit keyword positions; switch to version 3 when they would overflow.
    let version: i32 = if data + 64 < i32::MAX as usize { 2 } else { 3 };
    let mut b: Vec<u8> = Vec::with_capacity(data + 64);
    let put_pos = |b: &mut Vec<u8>, pos: usize| {
        if version == 2 {
            b.extend_from_slice(&(pos as i32).to_le_bytes());
        } else {
            b.extend_from_slice(&(pos as i64).to_le_bytes());
        }
    };
    let pos_width = if version == 2 { 4 } else { 8 };
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(&version.to_le_bytes());
    // Dimension: code, next position, 3.
    b.extend_from_slice(&KW_DIMENSION.to_le_bytes());
    let next = b.len() + pos_width + 4;
    put_pos(&mut b, next);
    b.extend_from_slice(&3i32.to_le_bytes());
    // SolAtVertices: code, next position, count, 1 field, type 3, data.
    b.extend_from_slice(&KW_SOL_AT_VERTICES.to_le_bytes());
    let next = b.len() + pos_width + 12 + data;
    put_pos(&mut b, next);
    b.extend_from_slice(&(metrics.len() as i32).to_le_bytes());
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(&(TYPE_SYM_MATRIX as i32).to_le_bytes());
    for m in metrics {
        for x in six(m) {
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    b.extend_from_slice(&KW_END.to_le_bytes());
    put_pos(&mut b, 0);
    b
}
