//! Stanford PLY: `ascii`, `binary_little_endian` and `binary_big_endian`.
//!
//! Read: element `vertex` with scalar `x y z` of any numeric type (optional `u v`, `s t` or
//! `texture_u texture_v`); element `face` with a list `vertex_indices` (or `vertex_index`) of
//! any integer count and index types, its scalar integer properties (kept as face attributes,
//! `red green blue` as colours); element `tristrips` (strips separated by `-1`, decoded with
//! alternating orientation). Every other element and property is skipped by its declared type.
//! Write: `double x y z` (bit-exact), optional `double u v`, `list uchar int vertex_indices`,
//! optional `int NAME` face properties and `uchar red green blue`.

use super::text::{as_text, short, Tokens};
use super::{
    build_mesh, capped, check_claim, IoError, LoadedMesh, MeshAttributes, RawFaces, Syntax,
    Truncation, Unread, Want, WriteOptions,
};
use crate::mesh::TriMesh;
use nalgebra::{Point2, Point3};
use std::io::Write;

const F: &str = "PLY";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

#[derive(Clone, Copy, Debug)]
enum Num {
    I(i64),
    F(f64),
}

impl Num {
    fn f64(self) -> f64 {
        match self {
            Num::I(i) => i as f64,
            Num::F(x) => x,
        }
    }
}

#[derive(Debug)]
struct Prop {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Ty>,
    ty: Ty,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Prop>,
}

impl Element {
    /// The least number of bytes one element can take in the body.
    fn min_bytes(&self, ascii: bool) -> u64 {
        self.props
            .iter()
            .map(|p| match (ascii, p.list) {
                (true, _) => 2,
                (false, Some(c)) => c.size() as u64,
                (false, None) => p.ty.size() as u64,
            })
            .sum()
    }
    fn find(&self, names: &[&str]) -> Option<usize> {
        self.props
            .iter()
            .position(|p| p.list.is_none() && names.contains(&p.name.as_str()))
    }
}

/// The body, ASCII tokens or binary bytes.
enum Body<'a> {
    Ascii(Tokens<'a>),
    Binary {
        data: &'a [u8],
        pos: usize,
        big_endian: bool,
    },
}

struct Reader<'a, 'p> {
    body: Body<'a>,
    path: &'p str,
}

impl Reader<'_, '_> {
    fn line(&self) -> usize {
        match &self.body {
            Body::Ascii(t) => t.last_line,
            Body::Binary { .. } => 0,
        }
    }

    fn remaining(&self) -> usize {
        match &self.body {
            Body::Ascii(_) => usize::MAX,
            Body::Binary { data, pos, .. } => data.len() - pos,
        }
    }

    fn truncated(&self, el: &Element, i: u64) -> IoError {
        IoError::Truncated {
            path: self.path.to_string(),
            format: F,
            missing: Truncation::InsideElement {
                element: el.name.clone(),
                index: i,
                claimed: el.count,
            },
        }
    }

    fn scalar(&mut self, ty: Ty, el: &Element, i: u64) -> Result<Num, IoError> {
        match &mut self.body {
            Body::Ascii(t) => {
                let Some((line, tok)) = t.next() else {
                    return Err(self.truncated(el, i));
                };
                let bad = |expected: Want| IoError::Parse {
                    path: self.path.to_string(),
                    format: F,
                    line,
                    defect: Syntax::ElementValue {
                        element: el.name.clone(),
                        index: i,
                        expected,
                        found: short(tok),
                    },
                };
                if ty.is_int() {
                    tok.parse::<i64>()
                        .map(Num::I)
                        .map_err(|_| bad(Want::Integer))
                } else {
                    tok.parse::<f64>()
                        .map(Num::F)
                        .map_err(|_| bad(Want::Number))
                }
            }
            Body::Binary {
                data,
                pos,
                big_endian,
            } => {
                let n = ty.size();
                let Some(b) = data.get(*pos..*pos + n) else {
                    return Err(self.truncated(el, i));
                };
                *pos += n;
                let mut a = [0u8; 8];
                a[..n].copy_from_slice(b);
                if *big_endian {
                    a[..n].reverse();
                }
                Ok(match ty {
                    Ty::I8 => Num::I(a[0] as i8 as i64),
                    Ty::U8 => Num::I(a[0] as i64),
                    Ty::I16 => Num::I(i16::from_le_bytes([a[0], a[1]]) as i64),
                    Ty::U16 => Num::I(u16::from_le_bytes([a[0], a[1]]) as i64),
                    Ty::I32 => Num::I(i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as i64),
                    Ty::U32 => Num::I(u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as i64),
                    Ty::F32 => Num::F(f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64),
                    Ty::F64 => Num::F(f64::from_le_bytes(a)),
                })
            }
        }
    }

    /// A list's length, checked against what the rest of the file can hold.
    fn list_len(&mut self, p: &Prop, count_ty: Ty, el: &Element, i: u64) -> Result<usize, IoError> {
        // Count types are integers (checked in the header); a float cannot arrive here.
        let n = match self.scalar(count_ty, el, i)? {
            Num::I(n) => n,
            Num::F(x) => x as i64,
        };
        let line = self.line();
        if n < 0 {
            return Err(IoError::Parse {
                path: self.path.to_string(),
                format: F,
                line,
                defect: Syntax::NegativeListLength {
                    element: el.name.clone(),
                    index: i,
                    list: p.name.clone(),
                    length: n,
                },
            });
        }
        let n = n as u64;
        if n.saturating_mul(p.ty.size() as u64) > self.remaining() as u64 {
            return Err(self.truncated(el, i));
        }
        Ok(n as usize)
    }
}

struct Header {
    /// Header lines skipped (unknown keywords), one warning each.
    warnings: Vec<String>,
    elements: Vec<Element>,
    format: Option<(bool, bool)>, // (binary, big endian)
    body_start: usize,
    body_first_line: usize,
}

fn parse_header(bytes: &[u8], path: &str) -> Result<Header, IoError> {
    let err = |line: usize, defect: Syntax| IoError::Parse {
        path: path.to_string(),
        format: F,
        line,
        defect,
    };
    let (lines, body_start, end_line) = header_lines(bytes, path)?;
    let mut h = Header {
        warnings: Vec::new(),
        elements: Vec::new(),
        format: None,
        body_start,
        body_first_line: end_line + 1,
    };
    for &(l, text) in lines.iter().skip(1) {
        let t: Vec<&str> = text.split_ascii_whitespace().collect();
        match t.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                h.format = Some(match t.get(1).copied() {
                    Some("ascii") => (false, false),
                    Some("binary_little_endian") => (true, false),
                    Some("binary_big_endian") => (true, true),
                    other => {
                        return Err(err(
                            l,
                            Syntax::PlyFormat {
                                found: short(other.unwrap_or("")),
                            },
                        ))
                    }
                });
            }
            Some("element") => {
                if t.len() != 3 {
                    return Err(err(
                        l,
                        Syntax::HeaderLine {
                            expected: "element NAME COUNT",
                        },
                    ));
                }
                let count = t[2]
                    .parse::<u64>()
                    .map_err(|_| err(l, Syntax::ElementCount { found: short(t[2]) }))?;
                h.elements.push(Element {
                    name: t[1].to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let Some(el) = h.elements.last_mut() else {
                    return Err(err(l, Syntax::PropertyBeforeElement));
                };
                let prop = parse_property(&t, l, el, path)?;
                el.props.push(prop);
            }
            // A line that is no keyword (an exporter's free text, `Created by Blender3D 247
            // ...`) cannot change the data layout, which only `format`, `element` and
            // `property` lines set: it is skipped, with a warning naming it.
            Some(k) => h.warnings.push(format!(
                "{path}:{l}: PLY header line starting with unknown keyword `{}` skipped",
                short(k)
            )),
        }
    }
    if h.format.is_none() {
        return Err(err(2, Syntax::NoFormatLine));
    }
    Ok(h)
}

/// Numbered text lines.
type HeaderLines<'b> = Vec<(usize, &'b str)>;

/// The header's text lines with their numbers (the magic `ply` first, `end_header` left
/// out), the body's byte offset and the number of the `end_header` line.
fn header_lines<'b>(
    bytes: &'b [u8],
    path: &str,
) -> Result<(HeaderLines<'b>, usize, usize), IoError> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(IoError::Empty {
            path: path.to_string(),
            format: F,
        });
    }
    let first_end = bytes
        .iter()
        .position(|&b| b == b'\n' || b == b'\r')
        .unwrap_or(bytes.len());
    let first = &bytes[..first_end];
    if first != b"ply" {
        return Err(IoError::BadMagic {
            path: path.to_string(),
            format: F,
            found: super::printable(&bytes[..first_end]),
        });
    }
    // The header ends at the line `end_header`; the body starts after its newline.
    let mut pos = 0;
    let mut line_no = 0;
    let mut lines = Vec::new();
    let body_start = loop {
        if pos >= bytes.len() {
            return Err(IoError::Truncated {
                path: path.to_string(),
                format: F,
                missing: Truncation::NoEndHeader,
            });
        }
        // A header line ends with LF, CRLF or a lone CR.
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .map_or(bytes.len(), |k| pos + k);
        line_no += 1;
        let raw = &bytes[pos..end];
        let crlf = bytes.get(end) == Some(&b'\r') && bytes.get(end + 1) == Some(&b'\n');
        pos = (end + if crlf { 2 } else { 1 }).min(bytes.len());
        let Ok(text) = std::str::from_utf8(raw) else {
            // Comments may hold any bytes (an exporter's code page); nothing else may.
            let word = raw
                .split(|b| b.is_ascii_whitespace())
                .find(|w| !w.is_empty());
            if matches!(word, Some(b"comment" | b"obj_info")) {
                continue;
            }
            return Err(IoError::Parse {
                path: path.to_string(),
                format: F,
                line: line_no,
                defect: Syntax::HeaderNotText,
            });
        };
        if text.trim() == "end_header" {
            break pos;
        }
        lines.push((line_no, text));
    };
    Ok((lines, body_start, line_no))
}

/// One `property` line (`t`, split at whitespace; line `l`) of element `el`.
fn parse_property(t: &[&str], l: usize, el: &Element, path: &str) -> Result<Prop, IoError> {
    let err = |defect: Syntax| IoError::Parse {
        path: path.to_string(),
        format: F,
        line: l,
        defect,
    };
    let unknown = |ty: &str, name: &str| IoError::UnknownProperty {
        path: path.to_string(),
        line: l,
        element: el.name.clone(),
        property: name.to_string(),
        ty: short(ty),
    };
    if t.get(1) == Some(&"list") {
        if t.len() != 5 {
            return Err(err(Syntax::HeaderLine {
                expected: "property list COUNT_TYPE TYPE NAME",
            }));
        }
        let ct = Ty::parse(t[2]).ok_or_else(|| unknown(t[2], t[4]))?;
        let ty = Ty::parse(t[3]).ok_or_else(|| unknown(t[3], t[4]))?;
        if !ct.is_int() {
            return Err(err(Syntax::ListCountType {
                list: short(t[4]),
                ty: short(t[2]),
            }));
        }
        Ok(Prop {
            name: t[4].to_string(),
            list: Some(ct),
            ty,
        })
    } else {
        if t.len() != 3 {
            return Err(err(Syntax::HeaderLine {
                expected: "property TYPE NAME",
            }));
        }
        Ok(Prop {
            name: t[2].to_string(),
            list: None,
            ty: Ty::parse(t[1]).ok_or_else(|| unknown(t[1], t[2]))?,
        })
    }
}

/// Per-element roles of the properties the reader keeps.
struct FaceRoles {
    list: usize,
    ints: Vec<usize>,
    rgb: Option<[usize; 3]>,
}

/// What the body's elements hold, as read so far.
struct Contents {
    positions: Vec<Point3<f64>>,
    uv: Option<Vec<Point2<f64>>>,
    faces: RawFaces,
    /// Integer face properties by name (one value per face).
    face_ints: Vec<(String, Vec<i64>)>,
    colors: Option<Vec<[u8; 3]>>,
    saw_vertex: bool,
    saw_faces: bool,
}

/// The scratch buffers one element is read into, reused across elements.
struct Scratch {
    vals: Vec<Num>,
    list: Vec<i64>,
}

pub(super) fn read(bytes: &[u8], path: &str) -> Result<LoadedMesh, IoError> {
    let mut h = parse_header(bytes, path)?;
    let (binary, big_endian) = h.format.unwrap_or((false, false));
    let body_bytes = &bytes[h.body_start..];
    let body = body(body_bytes, binary, big_endian, h.body_first_line, path)?;
    for el in &h.elements {
        // +1: the last ASCII token needs no separator after it.
        check_claim(
            path,
            F,
            "elements",
            el.count,
            el.min_bytes(!binary),
            body_bytes.len() + 1,
        )?;
    }
    let mut rd = Reader { body, path };
    let mut c = Contents {
        positions: Vec::new(),
        uv: None,
        faces: RawFaces::with_capacity(0, 0),
        face_ints: Vec::new(),
        colors: None,
        saw_vertex: false,
        saw_faces: false,
    };
    let mut warnings = std::mem::take(&mut h.warnings);
    let mut scratch = Scratch {
        vals: Vec::new(),
        list: Vec::new(),
    };
    for el in &h.elements {
        match el.name.as_str() {
            "vertex" => read_vertices(&mut rd, el, binary, &mut scratch, &mut c)?,
            "face" => read_faces(&mut rd, el, binary, &mut scratch, &mut c)?,
            "tristrips" => {
                read_tristrips(&mut rd, el, &mut scratch, &mut c)?;
                warnings.push(format!("{path}: triangle strips decoded"));
            }
            _ => {
                if !el.props.is_empty() {
                    for i in 0..el.count {
                        read_element(&mut rd, el, i, &mut scratch.vals, &mut scratch.list)?;
                    }
                }
                warnings.push(format!("{path}: PLY element `{}` skipped", el.name));
            }
        }
    }
    loaded_mesh(c, warnings, path)
}

/// The body after the header: binary as bytes, ASCII as tokens whose line numbers count
/// from the file's first line.
fn body<'a>(
    body_bytes: &'a [u8],
    binary: bool,
    big_endian: bool,
    body_first_line: usize,
    path: &str,
) -> Result<Body<'a>, IoError> {
    if binary {
        return Ok(Body::Binary {
            data: body_bytes,
            pos: 0,
            big_endian,
        });
    }
    Ok(Body::Ascii(Tokens::starting_at(
        as_text(body_bytes, path, F).map_err(|e| match e {
            IoError::Parse {
                path,
                format,
                line,
                defect,
            } => IoError::Parse {
                path,
                format,
                line: line + body_first_line - 1,
                defect,
            },
            e => e,
        })?,
        body_first_line,
    )))
}

fn parse_err(path: &str, defect: Syntax) -> IoError {
    IoError::Parse {
        path: path.to_string(),
        format: F,
        line: 0,
        defect,
    }
}

/// The `vertex` element: positions, and texture coordinates when it has them.
fn read_vertices(
    rd: &mut Reader,
    el: &Element,
    binary: bool,
    scratch: &mut Scratch,
    c: &mut Contents,
) -> Result<(), IoError> {
    let path = rd.path;
    c.saw_vertex = true;
    let xyz = [el.find(&["x"]), el.find(&["y"]), el.find(&["z"])];
    let [Some(x), Some(y), Some(z)] = xyz else {
        return Err(parse_err(path, Syntax::NoPosition));
    };
    let uvp = el
        .find(&["u", "s", "texture_u"])
        .zip(el.find(&["v", "t", "texture_v"]));
    let positions = &mut c.positions;
    positions.reserve(capped(
        el.count,
        rd.remaining(),
        el.min_bytes(!binary) as usize,
    ));
    if uvp.is_some() {
        c.uv = Some(Vec::with_capacity(positions.capacity()));
    }
    let vals = &mut scratch.vals;
    for i in 0..el.count {
        read_element(rd, el, i, vals, &mut scratch.list)?;
        let p = Point3::new(vals[x].f64(), vals[y].f64(), vals[z].f64());
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(IoError::NonFinite {
                path: path.to_string(),
                line: rd.line(),
                vertex: i as usize,
            });
        }
        positions.push(p);
        if let (Some((u, v)), Some(uv)) = (uvp, c.uv.as_mut()) {
            uv.push(Point2::new(vals[u].f64(), vals[v].f64()));
        }
    }
    Ok(())
}

/// The `face` element: the index lists, and the integer properties and colours that follow
/// each face.
fn read_faces(
    rd: &mut Reader,
    el: &Element,
    binary: bool,
    scratch: &mut Scratch,
    c: &mut Contents,
) -> Result<(), IoError> {
    let path = rd.path;
    c.saw_faces = true;
    let Some(li) = el
        .props
        .iter()
        .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"))
    else {
        return Err(IoError::Unsupported {
            path: path.to_string(),
            format: F,
            what: Unread::NoVertexIndices { element: "face" },
        });
    };
    if !el.props[li].ty.is_int() {
        return Err(parse_err(
            path,
            Syntax::ListIndexType {
                list: el.props[li].name.clone(),
            },
        ));
    }
    let int_scalar = |name: &str| {
        el.props
            .iter()
            .position(|p| p.list.is_none() && p.ty.is_int() && p.name == name)
    };
    let rgb = match (int_scalar("red"), int_scalar("green"), int_scalar("blue")) {
        (Some(r), Some(g), Some(b)) => Some([r, g, b]),
        _ => None,
    };
    let ints: Vec<usize> = (0..el.props.len())
        .filter(|&k| {
            let p = &el.props[k];
            p.list.is_none() && p.ty.is_int() && !rgb.is_some_and(|c| c.contains(&k))
        })
        .collect();
    let roles = FaceRoles {
        list: li,
        ints,
        rgb,
    };
    let cap = capped(el.count, rd.remaining(), el.min_bytes(!binary) as usize);
    c.face_ints = roles
        .ints
        .iter()
        .map(|&k| (el.props[k].name.clone(), Vec::with_capacity(cap)))
        .collect();
    if roles.rgb.is_some() {
        c.colors = Some(Vec::with_capacity(cap));
    }
    let Scratch { vals, list } = scratch;
    for i in 0..el.count {
        read_element_face(rd, el, i, &roles, vals, list)?;
        c.faces.begin(rd.line());
        for &v in list.iter() {
            c.faces.push(v);
        }
        for (slot, &k) in c.face_ints.iter_mut().zip(&roles.ints) {
            if let Num::I(v) = vals[k] {
                slot.1.push(v);
            }
        }
        if let (Some([r, g, b]), Some(colors)) = (roles.rgb, c.colors.as_mut()) {
            let u = |k: usize| match vals[k] {
                Num::I(v) => v.clamp(0, 255) as u8,
                Num::F(_) => 0,
            };
            colors.push([u(r), u(g), u(b)]);
        }
    }
    Ok(())
}

/// The `tristrips` element: each strip decoded into triangles.
fn read_tristrips(
    rd: &mut Reader,
    el: &Element,
    scratch: &mut Scratch,
    c: &mut Contents,
) -> Result<(), IoError> {
    c.saw_faces = true;
    let Some(li) = el
        .props
        .iter()
        .position(|p| p.list.is_some() && p.name == "vertex_indices")
    else {
        return Err(IoError::Unsupported {
            path: rd.path.to_string(),
            format: F,
            what: Unread::NoVertexIndices {
                element: "tristrips",
            },
        });
    };
    let roles = FaceRoles {
        list: li,
        ints: Vec::new(),
        rgb: None,
    };
    for i in 0..el.count {
        read_element_face(rd, el, i, &roles, &mut scratch.vals, &mut scratch.list)?;
        decode_strips(&scratch.list, rd.line(), &mut c.faces);
    }
    Ok(())
}

/// The mesh from the elements read, with the face attributes spread over the triangles.
fn loaded_mesh(c: Contents, mut warnings: Vec<String>, path: &str) -> Result<LoadedMesh, IoError> {
    if !c.saw_vertex {
        return Err(parse_err(path, Syntax::NoVertexElement));
    }
    if !c.saw_faces {
        return Err(IoError::NoFaces {
            path: path.to_string(),
            format: F,
        });
    }
    let n_v = c.positions.len();
    let (mesh, polygons, origin, repeated) = build_mesh(path, F, c.positions, &c.faces)?;
    if polygons > 0 {
        warnings.push(format!(
            "{path}: {polygons} polygon faces cut into triangles"
        ));
    }
    // Face attributes follow their face into each of its triangles (tristrips carry none).
    let spread =
        |v: &Vec<i64>| -> Option<Vec<i64>> { origin.iter().map(|&f| v.get(f).copied()).collect() };
    let attributes = MeshAttributes {
        face_ints: c
            .face_ints
            .iter()
            .filter_map(|(name, v)| Some((name.clone(), spread(v)?)))
            .collect(),
        face_colors: c
            .colors
            .and_then(|c| origin.iter().map(|&f| c.get(f).copied()).collect()),
        uv: c.uv.filter(|u| u.len() == n_v),
    };
    Ok(LoadedMesh {
        mesh,
        polygons_triangulated: polygons,
        welded_vertices: 0,
        warnings,
        attributes,
        repeated_index_faces: repeated,
    })
}

/// Read one element: scalars into `vals` (lists are skipped, `vals` gets a placeholder).
fn read_element(
    rd: &mut Reader,
    el: &Element,
    i: u64,
    vals: &mut Vec<Num>,
    list: &mut Vec<i64>,
) -> Result<(), IoError> {
    vals.clear();
    for p in &el.props {
        match p.list {
            None => vals.push(rd.scalar(p.ty, el, i)?),
            Some(ct) => {
                let k = rd.list_len(p, ct, el, i)?;
                list.clear();
                for _ in 0..k {
                    rd.scalar(p.ty, el, i)?;
                }
                vals.push(Num::I(k as i64));
            }
        }
    }
    Ok(())
}

/// Read one face-like element: scalars into `vals`, the index list `roles.list` into `list`.
fn read_element_face(
    rd: &mut Reader,
    el: &Element,
    i: u64,
    roles: &FaceRoles,
    vals: &mut Vec<Num>,
    list: &mut Vec<i64>,
) -> Result<(), IoError> {
    vals.clear();
    for (k, p) in el.props.iter().enumerate() {
        match p.list {
            None => vals.push(rd.scalar(p.ty, el, i)?),
            Some(ct) => {
                let n = rd.list_len(p, ct, el, i)?;
                if k == roles.list {
                    list.clear();
                    for _ in 0..n {
                        if let Num::I(v) = rd.scalar(p.ty, el, i)? {
                            list.push(v);
                        }
                    }
                } else {
                    for _ in 0..n {
                        rd.scalar(p.ty, el, i)?;
                    }
                }
                vals.push(Num::I(n as i64));
            }
        }
    }
    Ok(())
}

/// Triangle strips: `-1` ends a strip; triangle k of a strip is `(s[k], s[k+1], s[k+2])`,
/// with odd k reversed so that all triangles share the strip's orientation. Triangles with a
/// repeated vertex are the strips' usual joins and are dropped.
fn decode_strips(list: &[i64], line: usize, faces: &mut RawFaces) {
    for strip in list.split(|&v| v < 0) {
        for k in 0..strip.len().saturating_sub(2) {
            let (a, b, c) = (strip[k], strip[k + 1], strip[k + 2]);
            if a == b || b == c || a == c {
                continue;
            }
            faces.begin(line);
            if k % 2 == 0 {
                faces.push(a);
                faces.push(b);
            } else {
                faces.push(b);
                faces.push(a);
            }
            faces.push(c);
        }
    }
}

pub(super) fn write(
    w: &mut dyn Write,
    mesh: &TriMesh,
    attrs: &MeshAttributes,
    opts: &WriteOptions,
) -> std::io::Result<()> {
    let enc = match (opts.binary, opts.big_endian) {
        (false, _) => "ascii",
        (true, false) => "binary_little_endian",
        (true, true) => "binary_big_endian",
    };
    writeln!(w, "ply\nformat {enc} 1.0\ncomment written by conemesh")?;
    writeln!(w, "element vertex {}", mesh.n_vertices())?;
    writeln!(w, "property double x\nproperty double y\nproperty double z")?;
    if attrs.uv.is_some() {
        writeln!(w, "property double u\nproperty double v")?;
    }
    writeln!(w, "element face {}", mesh.n_faces())?;
    writeln!(w, "property list uchar int vertex_indices")?;
    for (name, _) in &attrs.face_ints {
        writeln!(w, "property int {name}")?;
    }
    if attrs.face_colors.is_some() {
        writeln!(
            w,
            "property uchar red\nproperty uchar green\nproperty uchar blue"
        )?;
    }
    writeln!(w, "end_header")?;
    let int = |v: i64| {
        i32::try_from(v).map_err(|_| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("face property value {v} does not fit a PLY int"),
            )
        })
    };
    if !opts.binary {
        for (i, p) in mesh.positions.iter().enumerate() {
            // `{:?}` of f64 is the shortest text that parses back to the same bits.
            write!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
            if let Some(uv) = &attrs.uv {
                write!(w, " {:?} {:?}", uv[i].x, uv[i].y)?;
            }
            writeln!(w)?;
        }
        for (f, t) in mesh.triangles.iter().enumerate() {
            write!(w, "3 {} {} {}", t[0].0, t[1].0, t[2].0)?;
            for (_, v) in &attrs.face_ints {
                write!(w, " {}", int(v[f])?)?;
            }
            if let Some(c) = &attrs.face_colors {
                write!(w, " {} {} {}", c[f][0], c[f][1], c[f][2])?;
            }
            writeln!(w)?;
        }
        return Ok(());
    }
    let be = opts.big_endian;
    let f64b = |x: f64| if be { x.to_be_bytes() } else { x.to_le_bytes() };
    let i32b = |x: i32| if be { x.to_be_bytes() } else { x.to_le_bytes() };
    for (i, p) in mesh.positions.iter().enumerate() {
        for x in [p.x, p.y, p.z] {
            w.write_all(&f64b(x))?;
        }
        if let Some(uv) = &attrs.uv {
            w.write_all(&f64b(uv[i].x))?;
            w.write_all(&f64b(uv[i].y))?;
        }
    }
    for (f, t) in mesh.triangles.iter().enumerate() {
        w.write_all(&[3])?;
        for v in t {
            w.write_all(&i32b(int(v.0 as i64)?))?;
        }
        for (_, v) in &attrs.face_ints {
            w.write_all(&i32b(int(v[f])?))?;
        }
        if let Some(c) = &attrs.face_colors {
            w.write_all(&c[f])?;
        }
    }
    Ok(())
}
