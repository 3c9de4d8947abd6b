//! `conemesh remesh` is reproducible (issues 9 and 19): the same seed gives byte-identical
//! output files whatever the number of threads, and a different seed gives a different mesh.
//!
//! The patch strategy draws from the seed's stream 0 and every patch from its own stream
//! (its slot in the loop); the patches of a batch run at the same time and are stitched in
//! batch order, and the other parallel code (distance queries, metric evaluation) must not
//! change any result. Running the binary with `RAYON_NUM_THREADS=1` and `=2`, and the library
//! in rayon pools of 1, 2 and 4 threads, checks exactly that, on the written bytes.

use conemesh::mesh::{generators, TriMesh};
use conemesh::pipeline::{RemeshOptions, Remesher};
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

fn remesh(input: &Path, out: &Path, seed: u64, threads: usize) -> Vec<u8> {
    let o = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("remesh")
        .arg(input)
        .arg("-o")
        .arg(out)
        .args(["--seed", &seed.to_string(), "--quiet"])
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("run conemesh");
    assert!(
        o.status.success(),
        "conemesh remesh {} --seed {seed} (RAYON_NUM_THREADS={threads}) failed:\n{}\n{}",
        input.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    std::fs::read(out).unwrap_or_else(|e| panic!("reading {}: {e}", out.display()))
}

fn assert_reproducible(input: &Path, dir: &Path) {
    let out = |tag: &str| -> PathBuf { dir.join(format!("out-{tag}.obj")) };
    let one = remesh(input, &out("s5-t1"), 5, 1);
    let two = remesh(input, &out("s5-t2"), 5, 2);
    assert!(!one.is_empty());
    assert!(
        one == two,
        "{}: seed 5 gives different bytes with 1 and 2 rayon threads ({} vs {} bytes)",
        input.display(),
        one.len(),
        two.len()
    );
    let other = remesh(input, &out("s6-t2"), 6, 2);
    assert!(
        other != one,
        "{}: seeds 5 and 6 give identical output (the seed is ignored)",
        input.display()
    );
}

#[test]
fn same_seed_same_bytes_on_a_generated_torus() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("torus.off");
    conemesh::io::write_mesh(&input, &generators::torus(1.0, 0.35, 40, 16)).expect("write");
    assert_reproducible(&input, dir.path());
}

#[test]
#[cfg_attr(debug_assertions, ignore = "heavy: run with cargo test --release")]
fn same_seed_same_bytes_on_3holes() {
    let dir = tempfile::tempdir().expect("tempdir");
    assert_reproducible(&common::path("3holes.off"), dir.path());
}

/// The library's output in a rayon pool of `threads` threads, as the bit patterns of its
/// coordinates and its triangles, with the run's loop patch and batch counts.
fn remesh_in_pool(
    mesh: &TriMesh,
    threads: usize,
    batch: usize,
) -> (Vec<u64>, Vec<[u32; 3]>, usize, usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let options = RemeshOptions {
        seed: 3,
        batch,
        ..RemeshOptions::default()
    };
    let r = pool
        .install(|| Remesher::new(options).run(mesh))
        .expect("remesh succeeds");
    let bits = r
        .mesh
        .positions
        .iter()
        .flat_map(|p| p.iter().map(|x| x.to_bits()))
        .collect();
    let tris = r.mesh.triangles.iter().map(|t| t.map(|v| v.0)).collect();
    (
        bits,
        tris,
        r.unit.report.loop_patches,
        r.unit.report.loop_batches,
    )
}

/// Parallel patches (issue 19): batches of several patches really ran (fewer batches than
/// patches), and 1, 2 and 4 threads give the same bits, on a closed surface and one with
/// boundary and genus.
#[test]
fn parallel_batches_give_the_same_bits_for_every_thread_count() {
    let meshes = [
        generators::torus(1.0, 0.35, 40, 16),
        generators::genus_plate(2, 1),
    ];
    for (k, mesh) in meshes.iter().enumerate() {
        let one = remesh_in_pool(mesh, 1, 8);
        let (patches, batches) = (one.2, one.3);
        assert!(
            batches < patches,
            "mesh {k}: {patches} patches in {batches} batches"
        );
        for threads in [2, 4] {
            let other = remesh_in_pool(mesh, threads, 8);
            assert!(one == other, "mesh {k}: 1 and {threads} threads differ");
        }
        // The batch size is part of the algorithm: one patch at a time is another run.
        let serial = remesh_in_pool(mesh, 2, 1);
        assert_eq!(serial.2, serial.3, "mesh {k}: batches of one patch");
        assert!(
            serial.0 != one.0,
            "mesh {k}: batch 1 and batch 8 gave the same mesh"
        );
    }
}

/// `--threads N` sets the pool like `RAYON_NUM_THREADS`, and 0 is refused by name.
#[test]
fn threads_option_gives_the_same_bytes_and_refuses_zero() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("torus.off");
    conemesh::io::write_mesh(&input, &generators::torus(1.0, 0.35, 40, 16)).expect("write");
    let env_one = remesh(&input, &dir.path().join("env1.obj"), 5, 1);
    let run = |args: &[&str], out: &str| {
        Command::new(env!("CARGO_BIN_EXE_conemesh"))
            .arg("remesh")
            .arg(&input)
            .arg("-o")
            .arg(dir.path().join(out))
            .args(["--seed", "5", "--quiet"])
            .args(args)
            .output()
            .expect("run conemesh")
    };
    let o = run(&["--threads", "2"], "t2.obj");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read(dir.path().join("t2.obj")).expect("output") == env_one);
    let zero = run(&["--threads", "0"], "t0.obj");
    assert!(!zero.status.success());
    assert!(String::from_utf8_lossy(&zero.stderr).contains("--threads must be at least 1"));
    assert!(
        !dir.path().join("t0.obj").exists(),
        "no output after a refused option"
    );
}
