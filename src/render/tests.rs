//! Properties of the pictures: coverage, the three views apart, the colour bar, a sliver in
//! magenta where it is drawn, distinct patch colours, the wireframe, determinism, errors.

use super::*;
use crate::ids::PatchId;
use crate::mesh::generators;
use crate::option_error::OptionError;
use nalgebra::{Matrix3, Point3, Vector3};

/// No text: the pixel counts below do not depend on the system's fonts.
fn plain(width: u32, height: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        wireframe: Wireframe::Auto,
        text: false,
    }
}

fn identity(mesh: &TriMesh) -> Vec<Matrix3<f64>> {
    vec![Matrix3::identity(); mesh.n_vertices()]
}

fn is_background(c: [u8; 3]) -> bool {
    c == BACKGROUND
}

/// Magenta after shading: red and blue equal and strong, no green.
fn is_magenta(c: [u8; 3]) -> bool {
    c[0] > 80 && c[0].abs_diff(c[2]) <= 2 && c[1] == 0
}

fn is_wire(c: [u8; 3]) -> bool {
    c == WIRE
}

/// Pixels of `img` inside `rect` that satisfy `pred`.
fn count(img: &Image, rect: (u32, u32, u32, u32), pred: impl Fn([u8; 3]) -> bool) -> usize {
    let (x0, y0, x1, y1) = rect;
    (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .filter(|&(x, y)| pred(img.pixel(x, y)))
        .count()
}

/// The bounding box of the non-background pixels inside `rect`.
fn drawn_box(img: &Image, rect: (u32, u32, u32, u32)) -> Option<(u32, u32, u32, u32)> {
    let (x0, y0, x1, y1) = rect;
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for y in y0..y1 {
        for x in x0..x1 {
            if !is_background(img.pixel(x, y)) {
                b = Some(match b {
                    None => (x, y, x + 1, y + 1),
                    Some((a, c, d, e)) => (a.min(x), c.min(y), d.max(x + 1), e.max(y + 1)),
                });
            }
        }
    }
    b
}

#[test]
fn three_views_cover_their_own_thirds_with_background_around() -> Result<(), RenderError> {
    let m = generators::torus(1.0, 0.35, 32, 16);
    let colors = face_colors(&m, ColorBy::None, &Sources::default())?;
    let (img, layout) = render(&m, &colors, &plain(600, 260))?;
    assert_eq!(
        (img.width, img.height, img.rgb.len()),
        (600, 260, 600 * 260 * 3)
    );
    assert_eq!(layout.views.len(), 3);
    let mut boxes = Vec::new();
    for v in &layout.views {
        let (x0, y0, x1, y1) = v.rect;
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let covered = count(&img, v.rect, |c| !is_background(c)) as f64 / area;
        // A torus seen from the front fills a ring; seen from the side, a band.
        assert!((0.1..0.9).contains(&covered), "{}: {covered}", v.name);
        let b = drawn_box(&img, v.rect).expect("drawn");
        // The margin stays background: the view does not touch its neighbours.
        assert!(
            b.0 > x0 && b.2 < x1 && b.1 > y0 && b.3 < y1,
            "{}: {b:?}",
            v.name
        );
        boxes.push(b);
    }
    for i in 0..3 {
        for j in i + 1..3 {
            let (a, b) = (boxes[i], boxes[j]);
            assert!(
                a.2 <= b.0 || b.2 <= a.0,
                "views {i} and {j} overlap: {a:?} {b:?}"
            );
        }
    }
    // The front view of a torus in the xy plane is a ring: its centre is background.
    let c = layout.to_pixel(0, &Point3::origin());
    assert!(is_background(img.pixel(c[0] as u32, c[1] as u32)));
    // Without a colour bar the views take the full height.
    assert_eq!(layout.color_bar, None);
    Ok(())
}

/// An equilateral triangle and, beside it, a sliver (smallest angle about 9.5°), in the
/// plane z = 0, seen from the front.
fn triangle_and_sliver() -> Result<TriMesh, crate::mesh::MeshError> {
    let h = 3f64.sqrt() / 2.0;
    TriMesh::from_indices(
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.5, h, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(4.0, 0.0, 0.0),
            Point3::new(2.2, 0.3, 0.0),
        ],
        &[[0, 1, 2], [3, 4, 5]],
    )
}

fn centroid(m: &TriMesh, f: usize) -> Point3<f64> {
    let [a, b, c] = m.face_points(crate::FaceId::new(f));
    Point3::from((a.coords + b.coords + c.coords) / 3.0)
}

#[test]
fn a_sliver_is_magenta_where_it_is_drawn_and_a_good_face_is_not(
) -> Result<(), Box<dyn std::error::Error>> {
    let m = triangle_and_sliver()?;
    let metric = identity(&m);
    for color in [ColorBy::Q, ColorBy::MinAngle] {
        let sources = Sources {
            metric: Some(VertexMetric::OnMesh(&metric)),
            ..Default::default()
        };
        let colors = face_colors(&m, color, &sources)?;
        assert_eq!(colors.colors[1], MAGENTA);
        assert_ne!(colors.colors[0], MAGENTA);
        let (img, layout) = render(&m, &colors, &plain(900, 400))?;
        let at = |f: usize| {
            let p = layout.to_pixel(0, &centroid(&m, f));
            img.pixel(p[0] as u32, p[1] as u32)
        };
        assert!(is_magenta(at(1)), "{color:?}: sliver drawn {:?}", at(1));
        // q = 1 and 60°: the good end of the map, blue.
        let good = at(0);
        assert!(
            !is_magenta(good) && good[2] > good[0],
            "{color:?}: {good:?}"
        );
        let Legend::Scale { flagged, .. } = &colors.legend else {
            panic!("a scale legend");
        };
        assert_eq!(*flagged, Some(1));
    }
    Ok(())
}

#[test]
fn the_color_bar_shows_both_ends_of_the_map() -> Result<(), RenderError> {
    let m = generators::icosphere(1.0, 2);
    let colors = face_colors(&m, ColorBy::Q, &Sources::default())?;
    let (img, layout) = render(&m, &colors, &plain(600, 300))?;
    let (x0, y0, x1, y1) = layout.color_bar.expect("a colour bar");
    let y = (y0 + y1) / 2;
    // Inside the frame: the first and the last colour of the map.
    let near = |a: [u8; 3], b: [u8; 3]| (0..3).all(|k| a[k].abs_diff(b[k]) <= 8);
    assert!(near(img.pixel(x0 + 2, y), QUALITY_MAP[0]));
    assert!(near(
        img.pixel(x1 - 2, y),
        QUALITY_MAP[QUALITY_MAP.len() - 1]
    ));
    // Below the views.
    assert!(layout.views.iter().all(|v| v.rect.3 <= y0));
    // The legend's magenta swatch for the faces below 20°.
    assert!(count(&img, (x1, y0, img.width, y1), |c| c == MAGENTA) > 20);
    Ok(())
}

/// A 8×8 plate cut into four quadrant patches, the lower left one kept (no patch).
fn quadrant_patches(m: &TriMesh) -> Vec<Option<PatchId>> {
    m.faces()
        .map(|f| {
            let c = centroid(m, f.idx());
            match (c.x > 0.5, c.y > 0.5) {
                (false, false) => None,
                (true, false) => Some(PatchId(7)),
                (false, true) => Some(PatchId(2)),
                (true, true) => Some(PatchId(40)),
            }
        })
        .collect()
}

#[test]
fn neighbouring_patches_get_distinct_colours() -> Result<(), RenderError> {
    let m = generators::plate(1.0, 8);
    let p = quadrant_patches(&m);
    let sources = Sources {
        patches: Some(&p),
        ..Default::default()
    };
    let colors = face_colors(&m, ColorBy::Patch, &sources)?;
    assert_eq!(
        colors.legend,
        Legend::Patches {
            patches: 3,
            kept: 32
        }
    );
    let (img, layout) = render(&m, &colors, &plain(900, 400))?;
    let at = |x: f64, y: f64| {
        let q = layout.to_pixel(0, &Point3::new(x, y, 0.0));
        img.pixel(q[0] as u32, q[1] as u32)
    };
    // In each quadrant, inside a cell away from its edges and both diagonals (the wireframe).
    let drawn = [
        at(0.2825, 0.3125),
        at(0.6575, 0.3125),
        at(0.2825, 0.6875),
        at(0.6575, 0.6875),
    ];
    // Quadrants 1 and 2 meet at a vertex only: they are not neighbours.
    for (i, j) in [(0, 1), (0, 2), (0, 3), (1, 3), (2, 3)] {
        assert_ne!(drawn[i], drawn[j], "quadrants {i} and {j}");
    }
    // The kept quadrant is grey (shaded), the others palette colours.
    assert!(drawn[0][0] == drawn[0][1] && drawn[0][1] == drawn[0][2]);
    let wrong = face_colors(
        &m,
        ColorBy::Patch,
        &Sources {
            patches: Some(&p[1..]),
            ..Default::default()
        },
    );
    assert!(matches!(
        wrong,
        Err(RenderError::CountMismatch {
            found: 127,
            expected: 128,
            ..
        })
    ));
    Ok(())
}

#[test]
fn the_wireframe_is_drawn_for_few_faces_and_not_for_many() -> Result<(), RenderError> {
    let small = generators::icosphere(1.0, 1);
    let huge = generators::icosphere(1.0, 6);
    let opts = plain(450, 200);
    let mut wires = Vec::new();
    for m in [&small, &huge] {
        let colors = face_colors(m, ColorBy::None, &Sources::default())?;
        let (img, layout) = render(m, &colors, &opts)?;
        wires.push((
            layout.wireframe,
            count(&img, (0, 0, img.width, img.height), is_wire),
        ));
    }
    assert!(wires[0].0 && wires[0].1 > 500, "{wires:?}");
    assert_eq!(wires[1], (false, 0));
    // Forced on for the huge one, off for the small one.
    let colors = face_colors(&small, ColorBy::None, &Sources::default())?;
    let off = RenderOptions {
        wireframe: Wireframe::Off,
        ..opts.clone()
    };
    let (img, layout) = render(&small, &colors, &off)?;
    assert!(!layout.wireframe);
    assert_eq!(count(&img, (0, 0, img.width, img.height), is_wire), 0);
    Ok(())
}

#[test]
fn distance_is_zero_on_the_reference_and_grows_off_it() -> Result<(), RenderError> {
    let reference = generators::icosphere(1.0, 3);
    let mut moved = reference.clone();
    // One vertex pushed out by 10% of the radius.
    let out = moved.positions[0].coords * 0.1;
    moved.positions[0] += out;
    let sources = Sources {
        reference: Some(&reference),
        ..Default::default()
    };
    let same = face_colors(&reference, ColorBy::Distance, &sources)?;
    assert!(same.colors.iter().all(|&c| c == DISTANCE_MAP[0]));
    let off = face_colors(&moved, ColorBy::Distance, &sources)?;
    let Legend::Scale { max, .. } = off.legend else {
        panic!("a scale legend");
    };
    // 0.1 of the radius, in % of the reference's bounding-box diagonal.
    let expected = 100.0 * 0.1 * crate::metric::Normalization::of(&reference).scale;
    assert!(
        (max - expected).abs() < 0.01 * expected,
        "{max} vs {expected}"
    );
    let far = off
        .colors
        .iter()
        .filter(|&&c| c == DISTANCE_MAP[DISTANCE_MAP.len() - 1])
        .count();
    assert!(far >= 1);
    Ok(())
}

#[test]
fn the_same_input_gives_the_same_bytes() -> Result<(), RenderError> {
    let m = generators::bumpy_sphere(2);
    let opts = RenderOptions {
        width: 480,
        height: 240,
        ..Default::default()
    };
    let png = || -> Result<Vec<u8>, RenderError> {
        let c = face_colors(&m, ColorBy::Q, &Sources::default())?;
        render(&m, &c, &opts)?.0.png()
    };
    let a = png()?;
    assert_eq!(&a[1..4], b"PNG");
    assert_eq!(a, png()?);
    Ok(())
}

#[test]
fn bad_inputs_are_named_errors() -> Result<(), RenderError> {
    let m = generators::icosphere(1.0, 1);
    let plainc = face_colors(&m, ColorBy::None, &Sources::default())?;
    let empty = TriMesh {
        positions: m.positions.clone(),
        triangles: Vec::new(),
    };
    let r = render(
        &empty,
        &FaceColors {
            colors: vec![],
            legend: Legend::None,
        },
        &plain(300, 200),
    );
    assert!(matches!(r, Err(RenderError::EmptyMesh)));
    let mut nan = m.clone();
    nan.positions[5].y = f64::NAN;
    assert!(matches!(
        render(&nan, &plainc, &plain(300, 200)),
        Err(RenderError::NonFinite { vertex: 5 })
    ));
    for (w, h) in [(0, 200), (300, 10), (MAX_SIDE + 1, 200)] {
        assert!(matches!(
            render(&m, &plainc, &plain(w, h)),
            Err(RenderError::BadSize { .. })
        ));
    }
    // A metric with a negative eigenvalue at v3, and one tensor short.
    let mut metric = identity(&m);
    metric[3] = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
    let bad = face_colors(
        &m,
        ColorBy::Q,
        &Sources {
            metric: Some(VertexMetric::OnMesh(&metric)),
            ..Default::default()
        },
    );
    assert!(
        matches!(
            bad,
            Err(RenderError::Metric(crate::metric::MetricError::NotSpd {
                vertex: 3,
                ..
            }))
        ),
        "{bad:?}"
    );
    let short = face_colors(
        &m,
        ColorBy::MinAngle,
        &Sources {
            metric: Some(VertexMetric::OnMesh(&metric[1..])),
            ..Default::default()
        },
    );
    assert!(matches!(short, Err(RenderError::CountMismatch { .. })));
    for c in [ColorBy::Patch, ColorBy::Distance] {
        assert!(matches!(
            face_colors(&m, c, &Sources::default()),
            Err(RenderError::Missing { .. })
        ));
    }
    Ok(())
}

#[test]
fn color_names_round_trip() {
    for n in ColorBy::NAMES {
        assert_eq!(ColorBy::parse(n).map(ColorBy::name), Ok(n));
    }
    match ColorBy::parse("quality") {
        Err(OptionError::Unparsed {
            value, expected, ..
        }) => {
            assert_eq!(value, "quality");
            assert_eq!(expected, format!("one of {}", ColorBy::NAMES.join(", ")));
        }
        other => panic!("{other:?}"),
    }
}
