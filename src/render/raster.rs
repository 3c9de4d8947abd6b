//! The z-buffer rasterizer: orthographic views of a triangle mesh, flat shaded, with an
//! optional wireframe, into an [`Image`].
//!
//! Each view is drawn in two passes. The first keeps, per pixel, the closest face whose
//! projected triangle covers the pixel centre (edge functions; ties keep the lower face id,
//! so the result does not depend on anything but the input). The second colours each pixel
//! from its face: the face colour times a head-light shading of the face normal, and the
//! wireframe colour within half a pixel of one of the face's projected edges, which draws
//! the edges of the visible faces only (hidden lines are never drawn), and only of faces
//! large enough on screen to show their colour between the lines.

use super::{Image, Wireframe, WIRE, WIRE_MIN_PIXELS};
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Point3, Vector3};

/// One view of the picture: its name, its pixel rectangle and its camera.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// `front`, `side` or `iso`.
    pub name: &'static str,
    /// The pixel rectangle `(x0, y0, x1, y1)`, half-open.
    pub rect: (u32, u32, u32, u32),
    /// Rows: the camera's right, up and towards-the-viewer axes in mesh coordinates.
    pub camera: Matrix3<f64>,
    /// Pixels at the top of the rectangle kept free for the view's name.
    pub top: u32,
}

/// Free pixels around the mesh inside each view.
const MARGIN: f64 = 8.0;
/// Pixels kept for the view's name above the mesh.
const LABEL_H: u32 = 24;
/// Half the wireframe's line width, in pixels.
const HALF_LINE: f64 = 0.5;

/// The cameras of the three views: front (looking down −z, y up), side (from +x) and iso
/// (from (1, 1, 1), y up).
pub fn cameras() -> [(&'static str, Matrix3<f64>); 3] {
    let s2 = std::f64::consts::SQRT_2;
    let s3 = 3f64.sqrt();
    let s6 = 6f64.sqrt();
    [
        ("front", Matrix3::identity()),
        (
            "side",
            Matrix3::new(0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0),
        ),
        (
            "iso",
            Matrix3::new(
                1.0 / s2,
                0.0,
                -1.0 / s2,
                -1.0 / s6,
                2.0 / s6,
                -1.0 / s6,
                1.0 / s3,
                1.0 / s3,
                1.0 / s3,
            ),
        ),
    ]
}

/// The three views side by side in a `width × height` area at the top of the picture.
pub fn panels(width: u32, height: u32, text: bool) -> Vec<View> {
    let top = if text { LABEL_H } else { 0 };
    cameras()
        .into_iter()
        .enumerate()
        .map(|(i, (name, camera))| {
            let x0 = width * i as u32 / 3;
            let x1 = width * (i as u32 + 1) / 3;
            View {
                name,
                rect: (x0, 0, x1, height),
                camera,
                top,
            }
        })
        .collect()
}

/// The vertices some face uses.
fn referenced(mesh: &TriMesh) -> Vec<bool> {
    let mut used = vec![false; mesh.n_vertices()];
    for t in &mesh.triangles {
        for v in t {
            used[v.idx()] = true;
        }
    }
    used
}

/// Vertex positions in each view's camera frame (relative to the bounding-box centre), and
/// the one scale (pixels per mesh unit) at which every view fits its rectangle.
fn project(mesh: &TriMesh, views: &[View]) -> (Vec<Vec<Vector3<f64>>>, Projection) {
    let used = referenced(mesh);
    let pts: Vec<&Point3<f64>> = (mesh.positions.iter().zip(&used))
        .filter(|(_, &u)| u)
        .map(|(p, _)| p)
        .collect();
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for p in &pts {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let centre = (lo + hi) * 0.5;
    let mut cam = Vec::with_capacity(views.len());
    let mut mids = Vec::with_capacity(views.len());
    let mut scale = f64::INFINITY;
    for v in views {
        let c: Vec<Vector3<f64>> = (mesh.positions.iter())
            .map(|p| v.camera * (p.coords - centre))
            .collect();
        let (mut xl, mut xh, mut yl, mut yh) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (q, _) in c.iter().zip(&used).filter(|(_, &u)| u) {
            (xl, xh, yl, yh) = (xl.min(q.x), xh.max(q.x), yl.min(q.y), yh.max(q.y));
        }
        let w = f64::from(v.rect.2 - v.rect.0) - 2.0 * MARGIN;
        let h = f64::from(v.rect.3 - v.rect.1 - v.top) - 2.0 * MARGIN;
        // A view in which the mesh is flat (a plate seen edge-on) does not limit the scale.
        for (room, extent) in [(w, xh - xl), (h, yh - yl)] {
            if extent > 0.0 {
                scale = scale.min(room.max(1.0) / extent);
            }
        }
        mids.push([0.5 * (xl + xh), 0.5 * (yl + yh)]);
        cam.push(c);
    }
    if !scale.is_finite() {
        scale = 1.0; // every vertex at one point: the faces are dots
    }
    let projection = Projection {
        centre: Point3::from(centre),
        scale,
        mids,
    };
    (cam, projection)
}

/// How mesh points map to the pixels of each view.
#[derive(Clone, Debug, PartialEq)]
pub struct Projection {
    /// The mesh's bounding-box centre (mesh units).
    pub centre: Point3<f64>,
    /// Pixels per mesh unit, the same in every view.
    pub scale: f64,
    /// Per view, the camera-plane point drawn at the centre of the view's drawing area.
    pub mids: Vec<[f64; 2]>,
}

impl Projection {
    /// Where `p` (mesh units) is drawn in `view` (one of the views it was computed for), in
    /// picture pixels (x right, y down; pixel `(i, j)` covers `[i, i+1) × [j, j+1)`).
    pub fn to_pixel(&self, view: &View, index: usize, p: &Point3<f64>) -> [f64; 2] {
        let q = view.camera * (p - self.centre);
        let (x0, y0, x1, y1) = view.rect;
        let cx = 0.5 * f64::from(x1 - x0);
        let cy = f64::from(view.top) + 0.5 * f64::from(y1 - y0 - view.top);
        let m = self.mids[index];
        [
            f64::from(x0) + cx + self.scale * (q.x - m[0]),
            f64::from(y0) + cy - self.scale * (q.y - m[1]),
        ]
    }
}

/// `(b − a) × (p − a)`, twice the signed area of (a, b, p).
fn edge(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// One view's rasterized faces: per pixel of its rectangle, the visible face (`u32::MAX`:
/// background), and each vertex's screen position.
struct Raster {
    face: Vec<u32>,
    screen: Vec<[f64; 2]>,
}

fn rasterize(
    mesh: &TriMesh,
    view: &View,
    cam: &[Vector3<f64>],
    mid: [f64; 2],
    scale: f64,
) -> Raster {
    let (x0, y0, x1, y1) = view.rect;
    let (w, h) = ((x1 - x0) as usize, (y1 - y0) as usize);
    let cx = 0.5 * f64::from(x1 - x0);
    let cy = f64::from(view.top) + 0.5 * f64::from(y1 - y0 - view.top);
    // Screen y grows downwards.
    let screen: Vec<[f64; 2]> = cam
        .iter()
        .map(|q| [cx + scale * (q.x - mid[0]), cy - scale * (q.y - mid[1])])
        .collect();
    let mut face = vec![u32::MAX; w * h];
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    for (fi, t) in mesh.triangles.iter().enumerate() {
        let p = t.map(|v| screen[v.idx()]);
        let z = t.map(|v| cam[v.idx()].z);
        let area = edge(p[0], p[1], p[2]);
        if area == 0.0 || !area.is_finite() {
            continue; // seen edge-on: its neighbours cover its pixels
        }
        let sign = area.signum();
        let lo_x = p.iter().map(|q| q[0]).fold(f64::INFINITY, f64::min);
        let hi_x = p.iter().map(|q| q[0]).fold(f64::NEG_INFINITY, f64::max);
        let lo_y = p.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min);
        let hi_y = p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max);
        let (px0, px1) = (pixel_range(lo_x, hi_x, w), pixel_range(lo_y, hi_y, h));
        for py in px1.0..px1.1 {
            for px in px0.0..px0.1 {
                let c = [px as f64 + 0.5, py as f64 + 0.5];
                let b = [
                    sign * edge(p[1], p[2], c),
                    sign * edge(p[2], p[0], c),
                    sign * edge(p[0], p[1], c),
                ];
                if b[0] < 0.0 || b[1] < 0.0 || b[2] < 0.0 {
                    continue;
                }
                let zz = (b[0] * z[0] + b[1] * z[1] + b[2] * z[2]) / (sign * area);
                let i = py * w + px;
                if zz > depth[i] {
                    depth[i] = zz;
                    face[i] = fi as u32;
                }
            }
        }
    }
    Raster { face, screen }
}

/// The pixels whose centres can lie in `[lo, hi]`, clipped to `0..n`.
fn pixel_range(lo: f64, hi: f64, n: usize) -> (usize, usize) {
    let a = (lo - 0.5).ceil().max(0.0);
    let b = ((hi - 0.5).floor() + 1.0).min(n as f64);
    // NaN bounds (cannot happen for finite, checked coordinates) give no pixels too.
    if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
        return (0, 0);
    }
    (a as usize, b as usize)
}

/// Draw the views of `mesh` with one colour per face into `img`; returns the projection and
/// whether the wireframe was drawn.
pub fn draw_views(
    img: &mut Image,
    mesh: &TriMesh,
    colors: &[[u8; 3]],
    views: &[View],
    wireframe: Wireframe,
) -> (Projection, bool) {
    let (cam, projection) = project(mesh, views);
    let rasters: Vec<Raster> = (views.iter().zip(&cam).zip(&projection.mids))
        .map(|((v, c), m)| rasterize(mesh, v, c, *m, projection.scale))
        .collect();
    let wire = match wireframe {
        Wireframe::On => true,
        Wireframe::Off => false,
        Wireframe::Auto => mean_face_pixels(&rasters, mesh.n_faces()) >= WIRE_MIN_PIXELS,
    };
    // Upper left, in front: the head light of every view.
    let light = Vector3::new(-0.3, 0.5, 1.0).normalize();
    let normals: Vec<Vector3<f64>> = mesh.faces().map(|f| mesh.face_normal(f)).collect();
    for (v, r) in views.iter().zip(&rasters) {
        let (x0, y0, x1, _) = v.rect;
        let w = (x1 - x0) as usize;
        for (i, &f) in r.face.iter().enumerate() {
            if f == u32::MAX {
                continue;
            }
            let (px, py) = (i % w, i / w);
            let fi = f as usize;
            let c = if wire && near_edge(mesh, r, fi, [px as f64 + 0.5, py as f64 + 0.5]) {
                WIRE
            } else {
                let n = v.camera * normals[fi];
                // Both sides lit alike: an open surface seen from behind is not black.
                let shade = 0.45 + 0.55 * n.dot(&light).abs();
                colors[fi].map(|x| (f64::from(x) * shade).round() as u8)
            };
            img.set(x0 + px as u32, y0 + py as u32, c);
        }
    }
    (projection, wire)
}

/// Mean pixels per visible face over all views (each view's visible faces counted once).
fn mean_face_pixels(rasters: &[Raster], n_faces: usize) -> f64 {
    let mut seen = vec![false; n_faces];
    let (mut pixels, mut faces) = (0usize, 0usize);
    for r in rasters {
        seen.iter_mut().for_each(|s| *s = false);
        for &f in r.face.iter().filter(|&&f| f != u32::MAX) {
            pixels += 1;
            if !std::mem::replace(&mut seen[f as usize], true) {
                faces += 1;
            }
        }
    }
    pixels as f64 / faces.max(1) as f64
}

/// Faces smaller than this on screen (pixels, e.g. seen at a grazing angle) get no lines:
/// their lines would cover them and draw a black band along the silhouette.
const WIRE_FACE_MIN_PIXELS: f64 = 12.0;

/// Whether the pixel centre `c` lies within half a line of an edge of face `f` on screen
/// (never for a face smaller than [`WIRE_FACE_MIN_PIXELS`] there).
fn near_edge(mesh: &TriMesh, r: &Raster, f: usize, c: [f64; 2]) -> bool {
    let p = mesh.triangles[f].map(|v| r.screen[v.idx()]);
    if 0.5 * edge(p[0], p[1], p[2]).abs() < WIRE_FACE_MIN_PIXELS {
        return false;
    }
    (0..3).any(|i| {
        let (a, b) = (p[(i + 1) % 3], p[(i + 2) % 3]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        len > 0.0 && edge(a, b, c).abs() / len < HALF_LINE
    })
}
