//! Test surfaces generated in code (seeded where random): icosphere, torus, genus-g
//! plate, open cylinder, flat square plate, disk, disk with holes, cone and cylinder pieces,
//! and random perturbations. Every generator returns a consistently oriented manifold with
//! outward normals.

use super::TriMesh;
use crate::ids::VertexId;
use nalgebra::{Point3, Vector3};
use rand::Rng;
use std::collections::HashMap;
use std::f64::consts::PI;
use thiserror::Error;

/// Why a generator could not build its surface (only [`disk_with_holes`] can fail).
#[derive(Debug, Error)]
pub enum GeneratorError {
    /// Radius and lattice spacing out of range (need 0 < spacing < radius, radius / spacing
    /// at most 1e4).
    #[error(
        "invalid parameters: radius {radius} and spacing {spacing} (need 0 < spacing < radius, \
         radius / spacing at most 1e4)"
    )]
    Spacing {
        /// the disk's radius
        radius: f64,
        /// the lattice spacing
        spacing: f64,
    },
    /// Wall layers that are not positive and ascending.
    #[error("invalid parameters: wall layers {0:?} (need positive and ascending)")]
    WallLayers(Vec<f64>),
    /// A hole (with its wall layers) not inside the disk by a spacing.
    #[error(
        "invalid parameters: hole {hole} (centre {centre:?}, radius {radius}) with its wall \
         layers is not inside the disk by a spacing"
    )]
    HoleOutside {
        /// the hole's index
        hole: usize,
        /// its centre
        centre: [f64; 2],
        /// its radius
        radius: f64,
    },
    /// Two holes (with their wall layers) closer than a spacing.
    #[error(
        "invalid parameters: holes {0} and {1} with their wall layers are closer than a spacing"
    )]
    HolesTooClose(usize, usize),
    /// The constrained Delaunay triangulation refused a point (NaN, too large or too small).
    #[error("triangulation failed: {0:?}")]
    Triangulation(spade::InsertionError),
    /// The circles' polygon sides cross.
    #[error("triangulation failed: crossing circle sides")]
    CrossingSides,
}

fn build(positions: Vec<Point3<f64>>, tris: Vec<[usize; 3]>) -> TriMesh {
    TriMesh {
        positions,
        triangles: tris
            .into_iter()
            .map(|t| {
                [
                    VertexId::new(t[0]),
                    VertexId::new(t[1]),
                    VertexId::new(t[2]),
                ]
            })
            .collect(),
    }
}

/// Icosahedron subdivided `subdivisions` times (each step ×4 faces), projected on the sphere
/// of the given radius centred at the origin. `20·4^s` faces, genus 0.
pub fn icosphere(radius: f64, subdivisions: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<Vector3<f64>> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::new(p[0], p[1], p[2]).normalize())
    .collect();
    let mut tris: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let mut midpoint = |a: usize, b: usize, pos: &mut Vec<Vector3<f64>>| -> usize {
            let k = (a.min(b), a.max(b));
            *mid.entry(k).or_insert_with(|| {
                pos.push(((pos[a] + pos[b]) * 0.5).normalize());
                pos.len() - 1
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    build(
        pos.into_iter().map(|v| Point3::from(v * radius)).collect(),
        tris,
    )
}

/// Quad grid on a periodic/open parameter domain, split into triangles; `wrap_u`/`wrap_v`
/// glue the last column/row to the first. `f(i, j)` gives the position of grid node (i, j).
fn grid(
    nu: usize,
    nv: usize,
    wrap_u: bool,
    wrap_v: bool,
    f: impl Fn(usize, usize) -> Point3<f64>,
) -> TriMesh {
    let cols = if wrap_u { nu } else { nu + 1 };
    let rows = if wrap_v { nv } else { nv + 1 };
    let mut pos = Vec::with_capacity(cols * rows);
    for j in 0..rows {
        for i in 0..cols {
            pos.push(f(i, j));
        }
    }
    let id = |i: usize, j: usize| (j % rows) * cols + (i % cols);
    let mut tris = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // Alternate the diagonal so the mesh has no preferred direction.
            if (i + j) % 2 == 0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    build(pos, tris)
}

/// Torus with major radius `big_r` (around the z axis) and tube radius `r`,
/// `nu` segments around the axis and `nv` around the tube. Genus 1.
pub fn torus(big_r: f64, r: f64, nu: usize, nv: usize) -> TriMesh {
    grid(nu, nv, true, true, |i, j| {
        let u = 2.0 * PI * i as f64 / nu as f64;
        let v = 2.0 * PI * j as f64 / nv as f64;
        Point3::new(
            (big_r + r * v.cos()) * u.cos(),
            (big_r + r * v.cos()) * u.sin(),
            r * v.sin(),
        )
    })
}

/// Open cylinder of radius `r` and height `h` around the z axis: `nu` segments around,
/// `nv` along. Two boundary loops, genus 0, developable.
pub fn cylinder(r: f64, h: f64, nu: usize, nv: usize) -> TriMesh {
    grid(nu, nv, true, false, |i, j| {
        let u = 2.0 * PI * i as f64 / nu as f64;
        Point3::new(r * u.cos(), r * u.sin(), h * j as f64 / nv as f64)
    })
}

/// Flat square plate `[0, size]²` in the xy plane (normal +z): `cells`×`cells` grid cells,
/// each split into two triangles (alternating diagonals). One boundary loop, genus 0.
pub fn plate(size: f64, cells: usize) -> TriMesh {
    let n = cells.max(1);
    grid(n, n, false, false, |i, j| {
        Point3::new(size * i as f64 / n as f64, size * j as f64 / n as f64, 0.0)
    })
}

/// The surface of the unit cube `[0, 1]³`, each side a `cells`×`cells` grid of squares split
/// into two triangles: closed, genus 0, with 12 sharp edges (90° between the normals) and 8
/// corners. For feature-line tests.
pub fn cube(cells: usize) -> TriMesh {
    let n = cells.max(1);
    let mut index: HashMap<[usize; 3], usize> = HashMap::new();
    let mut positions = Vec::new();
    let mut tris = Vec::new();
    let mut vertex = |c: [usize; 3], positions: &mut Vec<Point3<f64>>| {
        *index.entry(c).or_insert_with(|| {
            positions.push(Point3::new(
                c[0] as f64 / n as f64,
                c[1] as f64 / n as f64,
                c[2] as f64 / n as f64,
            ));
            positions.len() - 1
        })
    };
    // Side (axis, at 0 or n): the grid runs over the two other axes.
    for axis in 0..3 {
        for high in [false, true] {
            let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n {
                for j in 0..n {
                    let mut corner = |di: usize, dj: usize| {
                        let mut c = [0; 3];
                        c[axis] = if high { n } else { 0 };
                        c[a1] = i + di;
                        c[a2] = j + dj;
                        vertex(c, &mut positions)
                    };
                    let (p00, p10, p11, p01) =
                        (corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                    // (a1, a2, axis) is right-handed: counter-clockwise in (a1, a2) faces +axis.
                    match high {
                        true => {
                            tris.push([p00, p10, p11]);
                            tris.push([p00, p11, p01]);
                        }
                        false => {
                            tris.push([p00, p11, p10]);
                            tris.push([p00, p01, p11]);
                        }
                    }
                }
            }
        }
    }
    build(positions, tris)
}

/// A closed can as a CAD exporter tessellates one: a cylinder of radius `r` and height `h`
/// around +z with `sectors` vertices per rim, its wall `bands` bands of long triangles, each
/// flat cap a fan from its centre. Closed, genus 0, with two circular 90° creases. For
/// feature-line tests (curved creases on a coarse part).
pub fn can(r: f64, h: f64, sectors: usize, bands: usize) -> TriMesh {
    let (n, b) = (sectors.max(3), bands.max(1));
    let mut positions = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 0.0, h)];
    for k in 0..=b {
        let z = h * k as f64 / b as f64;
        for i in 0..n {
            let u = 2.0 * PI * i as f64 / n as f64;
            positions.push(Point3::new(r * u.cos(), r * u.sin(), z));
        }
    }
    let ring = |k: usize, i: usize| 2 + k * n + i % n;
    let mut tris = Vec::with_capacity(2 * n * (b + 1));
    for i in 0..n {
        tris.push([0, ring(0, i + 1), ring(0, i)]);
        tris.push([1, ring(b, i), ring(b, i + 1)]);
        for k in 0..b {
            tris.push([ring(k, i), ring(k, i + 1), ring(k + 1, i + 1)]);
            tris.push([ring(k, i), ring(k + 1, i + 1), ring(k + 1, i)]);
        }
    }
    build(positions, tris)
}

/// Piece of a cylinder of radius `r` over the angle range `[0, angle]` and height `h`
/// (a developable disk).
pub fn cylinder_piece(r: f64, angle: f64, h: f64, nu: usize, nv: usize) -> TriMesh {
    grid(nu, nv, false, false, |i, j| {
        let u = angle * i as f64 / nu as f64;
        Point3::new(r * u.cos(), r * u.sin(), h * j as f64 / nv as f64)
    })
}

/// Piece of a circular cone with apex at the origin, half-angle `half_angle` around +z,
/// over the angular range `[0, angle]` and slant distances `[s0, s1]` (a developable disk).
pub fn cone_piece(half_angle: f64, angle: f64, s0: f64, s1: f64, nu: usize, nv: usize) -> TriMesh {
    grid(nu, nv, false, false, |i, j| {
        let u = angle * i as f64 / nu as f64;
        let s = s0 + (s1 - s0) * j as f64 / nv as f64;
        let rr = s * half_angle.sin();
        Point3::new(rr * u.cos(), rr * u.sin(), s * half_angle.cos())
    })
}

/// A lens: two equal spherical caps glued along the unit circle in the xy plane, each cap
/// meeting the plane at `alpha` radians, so the equator is a crease where the surface
/// normals differ by `π − 2·alpha`. `rings` rings per cap from pole to
/// equator, `sectors` vertices per ring. Closed, genus 0; for sharp-feature tests.
pub fn lens(alpha: f64, rings: usize, sectors: usize) -> TriMesh {
    let big_r = 1.0 / alpha.sin();
    let c = big_r * alpha.cos();
    // Ring k of the upper cap (k = 0 the pole, k = rings the equator).
    let point = |k: usize, j: usize, up: bool| {
        let th = alpha * k as f64 / rings as f64;
        let ph = 2.0 * PI * j as f64 / sectors as f64;
        let z = -c + big_r * th.cos();
        let z = if k == rings { 0.0 } else { z };
        Point3::new(
            big_r * th.sin() * ph.cos(),
            big_r * th.sin() * ph.sin(),
            if up { z } else { -z },
        )
    };
    // Vertex ids: 0 north pole, then the upper rings 1..=rings (the equator last), then the
    // lower rings rings-1..=1, then the south pole.
    let mut pos = vec![point(0, 0, true)];
    let mut ring_ids: Vec<Vec<usize>> = vec![vec![0; sectors]];
    for k in 1..=rings {
        ring_ids.push((0..sectors).map(|j| pos.len() + j).collect());
        pos.extend((0..sectors).map(|j| point(k, j, true)));
    }
    for k in (1..rings).rev() {
        ring_ids.push((0..sectors).map(|j| pos.len() + j).collect());
        pos.extend((0..sectors).map(|j| point(k, j, false)));
    }
    let south = pos.len();
    pos.push(point(0, 0, false));
    ring_ids.push(vec![south; sectors]);
    let mut tris = Vec::new();
    for w in ring_ids.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        for j in 0..sectors {
            let jn = (j + 1) % sectors;
            // Counter-clockwise seen from outside: going down from the north pole, φ grows.
            if a[j] != a[jn] {
                tris.push([a[j], b[j], a[jn]]);
            }
            if b[j] != b[jn] {
                tris.push([a[jn], b[j], b[jn]]);
            }
        }
    }
    build(pos, tris)
}

/// Flat disk of radius `r` in the xy plane (normal +z) with `rings` concentric rings and
/// `sectors` segments in the first ring (ring k has k·sectors vertices). One boundary loop.
pub fn disk(r: f64, rings: usize, sectors: usize) -> TriMesh {
    let mut pos = vec![Point3::origin()];
    let mut ring_start = vec![0usize];
    for k in 1..=rings {
        ring_start.push(pos.len());
        let n = k * sectors;
        for i in 0..n {
            let a = 2.0 * PI * i as f64 / n as f64;
            let rr = r * k as f64 / rings as f64;
            pos.push(Point3::new(rr * a.cos(), rr * a.sin(), 0.0));
        }
    }
    let mut tris = Vec::new();
    for i in 0..sectors {
        tris.push([0, 1 + i, 1 + (i + 1) % sectors]);
    }
    for k in 1..rings {
        let (n_in, n_out) = (k * sectors, (k + 1) * sectors);
        let (s_in, s_out) = (ring_start[k], ring_start[k + 1]);
        // Merge the two rings by angle: advance whichever next vertex has the smaller angle.
        let (mut i, mut o) = (0usize, 0usize);
        while i < n_in || o < n_out {
            let ai = (i + 1) as f64 / n_in as f64;
            let ao = (o + 1) as f64 / n_out as f64;
            if o < n_out && (i >= n_in || ao <= ai) {
                tris.push([s_in + i % n_in, s_out + o, s_out + (o + 1) % n_out]);
                o += 1;
            } else {
                tris.push([s_in + i % n_in, s_out + o % n_out, s_in + (i + 1) % n_in]);
                i += 1;
            }
        }
    }
    build(pos, tris)
}

/// A hole of [`disk_with_holes`]: a circle of the xy plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hole {
    /// Centre (x, y).
    pub centre: [f64; 2],
    /// Radius.
    pub radius: f64,
}

/// Flat disk of radius `r` centred at the origin of the xy plane (normal +z) with circular
/// `holes`, meshed at about `spacing`: the outer circle and every hole circle are polygons with
/// sides of at most `spacing` (vertices on the circles); around every hole, one ring of
/// vertices at each distance of `wall_layers` (ascending, as in a boundary-layer mesh: fine
/// normal to the wall, `spacing` along it); the rest a triangular lattice of side `spacing`
/// (points closer than 0.6·spacing to a circle or the last ring dropped); triangulated by
/// spade's constrained Delaunay triangulation. `1 + holes.len()` boundary loops, genus 0.
/// Each hole with its rings must lie inside the disk and apart from the others by at least
/// `spacing`.
pub fn disk_with_holes(
    r: f64,
    holes: &[Hole],
    spacing: f64,
    wall_layers: &[f64],
) -> Result<TriMesh, GeneratorError> {
    let reach = wall_layers.last().copied().unwrap_or(0.0);
    check_holes(r, holes, spacing, wall_layers)?;
    // The circles' polygons are the constraints; the rings are free points.
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut edges: Vec<[usize; 2]> = Vec::new();
    let mut add_circle = |c: [f64; 2], rad: f64, points: &mut Vec<[f64; 2]>, constrain: bool| {
        let n = ((2.0 * PI * rad / spacing).ceil() as usize).max(8);
        let first = points.len();
        for k in 0..n {
            let a = 2.0 * PI * k as f64 / n as f64;
            points.push([c[0] + rad * a.cos(), c[1] + rad * a.sin()]);
            if constrain {
                edges.push([first + k, first + (k + 1) % n]);
            }
        }
    };
    add_circle([0.0, 0.0], r, &mut points, true);
    for h in holes {
        add_circle(h.centre, h.radius, &mut points, true);
        for d in wall_layers {
            add_circle(h.centre, h.radius + d, &mut points, false);
        }
    }
    // Lattice rows √3/2·spacing apart, every other row shifted by half a side.
    let clearance = 0.6 * spacing;
    let dy = spacing * 3f64.sqrt() / 2.0;
    let (rows, cols) = ((r / dy).ceil() as i64, (r / spacing).ceil() as i64 + 1);
    for j in -rows..=rows {
        let y = j as f64 * dy;
        let shift = if j.rem_euclid(2) == 1 {
            0.5 * spacing
        } else {
            0.0
        };
        for i in -cols..=cols {
            let x = i as f64 * spacing + shift;
            let clear_of_holes = holes
                .iter()
                .all(|h| (x - h.centre[0]).hypot(y - h.centre[1]) >= h.radius + reach + clearance);
            if clear_of_holes && x.hypot(y) <= r - clearance {
                points.push([x, y]);
            }
        }
    }
    let verts: Vec<spade::Point2<f64>> = points
        .iter()
        .map(|p| spade::Point2::new(p[0], p[1]))
        .collect();
    let mut conflict = false;
    let cdt: spade::ConstrainedDelaunayTriangulation<spade::Point2<f64>> =
        spade::ConstrainedDelaunayTriangulation::try_bulk_load_cdt(verts, edges, |_| {
            conflict = true
        })
        .map_err(GeneratorError::Triangulation)?;
    if conflict {
        return Err(GeneratorError::CrossingSides);
    }
    use spade::Triangulation as _;
    let positions: Vec<Point3<f64>> = cdt
        .vertices()
        .map(|v| Point3::new(v.position().x, v.position().y, 0.0))
        .collect();
    // The CDT covers the convex hull, i.e. the outer polygon; drop the faces inside a hole
    // polygon. A face never crosses a hole's sides (constraints), so its centroid decides, and a
    // centroid inside the polygon lies inside the (circumscribed) circle.
    let tris: Vec<[usize; 3]> = cdt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .filter(|t| {
            let c = t.iter().fold([0.0, 0.0], |s, &v| {
                [s[0] + positions[v].x / 3.0, s[1] + positions[v].y / 3.0]
            });
            holes
                .iter()
                .all(|h| (c[0] - h.centre[0]).hypot(c[1] - h.centre[1]) > h.radius)
        })
        .collect();
    Ok(build(positions, tris).without_unreferenced_vertices().0)
}

/// The rules of [`disk_with_holes`]'s parameters.
fn check_holes(
    r: f64,
    holes: &[Hole],
    spacing: f64,
    wall_layers: &[f64],
) -> Result<(), GeneratorError> {
    // The lattice has (r/spacing)² points; refuse sizes beyond any use.
    if !(r > 0.0 && r.is_finite() && spacing > 0.0 && spacing < r) || r / spacing > 1e4 {
        return Err(GeneratorError::Spacing { radius: r, spacing });
    }
    if !wall_layers.windows(2).all(|w| w[0] < w[1])
        || wall_layers.first().is_some_and(|d| d.is_nan() || *d <= 0.0)
    {
        return Err(GeneratorError::WallLayers(wall_layers.to_vec()));
    }
    let reach = wall_layers.last().copied().unwrap_or(0.0);
    for (i, h) in holes.iter().enumerate() {
        let d = h.centre[0].hypot(h.centre[1]);
        if !(h.radius > 0.0 && d + h.radius + reach + spacing <= r) {
            return Err(GeneratorError::HoleOutside {
                hole: i,
                centre: h.centre,
                radius: h.radius,
            });
        }
        for (k, g) in holes.iter().enumerate().skip(i + 1) {
            let d = (h.centre[0] - g.centre[0]).hypot(h.centre[1] - g.centre[1]);
            if d < h.radius + g.radius + 2.0 * reach + spacing {
                return Err(GeneratorError::HolesTooClose(i, k));
            }
        }
    }
    Ok(())
}

/// Closed surface of genus `g` (g ≥ 0): a thickened rectangular plate with `g` square
/// holes, made of a top sheet, a bottom sheet and side walls along every boundary loop of
/// the sheet. `res` subdivides each unit grid cell (≥ 1). Sharp edges, flat faces.
pub fn genus_plate(g: usize, res: usize) -> TriMesh {
    let res = res.max(1);
    let (w, h) = (3 * g + 1, 3usize);
    let (nx, ny) = (w * res, h * res);
    let hole = |cx: usize, cy: usize| -> bool {
        let (x, y) = (cx / res, cy / res);
        y == 1 && x % 3 == 1 && x / 3 < g
    };
    let node = |i: usize, j: usize| j * (nx + 1) + i;
    let mut pos = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            pos.push(Point3::new(
                i as f64 / res as f64,
                j as f64 / res as f64,
                0.25,
            ));
        }
    }
    let n_top = pos.len();
    let mut top = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if hole(i, j) {
                continue;
            }
            let (a, b, c, d) = (
                node(i, j),
                node(i + 1, j),
                node(i + 1, j + 1),
                node(i, j + 1),
            );
            top.push([a, b, c]);
            top.push([a, c, d]);
        }
    }
    // Drop grid nodes that only touch holes (none do for this layout) and reindex later.
    let mut tris = top.clone();
    for p in 0..n_top {
        let q = pos[p];
        pos.push(Point3::new(q.x, q.y, -0.25));
    }
    for t in &top {
        tris.push([t[0] + n_top, t[2] + n_top, t[1] + n_top]);
    }
    // Walls: for every boundary half-edge a→b of the top sheet add (b, a, a') and (b, a', b').
    let mut count: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &top {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    for t in &top {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if count[&(a.min(b), a.max(b))] == 1 {
                tris.push([b, a, a + n_top]);
                tris.push([b, a + n_top, b + n_top]);
            }
        }
    }
    let m = build(pos, tris);
    m.without_unreferenced_vertices().0
}

/// The bumpy sphere of the scaling benchmark: [`icosphere`] of radius 1 at `level`
/// (`20·4^level` faces) with the radius modulated by `1 + 0.1·sin 5θ·sin 4φ` (θ polar, φ
/// azimuth), so the curvature metric varies over the surface at every level.
pub fn bumpy_sphere(level: u32) -> TriMesh {
    let mut m = icosphere(1.0, level);
    for p in &mut m.positions {
        let r = p.coords.norm();
        let theta = (p.z / r).clamp(-1.0, 1.0).acos();
        let phi = p.y.atan2(p.x);
        *p = Point3::from(p.coords * (1.0 + 0.1 * (5.0 * theta).sin() * (4.0 * phi).sin()));
    }
    m
}

/// A scan-like surface for the scaling benchmark: [`bumpy_sphere`] at `level` with every
/// vertex moved along its radius by seeded uniform noise of ±15 % of the mean edge length
/// (a scanner's noise), and the cap `z > 0.9` cut away (a scan's hole: an open boundary
/// whose curve is jagged at the scale of the edges).
pub fn noisy_scan(level: u32, seed: u64) -> TriMesh {
    use rand::SeedableRng;
    let m = bumpy_sphere(level);
    let mean_edge = {
        let (mut sum, mut n) = (0.0, 0usize);
        for t in &m.triangles {
            for i in 0..3 {
                sum += (m.positions[t[i].idx()] - m.positions[t[(i + 1) % 3].idx()]).norm();
                n += 1;
            }
        }
        sum / n.max(1) as f64
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let positions: Vec<Point3<f64>> = m
        .positions
        .iter()
        .map(|p| {
            let r = p.coords.norm();
            let dr = rng.random_range(-0.15..0.15) * mean_edge;
            Point3::from(p.coords * ((r + dr) / r))
        })
        .collect();
    let tris: Vec<[usize; 3]> = m
        .triangles
        .iter()
        .filter(|t| t.iter().all(|v| m.positions[v.idx()].z <= 0.9))
        .map(|t| [t[0].idx(), t[1].idx(), t[2].idx()])
        .collect();
    build(positions, tris).without_unreferenced_vertices().0
}

/// Move every vertex by a uniformly random vector of length ≤ `amplitude` (seeded).
pub fn perturb<R: Rng>(mesh: &TriMesh, amplitude: f64, rng: &mut R) -> TriMesh {
    let mut m = mesh.clone();
    for p in &mut m.positions {
        let d = loop {
            let v = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if v.norm_squared() <= 1.0 {
                break v;
            }
        };
        *p += d * amplitude;
    }
    m
}

/// Broken inputs, for the repair's tests (the exceptions to this module's rule): every face of
/// `mesh` with three vertices of its own, at the same positions (an STL-style soup).
pub fn triangle_soup(mesh: &TriMesh) -> TriMesh {
    let positions = mesh.faces().flat_map(|f| mesh.face_points(f)).collect();
    let tris = (0..mesh.n_faces())
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    build(positions, tris)
}

/// A Möbius band of `2k` triangles (radius 2, width 0.6): a strip whose ends are glued with a
/// half twist, so it cannot be oriented (another exception to this module's rule).
pub fn moebius_band(k: usize) -> TriMesh {
    let mut positions = Vec::with_capacity(2 * k);
    for i in 0..k {
        let t = std::f64::consts::TAU * i as f64 / k as f64;
        let radial = Vector3::new(t.cos(), t.sin(), 0.0);
        let across = (t / 2.0).cos() * radial + (t / 2.0).sin() * Vector3::z();
        for w in [-0.3, 0.3] {
            positions.push(Point3::from(2.0 * radial + w * across));
        }
    }
    let mut tris = Vec::with_capacity(2 * k);
    for i in 0..k {
        let (a, b) = (2 * i, 2 * i + 1);
        let (c, d) = if i + 1 < k { (a + 2, b + 2) } else { (1, 0) }; // the half twist
        tris.push([a, c, b]);
        tris.push([b, c, d]);
    }
    build(positions, tris)
}

/// The built-in default surface of the CLI: a torus with major radius 1 and tube radius
/// 0.35 (anisotropic curvature: the tube direction is curved ~3× more than the ring).
pub fn default_surface() -> TriMesh {
    torus(1.0, 0.35, 96, 36)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;
    use rand::SeedableRng;

    #[test]
    fn generators_have_expected_topology() {
        let cases: Vec<(&str, TriMesh, u32, usize)> = vec![
            ("icosphere", icosphere(1.0, 3), 0, 0),
            ("torus", torus(1.0, 0.3, 20, 10), 1, 0),
            ("cylinder", cylinder(1.0, 2.0, 16, 6), 0, 2),
            ("cylinder_piece", cylinder_piece(1.0, 2.0, 1.0, 10, 5), 0, 1),
            ("cone_piece", cone_piece(0.5, 2.0, 0.5, 2.0, 10, 5), 0, 1),
            ("disk", disk(1.0, 5, 6), 0, 1),
            ("plate", plate(1.0, 6), 0, 1),
            (
                "disk_with_holes",
                disk_with_holes(
                    1.0,
                    &[
                        Hole {
                            centre: [0.4, 0.0],
                            radius: 0.2,
                        },
                        Hole {
                            centre: [-0.4, 0.1],
                            radius: 0.15,
                        },
                    ],
                    0.1,
                    &[0.01, 0.03],
                )
                .unwrap(),
                0,
                3,
            ),
            ("genus0", genus_plate(0, 2), 0, 0),
            ("genus1", genus_plate(1, 1), 1, 0),
            ("genus3", genus_plate(3, 2), 3, 0),
        ];
        for (name, m, g, b) in cases {
            m.validate().unwrap();
            let t = Topology::build(&m);
            assert!(t.is_oriented_manifold(), "{name}");
            assert_eq!(t.components().len(), 1, "{name}");
            assert_eq!(t.components()[0].genus, Some(g), "{name}");
            assert_eq!(t.boundary_loops().len(), b, "{name}");
            assert!(m.faces().all(|f| m.face_area(f) > 0.0), "{name}");
        }
    }

    #[test]
    fn closed_generators_have_outward_normals() {
        // Outward orientation ⇔ positive signed volume.
        for m in [
            icosphere(1.0, 2),
            torus(1.0, 0.3, 20, 10),
            genus_plate(2, 1),
        ] {
            let vol: f64 = m
                .faces()
                .map(|f| {
                    let [a, b, c] = m.face_points(f);
                    a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
                })
                .sum();
            assert!(vol > 0.0);
        }
        let s = icosphere(2.0, 4);
        let vol: f64 = s
            .faces()
            .map(|f| {
                let [a, b, c] = s.face_points(f);
                a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
            })
            .sum();
        assert!((vol - 4.0 / 3.0 * PI * 8.0).abs() / vol < 0.01);
    }

    #[test]
    fn disk_with_holes_refuses_holes_outside_or_overlapping() {
        let h = |x: f64, r: f64| Hole {
            centre: [x, 0.0],
            radius: r,
        };
        let e = disk_with_holes(1.0, &[h(0.9, 0.2)], 0.05, &[]).unwrap_err();
        assert!(
            matches!(e, GeneratorError::HoleOutside { hole: 0, .. }),
            "{e}"
        );
        let e = disk_with_holes(1.0, &[h(0.3, 0.2), h(-0.05, 0.2)], 0.05, &[]).unwrap_err();
        assert!(matches!(e, GeneratorError::HolesTooClose(0, 1)), "{e}");
        let e = disk_with_holes(1.0, &[h(0.0, -0.1)], 0.05, &[]).unwrap_err();
        assert!(
            matches!(e, GeneratorError::HoleOutside { hole: 0, .. }),
            "{e}"
        );
        let e = disk_with_holes(1.0, &[], 2.0, &[]).unwrap_err();
        assert!(matches!(e, GeneratorError::Spacing { .. }), "{e}");
        let e = disk_with_holes(1.0, &[h(0.0, 0.2)], 0.05, &[0.02, 0.01]).unwrap_err();
        assert!(matches!(e, GeneratorError::WallLayers(_)), "{e}");
    }

    #[test]
    fn perturb_is_seeded() {
        let m = icosphere(1.0, 1);
        let a = perturb(&m, 0.01, &mut rand_chacha::ChaCha8Rng::seed_from_u64(3));
        let b = perturb(&m, 0.01, &mut rand_chacha::ChaCha8Rng::seed_from_u64(3));
        let c = perturb(&m, 0.01, &mut rand_chacha::ChaCha8Rng::seed_from_u64(4));
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!(a
            .positions
            .iter()
            .zip(&m.positions)
            .all(|(p, q)| (p - q).norm() <= 0.01));
    }
}
