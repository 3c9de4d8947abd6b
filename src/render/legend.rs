//! The colour bar under the views, and the text of the picture (drawn with plotters on the
//! picture's buffer, in the font of [`crate::report`]).

use super::colors::{map_color, Legend, FLAG_ANGLE, KEPT_GREY, PATCH_PALETTE};
use super::raster::View;
use super::{Image, RenderError, MAGENTA};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Height of the colour bar's strip, in pixels.
pub fn bar_height(height: u32, legend: &Legend) -> u32 {
    match legend {
        Legend::None => 0,
        _ => (height / 8).clamp(30, 76),
    }
}

/// The text size of the colour bar's labels, in pixels.
fn text_size(bar_h: u32) -> u32 {
    (bar_h / 5).clamp(10, 14)
}

/// A filled rectangle, half-open, clipped to the picture.
fn fill(img: &mut Image, (x0, y0, x1, y1): (u32, u32, u32, u32), c: [u8; 3]) {
    for y in y0..y1.min(img.height) {
        for x in x0..x1.min(img.width) {
            img.set(x, y, c);
        }
    }
}

/// A one-pixel black frame around a rectangle.
fn frame(img: &mut Image, (x0, y0, x1, y1): (u32, u32, u32, u32)) {
    let k = [0, 0, 0];
    fill(img, (x0, y0, x1, y0 + 1), k);
    fill(img, (x0, y1 - 1, x1, y1), k);
    fill(img, (x0, y0, x0 + 1, y1), k);
    fill(img, (x1 - 1, y0, x1, y1), k);
}

/// Texts to draw: (text, x, y, horizontal anchor).
type Texts = Vec<(String, i32, i32, HPos)>;

/// Draw the colour bar for `legend` in the bottom `bar_h` rows; returns its rectangle.
pub fn draw(
    img: &mut Image,
    legend: &Legend,
    bar_h: u32,
    text: bool,
) -> Result<Option<(u32, u32, u32, u32)>, RenderError> {
    if bar_h == 0 {
        return Ok(None);
    }
    let (w, h) = (img.width, img.height);
    let y0 = h - bar_h + 4;
    let y1 = y0 + (bar_h / 4).max(8);
    let (x0, x1) = (w / 5, w * 3 / 5);
    let mut texts: Texts = Vec::new();
    let label_y = y1 as i32 + 2;
    match legend {
        Legend::None => return Ok(None),
        Legend::Scale {
            title,
            min,
            max,
            decimals,
            stops,
            flagged,
        } => {
            for x in x0..x1 {
                let t = f64::from(x - x0) / f64::from((x1 - x0 - 1).max(1));
                fill(img, (x, y0, x + 1, y1), map_color(stops, t));
            }
            frame(img, (x0, y0, x1, y1));
            for k in 0..=4 {
                let t = f64::from(k) / 4.0;
                let x = x0 + ((x1 - x0 - 1) as f64 * t) as u32;
                fill(img, (x, y1, x + 1, y1 + 4), [0, 0, 0]);
                let v = min + t * (max - min);
                texts.push((
                    format!("{v:.decimals$}"),
                    x as i32,
                    label_y + 3,
                    HPos::Center,
                ));
            }
            let size = text_size(bar_h) as i32;
            texts.push((
                title.clone(),
                ((x0 + x1) / 2) as i32,
                label_y + size + 6,
                HPos::Center,
            ));
            if let Some(n) = flagged {
                let sx = x1 + 24;
                fill(img, (sx, y0, sx + (y1 - y0), y1), MAGENTA);
                frame(img, (sx, y0, sx + (y1 - y0), y1));
                texts.push((
                    format!("smallest angle < {FLAG_ANGLE}°: {n} faces"),
                    (sx + (y1 - y0) + 6) as i32,
                    y0 as i32,
                    HPos::Left,
                ));
            }
        }
        Legend::Patches { patches, kept } => {
            let n = PATCH_PALETTE.len() as u32 + 1;
            let cell = (x1 - x0) / n;
            for (i, c) in PATCH_PALETTE.iter().chain([&KEPT_GREY]).enumerate() {
                let cx = x0 + i as u32 * cell;
                fill(img, (cx, y0, cx + cell, y1), *c);
            }
            frame(img, (x0, y0, x0 + n * cell, y1));
            texts.push((
                format!("{patches} patches, neighbours in different colours; grey: {kept} faces of no patch"),
                ((x0 + x1) / 2) as i32,
                label_y + 3,
                HPos::Center,
            ));
        }
    }
    if text {
        draw_texts(img, &texts, text_size(bar_h))?;
    }
    Ok(Some((x0, y0, x1, y1)))
}

/// The view names at the top left of each view.
pub fn label_views(img: &mut Image, views: &[View]) -> Result<(), RenderError> {
    let texts: Texts = views
        .iter()
        .map(|v| {
            (
                v.name.to_string(),
                v.rect.0 as i32 + 8,
                v.rect.1 as i32 + 4,
                HPos::Left,
            )
        })
        .collect();
    draw_texts(img, &texts, 16)
}

fn draw_texts(img: &mut Image, texts: &Texts, size: u32) -> Result<(), RenderError> {
    let err = |e: DrawingAreaErrorKind<_>| RenderError::Text(Box::new(e));
    let (w, h) = (img.width, img.height);
    let root = BitMapBackend::with_buffer(&mut img.rgb, (w, h)).into_drawing_area();
    for (s, x, y, hpos) in texts {
        let style = TextStyle::from((crate::report::FONT_FAMILY, size).into_font())
            .color(&BLACK)
            .pos(Pos::new(*hpos, VPos::Top));
        root.draw(&Text::new(s.clone(), (*x, *y), style))
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}
