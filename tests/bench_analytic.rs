//! `conemesh bench --suite analytic` without a real MMG: the selected cases are written and
//! run, the table has one conemesh and one MMG row per case with the numbers of the eval
//! reports, the MMG rows say "not installed" when there is no MMG, a (fake) MMG is run with the
//! issue's protocol and scored like conemesh, failures and timeouts are FAILED rows with a
//! non-zero exit, and bad arguments are errors naming what is wrong.

use std::path::Path;
use std::process::Command;

/// `conemesh bench ARGS` with no MMG to be found: PATH empty, CONEMESH_MMG unset (bench
/// starts its children through its own path, not PATH).
fn bench(args: &[&str], empty_dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("bench")
        .args(args)
        .env("PATH", empty_dir)
        .env_remove("CONEMESH_MMG")
        .output()
        .expect("run conemesh bench")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// The cells of the row of `case` and `tool`.
fn row(table: &str, case: &str, tool: &str) -> Vec<String> {
    table
        .lines()
        .find(|l| l.starts_with(&format!("| {case} | {tool} |")))
        .unwrap_or_else(|| panic!("no {tool} row for {case} in\n{table}"))
        .trim_matches('|')
        .split('|')
        .map(|c| c.trim().to_string())
        .collect()
}

fn result_rows(table: &str) -> usize {
    table
        .lines()
        .filter(|l| l.contains(" | conemesh | ") || l.contains(" | MMG | "))
        .count()
}

fn eval_report(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("eval json")
}

/// A FAKE `mmgs_O3` (a shell script, for tests only): it remeshes nothing, it copies the `-in`
/// mesh to `-out`, so the MMG row must show the input's own faces. `-h` prints a release
/// line; `body` runs after the arguments are parsed (`$in`, `$out`, all of them in `$args`).
fn fake_mmg(dir: &Path, body: &str) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("fake-mmgs_O3");
    let script = format!(
        "#!/bin/sh\n# FAKE mmgs_O3 for conemesh's tests: not MMG, it only copies -in to -out.\n\
         PATH=/usr/bin:/bin; args=\"$*\"\n\
         if [ \"$1\" = \"-h\" ]; then echo '  -- FAKE MMGS, Release 0.0 (test stub)'; exit 0; fi\n\
         while [ $# -gt 0 ]; do case \"$1\" in -in) in=\"$2\"; shift;; -out) out=\"$2\"; shift;; esac; shift; done\n\
         {body}\n"
    );
    std::fs::write(&path, script).expect("write fake");
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    path
}

#[test]
fn one_case_without_mmg_gives_a_scored_conemesh_row_and_an_mmg_row_not_installed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let o = bench(
        &["--suite", "analytic", "--case", "plate-iso", "-o", s(&out)],
        dir.path(),
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let table = std::fs::read_to_string(out.join("analytic.md")).expect("table written");
    assert_eq!(
        String::from_utf8_lossy(&o.stdout)
            .matches("| plate-iso | conemesh |")
            .count(),
        1
    );
    assert!(table.contains("MMG: not installed"), "{table}");
    assert_eq!(result_rows(&table), 2, "one case, two tools:\n{table}");
    assert!(table
        .contains("| plate-iso | unit square plate, 40×40 cells | isotropic h = 0.02 | 3200 |"));

    let c = row(&table, "plate-iso", "conemesh");
    let r = &eval_report(&out.join("plate-iso-conemesh-eval.json"))["report"];
    assert_eq!(c[2], r["output"]["faces"].to_string());
    let faces: f64 = c[2].parse().expect("faces");
    // An isotropic 0.02 metric on the unit square: about 5,774 faces on target.
    assert!((3_000.0..12_000.0).contains(&faces), "{faces}");
    let q_avg = r["output_quality"]["q_avg"].as_f64().expect("q_avg");
    assert!(c[3].ends_with(&format!("{q_avg:.3}")), "{}", c[3]);
    let in_range: f64 = c[5].parse().expect("in range %");
    let in_range_json = r["output_conformity"]["fraction_in_range"]
        .as_f64()
        .expect("fraction");
    assert!((in_range - 100.0 * in_range_json).abs() <= 0.05 + 1e-9);
    let mean: f64 = c[6].parse().expect("mean L/L_tar");
    assert!((0.7..1.4).contains(&mean), "edges near L_tar = 1: {mean}");
    assert_eq!(c[8], "0", "no flips");
    assert_eq!(c[9], "yes", "valid");
    let wall: f64 = c[10].parse().expect("wall");
    let own: f64 = c[11].parse().expect("remesh s");
    assert!(own > 0.0 && own <= wall, "own {own} within wall {wall}");
    assert_eq!(c[12], "-", "no ratio without MMG");
    assert!(r["metric_source"] == "user" && r["l_tar"].as_f64().is_some());

    let m = row(&table, "plate-iso", "MMG");
    assert_eq!(m[2], "not installed");
    assert!(out.join("plate-iso.mesh").is_file() && out.join("plate-iso.sol").is_file());
    assert!(out.join("plate-iso-conemesh.obj").is_file());
    assert!(!out.join("plate-iso-mmg.mesh").exists());
}

#[test]
fn a_fake_mmg_runs_with_the_protocol_and_a_failing_one_is_a_failed_row() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    // Records its arguments, takes half a second (a wall time the table's two decimals
    // resolve), copies the input.
    let args_file = dir.path().join("mmg-args");
    let copy = fake_mmg(
        dir.path(),
        &format!(
            "echo \"$args\" > '{}'; sleep 0.5; cp \"$in\" \"$out\"",
            s(&args_file)
        ),
    );
    let o = bench(
        &[
            "--suite",
            "analytic",
            "--case",
            "plate-iso",
            "-o",
            s(&out),
            "--mmg",
            s(&copy),
        ],
        dir.path(),
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let table = std::fs::read_to_string(out.join("analytic.md")).expect("table");
    assert!(
        table.contains("(FAKE MMGS, Release 0.0 (test stub))"),
        "{table}"
    );
    let recorded = std::fs::read_to_string(&args_file).expect("the fake ran");
    let mesh = out.join("plate-iso.mesh");
    assert!(
        recorded.contains(&format!(
            "-in {} -sol {} -out {} -nr -hausd 10 -hgrad -1 -v -1",
            s(&mesh),
            s(&out.join("plate-iso.sol")),
            s(&out.join("plate-iso-mmg.mesh"))
        )),
        "{recorded}"
    );
    let m = row(&table, "plate-iso", "MMG");
    assert_eq!(m[2], "3200", "the fake's output is the input");
    assert_eq!(m[7], "0.000", "no distance to itself");
    assert!(eval_report(&out.join("plate-iso-mmg-eval.json"))["report"]["topology_kept"] == true);
    let c = row(&table, "plate-iso", "conemesh");
    let ratio: f64 = c[12].parse().expect("a time ratio with both tools");
    let (cw, mw): (f64, f64) = (c[10].parse().expect("wall"), m[10].parse().expect("wall"));
    assert!(
        mw >= 0.5,
        "the fake's own half second is in its wall time: {mw}"
    );
    assert!(
        (ratio - cw / mw).abs() <= 0.03 * ratio,
        "{ratio} vs {cw}/{mw}"
    );

    // A failing MMG: a FAILED row naming its message, the conemesh row still there, exit 1;
    // the previous run's MMG output is not scored as this one's.
    let fail = fake_mmg(dir.path(), "echo 'cannot remesh this' >&2; exit 3");
    let o = bench(
        &[
            "--suite",
            "analytic",
            "--case",
            "plate-iso",
            "-o",
            s(&out),
            "--mmg",
            s(&fail),
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(1));
    let table = std::fs::read_to_string(out.join("analytic.md")).expect("table");
    let m = row(&table, "plate-iso", "MMG");
    assert!(
        m[2].starts_with("FAILED") && m[2].contains("cannot remesh this") && m[2].contains("3"),
        "{m:?}"
    );
    assert!(
        !out.join("plate-iso-mmg.mesh").exists(),
        "stale output removed"
    );
    assert!(row(&table, "plate-iso", "conemesh")[2]
        .parse::<u64>()
        .is_ok());
}

#[test]
fn children_past_the_timeout_are_killed_and_reported() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let hang = fake_mmg(dir.path(), "exec sleep 60");
    let t0 = std::time::Instant::now();
    let o = bench(
        &[
            "--suite",
            "analytic",
            "--case",
            "cylinder-iso",
            "-o",
            s(&out),
            "--mmg",
            s(&hang),
            "--timeout",
            "0.3",
        ],
        dir.path(),
    );
    assert!(
        t0.elapsed().as_secs_f64() < 30.0,
        "nothing waited for the sleeping child"
    );
    assert_eq!(o.status.code(), Some(1));
    let table = std::fs::read_to_string(out.join("analytic.md")).expect("table");
    for tool in ["conemesh", "MMG"] {
        let r = row(&table, "cylinder-iso", tool);
        assert!(
            r[2].contains("FAILED: timed out after 0.3 s (killed)"),
            "{r:?}"
        );
    }
}

#[test]
fn bad_arguments_are_errors_that_name_the_problem() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let err = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).into_owned();

    let o = bench(
        &["--suite", "analytic", "--case", "nosuch", "-o", s(&out)],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err(&o).contains("no case of the suite matches `nosuch`")
            && err(&o).contains("plate-aniso100")
    );
    assert!(!out.exists(), "nothing written");

    let o = bench(&["--suite", "nosuch"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err(&o).contains("analytic"),
        "clap lists the suites: {}",
        err(&o)
    );

    let o = bench(&["--case", "plate-iso"], dir.path());
    assert_eq!(o.status.code(), Some(2), "--case needs --suite");
    let o = bench(&["--suite", "analytic", "--dir", s(dir.path())], dir.path());
    assert_eq!(
        o.status.code(),
        Some(2),
        "a folder and a suite exclude each other"
    );
    assert!(err(&o).contains("cannot be used with"), "{}", err(&o));

    let missing = dir.path().join("no-mmg-here");
    let o = bench(
        &[
            "--suite",
            "analytic",
            "--case",
            "plate-iso",
            "--mmg",
            s(&missing),
            "-o",
            s(&out),
        ],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err(&o).contains(&format!("--mmg {}: no such file", s(&missing))),
        "{}",
        err(&o)
    );

    // An out dir under a regular file cannot be created.
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").expect("write");
    let bad = file.join("out");
    let o = bench(
        &["--suite", "analytic", "--case", "plate-iso", "-o", s(&bad)],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(err(&o).contains(s(&bad)), "{}", err(&o));

    let o = bench(
        &["--suite", "analytic", "-o", s(&out), "--", "--ltar", "2"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(err(&o).contains("`--ltar` is set by bench"), "{}", err(&o));
}
