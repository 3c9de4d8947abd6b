//! `conemesh bench --suite scaling`: how the cost grows with the mesh. Generates the bumpy
//! sphere ([`conemesh::mesh::generators::bumpy_sphere`]) and a noisy, open scan-like surface
//! ([`conemesh::mesh::generators::noisy_scan`]) at icosphere levels 5 to 8 (20k to 1.3M
//! faces for the sphere) into the out dir, runs them as a folder (one `conemesh remesh`
//! process each, MMG beside it when found, `--threads` as for a folder), and adds to
//! `remesh.md` the fitted time exponent of each family (least squares of ln time on ln faces,
//! and between consecutive levels) with the peak memory.

use anyhow::Context;
use conemesh::mesh::generators::{bumpy_sphere, noisy_scan};
use conemesh::mesh::TriMesh;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The icosphere levels of the suite (`20·4^level` faces for the sphere).
const LEVELS: [u32; 4] = [5, 6, 7, 8];

/// The seed of the scan's noise (fixed: the inputs are the same in every run).
const SCAN_SEED: u64 = 7;

/// One family of generated inputs.
struct Family {
    name: &'static str,
    make: fn(u32) -> TriMesh,
}

const FAMILIES: [Family; 2] = [
    Family {
        name: "bumpy",
        make: bumpy_sphere,
    },
    Family {
        name: "scan",
        make: |level| noisy_scan(level, SCAN_SEED),
    },
];

/// The case name of a family at a level (`bumpy-l7`): the mesh's file stem.
fn case_name(family: &str, level: u32) -> String {
    format!("{family}-l{level}")
}

/// Write the cases whose name contains one of `filters` (all without any) into `dir` as
/// binary PLY; returns their paths, by family then level.
pub(super) fn write_cases(dir: &Path, filters: &[String]) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut paths = Vec::new();
    for family in &FAMILIES {
        for level in LEVELS {
            let name = case_name(family.name, level);
            if !filters.is_empty() && !filters.iter().any(|f| name.contains(f.as_str())) {
                continue;
            }
            let path = dir.join(format!("{name}.ply"));
            let mesh = (family.make)(level);
            let options = conemesh::io::WriteOptions {
                binary: true,
                ..Default::default()
            };
            conemesh::io::write_mesh_with(&path, &mesh, &Default::default(), &options)
                .with_context(|| format!("writing {}", path.display()))?;
            paths.push(path);
        }
    }
    anyhow::ensure!(
        !paths.is_empty(),
        "no scaling case matches {filters:?} (the cases are {})",
        FAMILIES
            .iter()
            .flat_map(|f| LEVELS.iter().map(|&l| case_name(f.name, l)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(paths)
}

/// One finished run of a case: its family, input faces, own time and peak memory.
pub(super) struct Point<'a> {
    pub name: &'a str,
    pub faces_in: f64,
    pub seconds: f64,
    pub peak_mb: Option<f64>,
}

/// The least-squares slope of `ln y` on `ln x` (`None` under two points).
pub(super) fn fitted_exponent(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let lx: Vec<f64> = points.iter().map(|p| p.0.ln()).collect();
    let ly: Vec<f64> = points.iter().map(|p| p.1.ln()).collect();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxx: f64 = lx.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The `## Scaling` section: per family, each level's faces, time, time per face and peak
/// memory, the exponent from the level before, and the fitted exponent over all levels.
pub(super) fn section(s: &mut String, points: &[Point<'_>]) {
    let _ = writeln!(s, "\n## Scaling\n");
    let _ = writeln!(
        s,
        "The run's own time (`remesh s`) against the input's faces, per family; the exponent k \
         of time ∝ faces^k between consecutive levels and fitted (least squares of ln time on \
         ln faces) over every level that finished.\n"
    );
    let _ = writeln!(
        s,
        "| family | case | F in | remesh s | µs per face | peak MiB | k from previous |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for family in &FAMILIES {
        let mine: Vec<&Point> = points
            .iter()
            .filter(|p| p.name.starts_with(&format!("{}-l", family.name)))
            .collect();
        if mine.is_empty() {
            continue;
        }
        for (i, p) in mine.iter().enumerate() {
            let k = match i {
                0 => "-".to_string(),
                _ => fitted_exponent(&[
                    (mine[i - 1].faces_in, mine[i - 1].seconds),
                    (p.faces_in, p.seconds),
                ])
                .map_or("-".to_string(), |k| format!("{k:.2}")),
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.2} | {:.1} | {} | {} |",
                family.name,
                p.name,
                p.faces_in,
                p.seconds,
                1e6 * p.seconds / p.faces_in,
                p.peak_mb.map_or("-".to_string(), |m| format!("{m:.0}")),
                k
            );
        }
        let fit: Vec<(f64, f64)> = mine.iter().map(|p| (p.faces_in, p.seconds)).collect();
        let _ = writeln!(
            s,
            "| {} | **fitted** | {:.0}–{:.0} | | | | **{}** |",
            family.name,
            fit.first().map_or(0.0, |p| p.0),
            fit.last().map_or(0.0, |p| p.0),
            fitted_exponent(&fit).map_or("-".to_string(), |k| format!("{k:.2}"))
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fitted_exponent_of_a_power_law_is_its_power() {
        let pts: Vec<(f64, f64)> = [2e4, 8e4, 3.2e5, 1.3e6]
            .iter()
            .map(|&x: &f64| (x, 3e-5 * x.powf(1.07)))
            .collect();
        let k = fitted_exponent(&pts).expect("four points");
        assert!((k - 1.07).abs() < 1e-9, "{k}");
        assert_eq!(fitted_exponent(&pts[..1]), None);
        assert_eq!(fitted_exponent(&[(1.0, 1.0), (1.0, 2.0)]), None);
    }

    #[test]
    fn cases_are_written_by_filter_and_named_by_family_and_level() {
        let dir = tempfile::tempdir().expect("temp dir");
        let paths = write_cases(dir.path(), &["-l5".to_string()]).expect("written");
        let names: Vec<String> = paths
            .iter()
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["bumpy-l5", "scan-l5"]);
        let bumpy = conemesh::io::read_mesh(&paths[0]).expect("readable").mesh;
        assert_eq!(bumpy.n_faces(), 20 * 4usize.pow(5));
        assert!(write_cases(dir.path(), &["nothing".to_string()]).is_err());
    }
}
