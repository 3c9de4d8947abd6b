//! Reports of the yardstick (Sec. 4.1): PNG histograms of q, of all angles θ and of each
//! triangle's smallest angle (the paper's hist(q), hist(θ) of Fig. 10-11), drawn with
//! plotters' bitmap backend. Several meshes (e.g. input and output) can share one plot; bars
//! are percentages so meshes with different face counts compare.
//!
//! Text needs a TrueType font. The first usable font found in the usual system folders is
//! registered once with plotters (its font table is process-global; registering the same
//! bytes twice is harmless). Without any font the plots are drawn without text rather than
//! failing.

use crate::quality::QualityStats;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use thiserror::Error;

/// Errors of writing reports.
#[derive(Debug, Error)]
pub enum ReportError {
    /// Operating-system error on a path.
    #[error("{path}: {source}")]
    Os {
        /// the file or folder
        path: String,
        /// the OS error
        source: std::io::Error,
    },
    /// plotters failed to draw or encode a plot.
    #[error("{path}: cannot draw plot: {source}")]
    Plot {
        /// the PNG file
        path: String,
        /// plotters' error
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// The [`ReportError::Plot`] of a plotters error while drawing `path`.
fn plot_error<E: std::error::Error + Send + Sync + 'static>(
    path: &Path,
) -> impl Fn(E) -> ReportError + '_ {
    move |e| ReportError::Plot {
        path: path.display().to_string(),
        source: Box::new(e),
    }
}

/// The font family name the plots use (registered by [`font_available`]).
const FAMILY: &str = FONT_FAMILY;

/// The font family name of the text in plots and pictures (registered by [`font_available`]).
pub(crate) const FONT_FAMILY: &str = "sans-serif";

/// Where TrueType fonts usually live (Debian/Ubuntu, Fedora/Arch, macOS, Windows).
const FONT_CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

fn find_font_file() -> Option<Vec<u8>> {
    for p in FONT_CANDIDATES {
        if let Ok(b) = std::fs::read(p) {
            return Some(b);
        }
    }
    // Any .ttf under the system font folder (sorted, so the choice is deterministic).
    let mut stack = vec![PathBuf::from("/usr/share/fonts")];
    let mut found = Vec::new();
    while let Some(dir) = stack.pop() {
        let Ok(rd) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("ttf")) {
                found.push(p);
            }
        }
    }
    found.sort();
    found.iter().find_map(|p| std::fs::read(p).ok())
}

/// Whether a font could be registered for plot text (looked up once per process).
pub fn font_available() -> bool {
    static FONT: OnceLock<bool> = OnceLock::new();
    *FONT.get_or_init(|| {
        let Some(bytes) = find_font_file() else {
            return false;
        };
        // plotters' ab_glyph table keeps `&'static` font bytes: the one font is leaked once.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font(FAMILY, FontStyle::Normal, bytes).is_ok()
    })
}

/// One histogram to plot: what is binned, the bin range and each series' counts.
struct Histogram<'a> {
    file: &'a str,
    title: String,
    x_desc: &'a str,
    y_desc: &'a str,
    x_max: f64,
    series: Vec<(&'a str, Vec<usize>)>,
}

const COLORS: [RGBColor; 4] = [
    RGBColor(150, 150, 150),
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

fn draw_histogram(path: &Path, h: &Histogram, text: bool) -> Result<(), ReportError> {
    let root = BitMapBackend::new(path, (960, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error(path))?;
    let n_bins = h.series.first().map_or(1, |s| s.1.len()).max(1);
    let bin_w = h.x_max / n_bins as f64;
    // Percentages of each series' own total.
    let pct: Vec<Vec<f64>> = h
        .series
        .iter()
        .map(|(_, c)| {
            let tot = c.iter().sum::<usize>().max(1) as f64;
            c.iter().map(|&x| 100.0 * x as f64 / tot).collect()
        })
        .collect();
    let y_max = pct.iter().flatten().copied().fold(1.0, f64::max) * 1.1;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if text {
        builder
            .caption(&h.title, (FAMILY, 26))
            .x_label_area_size(50)
            .y_label_area_size(70);
    } else {
        builder.x_label_area_size(8).y_label_area_size(8);
    }
    let mut chart = builder
        .build_cartesian_2d(0.0..h.x_max, 0.0..y_max)
        .map_err(plot_error(path))?;
    let x_fmt = |x: &f64| {
        if h.x_max <= 1.0 {
            format!("{x:.1}")
        } else {
            format!("{x:.0}°")
        }
    };
    let y_fmt = |y: &f64| format!("{y:.0}%");
    let mut mesh = chart.configure_mesh();
    mesh.disable_x_mesh();
    if text {
        mesh.x_labels(n_bins + 1)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .x_desc(h.x_desc)
            .y_desc(h.y_desc)
            .label_style((FAMILY, 16))
            .axis_desc_style((FAMILY, 18));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(plot_error(path))?;
    let k = h.series.len().max(1) as f64;
    for (si, ((label, _), p)) in h.series.iter().zip(&pct).enumerate() {
        let color = COLORS[si % COLORS.len()];
        // Series side by side inside each bin, with a small gap between bins.
        let w = 0.9 * bin_w / k;
        let bars = p.iter().enumerate().map(move |(i, &v)| {
            let x0 = i as f64 * bin_w + 0.05 * bin_w + si as f64 * w;
            Rectangle::new([(x0, 0.0), (x0 + w, v)], color.filled())
        });
        let drawn = chart.draw_series(bars).map_err(plot_error(path))?;
        if text {
            drawn.label(*label).legend(move |(x, y)| {
                Rectangle::new([(x, y - 6), (x + 14, y + 6)], color.filled())
            });
        }
    }
    if text && !h.series.is_empty() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FAMILY, 18))
            .draw()
            .map_err(plot_error(path))?;
    }
    root.present().map_err(plot_error(path))?;
    Ok(())
}

/// Write `hist_q.png`, `hist_angles.png` and `hist_min_angles.png` into `dir` (created if
/// missing): the histograms of q (10 bins on [0, 1]), of all angles and of each triangle's
/// smallest angle (18 bins of 10°) of every `(label, stats)` series, in % of the series'
/// faces (angles: % of its angles). `name` goes into the titles. Returns the written paths.
pub fn write_quality_plots(
    dir: &Path,
    name: &str,
    series: &[(&str, &QualityStats)],
) -> Result<Vec<PathBuf>, ReportError> {
    write_quality_plots_with(dir, name, series, font_available())
}

/// [`write_quality_plots`] with text switched on or off explicitly (off: bars and axes only,
/// for systems without a font).
pub fn write_quality_plots_with(
    dir: &Path,
    name: &str,
    series: &[(&str, &QualityStats)],
    text: bool,
) -> Result<Vec<PathBuf>, ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Os {
        path: dir.display().to_string(),
        source,
    })?;
    let summary = |f: &dyn Fn(&QualityStats) -> String| {
        series
            .iter()
            .map(|(l, s)| format!("{l} {}", f(s)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let hists = [
        Histogram {
            file: "hist_q.png",
            title: format!(
                "{name}: quality q  ({})",
                summary(&|s| format!("avg {:.3}, min {:.3}", s.q_avg, s.q_min))
            ),
            x_desc: "q = 2√3·area / (semi-perimeter · longest edge), in the metric",
            y_desc: "% of triangles",
            x_max: 1.0,
            series: series
                .iter()
                .map(|(l, s)| (*l, s.hist_q.to_vec()))
                .collect(),
        },
        Histogram {
            file: "hist_angles.png",
            title: format!(
                "{name}: all angles θ  ({})",
                summary(&|s| format!("min {:.1}°, max {:.1}°", s.theta_min, s.theta_max))
            ),
            x_desc: "angle in the metric (degrees)",
            y_desc: "% of all angles",
            x_max: 180.0,
            series: series
                .iter()
                .map(|(l, s)| (*l, s.hist_angles.to_vec()))
                .collect(),
        },
        Histogram {
            file: "hist_min_angles.png",
            title: format!(
                "{name}: smallest angle per triangle  ({})",
                summary(&|s| format!("avg {:.1}°", s.theta_avg))
            ),
            x_desc: "smallest angle in the metric (degrees)",
            y_desc: "% of triangles",
            // A triangle's smallest angle is at most 60° (an equilateral one counts in the
            // [60°, 70°) bin): only the first seven bins can be non-empty.
            x_max: 70.0,
            series: series
                .iter()
                .map(|(l, s)| (*l, s.hist_min_angles[..7].to_vec()))
                .collect(),
        },
    ];
    let mut out = Vec::new();
    for h in &hists {
        let p = dir.join(h.file);
        draw_histogram(&p, h, text)?;
        out.push(p);
    }
    Ok(out)
}

/// The smallest-angle histogram before and after Algorithm 2 (`hist_min_angles_improve.png`
/// in `dir`), each in % of its faces; `before` and `after` are 10° bins from 0°.
pub fn write_improvement_plot(
    dir: &Path,
    name: &str,
    before: &[usize],
    after: &[usize],
    theta_min: (f64, f64),
) -> Result<PathBuf, ReportError> {
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Os {
        path: dir.display().to_string(),
        source,
    })?;
    let bins = |h: &[usize]| h.iter().take(7).copied().collect::<Vec<_>>();
    let h = Histogram {
        file: "hist_min_angles_improve.png",
        title: format!(
            "{name}: smallest angle per triangle, Algorithm 2  (min {:.1}° → {:.1}°)",
            theta_min.0, theta_min.1
        ),
        x_desc: "smallest angle in the metric (degrees)",
        y_desc: "% of triangles",
        x_max: 70.0,
        series: vec![("before", bins(before)), ("after", bins(after))],
    };
    let p = dir.join(h.file);
    draw_histogram(&p, &h, font_available())?;
    Ok(p)
}

/// Write a strip plot to `path` (PNG): one column per `(label, values)` group, each value a
/// dot (spread sideways by its index, so equal values stay visible) and the group's mean a
/// bar; `title` above, `y_desc` on the vertical axis. Used by `conemesh compare` (one plot
/// per measure, one column per configuration).
pub fn write_strip_plot(
    path: &Path,
    title: &str,
    y_desc: &str,
    groups: &[(&str, Vec<f64>)],
) -> Result<(), ReportError> {
    let text = font_available();
    let all: Vec<f64> = groups
        .iter()
        .flat_map(|g| g.1.iter().copied())
        .filter(|v| v.is_finite())
        .collect();
    let (lo, hi) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let (lo, hi) = if all.is_empty() {
        (0.0, 1.0)
    } else {
        // A margin of a tenth of the range (or of the value when all are equal).
        let pad = ((hi - lo).max(hi.abs().max(1e-9) * 0.01)) * 0.1;
        (lo - pad, hi + pad)
    };
    let root = BitMapBackend::new(path, (720, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error(path))?;
    let n = groups.len().max(1);
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if text {
        builder
            .caption(title, (FAMILY, 22))
            .x_label_area_size(40)
            .y_label_area_size(80);
    } else {
        builder.x_label_area_size(8).y_label_area_size(8);
    }
    let mut chart = builder
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), lo..hi)
        .map_err(plot_error(path))?;
    let label = |x: &f64| {
        let i = x.round();
        if (x - i).abs() < 1e-6 && i >= 0.0 {
            groups
                .get(i as usize)
                .map_or(String::new(), |g| g.0.to_string())
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.disable_x_mesh();
    if text {
        mesh.x_labels(n)
            .x_label_formatter(&label)
            .y_desc(y_desc)
            .label_style((FAMILY, 16))
            .axis_desc_style((FAMILY, 18));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(plot_error(path))?;
    for (gi, (_, values)) in groups.iter().enumerate() {
        let color = COLORS[(gi + 1) % COLORS.len()];
        let k = values.len().max(1) as f64;
        let dots = values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .map(move |(i, &v)| {
                let x = gi as f64 + 0.3 * ((i as f64 + 0.5) / k - 0.5);
                Circle::new((x, v), 5, color.filled())
            });
        chart.draw_series(dots).map_err(plot_error(path))?;
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        if !finite.is_empty() {
            let mean = finite.iter().sum::<f64>() / finite.len() as f64;
            let x0 = gi as f64 - 0.25;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x0, mean), (x0 + 0.5, mean)],
                    BLACK.stroke_width(2),
                )))
                .map_err(plot_error(path))?;
        }
    }
    root.present().map_err(plot_error(path))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generators;
    use crate::quality::quality_stats;
    use nalgebra::Matrix3;

    #[test]
    fn plots_are_written_with_and_without_text() -> Result<(), ReportError> {
        let m = generators::perturb(
            &generators::torus(1.0, 0.3, 24, 12),
            0.02,
            &mut <crate::Rng as rand::SeedableRng>::seed_from_u64(3),
        );
        let s = quality_stats(&m, &vec![Matrix3::identity(); m.n_vertices()]);
        let s2 = quality_stats(
            &m,
            &vec![Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 3.0, 1.0)); m.n_vertices()],
        );
        let dir = tempfile::tempdir().map_err(|source| ReportError::Os {
            path: "tmp".into(),
            source,
        })?;
        for text in [true, false] {
            let sub = dir.path().join(if text { "text" } else { "plain" });
            let files = write_quality_plots_with(
                &sub,
                "torus",
                &[("identity", &s), ("stretched", &s2)],
                text && font_available(),
            )?;
            assert_eq!(files.len(), 3);
            for f in files {
                let bytes = std::fs::read(&f).map_err(|source| ReportError::Os {
                    path: f.display().to_string(),
                    source,
                })?;
                assert_eq!(&bytes[1..4], b"PNG", "{}", f.display());
                assert!(bytes.len() > 2000, "{} is suspiciously small", f.display());
            }
        }
        Ok(())
    }
}
