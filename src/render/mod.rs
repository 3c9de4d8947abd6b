//! Pictures of a surface (`conemesh render`): the front, side and iso views of a mesh in one
//! image, each face coloured by a per-face measure, with a colour bar. The paper's figures
//! that this reproduces: Fig. 3 (patches in distinct colours, [`ColorBy::Patch`]) and Fig. 6
//! (faces whose smallest angle is below 20° in magenta, [`ColorBy::Q`] and
//! [`ColorBy::MinAngle`]).
//!
//! The views are drawn by a small z-buffer software rasterizer ([`raster`]) into an RGB
//! buffer: orthographic cameras, flat shading by a head light, and a wireframe where the
//! triangles are large enough on screen to show one. Text (view names, colour-bar labels) is
//! drawn with plotters on the same buffer, when a font is available ([`crate::report`]).
//! No GPU or display is needed, and the same input gives the same bytes.
//!
//! Entry points: [`face_colors`] turns a mesh and its data (metric, reference surface, patch
//! ids) into per-face colours, [`render`] draws them, [`Image::png`] encodes the result.

mod colors;
mod legend;
pub mod raster;

pub use colors::{
    face_colors, map_color, quality_face_colors, ColorBy, FaceColors, Legend, Sources,
    VertexMetric, DISTANCE_MAP, FLAG_ANGLE, KEPT_GREY, PATCH_PALETTE, PLAIN, QUALITY_MAP,
};

use crate::mesh::TriMesh;
use thiserror::Error;

/// Magenta, the colour of a flagged face (Fig. 6: smallest angle below [`FLAG_ANGLE`]).
pub const MAGENTA: [u8; 3] = [255, 0, 255];
/// The background of the picture.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];
/// The colour of the wireframe's lines.
pub const WIRE: [u8; 3] = [20, 20, 20];

/// The smallest and largest picture sides accepted, in pixels.
pub const MIN_SIZE: (u32, u32) = (150, 100);
/// The largest picture side accepted, in pixels (a 8192² RGB picture is 200 MB).
pub const MAX_SIDE: u32 = 8192;

/// Errors of drawing a picture.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The mesh has no faces: there is nothing to draw.
    #[error("the mesh has no faces")]
    EmptyMesh,
    /// A vertex position is NaN or infinite.
    #[error("vertex v{vertex} has a NaN or infinite coordinate")]
    NonFinite {
        /// the vertex
        vertex: usize,
    },
    /// The picture size is out of range.
    #[error(
        "picture size {width}×{height}: each side must be at least {}×{} and at most {MAX_SIDE} pixels",
        MIN_SIZE.0,
        MIN_SIZE.1
    )]
    BadSize {
        /// width asked for
        width: u32,
        /// height asked for
        height: u32,
    },
    /// Per-element data of the wrong length.
    #[error("{what}: {found} values given, but the mesh has {expected}")]
    CountMismatch {
        /// what the data is (e.g. "patch ids per face")
        what: &'static str,
        /// the mesh's count
        expected: usize,
        /// the data's count
        found: usize,
    },
    /// The colouring needs data that was not given.
    #[error("colouring by {color} needs {needs}")]
    Missing {
        /// the colouring
        color: &'static str,
        /// what it needs
        needs: &'static str,
    },
    /// The metric (a tensor that is not SPD on the tangent plane, NaN, or the curvature
    /// estimate failed).
    #[error(transparent)]
    Metric(#[from] crate::metric::MetricError),
    /// Encoding the PNG failed.
    #[error("cannot encode the picture: {0}")]
    Encode(#[source] png::EncodingError),
    /// Drawing the legend's text failed (plotters' error, boxed: its type names the backend).
    #[error("cannot encode the picture: drawing text: {0}")]
    Text(#[source] Box<dyn std::error::Error + Send + Sync>),
}

/// Whether the faces' edges are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wireframe {
    /// When the visible triangles cover at least [`WIRE_MIN_PIXELS`] pixels each on average
    /// (default).
    #[default]
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

/// The mean number of pixels a visible triangle must cover for [`Wireframe::Auto`] to draw
/// the wireframe: below it the lines would cover most of the surface and hide its colours.
pub const WIRE_MIN_PIXELS: f64 = 20.0;

/// Options of [`render`], with their defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Picture width in pixels (default 1500).
    pub width: u32,
    /// Picture height in pixels (default 600).
    pub height: u32,
    /// Wireframe (default [`Wireframe::Auto`]).
    pub wireframe: Wireframe,
    /// Draw the view names and the colour bar's labels (default: when a font is available,
    /// [`crate::report::font_available`]).
    pub text: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 1500,
            height: 600,
            wireframe: Wireframe::Auto,
            text: crate::report::font_available(),
        }
    }
}

/// An RGB picture, row by row from the top, 3 bytes a pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 · width · height` bytes.
    pub rgb: Vec<u8>,
}

impl Image {
    /// A picture of one colour.
    pub fn filled(width: u32, height: u32, color: [u8; 3]) -> Image {
        let n = width as usize * height as usize;
        Image {
            width,
            height,
            rgb: color.iter().copied().cycle().take(3 * n).collect(),
        }
    }

    /// The pixel at column `x`, row `y` (from the top).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        self.rgb[i..i + 3].copy_from_slice(&c);
    }

    /// The picture as PNG file bytes (8-bit RGB, deterministic).
    pub fn png(&self) -> Result<Vec<u8>, RenderError> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_compression(png::Compression::Best);
            let mut w = enc.write_header().map_err(RenderError::Encode)?;
            w.write_image_data(&self.rgb).map_err(RenderError::Encode)?;
        }
        Ok(out)
    }
}

/// Where [`render`] put things, for callers that check the picture (tests) or annotate it.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// The three views (front, side, iso): their names and pixel rectangles
    /// `(x0, y0, x1, y1)`, half-open.
    pub views: Vec<raster::View>,
    /// The colour bar's rectangle, when one is drawn.
    pub color_bar: Option<(u32, u32, u32, u32)>,
    /// Whether the wireframe was drawn.
    pub wireframe: bool,
    /// Where mesh points are drawn in each view.
    pub projection: raster::Projection,
}

impl Layout {
    /// Where the mesh point `p` is drawn in view `index` (0 front, 1 side, 2 iso), in
    /// picture pixels.
    pub fn to_pixel(&self, index: usize, p: &nalgebra::Point3<f64>) -> [f64; 2] {
        self.projection.to_pixel(&self.views[index], index, p)
    }
}

/// Draw `mesh` (any units) with one colour per face: the front (looking down −z, y up), side
/// (looking down −x) and iso (looking from (1, 1, 1)) views side by side, at one common
/// scale, above a colour bar for `colors.legend`.
pub fn render(
    mesh: &TriMesh,
    colors: &FaceColors,
    opts: &RenderOptions,
) -> Result<(Image, Layout), RenderError> {
    check(mesh, opts)?;
    if colors.colors.len() != mesh.n_faces() {
        return Err(RenderError::CountMismatch {
            what: "face colours",
            expected: mesh.n_faces(),
            found: colors.colors.len(),
        });
    }
    let mut img = Image::filled(opts.width, opts.height, BACKGROUND);
    let bar_h = legend::bar_height(opts.height, &colors.legend);
    let panels = raster::panels(opts.width, opts.height - bar_h, opts.text);
    let (projection, wire) =
        raster::draw_views(&mut img, mesh, &colors.colors, &panels, opts.wireframe);
    let color_bar = legend::draw(&mut img, &colors.legend, bar_h, opts.text)?;
    if opts.text {
        legend::label_views(&mut img, &panels)?;
    }
    Ok((
        img,
        Layout {
            views: panels,
            color_bar,
            wireframe: wire,
            projection,
        },
    ))
}

/// Faces, finite coordinates and the picture size.
fn check(mesh: &TriMesh, opts: &RenderOptions) -> Result<(), RenderError> {
    if mesh.n_faces() == 0 {
        return Err(RenderError::EmptyMesh);
    }
    if let Some(v) = mesh
        .positions
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
    {
        return Err(RenderError::NonFinite { vertex: v });
    }
    check_size(opts.width, opts.height)
}

/// Whether a picture of `width × height` pixels can be drawn ([`MIN_SIZE`], [`MAX_SIDE`]).
pub fn check_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width < MIN_SIZE.0 || height < MIN_SIZE.1 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(RenderError::BadSize { width, height });
    }
    Ok(())
}

#[cfg(test)]
mod tests;
