//! A sweep's report in a directory: `sweep.csv`, `sweep.md`, the plot `sweep.svg` (error
//! against time, log axes, one curve per parameter), every image as a PNG and a contact sheet
//! `contact.png` (one row of thumbnails per curve in table order, the reference last).

use super::{Param, Row, Sweep};
use crate::error::Error;
use crate::files::write_atomic;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Writes everything into `dir` (created if missing); returns the files written.
pub fn write(sweep: &Sweep, dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    let mut put = |name: &str, bytes: &[u8]| -> Result<(), Error> {
        let path = dir.join(name);
        write_atomic(&path, bytes)?;
        written.push(path);
        Ok(())
    };
    put("sweep.csv", csv(sweep).as_bytes())?;
    put("sweep.md", markdown(sweep).as_bytes())?;
    put("sweep.svg", plot(sweep)?.as_bytes())?;
    let (sheet, sw, sh) = contact_sheet(sweep);
    put("contact.png", &png_bytes(&sheet, sw, sh)?)?;
    for r in &sweep.rows {
        put(
            &image_name(r),
            &png_bytes(&r.rgb, sweep.width, sweep.height)?,
        )?;
    }
    put(
        "reference.png",
        &png_bytes(&sweep.reference_rgb, sweep.width, sweep.height)?,
    )?;
    Ok(written)
}

/// File name of a row's image: `samples-16.png`, `adaptive-0.05-3.png`.
pub fn image_name(r: &Row) -> String {
    let v: String = r
        .value
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect();
    format!("{}-{v}.png", r.param.name())
}

fn fmt_psnr(p: f64) -> String {
    if p.is_finite() {
        format!("{p:.2}")
    } else {
        "inf".into()
    }
}

fn fmt_ssim(s: Option<f64>) -> String {
    s.map_or("n/a".into(), |s| format!("{s:.4}"))
}

/// A row's cells; `digits`: decimals of the time, samples per pixel and RMSE.
fn cells(r: &Row, [time, spp, rmse]: [usize; 3]) -> [String; 8] {
    [
        r.param.name().to_string(),
        r.value.to_string(),
        format!("{:.time$}", r.time.as_secs_f64()),
        r.rays.to_string(),
        format!("{:.spp$}", r.samples_per_pixel),
        format!("{:.rmse$}", r.rmse),
        fmt_psnr(r.psnr),
        fmt_ssim(r.ssim),
    ]
}

pub fn csv(s: &Sweep) -> String {
    let mut out = String::from("parameter,value,time_s,rays,samples_per_pixel,rmse,psnr_db,ssim\n");
    for r in &s.rows {
        let _ = writeln!(out, "{}", cells(r, [6, 3, 6]).join(","));
    }
    out
}

pub fn markdown(s: &Sweep) -> String {
    let mut out = format!(
        "Reference: {}. Image {}x{}. Time: median render time of {} run(s) (scene build excluded). \
         Errors on the 8-bit sRGB images: RMSE on a 0..1 scale, PSNR in dB, SSIM of the luma.\n\n",
        s.reference, s.width, s.height, s.runs
    );
    out.push_str(
        "| parameter | value | time (s) | rays | samples/pixel | RMSE | PSNR (dB) | SSIM |\n",
    );
    out.push_str("|---|---|---:|---:|---:|---:|---:|---:|\n");
    for r in &s.rows {
        let _ = writeln!(out, "| {} |", cells(r, [3, 2, 5]).join(" | "));
    }
    out
}

const COLOURS: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];

/// The rows of each curve, in order (a parameter given twice makes two curves).
fn curves(s: &Sweep) -> Vec<(Param, Vec<&Row>)> {
    let mut out: Vec<(Param, Vec<&Row>)> = Vec::new();
    let mut prev: Option<Param> = None;
    for r in &s.rows {
        match out.last_mut() {
            Some((p, rows)) if prev == Some(r.param) && *p == r.param => rows.push(r),
            _ => out.push((r.param, vec![r])),
        }
        prev = Some(r.param);
    }
    out
}

/// RMSE against render time on log axes, one line per curve, each point labelled with its
/// value. SVG text needs no font files.
pub fn plot(s: &Sweep) -> Result<String, Error> {
    let err = |e: &dyn std::fmt::Display| Error::Render(format!("plot: {e}"));
    // Log axes need positive values: an exact match with the reference sits at the floor.
    let floor = 1e-5;
    let t = |r: &Row| r.time.as_secs_f64().max(1e-6);
    let e = |r: &Row| r.rmse.max(floor);
    let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for r in &s.rows {
        (t0, t1) = (t0.min(t(r)), t1.max(t(r)));
        (e0, e1) = (e0.min(e(r)), e1.max(e(r)));
    }
    let (t0, t1, e0, e1) = (t0 / 1.5, t1 * 1.5, e0 / 1.5, e1 * 1.5);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| err(&x))?;
        let mut chart = ChartBuilder::on(&root)
            .caption("Error against render time", ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d((t0..t1).log_scale(), (e0..e1).log_scale())
            .map_err(|x| err(&x))?;
        chart
            .configure_mesh()
            .x_desc("render time (s)")
            .y_desc("RMSE against the reference")
            .x_label_formatter(&|v| format!("{v:.3}"))
            .y_label_formatter(&|v| format!("{v:.4}"))
            .draw()
            .map_err(|x| err(&x))?;
        for (i, (param, rows)) in curves(s).into_iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            let points: Vec<(f64, f64)> = rows.iter().map(|r| (t(r), e(r))).collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(|x| err(&x))?
                .label(param.name())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(|x| err(&x))?;
            chart
                .draw_series(rows.iter().zip(&points).map(|(r, &p)| {
                    Text::new(
                        r.value.clone(),
                        p,
                        ("sans-serif", 13).into_font().color(&colour),
                    )
                }))
                .map_err(|x| err(&x))?;
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.9))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|x| err(&x))?;
        root.present().map_err(|x| err(&x))?;
    }
    Ok(svg)
}

/// Longest side of a contact-sheet thumbnail.
const THUMB: u32 = 160;
const GAP: u32 = 6;

/// Box-filters `rgb` (w x h) down by the whole factor `k`.
fn shrink(rgb: &[u8], w: u32, h: u32, k: u32) -> (Vec<u8>, u32, u32) {
    let (tw, th) = ((w / k).max(1), (h / k).max(1));
    let mut out = Vec::with_capacity((tw * th * 3) as usize);
    for y in 0..th {
        for x in 0..tw {
            for c in 0..3 {
                let mut sum = 0u32;
                let mut n = 0u32;
                for dy in 0..k.min(h) {
                    for dx in 0..k.min(w) {
                        let (sx, sy) = ((x * k + dx).min(w - 1), (y * k + dy).min(h - 1));
                        sum += rgb[((sy * w + sx) * 3 + c) as usize] as u32;
                        n += 1;
                    }
                }
                out.push(((sum + n / 2) / n) as u8);
            }
        }
    }
    (out, tw, th)
}

/// The contact sheet as (RGB, width, height): one row per curve in table order, then the
/// reference alone; white gaps.
pub fn contact_sheet(s: &Sweep) -> (Vec<u8>, u32, u32) {
    let k = s.width.max(s.height).div_ceil(THUMB).max(1);
    let (tw, th) = ((s.width / k).max(1), (s.height / k).max(1));
    let mut rows: Vec<Vec<&[u8]>> = curves(s)
        .into_iter()
        .map(|(_, rows)| rows.iter().map(|r| r.rgb.as_slice()).collect())
        .collect();
    rows.push(vec![s.reference_rgb.as_slice()]);
    let cols = rows.iter().map(Vec::len).max().unwrap_or(1) as u32;
    let (sw, sh) = (
        cols * tw + (cols + 1) * GAP,
        rows.len() as u32 * th + (rows.len() as u32 + 1) * GAP,
    );
    let mut sheet = vec![255u8; (sw * sh * 3) as usize];
    for (ri, row) in rows.iter().enumerate() {
        for (ci, img) in row.iter().enumerate() {
            let (t, _, _) = shrink(img, s.width, s.height, k);
            let (x0, y0) = (GAP + ci as u32 * (tw + GAP), GAP + ri as u32 * (th + GAP));
            for y in 0..th {
                let dst = (((y0 + y) * sw + x0) * 3) as usize;
                let src = (y * tw * 3) as usize;
                sheet[dst..dst + (tw * 3) as usize]
                    .copy_from_slice(&t[src..src + (tw * 3) as usize]);
            }
        }
    }
    (sheet, sw, sh)
}

/// PNG bytes of 8-bit RGB.
fn png_bytes(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, Error> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgb, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| Error::Render(format!("PNG encoding: {e}")))?;
    Ok(bytes)
}
