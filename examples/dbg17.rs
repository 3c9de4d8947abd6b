use conemesh::param::*;
use conemesh::pipeline::*;
use conemesh::remesh2d::*;
struct Wrap(Box<dyn PlanarRemesher>);
impl PlanarRemesher for Wrap {
    fn name(&self) -> &'static str {
        "wrap"
    }
    fn remesh(
        &self,
        d: &conemesh::mesh::PlanarDomain,
        m: &dyn Metric2d,
        l: f64,
        rng: &mut rand_chacha::ChaCha8Rng,
    ) -> Result<conemesh::mesh::PlanarMesh, Remesh2dError> {
        let r = self.0.remesh(d, m, l, rng);
        // metric edge stats of domain
        let mut s = 0.0;
        let mut n = 0;
        for t in &d.triangles {
            for k in 0..3 {
                let a = d.points[t[k] as usize];
                let b = d.points[t[(k + 1) % 3] as usize];
                let mm = m.metric(&nalgebra::Point2::from((a.coords + b.coords) * 0.5));
                let e = b - a;
                s += e.dot(&(mm * e)).sqrt();
                n += 1;
            }
        }
        if std::env::var("V").is_ok() {
            eprintln!(
                "domain {} tris {} pts, mean metric edge {:.3} (L {l}); out {:?}",
                d.triangles.len(),
                d.points.len(),
                s / n as f64,
                r.as_ref().map(|o| o.triangles.len())
            );
        }
        r
    }
}
struct WrapP(Box<dyn Parameterizer>);
impl Parameterizer for WrapP {
    fn name(&self) -> &'static str {
        "wrapp"
    }
    fn parameterize(
        &self,
        d: &conemesh::TriMesh,
        b: &[conemesh::VertexId],
    ) -> Result<Parameterization, ParamError> {
        let r = self.0.parameterize(d, b);
        if let Ok(dir) = std::env::var("DUMP") {
            static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
            let k = N.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let _ =
                conemesh::io::write_mesh(std::path::Path::new(&format!("{dir}/patch{k}.obj")), d);
        }
        if let Ok(p) = &r {
            if std::env::var("V").is_ok() {
                eprintln!("param {:?}", p.report);
            }
        }
        r
    }
}
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let mesh = conemesh::io::read_mesh(std::path::Path::new(&a[1]))
        .unwrap()
        .mesh;
    let met = conemesh::io::sol::read_sol(std::path::Path::new(&a[2]), mesh.n_vertices()).unwrap();
    let stages = Stages {
        remesher: Box::new(Wrap(Box::new(Lct::default()))),
        parameterizer: Box::new(WrapP(Box::new(SymmetricDirichlet::default()))),
        ..Stages::default()
    };
    let o = RemeshOptions {
        target: TargetLength::Absolute(1.0),
        edge_flips: std::env::var("NOFLIP").is_err(),
        relocate: std::env::var("NOMOVE").is_err(),
        ..Default::default()
    };
    let out = Remesher::new(o)
        .with_stages(stages)
        .run_with_metric(&mesh, &met)
        .unwrap();
    eprintln!("faces {}", out.mesh.n_faces());
    let e = conemesh::quality::evaluate(
        &out.input,
        &out.mesh,
        out.input_metric.as_deref(),
        &conemesh::quality::EvalOptions {
            target: TargetLength::Absolute(1.0),
            self_intersections: false,
            ..Default::default()
        },
    )
    .unwrap();
    println!("{}", e.table_row("x"));
}
