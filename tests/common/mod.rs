//! The catalogue of the 12 shared test meshes (`../shared/meshes` beside the crate, described in
//! its README.md; `CONEMESH_MESHES` names another folder, as for the Python tests) and the one
//! way tests find and load them. Include it with `mod common;`; a test that loops over meshes
//! loops over [`SHARED_MESHES`], so a new mesh is one new row here (`tests/check_shared.rs`
//! fails until the folder and the catalogue agree).

#![allow(dead_code)]

use conemesh::TriMesh;
use std::path::PathBuf;

/// The shared meshes directory beside the crate (the default of [`dir`]).
pub const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes");

/// One shared mesh: its file and what `../shared/meshes/README.md` says about it.
#[derive(Clone, Copy, Debug)]
pub struct SharedMesh {
    /// File name inside [`DIR`].
    pub file: &'static str,
    /// Vertices in the file, referenced or not.
    pub vertices: usize,
    /// Faces (all triangles).
    pub faces: usize,
    pub genus: u32,
    /// Open boundary loops.
    pub boundary_loops: usize,
    /// Vertices no face uses (dropped by `conemesh remesh`).
    pub unreferenced: usize,
    /// Sharp feature lines and flat regions (a CAD part).
    pub sharp_features: bool,
    /// Faces of the mesh really cross (it is not a valid input for `check`).
    pub self_intersects: bool,
}

const fn row(file: &'static str, vertices: usize, faces: usize, genus: u32) -> SharedMesh {
    SharedMesh {
        file,
        vertices,
        faces,
        genus,
        boundary_loops: 0,
        unreferenced: 0,
        sharp_features: false,
        self_intersects: false,
    }
}

/// Every shared mesh, sorted by file name (the order of a directory listing).
pub const SHARED_MESHES: [SharedMesh; 12] = [
    row("3holes.off", 3596, 7200, 3),
    row("armadillo.obj", 43243, 86482, 0),
    row("bumpy.off", 1250, 2496, 0),
    row("bunny.off", 3485, 6966, 0),
    SharedMesh {
        self_intersects: true,
        ..row("cow.off", 2762, 5520, 0)
    },
    row("decimated-knight.off", 502, 1000, 0),
    SharedMesh {
        sharp_features: true,
        ..row("fandisk.off", 7229, 14454, 0)
    },
    row("fertility.off", 4494, 9000, 4),
    row("homer.obj", 6002, 12000, 0),
    row("screwdriver.off", 3395, 6786, 0),
    row("spot.obj", 2930, 5856, 0),
    SharedMesh {
        boundary_loops: 5,
        unreferenced: 1113,
        ..row("stanford-bunny.obj", 35947, 69451, 0)
    },
];

impl SharedMesh {
    /// The file name without its extension ("decimated-knight").
    pub fn name(&self) -> &'static str {
        self.file
            .rsplit_once('.')
            .map_or(self.file, |(stem, _)| stem)
    }

    /// The file's path; panics with a clear message when the shared directory is missing.
    pub fn path(&self) -> PathBuf {
        dir().join(self.file)
    }

    /// The mesh as read (unreferenced vertices kept).
    pub fn load(&self) -> TriMesh {
        let path = self.path();
        conemesh::io::read_mesh(&path)
            .unwrap_or_else(|e| panic!("reading the shared mesh {}: {e}", path.display()))
            .mesh
    }

    /// The mesh without unreferenced vertices, as `conemesh remesh` reads it (they carry no
    /// surface).
    pub fn load_referenced(&self) -> TriMesh {
        self.load().without_unreferenced_vertices().0
    }
}

/// The shared meshes directory: `CONEMESH_MESHES` when set, else [`DIR`]. Panics, saying
/// where it looked, when the directory is missing.
pub fn dir() -> PathBuf {
    let dir = std::env::var_os("CONEMESH_MESHES").map_or_else(|| PathBuf::from(DIR), PathBuf::from);
    assert!(
        dir.is_dir(),
        "the shared test meshes are missing: expected the directory {} \
         (`../shared/meshes` beside the crate, see its README.md, or set CONEMESH_MESHES)",
        dir.display()
    );
    dir
}

/// The catalogue row of `file` ("cow.off"); panics when it is not a shared mesh.
pub fn shared_mesh(file: &str) -> &'static SharedMesh {
    SHARED_MESHES
        .iter()
        .find(|m| m.file == file)
        .unwrap_or_else(|| panic!("{file} is not in the shared-mesh catalogue (tests/common)"))
}

/// The path of the shared mesh `file` ("cow.off").
pub fn path(file: &str) -> PathBuf {
    shared_mesh(file).path()
}

/// The shared mesh `file` as read (unreferenced vertices kept).
pub fn load(file: &str) -> TriMesh {
    shared_mesh(file).load()
}

/// The shared mesh `file` without unreferenced vertices, as `conemesh remesh` reads it.
pub fn load_referenced(file: &str) -> TriMesh {
    shared_mesh(file).load_referenced()
}
