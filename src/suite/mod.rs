//! The analytic benchmark suite (issue 17, "the mesh follows the metric it is given"):
//! surfaces and metrics of the kinds simulation users bring as a Medit `.sol` — constant
//! strong anisotropy, turning directions, boundary layers, shocks — generated in code, each
//! written as `NAME.mesh` and `NAME.sol` for `conemesh bench --suite analytic` (which runs
//! conemesh and MMG on them side by side).
//!
//! Every metric is given as sizes: `h_across` along a unit tangent d1, `h_along` along the
//! orthogonal tangent d2, written per vertex as the SPD tensor
//! `M = d1 d1ᵀ/h_across² + d2 d2ᵀ/h_along² + n nᵀ/h_n²`, `h_n = min(h_across, h_along)`
//! ([`Frame::tensor`]; MMG wants SPD, conemesh ignores the normal part). An edge of metric
//! length 1 is on target, so every run uses **L_tar = 1**. The sizes are set for outputs of
//! about 2k–20k faces ([`crate::pipeline::expected_faces`] at L_tar = 1, checked by the tests).
//!
//! # Surfaces
//!
//! | surface | generator | resolution | boundary loops, genus |
//! |---|---|---|---|
//! | plate | the unit square `[0,1]²`, z = 0 | 40×40 grid cells (3,200 faces) | 1, 0 |
//! | fine plate | the same square | 100×100 grid cells (20,000 faces) | 1, 0 |
//! | cylinder | radius 1 around z, height 2 (z ∈ [0, 2]), open | 128 around × 64 along (16,384 faces) | 2, 0 |
//! | sphere | radius 1 at the origin | icosphere, 5 subdivisions (20,480 faces) | 0, 0 |
//! | torus | major radius 1 around z, tube radius 0.35 | 160 around × 56 around the tube (17,920 faces) | 0, 1 |
//! | holes | disk of radius 1 at the origin, z = 0, three holes of radius 0.1 centred 0.55 from the origin at 90°, 210°, 330° | spacing 0.025, vertex rings 0.004, 0.009, 0.015, 0.022 off each hole (11,682 faces) | 4, 0 |
//!
//! The boundary layers and shocks change their size across fast; their inputs (the fine
//! plate, the rings around the holes, the sphere's and cylinder's resolution) sample that
//! change at every vertex closely enough (the smallest size changes by at most ×2.1 along an
//! input edge) that the tensors interpolated between vertices, which is what both remeshers
//! and `eval` see, are still the documented field.
//!
//! # Cases (sizes in file units; d = distance to the wall or front)
//!
//! | name | surface | metric | across (d1) | along (d2) | ratio |
//! |---|---|---|---|---|---|
//! | `plate-iso` | plate | isotropic | 0.02 | 0.02 | 1 |
//! | `plate-aniso10` | plate | constant | 0.006 (y) | 0.06 (x) | 10 |
//! | `plate-aniso30` | plate | constant | 0.004 (y) | 0.12 (x) | 30 |
//! | `plate-aniso100` | plate | constant (the reference case) | 0.002 (y) | 0.2 (x) | 100 |
//! | `plate-aniso1000` | plate | constant | 0.0005 (y) | 0.5 (x) | 1,000 |
//! | `plate-turning10` | plate | along the circles around (0.5, 0.5); within ρ < 0.15 of the centre h_along = 0.006·10^s(ρ/0.15), s(t) = 3t² − 2t³ | 0.006 (radial) | 0.06 (circles) | 10 |
//! | `plate-blayer` | fine plate | boundary layer on the wall y = 0 (d = y) | min(0.001 + 0.05·d, 0.04) (y) | 0.04 (x) | 40 at the wall, 1 from d = 0.78 |
//! | `plate-shock-sine` | fine plate | shock on y = 0.5 + 0.15·sin(2πx) (first-order d = \|φ\|/\|∇φ\|) | 0.04 − 0.038·exp(−(d/0.08)²) (normal to the line) | 0.04 | 20 on the front |
//! | `plate-shock-circle` | fine plate | shock on the circle of radius 0.3 around (0.5, 0.5) | 0.04 − 0.038·exp(−(d/0.08)²) (radial) | 0.04 | 20 on the front |
//! | `cylinder-iso` | cylinder | isotropic (the case) | 0.1 | 0.1 | 1 |
//! | `cylinder-axial10` | cylinder | constant (the case) | 0.03 (axial) | 0.3 (circumferential) | 10 |
//! | `cylinder-axial30` | cylinder | constant (the case) | 0.02 (axial) | 0.6 (circumferential) | 30 |
//! | `cylinder-helix10` | cylinder | along the 45° helix (turning in 3D) | 0.03 | 0.3 (helix) | 10 |
//! | `cylinder-blayer` | cylinder | boundary layer on the bottom loop z = 0 (d = z) | min(0.005 + 0.1·d, 0.1) (axial) | 0.1 (circumferential) | 20 at the wall, 1 from d = 0.95 |
//! | `sphere-iso` | sphere | isotropic | 0.08 | 0.08 | 1 |
//! | `sphere-turning10` | sphere | along the parallels; within ρ < 0.3 of the z axis (the poles) h_along = 0.02·10^s(ρ/0.3) | 0.02 (meridians) | 0.2 (parallels) | 10 |
//! | `sphere-shock` | sphere | shock on the equator (d = \|z\|) | 0.08 − 0.075·exp(−(d/0.2)²) (meridians) | 0.08 | 16 on the front |
//! | `torus-iso` | torus | isotropic | 0.08 | 0.08 | 1 |
//! | `torus-turning10` | torus | along the ring (the circles around z) | 0.03 (around the tube) | 0.3 (along the ring) | 10 |
//! | `holes-iso` | holes | isotropic | 0.04 | 0.04 | 1 |
//! | `holes-blayer` | holes | boundary layer on the three hole walls (d to the nearest) | min(0.003 + 0.15·d, 0.05) (radial) | 0.05 (along the wall) | 16.7 at the wall, 1 from d = 0.31 |
//!
//! The normal n gets min(h_across, h_along). Where a direction field is undefined (the centre
//! of the plate's circles, the sphere's poles, the switch between the nearest holes, far from
//! a front) the metric is isotropic, so every tensor field is continuous.

mod cases;
mod sizing;

pub use cases::ANALYTIC;
pub use sizing::{Along, Curve, Frame, Sizing};

use crate::io::sol::SolError;
use crate::io::IoError;
use crate::mesh::generators::{self, GeneratorError, Hole};
use crate::mesh::TriMesh;
use nalgebra::{Matrix3, Point3, Vector3};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Errors of building and writing suite cases.
#[derive(Debug, Error)]
pub enum SuiteError {
    /// A `--case` filter that selects nothing (a typo would otherwise run nothing silently).
    #[error("no case of the suite matches `{filter}` (cases: {known})")]
    NoMatch {
        /// the filter
        filter: String,
        /// every case name
        known: crate::registry::Names,
    },
    /// The surface generator refused its parameters.
    #[error("case {case}: {source}")]
    Generator {
        /// the case
        case: String,
        /// what the generator said
        source: GeneratorError,
    },
    /// Writing the mesh.
    #[error(transparent)]
    Mesh(#[from] IoError),
    /// Writing the metric.
    #[error(transparent)]
    Sol(#[from] SolError),
}

/// A surface of the suite (see the module doc for the ones in use).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// The unit square `[0,1]²` of the xy plane, `cells`×`cells` grid cells.
    Plate {
        /// Grid cells per side.
        cells: usize,
    },
    /// Open cylinder around the z axis, z ∈ [0, height].
    Cylinder {
        /// Radius.
        radius: f64,
        /// Height.
        height: f64,
        /// Segments around.
        around: usize,
        /// Segments along.
        along: usize,
    },
    /// Icosphere centred at the origin.
    Sphere {
        /// Radius.
        radius: f64,
        /// Subdivisions of the icosahedron (20·4^s faces).
        subdivisions: u32,
    },
    /// Torus around the z axis.
    Torus {
        /// Major radius.
        major: f64,
        /// Tube radius.
        minor: f64,
        /// Segments around the axis.
        around: usize,
        /// Segments around the tube.
        tube: usize,
    },
    /// Disk at the origin of the xy plane with circular holes.
    DiskWithHoles {
        /// Radius.
        radius: f64,
        /// The holes.
        holes: &'static [Hole],
        /// Mesh spacing.
        spacing: f64,
        /// Distances of the vertex rings around every hole (a boundary-layer mesh).
        wall_layers: &'static [f64],
    },
}

impl Shape {
    /// The surface as a mesh (vertices on the analytic surface).
    pub fn mesh(&self) -> Result<TriMesh, GeneratorError> {
        Ok(match *self {
            Shape::Plate { cells } => generators::plate(1.0, cells),
            Shape::Cylinder {
                radius,
                height,
                around,
                along,
            } => generators::cylinder(radius, height, around, along),
            Shape::Sphere {
                radius,
                subdivisions,
            } => generators::icosphere(radius, subdivisions),
            Shape::Torus {
                major,
                minor,
                around,
                tube,
            } => generators::torus(major, minor, around, tube),
            Shape::DiskWithHoles {
                radius,
                holes,
                spacing,
                wall_layers,
            } => generators::disk_with_holes(radius, holes, spacing, wall_layers)?,
        })
    }

    /// The analytic outward unit normal at a point of the surface.
    pub fn normal_at(&self, p: &Point3<f64>) -> Vector3<f64> {
        let radial = Vector3::new(p.x, p.y, 0.0);
        let unit = |v: Vector3<f64>| {
            if v.norm() > 0.0 {
                v / v.norm()
            } else {
                Vector3::z()
            }
        };
        match *self {
            Shape::Plate { .. } | Shape::DiskWithHoles { .. } => Vector3::z(),
            Shape::Cylinder { .. } => unit(radial),
            Shape::Sphere { .. } => unit(p.coords),
            Shape::Torus { major, .. } => unit(p.coords - unit(radial) * major),
        }
    }

    /// Boundary loops of the surface.
    pub fn boundary_loops(&self) -> usize {
        match *self {
            Shape::Plate { .. } => 1,
            Shape::Cylinder { .. } => 2,
            Shape::Sphere { .. } | Shape::Torus { .. } => 0,
            Shape::DiskWithHoles { holes, .. } => 1 + holes.len(),
        }
    }

    /// Genus of the surface.
    pub fn genus(&self) -> u32 {
        match *self {
            Shape::Torus { .. } => 1,
            _ => 0,
        }
    }

    /// One line for a table.
    pub fn describe(&self) -> String {
        match *self {
            Shape::Plate { cells } => format!("unit square plate, {cells}×{cells} cells"),
            Shape::Cylinder {
                radius,
                height,
                around,
                along,
            } => format!("open cylinder r = {radius}, height {height}, {around}×{along}"),
            Shape::Sphere {
                radius,
                subdivisions,
            } => format!("sphere r = {radius}, icosphere ×{subdivisions}"),
            Shape::Torus {
                major,
                minor,
                around,
                tube,
            } => format!("torus R = {major}, r = {minor}, {around}×{tube}"),
            Shape::DiskWithHoles {
                radius,
                holes,
                spacing,
                wall_layers,
            } => format!(
                "disk r = {radius} with {} holes, spacing {spacing}, {} vertex rings around each hole",
                holes.len(),
                wall_layers.len()
            ),
        }
    }
}

/// One benchmark case: a surface and a metric on it, under a stable name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    /// Stable name: the stem of the case's files and its rows.
    pub name: &'static str,
    /// The surface.
    pub shape: Shape,
    /// The metric.
    pub sizing: Sizing,
}

/// The files [`Case::write`] wrote.
#[derive(Clone, Debug)]
pub struct CaseFiles {
    /// `NAME.mesh`.
    pub mesh: PathBuf,
    /// `NAME.sol`.
    pub sol: PathBuf,
    /// Faces of the mesh.
    pub faces: usize,
    /// Faces an output on target should have ([`crate::pipeline::expected_faces`], L_tar = 1).
    pub expected_faces: f64,
}

impl Case {
    /// The case's mesh.
    pub fn mesh(&self) -> Result<TriMesh, SuiteError> {
        self.shape.mesh().map_err(|source| SuiteError::Generator {
            case: self.name.to_string(),
            source,
        })
    }

    /// The metric's frame at a point of the surface.
    pub fn frame_at(&self, p: &Point3<f64>) -> Frame {
        self.sizing.frame(p, &self.shape.normal_at(p))
    }

    /// The metric tensor at every vertex of `mesh` (the case's mesh), in vertex order.
    pub fn metric(&self, mesh: &TriMesh) -> Vec<Matrix3<f64>> {
        mesh.positions
            .iter()
            .map(|p| self.frame_at(p).tensor())
            .collect()
    }

    /// Write `dir/NAME.mesh` (Medit) and `dir/NAME.sol` (ASCII, type 3); `dir` must exist.
    pub fn write(&self, dir: &Path) -> Result<CaseFiles, SuiteError> {
        let mesh = self.mesh()?;
        let metric = self.metric(&mesh);
        let files = CaseFiles {
            mesh: dir.join(format!("{}.mesh", self.name)),
            sol: dir.join(format!("{}.sol", self.name)),
            faces: mesh.n_faces(),
            expected_faces: crate::pipeline::expected_faces(&mesh, &metric, &[], 1.0),
        };
        crate::io::write_mesh(&files.mesh, &mesh)?;
        crate::io::sol::write_sol(&files.sol, &metric, false)?;
        Ok(files)
    }
}

/// The cases whose name contains one of `filters` (all of them without filters), in the
/// suite's order. A filter that matches no case is [`SuiteError::NoMatch`].
pub fn select<'a>(cases: &'a [Case], filters: &[String]) -> Result<Vec<&'a Case>, SuiteError> {
    if let Some(f) = filters
        .iter()
        .find(|f| !cases.iter().any(|c| c.name.contains(f.as_str())))
    {
        return Err(SuiteError::NoMatch {
            filter: f.clone(),
            known: crate::registry::Names(cases.iter().map(|c| c.name).collect()),
        });
    }
    Ok(cases
        .iter()
        .filter(|c| filters.is_empty() || filters.iter().any(|f| c.name.contains(f.as_str())))
        .collect())
}
