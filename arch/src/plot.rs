//! Line plots as SVG and PNG (plotters; text set in the DejaVu Sans subset of `assets/`, so no
//! system font libraries): several series, axis labels with units, a legend and optional
//! reference markers such as an experiment's value.

use std::path::Path;

use plotters::prelude::*;

use voussoir::error::{Error, Result};

/// The curves' colours, in order: dark, saturated and told apart by colour-blind readers
/// (Okabe–Ito, without its yellow, which was all but invisible on white).
const CURVE_COLORS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// One named curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// `(x, y)` points in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// A reference drawn over the curves.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// A horizontal line at `y` (for example an experimental peak load).
    Horizontal {
        /// Legend label.
        label: String,
        /// Ordinate.
        y: f64,
    },
    /// A single marked point (for example a measured value).
    Point {
        /// Legend label.
        label: String,
        /// Abscissa.
        x: f64,
        /// Ordinate.
        y: f64,
    },
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// The corner that covers the fewest curve points and no reference marker if it can
    /// (preference on a tie: upper right, upper left, lower right, lower left).
    #[default]
    Auto,
    /// Upper left corner.
    UpperLeft,
    /// Upper right corner.
    UpperRight,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
}

/// A line plot: title, axis labels (with units), curves and references.
///
/// ```
/// use voussoir_arch::plot::{Curve, LegendPosition, LinePlot, Reference};
/// let plot = LinePlot {
///     title: "load–displacement".into(),
///     x_label: "displacement [mm]".into(),
///     y_label: "load [kN]".into(),
///     curves: vec![Curve { label: "model".into(), points: vec![(0.0, 0.0), (1.0, 2.5), (2.0, 2.0)] }],
///     references: vec![Reference::Horizontal { label: "experiment".into(), y: 2.71 }],
///     legend: LegendPosition::Auto,
/// };
/// let svg = plot.to_svg_string()?;
/// assert!(svg.contains("<svg") && svg.contains("experiment"));
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinePlot {
    /// Title.
    pub title: String,
    /// Horizontal axis label, with its unit.
    pub x_label: String,
    /// Vertical axis label, with its unit.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
    /// Reference lines and points.
    pub references: Vec<Reference>,
    /// Where the legend goes.
    pub legend: LegendPosition,
}

const SIZE: (u32, u32) = (800, 560);

/// The largest coordinate magnitude drawn: larger finite values are clamped to ±1e300 (they lie
/// off any sensible chart anyway), so that spans and paddings cannot overflow to infinity.
/// Non-finite points and references are skipped.
pub const COORDINATE_LIMIT: f64 = 1e300;

/// DejaVu Sans, subset to Latin-1, Greek, punctuation, super- and subscripts, arrows and
/// mathematical operators (`assets/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans-subset.ttf");

/// Gives plotters the font for "sans-serif" in every style (once): the PNG backend draws its
/// glyphs, and both backends measure text with it (legend boxes, label areas).
fn register_fonts() {
    static DONE: std::sync::Once = std::sync::Once::new();
    DONE.call_once(|| {
        for style in [
            FontStyle::Normal,
            FontStyle::Bold,
            FontStyle::Italic,
            FontStyle::Oblique,
        ] {
            // The font is checked by the tests (`png_plots_have_text`); should it ever fail to
            // load, text would be missing, which the tests see.
            let _ = plotters::style::register_font("sans-serif", style, FONT);
        }
    });
}

fn clamp(v: f64) -> f64 {
    v.clamp(-COORDINATE_LIMIT, COORDINATE_LIMIT)
}

/// A curve's finite points, clamped to ±[`COORDINATE_LIMIT`].
fn drawable_points(c: &Curve) -> impl Iterator<Item = (f64, f64)> + '_ {
    c.points
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|&(x, y)| (clamp(x), clamp(y)))
}

/// A padded axis range over finite values within ±[`COORDINATE_LIMIT`] (`(0, 1)` if there are
/// none): 5 % of the span either side, or ±half the magnitude (at least ±0.5) when the values
/// are equal or closer than 1e-9 of their magnitude (or 1e-100), spans that plotters cannot
/// divide into ticks.
fn span(v: &[f64]) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let width = hi - lo;
    let magnitude = lo.abs().max(hi.abs());
    if width <= 1e-9 * magnitude || width < 1e-100 {
        let centre = lo + 0.5 * width;
        let pad = 0.5 * centre.abs().max(1.0);
        return (centre - pad, centre + pad);
    }
    let pad = 0.05 * width;
    (lo - pad, hi + pad)
}

impl LinePlot {
    /// Renders the plot as an SVG document. Total over any input: points and references with a
    /// non-finite coordinate are skipped, finite coordinates beyond ±[`COORDINATE_LIMIT`] are
    /// clamped to it, and an empty or single-valued axis gets a default span.
    ///
    /// # Errors
    /// [`Error::Io`] if plotters fails to draw.
    pub fn to_svg_string(&self) -> Result<String> {
        let mut svg = String::new();
        {
            register_fonts();
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            self.draw(root).map_err(|e| Error::Io {
                path: "(svg)".into(),
                message: format!("plot {:?}: {e}", self.title),
            })?;
        }
        Ok(svg)
    }

    /// Writes the plot to an SVG file, creating its folder.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        let svg = self.to_svg_string()?;
        voussoir::io::write_atomically(path, svg.as_bytes())
    }

    /// Renders the plot as a PNG image (800 × 560 pixels, RGB), as total over any input as
    /// [`LinePlot::to_svg_string`].
    ///
    /// # Errors
    /// [`Error::Io`] if plotters fails to draw or the image cannot be encoded.
    pub fn to_png_bytes(&self) -> Result<Vec<u8>> {
        let fail = |e: String| Error::Io {
            path: "(png)".into(),
            message: format!("plot {:?}: {e}", self.title),
        };
        let (w, h) = SIZE;
        let mut pixels = vec![0u8; 3 * w as usize * h as usize];
        {
            register_fonts();
            let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
            self.draw(root).map_err(fail)?;
        }
        let mut png = Vec::new();
        let mut encoder = png::Encoder::new(&mut png, w, h);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder
            .write_header()
            .and_then(|mut writer| writer.write_image_data(&pixels))
            .map_err(|e| fail(e.to_string()))?;
        Ok(png)
    }

    /// Writes the plot to a PNG file (atomically), creating its folder.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        let png = self.to_png_bytes()?;
        voussoir::io::write_atomically(path, &png)
    }

    /// The axis ranges: every finite curve point and reference, each coordinate clamped to
    /// ±[`COORDINATE_LIMIT`], padded by 5 % of the span. Always finite with `lo < hi` and a
    /// span that is neither zero nor below plotters' resolution at that magnitude (a single
    /// value, or values closer than 1e-9 of their magnitude, get a span of about their
    /// magnitude), so plotters' key-point search terminates.
    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let mut xs: Vec<f64> = Vec::new();
        let mut ys: Vec<f64> = Vec::new();
        for (x, y) in self.curves.iter().flat_map(drawable_points) {
            xs.push(x);
            ys.push(y);
        }
        for r in self.drawable_references() {
            match *r {
                Reference::Horizontal { y, .. } => ys.push(clamp(y)),
                Reference::Point { x, y, .. } => {
                    xs.push(clamp(x));
                    ys.push(clamp(y));
                }
            }
        }
        (span(&xs), span(&ys))
    }

    /// The references whose coordinates are all finite (the others are skipped).
    fn drawable_references(&self) -> impl Iterator<Item = &Reference> {
        self.references.iter().filter(|r| match **r {
            Reference::Horizontal { y, .. } => y.is_finite(),
            Reference::Point { x, y, .. } => x.is_finite() && y.is_finite(),
        })
    }

    /// The legend corner: the given one, or for [`LegendPosition::Auto`] the corner whose
    /// legend box (estimated from the number of entries and the longest label) covers the
    /// fewest curve points (segments sampled at 16 points each) — a reference marker or line
    /// counts as 1000 points.
    fn legend_corner(&self, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> LegendPosition {
        if self.legend != LegendPosition::Auto {
            return self.legend;
        }
        let labels = self
            .curves
            .iter()
            .map(|c| c.label.as_str())
            .chain(self.drawable_references().map(|r| match r {
                Reference::Horizontal { label, .. } | Reference::Point { label, .. } => label.as_str(),
            }));
        let (count, longest) = labels.fold((0usize, 0usize), |(n, w), l| (n + 1, w.max(l.chars().count())));
        // Plot area about 700 × 430 px; legend rows 20 px, characters about 7.5 px, plus the
        // sample and margins (45 px).
        let w = ((longest as f64 * 7.5 + 45.0) / 700.0).min(1.0);
        let h = ((count as f64 * 20.0 + 10.0) / 430.0).min(1.0);
        let to_frac = |x: f64, y: f64| ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0));
        let corners = [
            (LegendPosition::UpperRight, (1.0 - w, 1.0), (1.0 - h, 1.0)),
            (LegendPosition::UpperLeft, (0.0, w), (1.0 - h, 1.0)),
            (LegendPosition::LowerRight, (1.0 - w, 1.0), (0.0, h)),
            (LegendPosition::LowerLeft, (0.0, w), (0.0, h)),
        ];
        let inside = |(fx, fy): (f64, f64), (ax, bx): (f64, f64), (ay, by): (f64, f64)| {
            fx >= ax && fx <= bx && fy >= ay && fy <= by
        };
        let mut best = (LegendPosition::UpperRight, f64::INFINITY);
        for (corner, bx, by) in corners {
            let mut score = 0.0;
            for c in &self.curves {
                let points: Vec<(f64, f64)> = drawable_points(c).collect();
                for pair in points.windows(2) {
                    let ((xa, ya), (xb, yb)) = (pair[0], pair[1]);
                    for k in 0..16 {
                        let t = k as f64 / 16.0;
                        if inside(to_frac(xa + t * (xb - xa), ya + t * (yb - ya)), bx, by) {
                            score += 1.0;
                        }
                    }
                }
                if let Some(&(x, y)) = points.last() {
                    if inside(to_frac(x, y), bx, by) {
                        score += 1.0;
                    }
                }
            }
            for r in self.drawable_references() {
                let hit = match *r {
                    Reference::Point { x, y, .. } => {
                        // The marker's half-size, about 10 px.
                        let (fx, fy) = to_frac(clamp(x), clamp(y));
                        let (mx, my) = (10.0 / 700.0, 10.0 / 430.0);
                        fx + mx >= bx.0 && fx - mx <= bx.1 && fy + my >= by.0 && fy - my <= by.1
                    }
                    Reference::Horizontal { y, .. } => {
                        let fy = to_frac(x0, clamp(y)).1;
                        fy >= by.0 && fy <= by.1
                    }
                };
                if hit {
                    score += 1000.0;
                }
            }
            if score < best.1 {
                best = (corner, score);
            }
        }
        best.0
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, plotters::coord::Shift>) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for (k, c) in self.curves.iter().enumerate() {
            let color = CURVE_COLORS[k % CURVE_COLORS.len()];
            chart
                .draw_series(LineSeries::new(drawable_points(c), color.stroke_width(2)))
                .map_err(err)?
                .label(c.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            // Where the curve ends (a run stopped by a collapse, or at its end): a dot.
            if let Some(last) = drawable_points(c).last() {
                chart
                    .draw_series(std::iter::once(Circle::new(last, 4, color.filled())))
                    .map_err(err)?;
            }
        }
        let mut marker = 0usize;
        for r in self.drawable_references() {
            match r {
                Reference::Horizontal { label, y } => {
                    let y = clamp(*y);
                    let style = BLACK.stroke_width(1);
                    chart
                        .draw_series(DashedLineSeries::new(vec![(x0, y), (x1, y)], 8, 5, style))
                        .map_err(err)?
                        .label(label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                }
                Reference::Point { label, x, y } => {
                    // Each point its own symbol, so that the legend tells them apart.
                    let at = (clamp(*x), clamp(*y));
                    let style = BLACK.stroke_width(2);
                    let kind = marker % 4;
                    marker += 1;
                    let series = match kind {
                        0 => chart.draw_series(std::iter::once(EmptyElement::at(at) + Cross::new((0, 0), 7, style))),
                        1 => chart.draw_series(std::iter::once(
                            EmptyElement::at(at) + TriangleMarker::new((0, 0), 8, style),
                        )),
                        2 => chart.draw_series(std::iter::once(EmptyElement::at(at) + Circle::new((0, 0), 7, style))),
                        _ => chart.draw_series(std::iter::once(
                            EmptyElement::at(at) + Rectangle::new([(-6, -6), (6, 6)], style),
                        )),
                    }
                    .map_err(err)?;
                    series
                        .label(label.as_str())
                        .legend(move |(x, y)| -> DynElement<'static, DB, (i32, i32)> {
                            match kind {
                                0 => Cross::new((x + 10, y), 5, style).into_dyn(),
                                1 => TriangleMarker::new((x + 10, y), 6, style).into_dyn(),
                                2 => Circle::new((x + 10, y), 5, style).into_dyn(),
                                _ => Rectangle::new([(x + 5, y - 5), (x + 15, y + 5)], style).into_dyn(),
                            }
                        });
                }
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(match self.legend_corner((x0, x1), (y0, y1)) {
                LegendPosition::UpperLeft => SeriesLabelPosition::UpperLeft,
                LegendPosition::LowerLeft => SeriesLabelPosition::LowerLeft,
                LegendPosition::LowerRight => SeriesLabelPosition::LowerRight,
                LegendPosition::UpperRight | LegendPosition::Auto => SeriesLabelPosition::UpperRight,
            })
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PNG plot is a picture of the plot: its size, a white background, the first curve's
    /// colour, and text (the title's dark pixels), with labels beyond ASCII (φ, °, ², –).
    #[test]
    fn png_plots_have_text() {
        let plot = LinePlot {
            title: "capacity – φ 35°, kn 4 GPa/m²".into(),
            x_label: "φ (°)".into(),
            y_label: "P (kN)".into(),
            curves: vec![curve(vec![(0.0, 0.0), (1.0, 1.0), (2.0, 0.5)])],
            ..Default::default()
        };
        let bytes = plot.to_png_bytes().expect("renders");
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .expect("a PNG");
        let mut pixels = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut pixels).expect("decodes");
        assert_eq!((info.width, info.height), SIZE);
        let rgb = |x: usize, y: usize| {
            let i = 3 * (y * info.width as usize + x);
            (pixels[i], pixels[i + 1], pixels[i + 2])
        };
        assert_eq!(rgb(2, 2), (255, 255, 255), "white background");
        let dark = |y0: usize, y1: usize| {
            (y0..y1)
                .flat_map(|y| (0..info.width as usize).map(move |x| (x, y)))
                .filter(|&(x, y)| {
                    let (r, g, b) = rgb(x, y);
                    u16::from(r) + u16::from(g) + u16::from(b) < 200
                })
                .count()
        };
        assert!(dark(0, 40) > 200, "the title is set: {} dark pixels", dark(0, 40));
        let c = CURVE_COLORS[0];
        let curve_pixels = (0..info.height as usize)
            .flat_map(|y| (0..info.width as usize).map(move |x| (x, y)))
            .filter(|&(x, y)| rgb(x, y) == (c.0, c.1, c.2))
            .count();
        assert!(curve_pixels > 300, "the curve is drawn: {curve_pixels} pixels");
    }

    /// The impact benchmark's plot: three test markers rising to the upper right, model curves
    /// low. The legend must not go to the upper right, where it would hide the M60H30 marker.
    #[test]
    fn auto_legend_avoids_markers() {
        let model = |dy: f64| Curve {
            label: "model".into(),
            points: vec![(122.5, 15.0 + dy), (152.5, 17.0 + dy), (182.3, 18.0 + dy)],
        };
        let plot = LinePlot {
            curves: vec![model(0.0), model(-1.0), model(1.0)],
            references: [(122.5, 34.0), (152.5, 40.0), (182.3, 53.0)]
                .iter()
                .map(|&(x, y)| Reference::Point {
                    label: "test".into(),
                    x,
                    y,
                })
                .collect(),
            ..Default::default()
        };
        let ((x0, x1), (y0, y1)) = plot.ranges();
        assert_eq!(plot.legend_corner((x0, x1), (y0, y1)), LegendPosition::UpperLeft);
        let fixed = LinePlot {
            legend: LegendPosition::LowerRight,
            ..plot
        };
        assert_eq!(fixed.legend_corner((x0, x1), (y0, y1)), LegendPosition::LowerRight);
    }

    /// Renders `plot` on another thread and fails if it does not return within 10 s (on the
    /// code before issue 18 an infinite reference or a ±1e308 point looped forever in plotters'
    /// key-point computation).
    fn renders_quickly(plot: LinePlot) -> String {
        let (tx, rx) = std::sync::mpsc::channel();
        let title = plot.title.clone();
        std::thread::spawn(move || {
            let _ = tx.send(plot.to_svg_string());
        });
        match rx.recv_timeout(std::time::Duration::from_secs(10)) {
            Ok(Ok(svg)) => svg,
            Ok(Err(e)) => panic!("plot {title:?} failed: {e}"),
            Err(_) => panic!("plot {title:?} did not finish within 10 s"),
        }
    }

    fn curve(points: Vec<(f64, f64)>) -> Curve {
        Curve {
            label: "model".into(),
            points,
        }
    }

    #[test]
    fn infinite_reference_does_not_hang() {
        for y in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            let plot = LinePlot {
                title: format!("reference at {y}"),
                curves: vec![curve(vec![(0.0, 0.0), (1.0, 2.0)])],
                references: vec![
                    Reference::Horizontal {
                        label: "experiment".into(),
                        y,
                    },
                    Reference::Point {
                        label: "test".into(),
                        x: y,
                        y: 1.0,
                    },
                ],
                ..Default::default()
            };
            let svg = renders_quickly(plot);
            assert!(svg.contains("<svg"));
        }
    }

    #[test]
    fn extreme_points_do_not_hang() {
        let cases: Vec<Vec<(f64, f64)>> = vec![
            vec![(0.0, -1e308), (1.0, 1e308)],
            vec![(-1e308, 0.0), (1e308, 1.0)],
            vec![(-f64::MAX, -f64::MAX), (f64::MAX, f64::MAX)],
            vec![(0.0, f64::MAX), (1.0, f64::MAX)],
            vec![(0.0, 1.7e308), (1.0, 1.79e308)],
            vec![(0.0, 0.0), (1.0, 1e-310)],
            vec![(0.0, 1e15), (1.0, 1e15 + 0.125)],
            vec![(1e20, 0.0), (1e20 + 16384.0, 1.0)],
            vec![(0.0, 5e-324), (5e-324, 0.0)],
            vec![(f64::NAN, 1.0), (f64::INFINITY, f64::NEG_INFINITY)],
            vec![],
        ];
        for points in cases {
            let plot = LinePlot {
                title: format!("{points:?}"),
                curves: vec![curve(points)],
                references: vec![Reference::Horizontal {
                    label: "experiment".into(),
                    y: 1e308,
                }],
                ..Default::default()
            };
            let ((x0, x1), (y0, y1)) = plot.ranges();
            for (lo, hi) in [(x0, x1), (y0, y1)] {
                assert!(
                    lo.is_finite() && hi.is_finite() && (hi - lo).is_finite() && hi > lo,
                    "{lo}..{hi}"
                );
            }
            let svg = renders_quickly(plot);
            assert!(svg.contains("<svg"));
        }
    }
}
