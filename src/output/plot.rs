//! PNG line plots drawn by seam itself, for a quick look at a run without ParaView:
//! residual histories (with `log_y`), temperatures along a line, heat per step.
//!
//! Entry point: [`Plot::write_png`]. The image is 960×640 RGB: a title, a framed plot
//! area with light grid lines at the ticks, tick labels, axis labels (the y label turned
//! upright) and, when any series has a label, a legend in the inside corner that hides
//! the least of the lines (upper right on a tie). Text uses
//! seam's own 5×7 font drawn at twice its size. Series get the colours of
//! [`series_colour`] in order and are drawn as 2-pixel lines between consecutive
//! drawable points; a point with no drawable neighbour gets a square marker.
//!
//! Ranges: x spans the drawable points, y extends to the nearest ticks outside the data
//! (decades with `log_y`); then a margin of 2 % (x) and 4 % (y) keeps lines off the frame.
//! Non-finite points are skipped, and with `log_y` so are points with `y ≤ 0`; a range
//! of one value is widened by ±1 (±10 % of the value when that is larger), or by half
//! a decade on a log axis.

use std::io;
use std::path::Path;

use super::font;

/// One line of a plot.
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// A line plot of one or more series.
#[derive(Clone, Debug, Default)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_y: bool,
    pub series: Vec<Series>,
}

/// Image width and height in pixels.
pub const WIDTH: usize = 960;
pub const HEIGHT: usize = 640;
/// Text is drawn at this many pixels per font pixel.
const SCALE: usize = 2;
const LINE_HEIGHT: usize = (font::HEIGHT + 1) * SCALE;

const WHITE: [u8; 3] = [255, 255, 255];
const BLACK: [u8; 3] = [0, 0, 0];
const GRID: [u8; 3] = [225, 225, 225];

/// Colour of series `k` (cycling after eight): saturated hues that stay apart for
/// readers with red-green colour blindness (the Okabe–Ito palette), none grey.
pub fn series_colour(k: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [0, 114, 178],
        [213, 94, 0],
        [0, 158, 115],
        [204, 121, 167],
        [230, 159, 0],
        [86, 180, 233],
        [160, 40, 40],
        [120, 60, 160],
    ];
    PALETTE[k % PALETTE.len()]
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// One axis: data range and tick positions with their labels.
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: Vec<(f64, String)>,
}

impl Axis {
    /// Widen the range by `f` of its extent at each end (in log space for a log axis).
    fn widen(&mut self, f: f64) {
        if self.log {
            let (a, b) = (self.lo.log10(), self.hi.log10());
            self.lo = 10f64.powf(a - f * (b - a));
            self.hi = 10f64.powf(b + f * (b - a));
        } else {
            let d = f * (self.hi - self.lo);
            self.lo -= d;
            self.hi += d;
        }
    }

    /// Fraction 0..1 of the way from `lo` to `hi` (in log space for a log axis).
    fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

/// A step of 1, 2 or 5 × 10^k giving about `target` intervals over `range`.
fn nice_step(range: f64, target: f64) -> f64 {
    let raw = range / target;
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let m = if norm < 1.5 {
        1.0
    } else if norm < 3.0 {
        2.0
    } else if norm < 7.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

/// A tick label for `v` on an axis with tick spacing `step`: fixed notation with just
/// enough decimals, scientific for very large or small magnitudes.
fn tick_label(v: f64, step: f64, largest: f64) -> String {
    if v.abs() < step * 1e-6 {
        return "0".to_string();
    }
    let step_exp = step.log10().floor() as i32;
    if !(1e-3..1e5).contains(&largest) {
        let exp = v.abs().log10().floor() as i32;
        let digits = (exp - step_exp).clamp(0, 6) as usize;
        format!("{v:.digits$e}")
    } else {
        let decimals = (-step_exp).max(0) as usize;
        format!("{v:.decimals$}")
    }
}

/// A linear axis over `[lo, hi]`; `pad` extends it to the ticks outside the data.
fn linear_axis(lo: f64, hi: f64, pad: bool) -> Axis {
    let (lo, hi) = if lo == hi {
        let w = (lo.abs() * 0.1).max(1.0);
        (lo - w, hi + w)
    } else {
        (lo, hi)
    };
    let step = nice_step(hi - lo, 6.0);
    let (lo, hi) = if pad {
        ((lo / step).floor() * step, (hi / step).ceil() * step)
    } else {
        (lo, hi)
    };
    let largest = lo.abs().max(hi.abs());
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    let ticks = (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            (v, tick_label(v, step, largest))
        })
        .collect();
    Axis {
        lo,
        hi,
        log: false,
        ticks,
    }
}

/// A log axis over `[lo, hi]` (both positive), extended to whole decades.
fn log_axis(lo: f64, hi: f64) -> Axis {
    let (mut a, mut b) = (lo.log10().floor(), hi.log10().ceil());
    if a == b {
        a -= 0.5;
        b += 0.5;
    }
    let (first, last) = (a.ceil() as i32, b.floor() as i32);
    // At most about eight labelled decades.
    let every = ((last - first) / 8 + 1).max(1);
    let ticks = (first..=last)
        .filter(|k| (k - first) % every == 0)
        .map(|k| {
            let label = match k {
                0 => "1".to_string(),
                1 => "10".to_string(),
                _ => format!("1e{k}"),
            };
            (10f64.powi(k), label)
        })
        .collect();
    Axis {
        lo: 10f64.powf(a),
        hi: 10f64.powf(b),
        log: true,
        ticks,
    }
}

/// An RGB image with the drawing operations a plot needs.
struct Canvas {
    px: Vec<u8>,
}

impl Canvas {
    fn new() -> Self {
        Canvas {
            px: WHITE.repeat(WIDTH * HEIGHT),
        }
    }

    fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if (0..WIDTH as i64).contains(&x) && (0..HEIGHT as i64).contains(&y) {
            let i = 3 * (y as usize * WIDTH + x as usize);
            self.px[i..i + 3].copy_from_slice(&c);
        }
    }

    /// Pixels in the rectangle whose colour is none of `background`.
    fn count_not(&self, x0: i64, y0: i64, x1: i64, y1: i64, background: &[[u8; 3]]) -> usize {
        let mut n = 0;
        for y in y0.max(0)..=y1.min(HEIGHT as i64 - 1) {
            for x in x0.max(0)..=x1.min(WIDTH as i64 - 1) {
                let i = 3 * (y as usize * WIDTH + x as usize);
                if !background.iter().any(|b| self.px[i..i + 3] == *b) {
                    n += 1;
                }
            }
        }
        n
    }

    fn rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: [u8; 3]) {
        for y in y0..=y1 {
            for x in x0..=x1 {
                self.set(x, y, c);
            }
        }
    }

    /// A line of width 2 from `a` to `b` (Bresenham, with a 2×2 pen), kept inside `clip`.
    fn line(&mut self, a: (i64, i64), b: (i64, i64), c: [u8; 3], clip: [i64; 4]) {
        let (mut x, mut y) = a;
        let (dx, dy) = ((b.0 - x).abs(), -(b.1 - y).abs());
        let (sx, sy) = (if x < b.0 { 1 } else { -1 }, if y < b.1 { 1 } else { -1 });
        let mut err = dx + dy;
        loop {
            for (px, py) in [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)] {
                if (clip[0]..=clip[2]).contains(&px) && (clip[1]..=clip[3]).contains(&py) {
                    self.set(px, py, c);
                }
            }
            if (x, y) == b {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// `text` with its top-left corner at `(x, y)`; `upright` turns it to read upwards,
    /// starting at `(x, y)` as its bottom-left corner.
    fn text(&mut self, x: i64, y: i64, text: &str, c: [u8; 3], upright: bool) {
        for (k, ch) in text.chars().enumerate() {
            let base = (k * font::ADVANCE * SCALE) as i64;
            for (r, row) in font::glyph(ch).iter().enumerate() {
                for (col, bit) in row.bytes().enumerate() {
                    if bit != b'#' {
                        continue;
                    }
                    let (gx, gy) = (base + (col * SCALE) as i64, (r * SCALE) as i64);
                    let (px, py) = if upright {
                        (x + gy, y - gx - SCALE as i64 + 1)
                    } else {
                        (x + gx, y + gy)
                    };
                    self.rect(px, py, px + SCALE as i64 - 1, py + SCALE as i64 - 1, c);
                }
            }
        }
    }
}

fn text_px(text: &str) -> i64 {
    (font::text_width(text) * SCALE) as i64
}

impl Plot {
    /// Draw the plot and write it to `path` as a PNG. Errors (`InvalidInput`) when there
    /// is no series, a series has no points, or no point at all can be drawn.
    pub fn write_png(&self, path: &Path) -> io::Result<()> {
        let rgb = self.render()?;
        let file = std::fs::File::create(path)?;
        let mut enc = png::Encoder::new(io::BufWriter::new(file), WIDTH as u32, HEIGHT as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(io::Error::other)?;
        w.write_image_data(&rgb).map_err(io::Error::other)?;
        w.finish().map_err(io::Error::other)
    }

    fn drawable(&self, p: (f64, f64)) -> bool {
        p.0.is_finite() && p.1.is_finite() && (!self.log_y || p.1 > 0.0)
    }

    /// The image as RGB bytes, row by row.
    fn render(&self) -> io::Result<Vec<u8>> {
        let what = if self.title.is_empty() {
            "the plot".to_string()
        } else {
            format!("plot `{}`", self.title)
        };
        if self.series.is_empty() {
            return Err(invalid(format!(
                "{what} has no series; give at least one series with points"
            )));
        }
        for (k, s) in self.series.iter().enumerate() {
            if s.points.is_empty() {
                return Err(invalid(format!(
                    "series {} (`{}`) of {what} has no points; leave it out or give it points",
                    k + 1,
                    s.label
                )));
            }
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in self.series.iter().flat_map(|s| &s.points) {
            if self.drawable(*p) {
                lo = [lo[0].min(p.0), lo[1].min(p.1)];
                hi = [hi[0].max(p.0), hi[1].max(p.1)];
            }
        }
        if lo[0] > hi[0] {
            let why = if self.log_y {
                "finite points with y > 0 (the y axis is logarithmic)"
            } else {
                "finite points"
            };
            return Err(invalid(format!("{what} has no {why} to draw")));
        }
        let mut xa = linear_axis(lo[0], hi[0], false);
        let mut ya = if self.log_y {
            log_axis(lo[1], hi[1])
        } else {
            linear_axis(lo[1], hi[1], true)
        };
        // Margins keep lines at the ends of the range off the frame.
        xa.widen(0.02);
        ya.widen(0.04);

        // Frame: left margin fits the y label and the widest y tick label.
        let widest = ya.ticks.iter().map(|(_, l)| text_px(l)).max().unwrap_or(0);
        let left = 16 + LINE_HEIGHT as i64 + 12 + widest + 10;
        let top = 16 + 2 * LINE_HEIGHT as i64;
        let right = WIDTH as i64 - 30;
        let bottom = HEIGHT as i64 - (16 + 2 * LINE_HEIGHT as i64 + 20);
        let to_px = |x: f64, y: f64| {
            let px = left as f64 + xa.frac(x) * (right - left) as f64;
            let py = bottom as f64 - ya.frac(y) * (bottom - top) as f64;
            (px.round() as i64, py.round() as i64)
        };

        let mut c = Canvas::new();
        for (v, label) in &xa.ticks {
            let (x, _) = to_px(*v, ya.lo);
            c.rect(x, top, x, bottom, GRID);
            c.rect(x, bottom, x, bottom + 5, BLACK);
            c.text(x - text_px(label) / 2, bottom + 10, label, BLACK, false);
        }
        for (v, label) in &ya.ticks {
            let (_, y) = to_px(xa.lo, *v);
            c.rect(left, y, right, y, GRID);
            c.rect(left - 5, y, left, y, BLACK);
            let h = (font::HEIGHT * SCALE) as i64;
            c.text(left - 10 - text_px(label), y - h / 2, label, BLACK, false);
        }
        // Frame.
        c.rect(left, top, right, top, BLACK);
        c.rect(left, bottom, right, bottom, BLACK);
        c.rect(left, top, left, bottom, BLACK);
        c.rect(right, top, right, bottom, BLACK);
        // Title and axis labels.
        c.text(
            (WIDTH as i64 - text_px(&self.title)) / 2,
            16,
            &self.title,
            BLACK,
            false,
        );
        c.text(
            (left + right - text_px(&self.x_label)) / 2,
            bottom + 10 + LINE_HEIGHT as i64 + 8,
            &self.x_label,
            BLACK,
            false,
        );
        c.text(
            16,
            (top + bottom + text_px(&self.y_label)) / 2,
            &self.y_label,
            BLACK,
            true,
        );

        let clip = [left + 1, top + 1, right - 1, bottom - 1];
        for (k, s) in self.series.iter().enumerate() {
            let colour = series_colour(k);
            let ok: Vec<bool> = s.points.iter().map(|&p| self.drawable(p)).collect();
            for (i, &p) in s.points.iter().enumerate() {
                if !ok[i] {
                    continue;
                }
                let a = to_px(p.0, p.1);
                let next = ok.get(i + 1).copied().unwrap_or(false);
                if next {
                    let q = s.points[i + 1];
                    c.line(a, to_px(q.0, q.1), colour, clip);
                }
                let prev = i > 0 && ok[i - 1];
                if !next && !prev {
                    c.rect(a.0 - 3, a.1 - 3, a.0 + 3, a.1 + 3, colour);
                }
            }
        }

        // Legend, in the inside corner that covers the fewest drawn pixels.
        if self.series.iter().any(|s| !s.label.is_empty()) {
            let widest = self
                .series
                .iter()
                .map(|s| text_px(&s.label))
                .max()
                .unwrap_or(0);
            let (w, h) = (widest + 48, (self.series.len() * LINE_HEIGHT) as i64 + 12);
            let corners = [
                (right - 10 - w, top + 10),
                (left + 10, top + 10),
                (right - 10 - w, bottom - 10 - h),
                (left + 10, bottom - 10 - h),
            ];
            let (x0, y0) = corners
                .into_iter()
                .min_by_key(|&(x, y)| c.count_not(x, y, x + w, y + h, &[WHITE, GRID]))
                .unwrap_or(corners[0]);
            c.rect(x0, y0, x0 + w, y0 + h, WHITE);
            c.rect(x0, y0, x0 + w, y0, BLACK);
            c.rect(x0, y0 + h, x0 + w, y0 + h, BLACK);
            c.rect(x0, y0, x0, y0 + h, BLACK);
            c.rect(x0 + w, y0, x0 + w, y0 + h, BLACK);
            for (k, s) in self.series.iter().enumerate() {
                let y = y0 + 6 + (k * LINE_HEIGHT) as i64;
                let mid = y + (font::HEIGHT * SCALE / 2) as i64;
                c.rect(x0 + 6, mid - 1, x0 + 30, mid, series_colour(k));
                c.text(x0 + 38, y, &s.label, BLACK, false);
            }
        }
        Ok(c.px)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_are_1_2_5_decades() {
        assert_eq!(nice_step(10.0, 5.0), 2.0);
        assert_eq!(nice_step(1.0, 6.0), 0.2);
        assert!((nice_step(0.03, 6.0) - 0.005).abs() < 1e-15);
        assert_eq!(nice_step(700.0, 6.0), 100.0);
    }

    #[test]
    fn tick_labels_have_just_enough_digits() {
        assert_eq!(tick_label(0.25, 0.05, 1.0), "0.25");
        assert_eq!(tick_label(3.0, 1.0, 10.0), "3");
        assert_eq!(tick_label(1e-17, 0.1, 1.0), "0");
        assert_eq!(tick_label(2.5e6, 5e5, 3e6), "2.5e6");
        assert_eq!(tick_label(4e-5, 1e-5, 1e-4), "4e-5");
    }

    #[test]
    fn constant_data_gets_a_range_around_it() {
        let a = linear_axis(300.0, 300.0, true);
        assert!(a.lo < 300.0 && a.hi > 300.0 && a.hi - a.lo <= 100.0);
        let l = log_axis(1e-3, 1e-3);
        assert!(l.lo < 1e-3 && l.hi > 1e-3);
    }
}
