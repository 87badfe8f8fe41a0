//! The two backends: SVG text, and PNG drawn at twice its size and
//! box-filtered down.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::draw::*;
use super::figure::*;
use super::layout::*;
use super::theme::*;
use super::PlotError;
use crate::output::{commit_temp, temp_path, Pending};

// ---------------------------------------------------------------------------
// Backends and files

pub(super) fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

pub(super) fn render_svg(fig: &Figure, plan: &Plan) -> Result<String, String> {
    let size = ((W * SVG_SCALE) as u32, (H * SVG_SCALE) as u32);
    let mut svg = String::new();
    {
        let area = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        let cv = Canvas {
            scale: SVG_SCALE,
            kind: Kind::Svg,
        };
        draw_figure(&area, fig, plan, cv)?;
        area.present().map_err(de)?;
    }
    // Declare the nominal size; the viewBox keeps the finer coordinates.
    let from = format!("width=\"{}\" height=\"{}\"", size.0, size.1);
    let to = format!("width=\"{}\" height=\"{}\"", W as u32, H as u32);
    Ok(svg.replacen(&from, &to, 1))
}

/// The final PNG pixels (RGB, `PNG_W` × `PNG_H`), drawn supersampled.
pub(super) fn render_png_pixels(fig: &Figure, plan: &Plan) -> Result<Vec<u8>, String> {
    let (w, h) = (PNG_W * SUPERSAMPLE, PNG_H * SUPERSAMPLE);
    let mut big = vec![255u8; (w * h * 3) as usize];
    {
        let area = BitMapBackend::with_buffer(&mut big, (w, h)).into_drawing_area();
        let cv = Canvas {
            scale: f64::from(w) / W,
            kind: Kind::Bitmap,
        };
        draw_figure(&area, fig, plan, cv)?;
        area.present().map_err(de)?;
    }
    Ok(downsample(&big, w, h, SUPERSAMPLE))
}

/// Box filter: averages `k`×`k` blocks of an RGB image.
pub(super) fn downsample(src: &[u8], w: u32, h: u32, k: u32) -> Vec<u8> {
    let (w, h, k) = (w as usize, h as usize, k as usize);
    let (ow, oh) = (w / k, h / k);
    let n = (k * k) as u32;
    let mut out = vec![0u8; ow * oh * 3];
    for oy in 0..oh {
        for ox in 0..ow {
            for c in 0..3 {
                let mut sum = 0u32;
                for dy in 0..k {
                    let row = (oy * k + dy) * w;
                    for dx in 0..k {
                        sum += u32::from(src[(row + ox * k + dx) * 3 + c]);
                    }
                }
                out[(oy * ow + ox) * 3 + c] = ((sum + n / 2) / n) as u8;
            }
        }
    }
    out
}

/// Encodes `pixels` as PNG at `path`: written to a temporary sibling (whose
/// name ends in `.png`, as the encoder picks the format from it), synced, renamed.
pub(super) fn write_png(pixels: &[u8], path: &Path) -> Result<(), PlotError> {
    let tmp = with_suffix(&temp_path(path), ".png");
    let _pending = Pending::new(&tmp);
    let encoded = (|| {
        let mut backend = BitMapBackend::new(&tmp, (PNG_W, PNG_H));
        backend
            .blit_bitmap((0, 0), (PNG_W, PNG_H), pixels)
            .map_err(de)?;
        backend.present().map_err(de)
    })();
    let synced = encoded.and_then(|()| {
        std::fs::File::open(&tmp)
            .and_then(|f| f.sync_all())
            .map_err(de)
    });
    if let Err(reason) = synced {
        let _ = std::fs::remove_file(&tmp);
        return Err(PlotError::Render {
            path: path.to_path_buf(),
            reason,
        });
    }
    commit_temp(&tmp, path)?;
    Ok(())
}
