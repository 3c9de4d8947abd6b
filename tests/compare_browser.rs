//! `conemesh compare`'s index.html in a real browser (headless Chromium, `--dump-dom`): every
//! image loads and is not of one colour, and the tables are there. The page's own script
//! writes what it found into `#page-check`; a copy of the page with one blank and one broken
//! image shows the check can fail. Skips, saying why, when no browser is installed, unless
//! CONEMESH_REQUIRE_BROWSER is set (`scripts/test` installs one and sets it).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The browser: `$CONEMESH_BROWSER`, else the first of Debian's headless shell, Chromium or
/// Chrome on PATH.
fn browser() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("CONEMESH_BROWSER").filter(|p| !p.is_empty()) {
        return Some(PathBuf::from(p));
    }
    let names = [
        "chromium-headless-shell",
        "chromium",
        "chromium-browser",
        "google-chrome",
        "chrome-headless-shell",
    ];
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|d| names.iter().map(move |n| d.join(n)))
        .find(|p| p.is_file())
}

/// `#page-check`'s JSON after the page loaded in `browser`.
fn page_check(browser: &Path, page: &Path) -> serde_json::Value {
    let profile = tempfile::tempdir().expect("tempdir");
    let o = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg("--dump-dom")
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("run the browser");
    let dom = String::from_utf8_lossy(&o.stdout);
    let marker = "id=\"page-check\">PAGE-CHECK ";
    let at = dom.find(marker).unwrap_or_else(|| {
        panic!(
            "the page's check did not run ({:?}); stderr:\n{}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
        )
    });
    let rest = &dom[at + marker.len()..];
    let end = rest.find("</pre>").expect("end of the check");
    serde_json::from_str(&rest[..end]).expect("the check is JSON")
}

#[test]
fn index_html_loads_every_image_and_table_in_a_browser() {
    let Some(browser) = browser() else {
        assert!(
            std::env::var_os("CONEMESH_REQUIRE_BROWSER").is_none(),
            "CONEMESH_REQUIRE_BROWSER is set but no browser was found (chromium-headless-shell, chromium or $CONEMESH_BROWSER)"
        );
        eprintln!(
            "SKIPPED: no browser (chromium-headless-shell, chromium or $CONEMESH_BROWSER); `scripts/test` installs one"
        );
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = dir.path().join("torus.off");
    conemesh::io::write_mesh(&mesh, &conemesh::mesh::generators::torus(1.0, 0.35, 24, 10))
        .expect("write");
    let out = dir.path().join("cmp");
    let o = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .arg("compare")
        .arg(&mesh)
        .args(["-c", "base=", "-c", "kring=--strategy kring", "-q", "-o"])
        .arg(&out)
        .output()
        .expect("run compare");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let page = out.join("index.html");
    let c = page_check(&browser, &page);
    let images = c["images"].as_u64().expect("images");
    // A strip plot per measure and three histograms at least; a picture per output once
    // `conemesh render` is there.
    assert!(images >= 15, "{c}");
    assert_eq!(
        c["loaded"].as_u64(),
        Some(images),
        "every image loaded: {c}"
    );
    assert_eq!(c["blank"], 0, "no image of one colour: {c}");
    assert_eq!(c["unread"], 0, "every image could be read back: {c}");
    assert_eq!(c["tables"]["summary"], 2, "{c}");
    assert_eq!(c["tables"]["runs"], 2, "{c}");
    assert!(c["tables"]["paired"].as_u64() > Some(0), "{c}");

    // The same check sees a blank and a broken image.
    let html = std::fs::read_to_string(&page).expect("page");
    let white = "iVBORw0KGgoAAAANSUhEUgAAAAQAAAAECAIAAAAmkwkpAAAAD0lEQVR4nGP4jwQYiOMAANuQL9FuRbCyAAAAAElFTkSuQmCC";
    let bad = html.replacen(
        "<pre id=\"page-check\">",
        &format!(
            "<img src=\"data:image/png;base64,{white}\"><img src=\"data:image/png;base64,AAAA\"><pre id=\"page-check\">"
        ),
        1,
    );
    let bad_page = out.join("bad.html");
    std::fs::write(&bad_page, bad).expect("write");
    let c = page_check(&browser, &bad_page);
    assert_eq!(c["images"].as_u64(), Some(images + 2), "{c}");
    assert_eq!(
        c["loaded"].as_u64(),
        Some(images + 1),
        "the broken one: {c}"
    );
    assert_eq!(c["blank"], 1, "the white one: {c}");
}
