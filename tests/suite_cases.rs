//! The analytic suite (`conemesh::suite`): every case's mesh is a valid manifold with the
//! documented boundary loops and genus; its metric is SPD at every vertex, accepted by
//! conemesh, and equal to the documented sizes and directions (recomputed here from the
//! module doc's formulas, independently of the library's frames); boundary layers and shocks
//! vary as documented; outputs on target have 2k–20k faces; the files round-trip.

use conemesh::mesh::Topology;
use conemesh::suite::{self, Case, ANALYTIC};
use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};
use std::f64::consts::PI;

fn case(name: &str) -> &'static Case {
    ANALYTIC
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no case {name}"))
}

fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A documented frame: (unit direction, size) pairs spanning space.
type Documented = Vec<(Vector3<f64>, f64)>;

/// Sizes h1 across d1, h2 along d2, and the normal at min(h1, h2).
fn frame(d1: Vector3<f64>, h1: f64, d2: Vector3<f64>, h2: f64, n: Vector3<f64>) -> Documented {
    vec![(d1, h1), (d2, h2), (n, h1.min(h2))]
}

fn iso(h: f64) -> Documented {
    frame(Vector3::x(), h, Vector3::y(), h, Vector3::z())
}

/// Radial and circumferential unit vectors of p around the vertical line through (cx, cy);
/// `None` on the line.
fn polar(p: &Point3<f64>, cx: f64, cy: f64) -> Option<(Vector3<f64>, Vector3<f64>, f64)> {
    let r = Vector3::new(p.x - cx, p.y - cy, 0.0);
    let rho = r.norm();
    (rho > 1e-12).then(|| {
        let radial = r / rho;
        (radial, Vector3::z().cross(&radial), rho)
    })
}

/// The module doc's table, written out again for a vertex at `p`.
fn documented(name: &str, p: &Point3<f64>) -> Documented {
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    let shock = |d: f64, fine: f64, coarse: f64, w: f64| {
        coarse - (coarse - fine) * (-(d / w).powi(2)).exp()
    };
    match name {
        "plate-iso" => iso(0.02),
        "plate-aniso10" => frame(y, 0.006, x, 0.06, z),
        "plate-aniso30" => frame(y, 0.004, x, 0.12, z),
        "plate-aniso100" => frame(y, 0.002, x, 0.2, z),
        "plate-aniso1000" => frame(y, 0.0005, x, 0.5, z),
        "plate-turning10" => match polar(p, 0.5, 0.5) {
            Some((radial, circle, rho)) => frame(
                radial,
                0.006,
                circle,
                0.006 * 10f64.powf(smoothstep(rho / 0.15)),
                z,
            ),
            None => iso(0.006),
        },
        "plate-blayer" => frame(y, (0.001 + 0.05 * p.y).min(0.04), x, 0.04, z),
        "plate-shock-sine" => {
            let phi = p.y - 0.5 - 0.15 * (2.0 * PI * p.x).sin();
            let grad = Vector3::new(-0.15 * 2.0 * PI * (2.0 * PI * p.x).cos(), 1.0, 0.0);
            let across = grad.normalize();
            let h = shock(phi.abs() / grad.norm(), 0.002, 0.04, 0.08);
            frame(across, h, z.cross(&across), 0.04, z)
        }
        "plate-shock-circle" => match polar(p, 0.5, 0.5) {
            Some((radial, circle, rho)) => frame(
                radial,
                shock((rho - 0.3).abs(), 0.002, 0.04, 0.08),
                circle,
                0.04,
                z,
            ),
            // The centre, 0.3 = 3.75 widths from the front: the radial direction is undefined
            // and the size across is h_coarse to 1e-6; any direction does (the library's x).
            None => frame(x, shock(0.3, 0.002, 0.04, 0.08), y, 0.04, z),
        },
        _ => documented_curved(name, p),
    }
}

fn documented_curved(name: &str, p: &Point3<f64>) -> Documented {
    let z = Vector3::z();
    let around = polar(p, 0.0, 0.0);
    match name {
        "cylinder-iso" => iso(0.1),
        "cylinder-axial10" | "cylinder-axial30" | "cylinder-helix10" | "cylinder-blayer" => {
            let (radial, circle, _) = around.expect("cylinder vertices are off the axis");
            match name {
                "cylinder-axial10" => frame(z, 0.03, circle, 0.3, radial),
                "cylinder-axial30" => frame(z, 0.02, circle, 0.6, radial),
                "cylinder-helix10" => {
                    let helix = (circle + z) / 2f64.sqrt();
                    frame((circle - z) / 2f64.sqrt(), 0.03, helix, 0.3, radial)
                }
                _ => frame(z, (0.005 + 0.1 * p.z).min(0.1), circle, 0.1, radial),
            }
        }
        "sphere-iso" => iso(0.08),
        "sphere-turning10" | "sphere-shock" => {
            let n = p.coords.normalize();
            let Some((_, parallel, rho)) = around else {
                // The poles: the metric is isotropic there (turning: blended; shock: far).
                let h = if name == "sphere-shock" { 0.08 } else { 0.02 };
                return iso(h);
            };
            let meridian = n.cross(&parallel);
            if name == "sphere-turning10" {
                frame(
                    meridian,
                    0.02,
                    parallel,
                    0.02 * 10f64.powf(smoothstep(rho / 0.3)),
                    n,
                )
            } else {
                let h = 0.08 - 0.075 * (-(p.z.abs() / 0.2).powi(2)).exp();
                frame(meridian, h, parallel, 0.08, n)
            }
        }
        "torus-iso" => iso(0.08),
        "torus-turning10" => {
            let (radial, ring, _) = around.expect("torus vertices are off the axis");
            let n = (p.coords - radial).normalize();
            frame(n.cross(&ring), 0.03, ring, 0.3, n)
        }
        "holes-iso" => iso(0.04),
        "holes-blayer" => {
            let centres = [
                [0.0, 0.55],
                [-0.55 * (PI / 6.0).cos(), -0.275],
                [0.55 * (PI / 6.0).cos(), -0.275],
            ];
            let (d, radial, circle) = centres
                .iter()
                .map(|c| {
                    let (radial, circle, rho) = polar(p, c[0], c[1]).expect("outside the holes");
                    ((rho - 0.1).abs(), radial, circle)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .expect("three holes");
            frame(radial, (0.003 + 0.15 * d).min(0.05), circle, 0.05, z)
        }
        other => panic!("case {other} is not documented in this test"),
    }
}

fn tensor(doc: &Documented) -> Matrix3<f64> {
    doc.iter().map(|(d, h)| d * d.transpose() / (h * h)).sum()
}

#[test]
fn every_case_is_a_manifold_with_the_documented_topology() {
    // (name prefix, genus, boundary loops), from the module doc's table of surfaces.
    let expected = [
        ("plate", 0, 1),
        ("cylinder", 0, 2),
        ("sphere", 0, 0),
        ("torus", 1, 0),
        ("holes", 0, 4),
    ];
    for c in ANALYTIC {
        let m = c.mesh().expect("the generator builds every case");
        m.validate().expect("valid arrays");
        let t = Topology::build(&m);
        assert!(t.is_oriented_manifold(), "{}", c.name);
        assert_eq!(t.components().len(), 1, "{}", c.name);
        let &(_, genus, loops) = expected
            .iter()
            .find(|e| c.name.starts_with(e.0))
            .unwrap_or_else(|| panic!("{}: no documented surface", c.name));
        assert_eq!(t.components()[0].genus, Some(genus), "{}", c.name);
        assert_eq!(t.boundary_loops().len(), loops, "{}", c.name);
        assert_eq!(
            (c.shape.genus(), c.shape.boundary_loops()),
            (genus, loops),
            "{}",
            c.name
        );
        assert!(m.faces().all(|f| m.face_area(f) > 0.0), "{}", c.name);
        assert!(
            conemesh::invariants::self_intersections(&m).is_empty(),
            "{}: the input is embedded",
            c.name
        );
    }
}

#[test]
fn every_metric_is_spd_and_equals_the_documented_sizes_at_every_vertex() {
    for c in ANALYTIC {
        let m = c.mesh().expect("mesh");
        let metric = c.metric(&m);
        assert_eq!(metric.len(), m.n_vertices());
        for (v, (p, t)) in m.positions.iter().zip(&metric).enumerate() {
            assert!(
                (t - t.transpose()).norm() == 0.0,
                "{} v{v}: symmetric",
                c.name
            );
            let eig = SymmetricEigen::new(*t).eigenvalues;
            assert!(
                eig.iter().all(|l| *l > 0.0 && l.is_finite()),
                "{} v{v}: SPD, {eig:?}",
                c.name
            );
            let doc = documented(c.name, p);
            let expected = tensor(&doc);
            assert!(
                (t - expected).norm() <= 1e-9 * expected.norm(),
                "{} v{v} at {p:?}: {t} is not the documented {expected}",
                c.name
            );
            // The same, read as the brief puts it: a unit vector along d has metric length 1/h.
            for (d, h) in &doc {
                let len = (d.transpose() * t * d)[0].sqrt();
                assert!(
                    (len * h - 1.0).abs() < 1e-9,
                    "{} v{v}: |d|_M = {len}, 1/h = {}",
                    c.name,
                    1.0 / h
                );
            }
        }
    }
}

#[test]
fn conemesh_accepts_every_metric_and_outputs_on_target_have_2k_to_20k_faces() {
    for c in ANALYTIC {
        let m = c.mesh().expect("mesh");
        let metric = c.metric(&m);
        conemesh::metric::MetricField::new(m.clone(), metric.clone())
            .unwrap_or_else(|e| panic!("{}: {e}", c.name));
        let faces = conemesh::pipeline::expected_faces(&m, &metric, &[], 1.0);
        assert!(
            (2_000.0..=20_000.0).contains(&faces),
            "{}: {faces:.0} expected faces",
            c.name
        );
    }
}

/// The input's vertices sample each metric finely enough that the interpolated `.sol` is
/// still the documented field: along every input edge the smallest size changes by at most
/// a factor 2.1 (boundary layers and shocks get finer inputs for this).
#[test]
fn every_input_resolves_its_metric() {
    for c in ANALYTIC {
        let m = c.mesh().expect("mesh");
        let h: Vec<f64> = m
            .positions
            .iter()
            .map(|p| {
                let f = c.frame_at(p);
                f.h_across.min(f.h_along)
            })
            .collect();
        let worst = m
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].idx(), t[(k + 1) % 3].idx())))
            .map(|(a, b)| h[a].max(h[b]) / h[a].min(h[b]))
            .fold(1.0, f64::max);
        assert!(
            worst <= 2.1,
            "{}: size ratio {worst:.2} along an input edge",
            c.name
        );
    }
}

#[test]
fn boundary_layers_grow_linearly_from_the_wall_and_become_isotropic() {
    let c = case("plate-blayer");
    let mut last = 0.0;
    for k in 0..=100 {
        let y = k as f64 / 100.0;
        let f = c.frame_at(&Point3::new(0.5, y, 0.0));
        assert!(
            (f.across.dot(&Vector3::y()).abs() - 1.0).abs() < 1e-12,
            "across the wall is y"
        );
        assert_eq!(f.h_along, 0.04);
        if y <= 0.78 {
            assert!((f.h_across - (0.001 + 0.05 * y)).abs() < 1e-15, "y = {y}");
            assert!(f.h_across > last, "grows with the distance");
        } else {
            assert_eq!(f.h_across, 0.04, "isotropic far from the wall (y = {y})");
        }
        last = f.h_across;
    }
    assert!((c.frame_at(&Point3::new(0.3, 0.0, 0.0)).ratio() - 40.0).abs() < 1e-9);

    // Around the holes: fine across every wall, isotropic where the nearest hole changes.
    let c = case("holes-blayer");
    for a in [PI / 2.0, 7.0 * PI / 6.0, 11.0 * PI / 6.0] {
        for t in [0.0f64, 1.0, 2.5] {
            let p = Point3::new(
                0.55 * a.cos() + 0.1 * t.cos(),
                0.55 * a.sin() + 0.1 * t.sin(),
                0.0,
            );
            let f = c.frame_at(&p);
            assert!(
                (f.h_across - 0.003).abs() < 1e-12 && f.h_along == 0.05,
                "{f:?}"
            );
        }
    }
    for a in [PI / 6.0, 5.0 * PI / 6.0, 3.0 * PI / 2.0] {
        for r in [0.0, 0.2, 0.4, 0.6, 0.8] {
            let f = c.frame_at(&Point3::new(r * a.cos(), r * a.sin(), 0.0));
            assert_eq!((f.h_across, f.h_along), (0.05, 0.05), "bisector at r = {r}");
        }
    }
}

#[test]
fn shocks_are_fine_on_the_front_and_coarse_away_from_it() {
    // On the plates' fronts and along their normals.
    for (name, front, normal) in [
        (
            "plate-shock-sine",
            (|x: f64| Point3::new(x, 0.5 + 0.15 * (2.0 * PI * x).sin(), 0.0))
                as fn(f64) -> Point3<f64>,
            (|x: f64| Vector3::new(-0.15 * 2.0 * PI * (2.0 * PI * x).cos(), 1.0, 0.0).normalize())
                as fn(f64) -> Vector3<f64>,
        ),
        (
            "plate-shock-circle",
            |t: f64| {
                Point3::new(
                    0.5 + 0.3 * (2.0 * PI * t).cos(),
                    0.5 + 0.3 * (2.0 * PI * t).sin(),
                    0.0,
                )
            },
            |t: f64| Vector3::new((2.0 * PI * t).cos(), (2.0 * PI * t).sin(), 0.0),
        ),
    ] {
        let c = case(name);
        for k in 0..20 {
            let s = k as f64 / 20.0;
            let on = c.frame_at(&front(s));
            assert!(
                (on.h_across - 0.002).abs() < 1e-12 && on.h_along == 0.04,
                "{name}: {on:?}"
            );
            assert!(
                (on.across.dot(&normal(s)).abs() - 1.0).abs() < 1e-12,
                "{name}: across the front"
            );
            let mut last = on.h_across;
            for j in 1..=8 {
                let f = c.frame_at(&(front(s) + normal(s) * (0.01 * j as f64)));
                assert!(f.h_across > last, "{name}: grows away from the front");
                last = f.h_across;
            }
            // (The sine's first-order distance is a little short of the true one off the line.)
            let far = c.frame_at(&(front(s) + normal(s) * 0.16));
            assert!(
                (far.h_across - 0.04).abs() < 0.04 * 0.05,
                "{name}: 2 widths away, {far:?}"
            );
        }
    }
    // The sphere's equator.
    let c = case("sphere-shock");
    for k in 0..12 {
        let a = 2.0 * PI * k as f64 / 12.0;
        let on = c.frame_at(&Point3::new(a.cos(), a.sin(), 0.0));
        assert!((on.h_across - 0.005).abs() < 1e-12 && on.across.z.abs() > 1.0 - 1e-12);
        let pole = c.frame_at(&Point3::new(0.0, 0.0, 1.0));
        assert!((pole.h_across - 0.08).abs() < 1e-9 && pole.h_along == 0.08);
    }
}

#[test]
fn turning_fields_are_isotropic_where_their_direction_is_undefined() {
    let f = case("plate-turning10").frame_at(&Point3::new(0.5, 0.5, 0.0));
    assert_eq!((f.h_across, f.h_along), (0.006, 0.006));
    let f = case("sphere-turning10").frame_at(&Point3::new(0.0, 0.0, -1.0));
    assert_eq!((f.h_across, f.h_along), (0.02, 0.02));
    // Far from the centre: the full ratio, along the circles.
    let f = case("plate-turning10").frame_at(&Point3::new(0.9, 0.5, 0.0));
    assert!((f.ratio() - 10.0).abs() < 1e-9 && f.along.y.abs() > 1.0 - 1e-12);
}

#[test]
fn the_module_doc_lists_every_case_and_only_those() {
    let doc = include_str!("../src/suite/mod.rs");
    let listed: Vec<&str> = doc
        .lines()
        .filter_map(|l| l.strip_prefix("//! | `"))
        .filter_map(|l| l.split('`').next())
        .collect();
    let names: Vec<&str> = ANALYTIC.iter().map(|c| c.name).collect();
    assert_eq!(listed, names);
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "names are unique");
    assert!((15..=25).contains(&names.len()));
}

#[test]
fn select_filters_by_substring_and_names_a_filter_that_matches_nothing() {
    let all = suite::select(ANALYTIC, &[]).expect("all");
    assert_eq!(all.len(), ANALYTIC.len());
    let some = suite::select(ANALYTIC, &["aniso".into(), "torus-iso".into()]).expect("some");
    let names: Vec<&str> = some.iter().map(|c| c.name).collect();
    assert_eq!(
        names,
        [
            "plate-aniso10",
            "plate-aniso30",
            "plate-aniso100",
            "plate-aniso1000",
            "torus-iso"
        ]
    );
    let e = suite::select(ANALYTIC, &["plate".into(), "nosuch".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`nosuch`") && e.contains("plate-aniso100") && e.contains("holes-blayer"),
        "{e}"
    );
}

#[test]
fn written_cases_read_back_and_an_unwritable_folder_is_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let c = case("plate-aniso100");
    let files = c.write(dir.path()).expect("write");
    assert_eq!(files.mesh, dir.path().join("plate-aniso100.mesh"));
    let mesh = conemesh::io::read_mesh(&files.mesh)
        .expect("read mesh")
        .mesh;
    assert_eq!(
        mesh,
        c.mesh().expect("mesh"),
        "the .mesh stores f64 exactly"
    );
    assert_eq!(files.faces, 3200);
    let sol = conemesh::io::sol::read_sol(&files.sol, mesh.n_vertices()).expect("read sol");
    assert_eq!(sol, c.metric(&mesh), "the .sol stores f64 exactly");
    assert!((files.expected_faces - 2.0 / (3f64.sqrt() * 0.002 * 0.2) * 2.0).abs() < 1.0);

    let missing = dir.path().join("no").join("such");
    let e = c.write(&missing).unwrap_err().to_string();
    assert!(e.contains(&missing.display().to_string()), "{e}");
}
