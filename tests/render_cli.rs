//! `conemesh render` end to end: the PNG it writes (size, coverage, colour bar, magenta
//! faces), the patch and distance colourings, `remesh --plots` / `--write-patches`, byte
//! determinism, and bad inputs (exit code, message naming the file, no output written).

use conemesh::mesh::generators;
use conemesh::TriMesh;
use nalgebra::{Matrix3, Vector3};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;

/// One command-line argument (a path or a string).
type Arg<'a> = &'a dyn AsRef<std::ffi::OsStr>;

fn conemesh(args: &[Arg]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_conemesh"));
    for a in args {
        c.arg(a);
    }
    c.output().expect("run conemesh")
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A failure: exit code 2 and a message containing every word of `words`.
fn fails(out: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in: {err}");
    }
}

/// An RGB PNG decoded: (width, height, bytes).
fn decode(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).expect("png written");
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("png header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("png data");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

fn pixels(rgb: &[u8]) -> impl Iterator<Item = [u8; 3]> + '_ {
    rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]])
}

/// How many colours of the patch palette are drawn (shaded: a pixel is a palette colour
/// times a factor, within rounding).
fn palette_colours_seen(rgb: &[u8]) -> usize {
    let seen: std::collections::BTreeSet<[u8; 3]> = pixels(rgb).collect();
    conemesh::render::PATCH_PALETTE
        .iter()
        .filter(|c| {
            seen.iter().any(|p| {
                let k = (0..3).max_by_key(|&k| c[k]).unwrap_or(0);
                let s = f64::from(p[k]) / f64::from(c[k].max(1));
                s > 0.4 && (0..3).all(|j| (f64::from(p[j]) - s * f64::from(c[j])).abs() <= 2.0)
            })
        })
        .count()
}

fn write(dir: &Path, name: &str, mesh: &TriMesh) -> PathBuf {
    let p = dir.join(name);
    conemesh::io::write_mesh(&p, mesh).expect("write mesh");
    p
}

#[test]
fn a_picture_has_the_size_asked_for_the_object_a_bar_and_the_same_bytes_twice() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = write(dir.path(), "bumpy.off", &generators::bumpy_sphere(2));
    let a = dir.path().join("a.png");
    let b = dir.path().join("b.png");
    for p in [&a, &b] {
        ok(&conemesh(&[
            &"render",
            &mesh,
            &"-o",
            p,
            &"--width",
            &"540",
            &"--height",
            &"240",
        ]));
    }
    let (w, h, rgb) = decode(&a);
    assert_eq!((w, h), (540, 240));
    let white = pixels(&rgb).filter(|&c| c == [255, 255, 255]).count() as f64;
    let drawn = 1.0 - white / f64::from(w * h);
    assert!((0.15..0.8).contains(&drawn), "{drawn}");
    // The colour bar: the red end of the q map in the bottom rows.
    let bottom = &rgb[3 * (w * (h - 30)) as usize..];
    assert!(pixels(bottom).any(|c| c[0] > 150 && c[1] < 30 && c[2] < 60));
    assert_eq!(std::fs::read(&a).ok(), std::fs::read(&b).ok());
}

#[test]
fn remesh_writes_the_picture_and_the_patches_that_render_draws() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("torus.obj");
    let plots = dir.path().join("plots");
    let patches = dir.path().join("torus.patches");
    let metric = dir.path().join("torus.sol");
    ok(&conemesh(&[
        &"remesh",
        &"-q",
        &"-o",
        &out,
        &"--plots",
        &plots,
        &"--write-patches",
        &patches,
        &"--write-metric",
        &metric,
    ]));
    let (w, h, _) = decode(&plots.join("mesh.png"));
    assert_eq!((w, h), (1500, 600));
    // `render` in the run's metric draws what `remesh --plots` drew.
    let again = dir.path().join("again.png");
    ok(&conemesh(&[
        &"render",
        &out,
        &"-o",
        &again,
        &"--metric",
        &metric,
    ]));
    assert_eq!(
        std::fs::read(&again).ok(),
        std::fs::read(plots.join("mesh.png")).ok()
    );
    // Patches: several colours, no magenta (only q and angles flag faces).
    let pic = dir.path().join("patches.png");
    ok(&conemesh(&[
        &"render",
        &out,
        &"-o",
        &pic,
        &"--color",
        &"patch",
        &"--patches",
        &patches,
    ]));
    let (_, _, rgb) = decode(&pic);
    assert!(!pixels(&rgb).any(|c| c == [255, 0, 255]));
    // Neighbouring patches differ: at least three palette colours on a closed surface (the
    // colour bar shows all of them: only the views are counted).
    let views = &rgb[..3 * 1500 * 500];
    assert!(palette_colours_seen(views) >= 3);
    // The patch file of another mesh: the count is named, nothing written.
    let other = write(dir.path(), "other.off", &generators::icosphere(1.0, 1));
    let none = dir.path().join("none.png");
    let r = conemesh(&[
        &"render",
        &other,
        &"-o",
        &none,
        &"--color",
        &"patch",
        &"--patches",
        &patches,
    ]);
    fails(&r, &["torus.patches", "other.off", "80 faces"]);
    assert!(!none.exists());
}

#[test]
fn distance_and_a_reference_metric_are_read_against_the_reference() {
    let dir = tempfile::tempdir().expect("tempdir");
    let reference = generators::icosphere(1.0, 3);
    let mut moved = reference.clone();
    let push = moved.positions[0].coords * 0.2;
    moved.positions[0] += push;
    let r = write(dir.path(), "ref.off", &reference);
    let m = write(dir.path(), "moved.off", &moved);
    let pic = dir.path().join("d.png");
    ok(&conemesh(&[
        &"render",
        &m,
        &"-o",
        &pic,
        &"--color",
        &"distance",
        &"--reference",
        &r,
    ]));
    // The pushed-out vertex's faces: the dark red end of the distance map.
    let (_, _, rgb) = decode(&pic);
    assert!(pixels(&rgb).any(|c| c[0] > 60 && c[1] < 10 && c[2] < 40 && c[2] > 5));
    // A metric on the reference's vertices (a different count from the mesh's).
    let coarse = write(dir.path(), "coarse.off", &generators::icosphere(1.0, 2));
    let sol = dir.path().join("ref.sol");
    let stretched = Matrix3::from_diagonal(&Vector3::new(1.0, 9.0, 1.0));
    conemesh::io::sol::write_sol(&sol, &vec![stretched; reference.n_vertices()], false)
        .expect("write sol");
    let q = dir.path().join("q.png");
    ok(&conemesh(&[
        &"render",
        &coarse,
        &"-o",
        &q,
        &"--metric",
        &sol,
        &"--reference",
        &r,
    ]));
    // Without the reference the count cannot match: named, nothing written.
    let q2 = dir.path().join("q2.png");
    let out = conemesh(&[&"render", &coarse, &"-o", &q2, &"--metric", &sol]);
    fails(&out, &["ref.sol", "642", "162"]);
    assert!(!q2.exists());
}

#[test]
fn bad_inputs_fail_with_a_named_cause_and_no_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let good = write(d, "s.off", &generators::icosphere(1.0, 1));
    let pic = d.join("p.png");
    let missing = d.join("missing.off");
    let empty = d.join("empty.off");
    std::fs::write(&empty, "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n").expect("write");
    let nan = d.join("nan.off");
    std::fs::write(&nan, "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n").expect("write");
    let bad_sol = d.join("bad.sol");
    let mut metric = vec![Matrix3::identity(); 42];
    metric[3] = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
    conemesh::io::sol::write_sol(&bad_sol, &metric, false).expect("write sol");
    let no_dir = d.join("no").join("p.png");
    let jpg = d.join("p.jpg");
    let cases: Vec<(Vec<Arg>, Vec<&str>)> = vec![
        (vec![&missing, &"-o", &pic], vec!["missing.off"]),
        (vec![&empty, &"-o", &pic], vec!["empty.off"]),
        (vec![&nan, &"-o", &pic], vec!["nan.off"]),
        (
            vec![&good, &"-o", &pic, &"--metric", &bad_sol],
            vec!["v3", "bad.sol"],
        ),
        (vec![&good, &"-o", &no_dir], vec!["does not exist"]),
        (vec![&good, &"-o", &jpg], vec!["PNG"]),
        (
            vec![&good, &"-o", &pic, &"--color", &"distance"],
            vec!["--reference"],
        ),
        (
            vec![&good, &"-o", &pic, &"--color", &"patch"],
            vec!["--patches", "s.off"],
        ),
        (vec![&good, &"-o", &pic, &"--width", &"20"], vec!["20"]),
        (
            vec![&good, &"-o", &pic, &"--patches", &pic],
            vec!["same path"],
        ),
    ];
    for (args, words) in cases {
        let mut all: Vec<Arg> = vec![&"render"];
        all.extend(args);
        fails(&conemesh(&all), &words);
        assert!(!pic.exists(), "{words:?}");
    }
    // A bad option value is clap's error (exit 2 as well).
    let out = conemesh(&[&"render", &good, &"-o", &pic, &"--color", &"quality"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("min-angle"));
    // The leftover of no failure: only the inputs are in the folder.
    let names: Vec<String> = std::fs::read_dir(d)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(conemesh::io::TEMP_PREFIX))
        .collect();
    assert!(names.is_empty(), "{names:?}");
}

#[test]
fn the_patch_property_of_a_patches_ply_is_drawn_without_a_patch_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let ply = dir.path().join("p.ply");
    ok(&conemesh(&[&"patches", &"--seed", &"3", &"-o", &ply]));
    let pic = dir.path().join("p.png");
    ok(&conemesh(&[
        &"render",
        &ply,
        &"-o",
        &pic,
        &"--color",
        &"patch",
        &"--width",
        &"600",
        &"--height",
        &"260",
    ]));
    let (_, _, rgb) = decode(&pic);
    // The views only (the colour bar shows the whole palette).
    assert!(palette_colours_seen(&rgb[..3 * 600 * 200]) >= 3);
}

/// A shared mesh, coloured by q against itself and by distance to itself.
#[test]
fn a_shared_mesh_is_drawn() {
    let mesh = &common::path("bumpy.off");
    let dir = tempfile::tempdir().expect("tempdir");
    let pic = dir.path().join("bumpy.png");
    ok(&conemesh(&[
        &"render",
        &mesh,
        &"-o",
        &pic,
        &"--reference",
        &mesh,
        &"--width",
        &"600",
        &"--height",
        &"260",
    ]));
    let (w, h, rgb) = decode(&pic);
    assert_eq!((w, h), (600, 260));
    // bumpy's remeshed input has faces below 20° in the curvature metric: magenta pixels.
    assert!(pixels(&rgb).any(|c| c[0] > 80 && c[0] == c[2] && c[1] == 0));
}
