//! The comparison's folder: `compare.md` (the tables), `compare.json` (every run and
//! statistic), the plots (one strip plot per measure, the q and angle histograms of the
//! configurations overlaid) and `index.html`, a static page with every table, plot and
//! picture embedded (data URIs: it opens from anywhere, with no network).

use super::measures::{Measure, MEASURES};
use super::{CompareError, Comparison, Status, SummaryRow};
use crate::quality::QualityStats;
use std::fmt::Write as _;
use std::path::Path;

/// The file names of the plots [`write_plots`] writes, with their captions.
pub fn plot_files() -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = MEASURES
        .iter()
        .map(|m| {
            (
                format!("plot-{}.png", m.key),
                format!("{} per configuration", m.label),
            )
        })
        .collect();
    for (f, c) in [
        (
            "hist_q.png",
            "quality q, every output of each configuration",
        ),
        (
            "hist_angles.png",
            "angles, every output of each configuration",
        ),
        (
            "hist_min_angles.png",
            "smallest angles, every output of each configuration",
        ),
    ] {
        out.push((f.to_string(), c.to_string()));
    }
    out
}

/// Write the plots into `dir`: per measure a strip plot of every ok run per configuration,
/// and the histograms of q, of the angles and of the smallest angles of each configuration's
/// outputs together (summed over its runs), overlaid.
pub fn write_plots(dir: &Path, c: &Comparison) -> Result<(), CompareError> {
    for m in &MEASURES {
        let groups: Vec<(&str, Vec<f64>)> = c
            .configs
            .iter()
            .map(|cfg| {
                let xs = c
                    .runs
                    .iter()
                    .filter(|r| r.config == cfg.name)
                    .filter_map(|r| r.result.as_ref()?.measures.get(m.key).copied())
                    .collect();
                (cfg.name.as_str(), xs)
            })
            .collect();
        crate::report::write_strip_plot(
            &dir.join(format!("plot-{}.png", m.key)),
            &format!("{}: every run (dots), mean (bar)", m.label),
            m.label,
            &groups,
        )?;
    }
    let pooled: Vec<(String, QualityStats)> = c
        .configs
        .iter()
        .filter_map(|cfg| {
            let stats: Vec<&QualityStats> = c
                .runs
                .iter()
                .filter(|r| r.config == cfg.name)
                .filter_map(|r| r.result.as_ref().map(|res| &res.quality))
                .collect();
            Some((cfg.name.clone(), pool(&stats)?))
        })
        .collect();
    let series: Vec<(&str, &QualityStats)> = pooled.iter().map(|(n, s)| (n.as_str(), s)).collect();
    crate::report::write_quality_plots(dir, "all outputs", &series)?;
    Ok(())
}

/// Several outputs' statistics as one: histograms summed, averages weighted by faces,
/// extremes over all (`None` for none).
fn pool(stats: &[&QualityStats]) -> Option<QualityStats> {
    let first = *stats.first()?;
    let mut p = first.clone();
    let faces: usize = stats.iter().map(|s| s.faces).sum();
    let w = |f: &dyn Fn(&QualityStats) -> f64| {
        stats.iter().map(|s| f(s) * s.faces as f64).sum::<f64>() / faces.max(1) as f64
    };
    p.faces = faces;
    p.q_avg = w(&|s| s.q_avg);
    p.theta_avg = w(&|s| s.theta_avg);
    p.q_min = stats.iter().map(|s| s.q_min).fold(f64::INFINITY, f64::min);
    p.q_max = stats
        .iter()
        .map(|s| s.q_max)
        .fold(f64::NEG_INFINITY, f64::max);
    p.theta_min = stats
        .iter()
        .map(|s| s.theta_min)
        .fold(f64::INFINITY, f64::min);
    p.theta_max = stats
        .iter()
        .map(|s| s.theta_max)
        .fold(f64::NEG_INFINITY, f64::max);
    for s in &stats[1..] {
        for (a, b) in p.hist_q.iter_mut().zip(&s.hist_q) {
            *a += b;
        }
        for (a, b) in p.hist_angles.iter_mut().zip(&s.hist_angles) {
            *a += b;
        }
        for (a, b) in p.hist_min_angles.iter_mut().zip(&s.hist_min_angles) {
            *a += b;
        }
    }
    Some(p)
}

/// A p-value to three decimals, "< 0.001" below what three decimals show.
fn p_value(p: f64) -> String {
    match p < 0.0005 {
        true => "< 0.001".to_string(),
        false => format!("{p:.3}"),
    }
}

/// Each measure of a summary row as "mean ± sd" ("-" where no run gave it), in [`MEASURES`]'
/// order.
fn mean_sd_cells(row: &SummaryRow) -> Vec<String> {
    (MEASURES.iter())
        .map(|m| {
            row.measures.get(m.key).map_or("-".to_string(), |v| {
                format!("{} ± {}", fmt(m, v.mean), fmt(m, v.sd))
            })
        })
        .collect()
}

fn fmt(m: &Measure, x: f64) -> String {
    format!("{x:.*}", m.digits)
}

/// `compare.md`.
pub fn markdown(c: &Comparison) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# conemesh compare\n");
    let _ = writeln!(
        s,
        "conemesh {} ({}); seeds {}; every run `conemesh remesh INPUT --seed S ARGS`, one process each.\n",
        c.conemesh.version,
        c.conemesh.commit,
        c.seeds.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")
    );
    let _ = writeln!(s, "| configuration | ARGS |\n|---|---|");
    for cfg in &c.configs {
        let _ = writeln!(
            s,
            "| {} | `{}` |",
            cell(&cfg.name),
            cell(&cfg.args.join(" "))
        );
    }
    let _ = writeln!(
        s,
        "\n## Per input: mean ± sd over the seeds\n\nq and θ in the metric at the run's target (`eval`, Table 1); Hausdorff in % of the input's bounding-box diagonal; cert. retries: patch attempts that failed a certificate and were retried smaller; time s: the run's own; peak MiB: its process's peak resident memory. `ok` counts the runs the statistics are over.\n"
    );
    let mut head = "| input | configuration | ok |".to_string();
    let mut rule = "|---|---|---|".to_string();
    for m in &MEASURES {
        let _ = write!(head, " {} |", m.label);
        rule.push_str("---|");
    }
    let _ = writeln!(s, "{head}\n{rule}");
    for row in &c.summary {
        let mut line = format!(
            "| {} | {} | {}/{} |",
            cell(&row.mesh),
            cell(&row.config),
            row.ok,
            row.runs
        );
        for v in mean_sd_cells(row) {
            let _ = write!(line, " {v} |");
        }
        let _ = writeln!(s, "{line}");
    }
    if let Some(base) = c.configs.first().filter(|_| c.configs.len() > 1) {
        let _ = writeln!(
            s,
            "\n## Against `{}`, paired over (input, seed)\n\nmean difference (configuration − {0}) with its 95 % bootstrap interval (10000 resamples, seeded); sign test: exact two-sided binomial p of wins against losses (ties left out); W/T/L: pairs where the configuration is better / equal / worse (by the measure's direction: higher q and θ_min/θ_avg, lower θ_max, Hausdorff, flips, retries, faces, time, memory). **bold** = significant: p < 0.05 and the interval leaves 0 out.\n",
            base.name
        );
        let _ = writeln!(s, "| measure | configuration | pairs | mean diff | 95 % interval | sign p | W/T/L |\n|---|---|---|---|---|---|---|");
        for p in &c.paired {
            let Some(m) = super::measures::measure(&p.measure) else {
                continue;
            };
            let st = &p.stats;
            let digits = m.digits + 1;
            let (diff, ci) = match st.ci {
                Some((lo, hi)) => (
                    format!("{:+.*}", digits, st.mean_diff),
                    format!("[{lo:+.digits$}, {hi:+.digits$}]"),
                ),
                None => ("-".into(), "-".into()),
            };
            let (b0, b1) = if st.significant {
                ("**", "**")
            } else {
                ("", "")
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {b0}{diff}{b1} | {ci} | {b0}{}{b1} | {}/{}/{} |",
                m.label,
                cell(&p.config),
                st.n,
                p_value(st.p_sign),
                st.wins,
                st.ties,
                st.losses
            );
        }
    }
    let failed: Vec<_> = c.runs.iter().filter(|r| r.status != Status::Ok).collect();
    if !failed.is_empty() {
        let _ = writeln!(s, "\n## Runs that did not finish\n\n| input | configuration | seed | status | error |\n|---|---|---|---|---|");
        for r in failed {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                cell(&r.mesh),
                cell(&r.config),
                r.seed,
                r.status,
                cell(&r.error)
            );
        }
    }
    s
}

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `index.html`: the tables of [`markdown`], the plots and a picture of every output, images
/// read from `dir` and embedded. Its script writes, once the page has loaded, a summary of
/// the images (how many, loaded, blank) and tables into `#page-check` (what the browser
/// test reads).
pub fn html(c: &Comparison, dir: &Path) -> String {
    let mut s = String::new();
    s.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>conemesh compare</title>\n<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#eee}td:first-child,td:nth-child(2){text-align:left}.sig{font-weight:bold;color:#063}figure{display:inline-block;margin:4px}img{max-width:480px}figcaption{font-size:small}</style></head><body>\n");
    let _ = writeln!(
        s,
        "<h1>conemesh compare</h1><p>conemesh {} ({}); seeds {}</p>",
        esc(&c.conemesh.version),
        esc(&c.conemesh.commit),
        c.seeds
            .iter()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    );
    s.push_str("<table id=\"configs\"><tr><th>configuration</th><th>ARGS</th></tr>\n");
    for cfg in &c.configs {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td><code>{}</code></td></tr>",
            esc(&cfg.name),
            esc(&cfg.args.join(" "))
        );
    }
    s.push_str("</table>\n<h2>Per input: mean ± sd over the seeds</h2>\n<table id=\"summary\"><tr><th>input</th><th>configuration</th><th>ok</th>");
    for m in &MEASURES {
        let _ = write!(s, "<th>{}</th>", esc(m.label));
    }
    s.push_str("</tr>\n");
    for row in &c.summary {
        let _ = write!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}/{}</td>",
            esc(&row.mesh),
            esc(&row.config),
            row.ok,
            row.runs
        );
        for v in mean_sd_cells(row) {
            let _ = write!(s, "<td>{v}</td>");
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
    html_paired(&mut s, c);
    html_outputs(&mut s, c, dir);
    s.push_str("<pre id=\"page-check\">pending</pre>\n<script>\n");
    s.push_str(CHECK_SCRIPT);
    s.push_str("</script>\n</body></html>\n");
    s
}

/// The paired table of [`html`] (with more than one configuration).
fn html_paired(s: &mut String, c: &Comparison) {
    if c.configs.len() > 1 {
        let _ = writeln!(s, "<h2>Against <code>{}</code>, paired over (input, seed)</h2><p>Bold: sign-test p &lt; 0.05 and the 95 % bootstrap interval leaves 0 out.</p>", esc(&c.configs[0].name));
        s.push_str("<table id=\"paired\"><tr><th>measure</th><th>configuration</th><th>pairs</th><th>mean diff</th><th>95 % interval</th><th>sign p</th><th>W/T/L</th></tr>\n");
        for p in &c.paired {
            let Some(m) = super::measures::measure(&p.measure) else {
                continue;
            };
            let st = &p.stats;
            let d = m.digits + 1;
            let ci = st.ci.map_or("-".to_string(), |(lo, hi)| {
                format!("[{lo:+.d$}, {hi:+.d$}]")
            });
            let _ = writeln!(
                s,
                "<tr{}><td>{}</td><td>{}</td><td>{}</td><td>{:+.d$}</td><td>{ci}</td><td>{}</td><td>{}/{}/{}</td></tr>",
                if st.significant { " class=\"sig\"" } else { "" },
                esc(m.label),
                esc(&p.config),
                st.n,
                st.mean_diff,
                p_value(st.p_sign),
                st.wins,
                st.ties,
                st.losses
            );
        }
        s.push_str("</table>\n");
    }
}

/// The plots and the outputs' table with their pictures, for [`html`].
fn html_outputs(s: &mut String, c: &Comparison, dir: &Path) {
    s.push_str("<h2>Plots</h2>\n");
    for (file, caption) in plot_files() {
        figure(s, dir, &file, &caption, "plot");
    }
    s.push_str("<h2>Outputs</h2>\n<table id=\"runs\"><tr><th>input</th><th>configuration</th><th>seed</th><th>status</th><th>picture</th></tr>\n");
    for r in &c.runs {
        let _ = write!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}{}</td><td>",
            esc(&r.mesh),
            esc(&r.config),
            r.seed,
            r.status,
            if r.error.is_empty() {
                String::new()
            } else {
                format!(": {}", esc(&r.error))
            }
        );
        match &r.picture {
            Ok(file) => figure(s, dir, file, &r.files.output, "picture"),
            Err(why) => {
                let _ = write!(
                    s,
                    "<span class=\"no-picture\">{}</span>",
                    esc(&why.to_string())
                );
            }
        }
        s.push_str("</td></tr>\n");
    }
    s.push_str("</table>\n");
}

/// Counts the images, those loaded (`naturalWidth > 0`) and those of one colour (drawn into
/// a canvas: data URIs keep it readable), and the tables, into `#page-check` as JSON.
const CHECK_SCRIPT: &str = r#"window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.images);
  var loaded = 0, blank = 0, unread = 0;
  imgs.forEach(function (im) {
    if (!(im.complete && im.naturalWidth > 0)) return;
    loaded++;
    try {
      var c = document.createElement('canvas');
      c.width = im.naturalWidth; c.height = im.naturalHeight;
      var g = c.getContext('2d'); g.drawImage(im, 0, 0);
      var d = g.getImageData(0, 0, c.width, c.height).data, same = true;
      for (var i = 4; i < d.length; i += 4) {
        if (d[i] !== d[0] || d[i + 1] !== d[1] || d[i + 2] !== d[2]) { same = false; break; }
      }
      if (same) blank++;
    } catch (e) { unread++; }
  });
  var tables = {};
  Array.prototype.forEach.call(document.querySelectorAll('table[id]'), function (t) {
    tables[t.id] = t.rows.length - 1;
  });
  document.getElementById('page-check').textContent = 'PAGE-CHECK ' + JSON.stringify({
    images: imgs.length, loaded: loaded, blank: blank, unread: unread, tables: tables
  });
});
"#;

fn figure(s: &mut String, dir: &Path, file: &str, caption: &str, class: &str) {
    match std::fs::read(dir.join(file)) {
        Ok(bytes) => {
            let _ = writeln!(
                s,
                "<figure class=\"{class}\"><img alt=\"{}\" src=\"data:image/png;base64,{}\"><figcaption>{}</figcaption></figure>",
                esc(file),
                base64(&bytes),
                esc(caption)
            );
        }
        Err(e) => {
            let _ = writeln!(
                s,
                "<span class=\"no-picture\">{}: {}</span>",
                esc(file),
                esc(&e.to_string())
            );
        }
    }
}

/// Standard base64 with padding (RFC 4648), for the data URIs: a dozen lines, not a
/// dependency.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(A[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (a, b) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(super::base64(a.as_bytes()), b);
        }
    }

    #[test]
    fn p_values_below_three_decimals_are_not_printed_as_zero() {
        assert_eq!(super::p_value(2.0 / 2f64.powi(36)), "< 0.001");
        assert_eq!(super::p_value(0.0005), "0.001");
        assert_eq!(super::p_value(0.125), "0.125");
        assert_eq!(super::p_value(1.0), "1.000");
    }
}
