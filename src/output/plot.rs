//! Line plots for a quick look at a run without ParaView: residual histories (with
//! `log_y`), temperatures along a line, heat per step.
//!
//! Entry points: [`Plot::write_svg`] (vector, text kept as text) and [`Plot::write_png`]
//! (a 960×640 RGB picture). Both are laid out by the `plotters` crate: a title, a framed
//! plot area with light grid lines at the ticks, tick labels, axis labels with their
//! units (the caller writes them into the labels: `T (K)`), and, when any series has a
//! label, a legend in the inside corner holding the fewest points (upper right on a
//! tie). The PNG's text is DejaVu Sans, carried in the binary and rasterised in pure Rust
//! (ab_glyph), so no system font library is needed. Series get the colours of
//! [`series_colour`] in order and are drawn as 2-pixel lines between consecutive
//! drawable points; a point with no drawable neighbour gets a square marker.
//!
//! Ranges: x spans the drawable points and y the same (in decades with `log_y`, drawn
//! as `log10 y` with labels `1e-5`), each widened by a margin of 2 % (x) and 4 % (y)
//! to keep lines off the frame. Non-finite points are skipped, and with `log_y` so are
//! points with `y ≤ 0`; a range of one value is widened by ±1 (±10 % of the value when
//! that is larger), or by half a decade on a log axis.

use std::io;
use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

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

/// Image width and height in pixels (the SVG's size in user units too).
pub const WIDTH: usize = 960;
pub const HEIGHT: usize = 640;

/// The family name the bundled font is registered under.
const FONT: &str = "sans-serif";

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

/// Hand DejaVu Sans to plotters' text layout, once per process.
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font shipped by the `dejavu` crate; should
        // they not parse, plotters reports the missing font when it draws text.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// The data ranges of a plot: x and the drawn y (log10 y on a log axis).
struct Ranges {
    x: (f64, f64),
    y: (f64, f64),
}

/// `[lo, hi]` widened when it is one value (±1, or ±10 % when larger), then by `margin`
/// of its extent at each end.
fn widen(lo: f64, hi: f64, one_value: f64, margin: f64) -> (f64, f64) {
    let (lo, hi) = if lo == hi {
        (lo - one_value, hi + one_value)
    } else {
        (lo, hi)
    };
    let d = margin * (hi - lo);
    (lo - d, hi + d)
}

/// A tick label for `v` on a linear axis spanning `(lo, hi)`: every label with the same
/// number of decimals, just enough for ticks about an eighth of the span apart;
/// scientific for very large or small magnitudes.
fn tick_label(v: f64, (lo, hi): (f64, f64)) -> String {
    let step = 10f64.powf(((hi - lo) / 8.0).log10().floor());
    if v.abs() < step * 1e-6 {
        return "0".to_string();
    }
    let largest = lo.abs().max(hi.abs());
    let step_exp = step.log10().floor() as i32;
    if !(1e-3..1e5).contains(&largest) {
        let exp = v.abs().log10().floor() as i32;
        let digits = (exp - step_exp).clamp(0, 6) as usize;
        format!("{v:.digits$e}")
    } else {
        let decimals = (-step_exp).clamp(0, 9) as usize;
        format!("{v:.decimals$}")
    }
}

/// A label for `v` on a log axis drawn as log10: `1e-5` at whole decades.
fn log_label(v: f64) -> String {
    let k = v.round();
    if (v - k).abs() < 1e-9 {
        match k as i32 {
            0 => "1".to_string(),
            1 => "10".to_string(),
            k => format!("1e{k}"),
        }
    } else {
        format!("{:.1e}", 10f64.powf(v))
    }
}

impl Plot {
    /// Draw the plot and write it to `path` as a PNG. Errors (`InvalidInput`) when there
    /// is no series, a series has no points, or no point at all can be drawn.
    pub fn write_png(&self, path: &Path) -> io::Result<()> {
        let ranges = self.ranges()?;
        let mut rgb = vec![255u8; 3 * WIDTH * HEIGHT];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH as u32, HEIGHT as u32))
                .into_drawing_area();
            self.draw(&root, &ranges)?;
            root.present().map_err(io::Error::other)?;
        }
        let file = std::fs::File::create(path)?;
        let mut enc = png::Encoder::new(io::BufWriter::new(file), WIDTH as u32, HEIGHT as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(io::Error::other)?;
        w.write_image_data(&rgb).map_err(io::Error::other)?;
        w.finish().map_err(io::Error::other)
    }

    /// Draw the plot and write it to `path` as SVG, its text as `<text>` elements. The
    /// same errors as [`Plot::write_png`].
    pub fn write_svg(&self, path: &Path) -> io::Result<()> {
        let ranges = self.ranges()?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (WIDTH as u32, HEIGHT as u32))
                .into_drawing_area();
            self.draw(&root, &ranges)?;
            root.present().map_err(io::Error::other)?;
        }
        std::fs::write(path, svg)
    }

    fn drawable(&self, p: (f64, f64)) -> bool {
        p.0.is_finite() && p.1.is_finite() && (!self.log_y || p.1 > 0.0)
    }

    /// Where a point is drawn: y as log10 y on a log axis.
    fn at(&self, p: (f64, f64)) -> (f64, f64) {
        if self.log_y { (p.0, p.1.log10()) } else { p }
    }

    /// Check the plot can be drawn and find its ranges.
    fn ranges(&self) -> io::Result<Ranges> {
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
                let (x, y) = self.at(*p);
                lo = [lo[0].min(x), lo[1].min(y)];
                hi = [hi[0].max(x), hi[1].max(y)];
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
        let one = |v: f64| (v.abs() * 0.1).max(1.0);
        let y_one = if self.log_y { 0.5 } else { one(lo[1]) };
        Ok(Ranges {
            x: widen(lo[0], hi[0], one(lo[0]), 0.02),
            y: widen(lo[1], hi[1], y_one, 0.04),
        })
    }

    /// The legend's corner: the one whose inside region covers the least of the drawn
    /// lines and markers (upper right, upper left, lower right, lower left on a tie).
    /// Lines are sampled at 64 places per segment, in fractions of the plot area; a lone
    /// point's marker counts as much as a segment.
    fn legend_corner(&self, r: &Ranges) -> SeriesLabelPosition {
        let longest = self.series.iter().map(|s| s.label.chars().count()).max();
        let w = (0.06 + 0.011 * longest.unwrap_or(0) as f64).min(0.9);
        let h = (0.045 * self.series.len() as f64 + 0.03).min(0.9);
        let frac =
            |(x, y): (f64, f64)| ((x - r.x.0) / (r.x.1 - r.x.0), (y - r.y.0) / (r.y.1 - r.y.0));
        let mut samples = Vec::new();
        for s in &self.series {
            let ok: Vec<bool> = s.points.iter().map(|&p| self.drawable(p)).collect();
            for (i, &p) in s.points.iter().enumerate() {
                if !ok[i] {
                    continue;
                }
                let a = frac(self.at(p));
                samples.push(a);
                let next = ok.get(i + 1).copied().unwrap_or(false);
                let prev = i > 0 && ok[i - 1];
                if !next && !prev {
                    // A marker is all there is of its point: as costly to hide as a segment.
                    samples.extend(std::iter::repeat_n(a, 63));
                } else if next {
                    let b = frac(self.at(s.points[i + 1]));
                    for k in 1..64 {
                        let t = f64::from(k) / 64.0;
                        samples.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
                    }
                }
            }
        }
        let count = |right: bool, upper: bool| {
            samples
                .iter()
                .filter(|&&(fx, fy)| {
                    let in_x = if right { fx >= 1.0 - w } else { fx <= w };
                    let in_y = if upper { fy >= 1.0 - h } else { fy <= h };
                    in_x && in_y
                })
                .count()
        };
        [
            (SeriesLabelPosition::UpperRight, true, true),
            (SeriesLabelPosition::UpperLeft, false, true),
            (SeriesLabelPosition::LowerRight, true, false),
            (SeriesLabelPosition::LowerLeft, false, false),
        ]
        .into_iter()
        .min_by_key(|&(_, right, upper)| count(right, upper))
        .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        r: &Ranges,
    ) -> io::Result<()> {
        register_font();
        let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| io::Error::other(e.to_string());
        root.fill(&WHITE).map_err(fail)?;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 24))
            .margin(16)
            .x_label_area_size(56)
            .y_label_area_size(88)
            .build_cartesian_2d(r.x.0..r.x.1, r.y.0..r.y.1)
            .map_err(fail)?;
        let log_label = |v: &f64| log_label(*v);
        let x_label = |v: &f64| tick_label(*v, r.x);
        let y_label = |v: &f64| tick_label(*v, r.y);
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .bold_line_style(RGBColor(225, 225, 225))
            .light_line_style(TRANSPARENT)
            .x_labels(8)
            .y_labels(10)
            .x_label_formatter(&x_label)
            .y_label_formatter(&y_label);
        if self.log_y {
            mesh.y_label_formatter(&log_label);
        }
        mesh.draw().map_err(fail)?;
        // The frame's top and right sides (the axes drew the other two).
        let frame = [(r.x.0, r.y.1), (r.x.1, r.y.1), (r.x.1, r.y.0)];
        chart
            .draw_series(std::iter::once(PathElement::new(frame, BLACK)))
            .map_err(fail)?;

        for (k, s) in self.series.iter().enumerate() {
            let [red, green, blue] = series_colour(k);
            let colour = RGBColor(red, green, blue);
            let style = colour.stroke_width(2);
            // Runs of consecutive drawable points are lines; a lone point is a square.
            let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
            for &p in &s.points {
                if self.drawable(p) {
                    runs.last_mut().expect("a run").push(self.at(p));
                } else if !runs.last().is_some_and(Vec::is_empty) {
                    runs.push(Vec::new());
                }
            }
            let mut labelled = false;
            for run in runs.into_iter().filter(|r| !r.is_empty()) {
                let anno = if run.len() == 1 {
                    let (x, y) = run[0];
                    chart.draw_series(std::iter::once(
                        EmptyElement::at((x, y))
                            + Rectangle::new([(-3, -3), (3, 3)], colour.filled()),
                    ))
                } else {
                    chart.draw_series(LineSeries::new(run, style))
                }
                .map_err(fail)?;
                if !labelled && !s.label.is_empty() {
                    labelled = true;
                    anno.label(s.label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
                }
            }
        }
        if self.series.iter().any(|s| !s.label.is_empty()) {
            chart
                .configure_series_labels()
                .position(self.legend_corner(r))
                .label_font((FONT, 16))
                .background_style(WHITE)
                .border_style(BLACK)
                .draw()
                .map_err(fail)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_labels_name_the_decades() {
        assert_eq!(log_label(-5.0), "1e-5");
        assert_eq!(log_label(0.0), "1");
        assert_eq!(log_label(1.0), "10");
        assert_eq!(log_label(2.0), "1e2");
        assert_eq!(log_label(0.5), "3.2e0");
    }

    #[test]
    fn tick_labels_share_their_decimals() {
        assert_eq!(tick_label(9.9, (9.6, 10.02)), "9.90");
        assert_eq!(tick_label(100.0, (-2.0, 410.0)), "100");
        assert_eq!(tick_label(0.0005, (-0.0011, 0.0031)), "0.0005");
        assert_eq!(tick_label(1e-17, (0.0, 1.0)), "0");
        assert_eq!(tick_label(2.5e6, (0.0, 3e6)), "2.5e6");
        assert_eq!(tick_label(4e-5, (0.0, 1e-4)), "4e-5");
    }

    #[test]
    fn constant_data_gets_a_range_around_it() {
        let (lo, hi) = widen(300.0, 300.0, 30.0, 0.04);
        assert!(lo < 300.0 && hi > 300.0 && hi - lo <= 100.0);
        let (lo, hi) = widen(-3.0, -3.0, 0.5, 0.04);
        assert!(lo < -3.0 && hi > -3.0);
    }
}
