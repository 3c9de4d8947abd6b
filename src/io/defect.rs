//! What is wrong with a mesh file, or with the attributes handed to a writer, as data: the
//! element, the counts claimed and found, the token read. [`super::IoError`] adds the file,
//! the format and the line; the `Display` of each type here is the rest of its message.

use crate::ids::VertexId;
use thiserror::Error;

/// What kind of value a token should have been ([`Syntax::Expected`],
/// [`Syntax::ElementValue`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Want {
    /// A number (integer or floating point).
    Number,
    /// An integer.
    Integer,
    /// A non-negative count.
    Count,
}

impl std::fmt::Display for Want {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Want::Number => f.write_str("a number"),
            Want::Integer => f.write_str("an integer"),
            Want::Count => f.write_str("a count"),
        }
    }
}

/// What does not parse in a mesh file ([`super::IoError::Parse`]). Element numbers are
/// 0-based in the file's own order; tokens copied from the file are shortened to 24
/// characters.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum Syntax {
    /// A byte that is not text (not UTF-8, or NUL) in a text format.
    #[error("binary data (byte {byte} is not text)")]
    Binary {
        /// its offset in the file
        byte: usize,
    },
    /// A byte that is not UTF-8 outside the names and comments that may hold such bytes.
    #[error(
        "binary data (byte {byte} is not text; only names and comments may hold bytes that \
         are not UTF-8)"
    )]
    BinaryOutsideNames {
        /// its offset in the file
        byte: usize,
    },
    /// A file that must be UTF-8 text throughout is not.
    #[error("not UTF-8 text")]
    NotUtf8,
    /// Another token where a number or a count was expected.
    #[error("expected {expected}, found `{found}`")]
    Expected {
        /// what was expected
        expected: Want,
        /// the token found
        found: String,
    },
    /// Another token where a keyword was expected.
    #[error("expected `{keyword}`, found `{found}`")]
    ExpectedKeyword {
        /// the keyword
        keyword: &'static str,
        /// the token found
        found: String,
    },
    /// Inside an ASCII STL solid, another token where a facet or the solid's end should
    /// start.
    #[error("expected `facet` or `endsolid`, found `{found}`")]
    NotAFacet {
        /// the token found
        found: String,
    },
    /// A face with fewer than three corners.
    #[error("face {face} has {vertices} vertices (at least 3 needed)")]
    FewVertices {
        /// the face
        face: usize,
        /// its number of vertices
        vertices: usize,
    },
    /// A vertex line with fewer than three coordinates.
    #[error("vertex {vertex} has {coordinates} coordinates, 3 needed")]
    FewCoordinates {
        /// the vertex
        vertex: usize,
        /// its number of coordinates
        coordinates: usize,
    },
    /// An OBJ texture coordinate (`vt`) that is NaN or infinite.
    #[error("non-finite texture coordinate")]
    NonFiniteTexture,
    /// An OBJ face corner names a texture coordinate that does not exist.
    #[error("face {face}: texture index {index} does not exist ({defined} defined)")]
    BadTextureIndex {
        /// the face
        face: usize,
        /// the index as written (1-based, may be negative)
        index: i64,
        /// the number of `vt` lines above the face
        defined: usize,
    },
    /// An OFF counts line with fewer than two counts.
    #[error("expected the counts `V F E`")]
    NoCounts,
    /// An OFF face continued on the next line, which holds more indices than the face lacks.
    #[error(
        "face {face} announces {announced} vertices; it continues from line {from_line} on \
         this line, which holds more than the rest of its indices"
    )]
    FaceOverflow {
        /// the face
        face: usize,
        /// the vertex count it announces
        announced: u64,
        /// the line the face starts on
        from_line: usize,
    },
    /// An OFF face with fewer indices than it announces.
    #[error("face {face} announces {announced} vertices but lists {listed}")]
    FaceShort {
        /// the face
        face: usize,
        /// the vertex count it announces
        announced: u64,
        /// the indices it lists
        listed: u64,
    },
    /// A PLY value that does not parse as its property's type.
    #[error("element `{element}` {index}: expected {expected}, found `{found}`")]
    ElementValue {
        /// the element's name
        element: String,
        /// the element's number
        index: u64,
        /// what the property's type needs
        expected: Want,
        /// the token found
        found: String,
    },
    /// A PLY list with a negative length.
    #[error("element `{element}` {index}: list `{list}` has length {length}")]
    NegativeListLength {
        /// the element's name
        element: String,
        /// the element's number
        index: u64,
        /// the list property's name
        list: String,
        /// the length read
        length: i64,
    },
    /// A PLY `format` line with another format.
    #[error("unknown format `{found}`")]
    PlyFormat {
        /// the format named
        found: String,
    },
    /// A PLY header line of the wrong shape.
    #[error("expected `{expected}`")]
    HeaderLine {
        /// the shape of the line
        expected: &'static str,
    },
    /// A PLY element count that is not a count.
    #[error("bad element count `{found}`")]
    ElementCount {
        /// the token found
        found: String,
    },
    /// A PLY `property` line before any `element` line.
    #[error("property before any element")]
    PropertyBeforeElement,
    /// A PLY header without a `format` line.
    #[error("no `format` line")]
    NoFormatLine,
    /// A PLY header line (no comment) that is not text.
    #[error("header line is not text")]
    HeaderNotText,
    /// A PLY list whose count type is not an integer type.
    #[error("list `{list}` has non-integer count type `{ty}`")]
    ListCountType {
        /// the list property's name
        list: String,
        /// its count type
        ty: String,
    },
    /// A PLY face list whose index type is not an integer type.
    #[error("face list `{list}` has non-integer index type")]
    ListIndexType {
        /// the list property's name
        list: String,
    },
    /// A PLY `vertex` element without scalar `x`, `y` and `z`.
    #[error("element `vertex` lacks scalar x, y or z")]
    NoPosition,
    /// A PLY file without a `vertex` element.
    #[error("no `vertex` element")]
    NoVertexElement,
    /// A Medit `Dimension` other than 2 or 3.
    #[error("dimension {0} (2 or 3 expected)")]
    Dimension(i64),
    /// A Medit section keyword that conemesh does not know.
    #[error("unknown section `{found}`")]
    UnknownSection {
        /// the keyword found
        found: String,
    },
    /// A line of a patch file that is neither a patch id nor `-`.
    #[error("expected a patch id (0 to {}) or -, got {found:?}", u32::MAX)]
    NotAPatchId {
        /// the line (shortened, non-printable bytes as `?`)
        found: String,
    },
}

/// What a truncated mesh file lacks ([`super::IoError::Truncated`]): what its header claims,
/// or where the text ends.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum Truncation {
    /// A header claims more elements than the file's size can hold.
    #[error("header claims {claimed} {what}, more than the file's {file_bytes} bytes can hold")]
    Claim {
        /// the claimed count
        claimed: u64,
        /// "vertices", "faces", "elements", ...
        what: &'static str,
        /// the size of the file (plus one where the last token needs no separator)
        file_bytes: usize,
    },
    /// The file ends before the elements its header claims.
    #[error("header claims {claimed} {what}, file ends after {found}")]
    Elements {
        /// the claimed count
        claimed: u64,
        /// "vertices" or "faces"
        what: &'static str,
        /// the elements read
        found: usize,
    },
    /// The file ends inside a PLY element.
    #[error("file ends inside element `{element}` {index} of {claimed} (header claims {claimed})")]
    InsideElement {
        /// the element's name
        element: String,
        /// the element's number
        index: u64,
        /// the count its header claims
        claimed: u64,
    },
    /// The file ends where a keyword was expected.
    #[error("file ends where `{keyword}` was expected (line {line})")]
    Keyword {
        /// the keyword
        keyword: &'static str,
        /// the last line of the file
        line: usize,
    },
    /// The file ends inside its header.
    #[error("file ends inside the header (line {line})")]
    InsideHeader {
        /// the last line read
        line: usize,
    },
    /// The file ends after a keyword, before its value.
    #[error("file ends inside `{keyword}` (line {line})")]
    InsideKeyword {
        /// the keyword
        keyword: &'static str,
        /// its line
        line: usize,
    },
    /// The file ends inside a Medit section.
    #[error("file ends inside {section} (line {line})")]
    InsideSection {
        /// the section's keyword as written
        section: String,
        /// the last line read
        line: usize,
    },
    /// The file ends inside an ASCII STL facet.
    #[error("file ends inside a facet (line {line})")]
    InsideFacet {
        /// the last line of the file
        line: usize,
    },
    /// An ASCII STL file ends before `endsolid`.
    #[error("file ends before `endsolid` (line {line})")]
    NoEndsolid {
        /// the last line of the file
        line: usize,
    },
    /// An OFF header without its counts line.
    #[error("no counts line after the header")]
    NoCounts,
    /// A PLY header without `end_header`.
    #[error("header has no `end_header` line")]
    NoEndHeader,
    /// An STL file that is neither ASCII nor long enough for a binary header.
    #[error(
        "{file_bytes} bytes: not ASCII (no `solid`) and shorter than the 84-byte binary header"
    )]
    ShortStl {
        /// the size of the file
        file_bytes: usize,
    },
    /// A binary STL file shorter than its facet count needs.
    #[error("header claims {claimed} facets ({need} bytes), file has {file_bytes} bytes")]
    Facets {
        /// the claimed facet count
        claimed: u64,
        /// the bytes those facets need
        need: u64,
        /// the size of the file
        file_bytes: usize,
    },
}

/// A format variant that conemesh does not read ([`super::IoError::Unsupported`]).
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum Unread {
    /// An OFF variant whose vertices are not in 3D (`4OFF`, `nOFF`).
    #[error("`{magic}` (vertices not in 3D)")]
    OffDimension {
        /// the magic word as written
        magic: String,
    },
    /// Binary OFF.
    #[error("binary OFF")]
    BinaryOff,
    /// A PLY face element (`face`, `tristrips`) without a `vertex_indices` list.
    #[error("element `{element}` without a `vertex_indices` list")]
    NoVertexIndices {
        /// the element's name
        element: &'static str,
    },
}

/// Attributes handed to a writer that do not match the mesh ([`super::IoError::BadAttribute`]).
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum AttributeProblem {
    /// A face property with another number of values than the mesh has faces.
    #[error("face property `{name}` has {values} values for {faces} faces")]
    FacePropertyLength {
        /// the property
        name: String,
        /// its number of values
        values: usize,
        /// the mesh's number of faces
        faces: usize,
    },
    /// A face property name that is empty or holds whitespace.
    #[error("face property name {name:?} is not one word")]
    FacePropertyName {
        /// the name
        name: String,
    },
    /// Another number of face colours than the mesh has faces.
    #[error("{colors} face colours for {faces} faces")]
    FaceColors {
        /// the number of colours
        colors: usize,
        /// the mesh's number of faces
        faces: usize,
    },
    /// Another number of uv coordinates than the mesh has vertices.
    #[error("{uvs} uv coordinates for {vertices} vertices")]
    UvCount {
        /// the number of uv coordinates
        uvs: usize,
        /// the mesh's number of vertices
        vertices: usize,
    },
    /// A uv coordinate that is NaN or infinite.
    #[error("non-finite uv coordinate at vertex {vertex}")]
    NonFiniteUv {
        /// the first vertex with one
        vertex: VertexId,
    },
}
