//! Write → read round trips of every format and encoding on random small meshes: positions
//! bit-exact and the same triangles (OBJ, OFF, PLY ascii / binary LE / binary BE, Medit,
//! ASCII STL after welding); binary STL equal to the `f32`-rounded, welded mesh. PLY also
//! returns its face properties, colours and uv; OBJ its uv.

#[path = "seed.rs"]
mod seed;
use conemesh::io::{read_mesh, write_mesh_with, MeshAttributes, WriteOptions};
use conemesh::mesh::generators;
use conemesh::{TriMesh, VertexId};
use nalgebra::{Point2, Point3};
use proptest::prelude::*;
use rand::{Rng as _, SeedableRng};
use std::collections::HashMap;

fn config(cases: u32) -> ProptestConfig {
    seed::config(cases, "io", 0x10f0)
}

/// A small generated surface, perturbed and scaled by `10^scale` (seeded).
fn surface(kind: u8, seed: u64, scale: i32) -> TriMesh {
    let base = match kind % 5 {
        0 => generators::icosphere(1.0, 1),
        1 => generators::torus(1.0, 0.3, 8, 5),
        2 => generators::cylinder(1.0, 2.0, 7, 3),
        3 => generators::disk(1.0, 3, 6),
        _ => generators::genus_plate(1, 2),
    };
    let mut rng = conemesh::Rng::seed_from_u64(seed);
    let mut m = generators::perturb(&base, 0.01, &mut rng);
    let s = 10f64.powi(scale);
    for p in &mut m.positions {
        *p = Point3::from(p.coords * s);
    }
    m
}

fn bits(m: &TriMesh) -> Vec<[u64; 3]> {
    m.positions
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// What an STL round trip must give: corners in facet order, rounded by `round`, welded at
/// their first occurrence (`-0.0` equal to `0.0`).
fn stl_expected(m: &TriMesh, round: impl Fn(f64) -> f64) -> TriMesh {
    let mut map: HashMap<[u64; 3], usize> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in &m.triangles {
        let mut nt = [VertexId(0); 3];
        for (k, v) in t.iter().enumerate() {
            let p = m.positions[v.idx()].map(&round);
            let key = [p.x, p.y, p.z].map(|x| (x + 0.0).to_bits());
            let i = *map.entry(key).or_insert_with(|| {
                positions.push(p);
                positions.len() - 1
            });
            nt[k] = VertexId::new(i);
        }
        triangles.push(nt);
    }
    TriMesh {
        positions,
        triangles,
    }
}

proptest! {
    #![proptest_config(config(32))]

    #[test]
    fn every_format_round_trips(kind in 0u8..5, seed in any::<u64>(), scale in -8i32..8,
                                wild in proptest::collection::vec((any::<u64>(), 0usize..1000, 0usize..3), 0..4)) {
        let mut m = surface(kind, seed, scale);
        // Arbitrary finite doubles (subnormals, huge, negative zero) must survive text too.
        for (b, v, k) in wild {
            let x = f64::from_bits(b);
            if x.is_finite() {
                let v = v % m.n_vertices();
                m.positions[v][k] = x;
            }
        }
        let mut rng = conemesh::Rng::seed_from_u64(seed ^ 0x5eed);
        let attrs = MeshAttributes {
            face_ints: vec![("patch".into(), (0..m.n_faces()).map(|_| rng.random_range(-9..1000)).collect())],
            face_colors: Some((0..m.n_faces()).map(|_| [rng.random(), rng.random(), rng.random()]).collect()),
            uv: Some((0..m.n_vertices()).map(|_| Point2::new(rng.random(), rng.random())).collect()),
        };
        let dir = tempfile::tempdir().expect("tempdir");
        for (name, binary, big_endian) in [
            ("m.obj", false, false), ("m.off", false, false), ("m.mesh", false, false),
            ("a.ply", false, false), ("le.ply", true, false), ("be.ply", true, true),
        ] {
            let path = dir.path().join(name);
            write_mesh_with(&path, &m, &attrs, &WriteOptions { binary, big_endian })
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let back = read_mesh(&path).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(bits(&back.mesh), bits(&m), "{}", name);
            prop_assert_eq!(&back.mesh.triangles, &m.triangles, "{}", name);
            if name.ends_with(".ply") {
                prop_assert_eq!(&back.attributes, &attrs, "{}", name);
            }
            if name.ends_with(".obj") {
                prop_assert_eq!(&back.attributes.uv, &attrs.uv, "{}", name);
            }
        }
    }

    #[test]
    fn stl_round_trips_after_welding(kind in 0u8..5, seed in any::<u64>(), scale in -8i32..8) {
        let m = surface(kind, seed, scale);
        let dir = tempfile::tempdir().expect("tempdir");
        for binary in [false, true] {
            let path = dir.path().join(if binary { "b.stl" } else { "a.stl" });
            write_mesh_with(&path, &m, &MeshAttributes::default(), &WriteOptions { binary, big_endian: false })
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let back = read_mesh(&path).map_err(|e| TestCaseError::fail(e.to_string()))?;
            // Binary STL holds f32: exactly the nearest-f32 rounding, nothing more.
            let expected = if binary {
                stl_expected(&m, |x| x as f32 as f64)
            } else {
                stl_expected(&m, |x| x)
            };
            prop_assert_eq!(bits(&back.mesh), bits(&expected), "binary {}", binary);
            prop_assert_eq!(&back.mesh.triangles, &expected.triangles);
            prop_assert_eq!(back.welded_vertices, 3 * m.n_faces() - expected.n_vertices());
        }
    }
}

/// Valid files of every format and encoding, for mutation (written once).
fn valid_files() -> &'static [(conemesh::io::Format, Vec<u8>)] {
    static FILES: std::sync::OnceLock<Vec<(conemesh::io::Format, Vec<u8>)>> =
        std::sync::OnceLock::new();
    FILES.get_or_init(write_valid_files)
}

fn write_valid_files() -> Vec<(conemesh::io::Format, Vec<u8>)> {
    use conemesh::io::Format;
    let m = surface(0, 1, 0);
    let attrs = MeshAttributes {
        face_ints: vec![("patch".into(), vec![1; m.n_faces()])],
        face_colors: Some(vec![[1, 2, 3]; m.n_faces()]),
        uv: Some(vec![Point2::new(0.5, 0.5); m.n_vertices()]),
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let mut out = Vec::new();
    for (name, f, binary, big_endian) in [
        ("m.obj", Format::Obj, false, false),
        ("m.off", Format::Off, false, false),
        ("m.mesh", Format::Medit, false, false),
        ("a.ply", Format::Ply, false, false),
        ("le.ply", Format::Ply, true, false),
        ("be.ply", Format::Ply, true, true),
        ("a.stl", Format::Stl, false, false),
        ("b.stl", Format::Stl, true, false),
    ] {
        let path = dir.path().join(name);
        write_mesh_with(&path, &m, &attrs, &WriteOptions { binary, big_endian }).expect("write");
        out.push((f, std::fs::read(&path).expect("read back")));
    }
    out
}

proptest! {
    #![proptest_config(config(256))]

    /// Readers never panic: random byte edits and truncations of valid files either read or
    /// give a typed error.
    #[test]
    fn mutated_files_never_panic(which in 0usize..8,
                                 edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..6),
                                 cut in any::<prop::sample::Index>(), do_cut in any::<bool>()) {
        let files = valid_files();
        let (format, mut bytes) = files[which].clone();
        for (at, b) in edits {
            let i = at.index(bytes.len());
            bytes[i] = b;
        }
        if do_cut {
            bytes.truncate(cut.index(bytes.len() + 1));
        }
        let r = conemesh::io::read_mesh_bytes(&bytes, format, "fuzz");
        if let Err(e) = r {
            prop_assert!(e.to_string().starts_with("fuzz"));
        }
    }
}

/// Values that break a reader's assumptions, for the structural mutations below.
const HOSTILE_TOKENS: [&str; 14] = [
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "1e308",
    "-1e308",
    "1e-320",
    "x",
    "",
    "3.5",
];

/// A structural edit of a text file: (line, other line, token index, what).
type LineEdit = (
    prop::sample::Index,
    prop::sample::Index,
    prop::sample::Index,
    u8,
);

/// Apply line-level edits: delete, duplicate or swap lines, or put a hostile token in place
/// of one of a line's tokens (counts, indices and coordinates alike).
fn mutate_lines(bytes: &[u8], edits: &[LineEdit]) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for (at, other, token, what) in edits {
        if lines.is_empty() {
            break;
        }
        let i = at.index(lines.len());
        match what % 4 {
            0 => {
                lines.remove(i);
            }
            1 => {
                let l = lines[i].clone();
                lines.insert(i, l);
            }
            2 => {
                let j = other.index(lines.len());
                lines.swap(i, j);
            }
            _ => {
                let mut toks: Vec<String> =
                    lines[i].split_whitespace().map(str::to_string).collect();
                if !toks.is_empty() {
                    let t = token.index(toks.len());
                    toks[t] = HOSTILE_TOKENS[other.index(HOSTILE_TOKENS.len())].to_string();
                }
                lines[i] = toks.join(" ");
            }
        }
    }
    let mut out = lines.join("\n").into_bytes();
    out.push(b'\n');
    out
}

/// A `.sol` for [`valid_files`]' mesh (one tensor per vertex), ascii and binary.
fn valid_sols() -> &'static [Vec<u8>; 2] {
    static SOLS: std::sync::OnceLock<[Vec<u8>; 2]> = std::sync::OnceLock::new();
    SOLS.get_or_init(|| {
        let m = surface(0, 1, 0);
        let tensors: Vec<_> = (0..m.n_vertices())
            .map(|i| {
                nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(4.0 + i as f64, 4.0, 1.0))
            })
            .collect();
        let p = std::path::Path::new("m.sol");
        [false, true].map(|b| conemesh::io::sol::sol_bytes(p, &tensors, b).expect("sol"))
    })
}

/// Algorithm 1 on whatever a mutated file read as: a certified mesh or a typed error, never
/// a panic nor a run that does not end (`CONEMESH_FUZZ_DUMP=<path.obj>` writes each case's
/// mesh there before its run, so one that hangs can be taken out). Two patches and no
/// improver keep each case to milliseconds; `--repair` runs first when the mesh is not an
/// oriented manifold, as a user would try next.
fn remesh_never_panics(mesh: &TriMesh, metric: Option<&[nalgebra::Matrix3<f64>]>) {
    use conemesh::pipeline::{RemeshOptions, Remesher, Stages};
    let options = RemeshOptions {
        max_patches: Some(2),
        ..Default::default()
    };
    let remesher = Remesher::new(options).with_stages(Stages {
        improvers: vec![],
        ..Default::default()
    });
    // A case that does not end is found by writing each one out first.
    if let Some(path) = std::env::var_os("CONEMESH_FUZZ_DUMP") {
        let _ = conemesh::io::write_mesh(std::path::Path::new(&path), mesh);
    }
    let run = |m: &TriMesh, metric: Option<&[nalgebra::Matrix3<f64>]>| match metric {
        Some(t) => remesher.run_with_metric(m, t).map(|_| ()),
        None => remesher.run(m).map(|_| ()),
    };
    if run(mesh, metric).is_err() {
        if let Ok(r) = conemesh::repair::repair(mesh, &Default::default()) {
            let carried = metric.map(|t| r.vertex_values(t));
            let _ = run(&r.mesh, carried.as_deref());
        }
    }
}

proptest! {
    #![proptest_config(config(96))]

    /// Structural mutations (lines deleted, duplicated, swapped; counts, indices and
    /// coordinates replaced by hostile values) of every text format, then byte edits of
    /// every binary one, through the readers and, when they read, through `remesh`.
    #[test]
    fn mutated_files_read_or_refuse_and_remesh_or_refuse(
        which in 0usize..8,
        line_edits in proptest::collection::vec(
            (any::<prop::sample::Index>(), any::<prop::sample::Index>(), any::<prop::sample::Index>(), any::<u8>()),
            1..4),
        byte_edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..3),
    ) {
        let (format, bytes) = valid_files()[which].clone();
        let text = !matches!(which, 4 | 5 | 7); // le.ply, be.ply, b.stl are binary
        let bytes = if text {
            mutate_lines(&bytes, &line_edits)
        } else {
            let mut b = bytes;
            for (at, v) in &byte_edits {
                let i = at.index(b.len());
                b[i] = *v;
            }
            b
        };
        match conemesh::io::read_mesh_bytes(&bytes, format, "fuzz") {
            Err(e) => prop_assert!(e.to_string().starts_with("fuzz"), "{e}"),
            Ok(loaded) => remesh_never_panics(&loaded.mesh, None),
        }
    }

    /// `.sol` files mutated the same way, read for the mesh they belong to and, when they
    /// read, used as the user metric of a run.
    #[test]
    fn mutated_metrics_read_or_refuse_and_remesh_or_refuse(
        binary in any::<bool>(),
        line_edits in proptest::collection::vec(
            (any::<prop::sample::Index>(), any::<prop::sample::Index>(), any::<prop::sample::Index>(), any::<u8>()),
            1..4),
        byte_edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4),
    ) {
        let m = surface(0, 1, 0);
        let sol = &valid_sols()[binary as usize];
        let bytes = if binary {
            let mut b = sol.clone();
            for (at, v) in &byte_edits {
                let i = at.index(b.len());
                b[i] = *v;
            }
            b
        } else {
            mutate_lines(sol, &line_edits)
        };
        match conemesh::io::sol::read_sol_bytes(&bytes, "fuzz.sol", m.n_vertices()) {
            Err(e) => prop_assert!(e.to_string().contains("fuzz.sol"), "{e}"),
            Ok(tensors) => remesh_never_panics(&m, Some(&tensors)),
        }
    }
}

/// A star-shaped polygon of `n` corners (random angles and radii, so mostly concave) in a
/// random plane through a random point, as an OBJ file with one face, and its corners in the
/// plane's own coordinates.
fn star_obj(n: usize, seed: u64) -> (Vec<u8>, Vec<Point2<f64>>, nalgebra::Vector3<f64>) {
    let mut rng = conemesh::Rng::seed_from_u64(seed);
    let mut angles: Vec<f64> = (0..n)
        .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
        .collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    let flat: Vec<Point2<f64>> = angles
        .iter()
        .map(|t| {
            let r = rng.random_range(0.2..1.0);
            Point2::new(r * t.cos(), r * t.sin())
        })
        .collect();
    let normal = nalgebra::Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(0.1..1.0),
    )
    .normalize();
    let e1 = normal.cross(&nalgebra::Vector3::z()).normalize();
    let e2 = normal.cross(&e1);
    let origin = nalgebra::Vector3::new(rng.random_range(-5.0..5.0), 3.0, -2.0);
    let mut obj = String::new();
    for p in &flat {
        let x = origin + e1 * p.x + e2 * p.y;
        obj.push_str(&format!("v {:?} {:?} {:?}\n", x.x, x.y, x.z));
    }
    obj.push('f');
    for k in 1..=flat.len() {
        obj.push_str(&format!(" {k}"));
    }
    obj.push('\n');
    (obj.into_bytes(), flat, normal)
}

/// Winding number of the polygon `ring` around `x`.
fn winding(ring: &[Point2<f64>], x: &Point2<f64>) -> i32 {
    let mut w = 0;
    for k in 0..ring.len() {
        let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
        let side = (b.x - a.x) * (x.y - a.y) - (x.x - a.x) * (b.y - a.y);
        if a.y <= x.y && b.y > x.y && side > 0.0 {
            w += 1;
        } else if a.y > x.y && b.y <= x.y && side < 0.0 {
            w -= 1;
        }
    }
    w
}

proptest! {
    #![proptest_config(config(128))]

    /// A random simple polygon read from an OBJ face becomes `n − 2` triangles, each
    /// oriented like the polygon and inside it, covering its area.
    #[test]
    fn polygon_faces_become_triangles_inside_them(n in 4usize..60, seed in any::<u64>()) {
        let (obj, flat, normal) = star_obj(n, seed);
        let read = conemesh::io::read_mesh_bytes(&obj, conemesh::io::Format::Obj, "star.obj");
        let m = match read {
            Ok(m) => m,
            // Corners closer than rounding can tell apart in the plane: a named refusal.
            Err(e) => {
                prop_assert_eq!(e.kind(), "bad-polygon", "{}", e);
                return Ok(());
            }
        };
        prop_assert_eq!(m.polygons_triangulated, 1);
        let mesh = &m.mesh;
        prop_assert_eq!(mesh.n_faces(), flat.len() - 2);
        let shoelace = |r: &[Point2<f64>]| -> f64 {
            (0..r.len()).map(|k| {
                let (a, b) = (r[k], r[(k + 1) % r.len()]);
                a.x * b.y - b.x * a.y
            }).sum::<f64>() / 2.0
        };
        let mut sum = 0.0;
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|v| mesh.positions[v.idx()]);
            let cross = (b - a).cross(&(c - a));
            prop_assert!(cross.dot(&normal) > 0.0, "a triangle faces against the polygon");
            sum += cross.norm() / 2.0;
            let centroid = t.iter().fold(Point2::origin(), |s, v| s + flat[v.idx()].coords / 3.0);
            prop_assert_eq!(winding(&flat, &centroid), 1, "a triangle lies outside the polygon");
        }
        let area = shoelace(&flat);
        prop_assert!((sum - area).abs() <= 1e-9 * area, "{} against {}", sum, area);
    }
}
