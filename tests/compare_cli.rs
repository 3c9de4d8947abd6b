//! `conemesh compare` (issue 33): every (configuration, input, seed) a row of compare.json
//! with the report's measures, the tables in compare.md and index.html, a timeout and a
//! refused input as rows, `--check` identical on the snapshot it wrote and naming the run
//! after an option in the snapshot is changed, and bad inputs refused with no output.

use conemesh::mesh::generators;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn conemesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(args)
        .output()
        .expect("run conemesh")
}

fn text(o: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A small torus in `dir` (a run takes well under a second).
fn torus(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    conemesh::io::write_mesh(&p, &generators::torus(1.0, 0.35, 24, 10)).expect("write torus");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).expect("read json")).expect("json")
}

#[test]
fn compare_tables_the_grid_and_check_finds_an_edited_option() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = torus(dir.path(), "torus.off");
    let out = dir.path().join("cmp");
    let o = conemesh(&[
        "compare",
        s(&mesh),
        "-c",
        "base=",
        "-c",
        "kring=--strategy kring --strategy-opt rings=4",
        "--seeds",
        "1-2",
        "--jobs",
        "2",
        "-o",
        s(&out),
        "-q",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let c = json(&out.join("compare.json"));
    let runs = c["runs"].as_array().expect("runs");
    assert_eq!(runs.len(), 4, "2 configurations × 1 input × 2 seeds");
    for r in runs {
        assert_eq!(r["status"], "ok", "{r}");
        let report = json(&out.join(r["files"]["report"].as_str().expect("report")));
        // The measures are the report's own numbers.
        assert_eq!(
            r["result"]["measures"]["q_avg"].as_f64(),
            report["eval"]["output_quality"]["q_avg"].as_f64()
        );
        assert_eq!(report["run"]["options"]["seed"], r["seed"]);
        assert!(out
            .join(r["files"]["output"].as_str().expect("output"))
            .is_file());
        // Without a `render` subcommand in this binary the row says why there is no picture.
        if let Some(why) = r["picture"].get("Err") {
            assert!(
                why.as_str().expect("reason").contains("no picture"),
                "{why}"
            );
        }
    }
    let kring = runs.iter().find(|r| r["config"] == "kring").expect("kring");
    let report = json(&out.join(kring["files"]["report"].as_str().expect("report")));
    assert_eq!(
        report["run"]["stages"][0], "kring",
        "the configuration's arguments reach remesh"
    );
    // The summary is the mean over the seeds; the paired rows compare kring with base.
    let summary = c["summary"].as_array().expect("summary");
    assert_eq!(summary.len(), 2);
    let q: Vec<f64> = runs
        .iter()
        .filter(|r| r["config"] == "base")
        .map(|r| r["result"]["measures"]["q_avg"].as_f64().expect("q_avg"))
        .collect();
    let base = summary
        .iter()
        .find(|r| r["config"] == "base")
        .expect("base row");
    let mean = base["measures"]["q_avg"]["mean"].as_f64().expect("mean");
    assert!((mean - (q[0] + q[1]) / 2.0).abs() < 1e-12);
    let paired = c["paired"].as_array().expect("paired");
    let qp = paired
        .iter()
        .find(|p| p["measure"] == "q_avg")
        .expect("q_avg row");
    assert_eq!(
        (
            qp["config"].as_str(),
            qp["against"].as_str(),
            qp["n"].as_u64()
        ),
        (Some("kring"), Some("base"), Some(2))
    );
    let md = std::fs::read_to_string(out.join("compare.md")).expect("compare.md");
    assert!(
        md.contains("| torus | base | 2/2 |") && md.contains("| torus | kring | 2/2 |"),
        "{md}"
    );
    assert!(md.contains("| q_avg | kring | 2 |"), "{md}");
    let html = std::fs::read_to_string(out.join("index.html")).expect("index.html");
    assert!(html.contains("<table id=\"summary\">") && html.contains("data:image/png;base64,"));
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "no network"
    );
    for plot in ["plot-q_avg.png", "hist_q.png", "hist_angles.png"] {
        assert!(out.join(plot).is_file(), "{plot}");
    }

    // The same grid again (another --jobs): the same snapshot, byte for byte.
    let again = dir.path().join("again");
    let o = conemesh(&[
        "compare",
        s(&mesh),
        "-c",
        "base=",
        "-c",
        "kring=--strategy kring --strategy-opt rings=4",
        "--seeds",
        "1-2",
        "-o",
        s(&again),
        "-q",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let bytes = |d: &Path| std::fs::read(d.join("snapshot.json")).expect("snapshot");
    assert!(
        bytes(&out) == bytes(&again),
        "snapshot.json depends on nothing but the grid"
    );

    // The snapshot reruns to the same bytes.
    let snap = out.join("snapshot.json");
    let sj = json(&snap);
    assert_eq!(sj["inputs"][0]["sha256"].as_str().map(str::len), Some(64));
    assert!(sj["conemesh"]["commit"]
        .as_str()
        .is_some_and(|c| !c.is_empty()));
    let o = conemesh(&["compare", "--check", s(&snap), "-q", "-j", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("identical"),
        "{}",
        text(&o)
    );

    // One option of one run changed: exit 1, that run named.
    let mut edited = sj.clone();
    let run = edited["runs"]
        .as_array_mut()
        .expect("runs")
        .iter_mut()
        .find(|r| r["config"] == "kring" && r["seed"] == 2)
        .expect("kring seed 2");
    run["options"]["options"]["sweeps"] = 5.into();
    let e = dir.path().join("edited.json");
    std::fs::write(&e, serde_json::to_string(&edited).expect("json")).expect("write");
    let o = conemesh(&["compare", "--check", s(&e), "-q"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let drift: Vec<&str> = stdout.lines().filter(|l| l.starts_with("drift:")).collect();
    assert_eq!(
        drift,
        ["drift: kring/torus/seed 2: options.options.sweeps: snapshot 5, now 1"],
        "{}",
        text(&o)
    );

    // A configuration's arguments changed: every run of it drifts in bytes and measures.
    let mut edited = sj.clone();
    edited["configs"][1]["args"] =
        serde_json::json!(["--strategy", "kring", "--strategy-opt", "rings=2"]);
    std::fs::write(&e, serde_json::to_string(&edited).expect("json")).expect("write");
    let o = conemesh(&["compare", "--check", s(&e), "-q"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    for seed in [1, 2] {
        assert!(
            stdout.contains(&format!("drift: kring/torus/seed {seed}: output_sha256")),
            "{stdout}"
        );
    }
    assert!(!stdout.contains("drift: base/"), "{stdout}");

    // A snapshot that is not one: exit 2, named.
    std::fs::write(&e, "{\"format\": \"conemesh-compare-snapshot/1\"}").expect("write");
    let o = conemesh(&["compare", "--check", s(&e)]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("edited.json"),
        "{}",
        text(&o)
    );
}

#[test]
fn a_timeout_and_a_refused_input_are_rows() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = torus(dir.path(), "torus.off");
    // A vertex with a NaN coordinate: remesh refuses it.
    let broken = dir.path().join("broken.off");
    std::fs::write(&broken, "OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n").expect("write");
    let out = dir.path().join("cmp");
    let o = conemesh(&[
        "compare",
        s(&broken),
        s(&mesh),
        "-c",
        "base=",
        "-o",
        s(&out),
        "-q",
        "--no-pictures",
    ]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "a run did not finish: {}",
        text(&o)
    );
    let c = json(&out.join("compare.json"));
    let status = |mesh: &str| {
        c["runs"]
            .as_array()
            .expect("runs")
            .iter()
            .find(|r| r["mesh"] == mesh)
            .expect("row")["status"]
            .clone()
    };
    assert_eq!(status("broken"), "refused");
    assert_eq!(status("torus"), "ok");
    let md = std::fs::read_to_string(out.join("compare.md")).expect("md");
    assert!(
        md.contains("| broken | base | 1 | refused |") && md.contains("non-finite"),
        "{md}"
    );

    // A limit far below a run's time: the row says timeout.
    let out = dir.path().join("slow");
    let o = conemesh(&[
        "compare",
        s(&mesh),
        "-c",
        "base=",
        "--timeout",
        "0.02",
        "-o",
        s(&out),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let c = json(&out.join("compare.json"));
    assert_eq!(c["runs"][0]["status"], "timeout", "{}", c["runs"][0]);
    assert!(c["runs"][0]["error"]
        .as_str()
        .expect("error")
        .contains("timed out"));
}

#[test]
fn bad_inputs_are_refused_before_anything_runs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = torus(dir.path(), "torus.off");
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).expect("mkdir");
    let toml = dir.path().join("bad.toml");
    std::fs::write(&toml, "[[config]\nname = 3").expect("write");
    let out = dir.path().join("out");
    let missing = dir.path().join("missing.off");
    let nowhere = dir.path().join("no/such/folder");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![s(&missing), "-c", "a="], "missing.off"),
        (vec![s(&empty), "-c", "a="], "holds no mesh"),
        (vec![s(&mesh), "--config", s(&toml)], "bad.toml"),
        (vec![s(&mesh), "-c", "a=", "--seeds", "5-1"], "5-1"),
        (vec![s(&mesh)], "no configuration"),
        (vec![s(&mesh), "-c", "a=--seed 4"], "--seed"),
        (
            vec![s(&mesh), "-c", "a=", "-c", "a=--sweeps 1"],
            "two configurations",
        ),
    ];
    for (args, needle) in cases {
        let mut all = vec!["compare"];
        all.extend(&args);
        all.extend(["-o", s(&out), "-q"]);
        let o = conemesh(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{args:?}: `{needle}` not in {err}");
        assert!(!out.exists(), "{args:?}: no partial output");
    }
    let o = conemesh(&["compare", s(&mesh), "-c", "a=", "-o", s(&nowhere), "-q"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("does not exist"),
        "{}",
        text(&o)
    );
}

/// A stand-in `conemesh`: `remesh` runs the real binary (or dies of SIGSEGV when its
/// arguments hold `--crash`), `render` copies `png` to its `-o` (or, with `render: false`,
/// answers as a binary without the subcommand does).
fn fake_conemesh(dir: &Path, png: &Path, render: bool) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let real = env!("CARGO_BIN_EXE_conemesh");
    let render_case = if render {
        format!(
            "  render) [ \"$2\" = --help ] && exit 0; cp '{}' \"$4\"; exit 0;;",
            png.display()
        )
    } else {
        "  render) echo \"error: unrecognized subcommand 'render'\" >&2; exit 2;;".to_string()
    };
    let script = format!(
        "#!/bin/sh\ncase \"$1\" in\n{render_case}\n  remesh) for a in \"$@\"; do [ \"$a\" = --crash ] && kill -SEGV $$; done; exec '{real}' \"$@\";;\nesac\nexit 2\n"
    );
    let p = dir.join(if render {
        "fake-render"
    } else {
        "fake-norender"
    });
    std::fs::write(&p, script).expect("write script");
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    p
}

#[test]
fn pictures_are_drawn_where_render_exists_and_a_crash_is_a_row() {
    use conemesh::compare::{page, Comparison, Config, Grid, PictureError, Status};
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = torus(dir.path(), "torus.off");
    let png = dir.path().join("picture.png");
    conemesh::report::write_strip_plot(&png, "a picture", "y", &[("a", vec![1.0, 2.0])])
        .expect("png");
    let inputs = conemesh::compare::config::collect_inputs(&[mesh]).expect("inputs");
    let grid = |exe: PathBuf| Grid {
        exe,
        configs: vec![
            Config::new("base", vec![]).expect("config"),
            Config::new("boom", vec!["--crash".into()]).expect("config"),
        ],
        inputs: inputs.clone(),
        seeds: vec![1],
        timeout: std::time::Duration::from_secs(60),
        jobs: 2,
        pictures: true,
    };
    let out = dir.path().join("with");
    std::fs::create_dir(&out).expect("mkdir");
    let g = grid(fake_conemesh(dir.path(), &png, true));
    let runs = g.run(&g.jobs(), &out, &|_| {}).expect("grid");
    assert_eq!(runs[0].status, Status::Ok, "{:?}", runs[0].error);
    assert_eq!(
        runs[0].picture.as_ref().ok().map(String::as_str),
        Some("base--torus--s1.png")
    );
    assert!(out.join("base--torus--s1.png").is_file());
    assert_eq!(runs[1].status, Status::Crashed);
    assert!(runs[1].error.contains("signal"), "{}", runs[1].error);
    assert!(runs[1].picture.is_err(), "no output, no picture");
    let c = Comparison::of(&g, runs);
    page::write_plots(&out, &c).expect("plots");
    let html = page::html(&c, &out);
    assert_eq!(
        html.matches("<figure class=\"picture\">").count(),
        1,
        "the ok run's picture"
    );
    assert!(page::markdown(&c).contains("| torus | boom | 1 | crashed |"));

    // A binary without `render`: every row says so, and the run is still ok.
    let out = dir.path().join("without");
    std::fs::create_dir(&out).expect("mkdir");
    let g = grid(fake_conemesh(dir.path(), &png, false));
    let runs = g.run(&g.jobs()[..1], &out, &|_| {}).expect("grid");
    assert_eq!(runs[0].status, Status::Ok);
    let why = runs[0].picture.clone().expect_err("no picture");
    assert!(matches!(why, PictureError::NoRender), "{why:?}");
}
